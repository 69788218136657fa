"""Path-following and actuator-use metrics: the compiled accumulator against the NumPy reference,
hand-computed cases, and whole runs (the engine's numbers against the reference on the logged trajectory).
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import auvtrack
from auvtrack.metrics import (LIMIT_TOL, METRIC_NAMES, METRICS_SIZE, PATH_NAMES, effort_update, metrics_finalize,
                              metrics_from_trajectory, metrics_init, metrics_update, path_update)
from auvtrack.reference import Circle, Helix, Lawnmower, Line, Waypoints
from auvtrack.scenario import paper_scenario_path

NEW = tuple(METRIC_NAMES[METRIC_NAMES.index("xtrack_rmse"):])
PATHS = {
    "helix": Helix(radius=30.0, omega=1.25 / 30.0, climb=0.05, center=(-30.0, 0.0, 2.0)),
    "circle": Circle(radius=12.0, omega=0.1, depth=4.0),
    "line": Line(start=(0.0, 0.0, 5.0), velocity=(1.0, 0.5, 0.0)),
    "lawnmower": Lawnmower(leg_length=10.0, spacing=16.0, legs=3, speed=1.25, depth=5.0),
    "waypoints": Waypoints(points=[[0.0, 0.0, 2.0], [30.0, 0.0, 4.0], [50.0, 20.0, 6.0]], speed=1.25),
}


def run_accumulator(t, position, path, effort, t0=0.0, t1=math.inf, t_late=None):
    """Feed the compiled accumulator as the engine does (left-point values, every step)."""
    acc = np.zeros(METRICS_SIZE)
    metrics_init(acc)
    packed = path.pack()
    t_late = 0.5 * (t0 + min(t1, t[-1])) if t_late is None else t_late
    z3 = np.zeros(3)
    for k in range(t.size - 1):
        dt = t[k + 1] - t[k]
        metrics_update(acc, t[k], dt, z3, z3, t0, t1)
        path_update(acc, t[k], dt, tuple(position[k]), packed, t0, t1, t_late)
        effort_update(acc, t[k], dt, tuple(effort[k]), t0, t1)
    return metrics_finalize(acc, t0, min(t1, t[-1]))


def _close(a, b, names, rel, abs_=0.0):
    for n in names:
        x, y = a[n], b[n]
        if math.isnan(x) or math.isnan(y):
            assert math.isnan(x) and math.isnan(y), n
        else:
            assert math.isclose(x, y, rel_tol=rel, abs_tol=abs_), (n, x, y)


@st.composite
def runs_near_a_path(draw):
    kind = draw(st.sampled_from(sorted(PATHS)))
    path = PATHS[kind]
    n = draw(st.integers(2, 300))
    dt = draw(st.sampled_from([1e-3, 2e-3, 5e-3, 0.01, 0.03]))
    # steps of up to 0.2 s (the engine's are ms: each projection starts near the previous one)
    t = np.arange(n) * min(40.0 / n, 0.2) if draw(st.booleans()) else np.arange(n) * dt
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    lag = draw(st.floats(-1.0, 1.0))
    pos, _, _ = path.evaluate(t + lag)  # before 0 a lawnmower and a spline hold their start
    position = pos + rng.normal(0.0, draw(st.sampled_from([0.01, 0.1, 0.3])), (n, 3))
    effort = np.clip(np.abs(rng.normal(0.5, 0.5, (n, 3))), 0.0, 1.0)
    span = t[-1] - t[0]
    t0 = draw(st.sampled_from([0.0, 0.25, 0.5])) * span
    t1 = draw(st.sampled_from([math.inf, t0 + 0.6 * span]))
    return t, position, path, effort, t0, t1


@settings(max_examples=40)
@given(runs_near_a_path())
def test_compiled_matches_reference(case):
    t, position, path, effort, t0, t1 = case
    got = run_accumulator(t, position, path, effort, t0, t1)
    ref = metrics_from_trajectory(t, np.zeros((t.size, 3)), np.zeros((t.size, 3)), t0, t1, position=position,
                                  path=path, effort=effort)
    assert list(got) == list(METRIC_NAMES) and list(ref) == list(METRIC_NAMES)
    # Both projections accept a step only when it decreases D(s) = |p - eta_d(s)|^2, which near its
    # minimum d^2 grows by |eta_d'|^2 ds^2 while its rounding is about eps d (d + 2 |p|) (the
    # differences p - eta_d are rounded to eps |p|): a search ends within about
    # sqrt(eps d (d + 2 |p|)) / |eta_d'| of the minimum (s of path time) whatever its start, and the
    # accumulator warm-starts from its previous answer while the reference does not.  The along-track
    # error moves by |eta_d'| ds, i.e. by up to about sqrt(eps d (d + 2 |p|)) (m); the cross- and
    # vertical-track errors only to second order.  d <= the distance to any path point, e.g. eta_d(t).
    along = tuple(n for n in NEW if n.startswith("along"))
    d = float(np.max(np.linalg.norm(position - path.evaluate(t)[0], axis=1)))
    p_max = float(np.max(np.linalg.norm(position, axis=1)))
    resolution = math.sqrt(np.finfo(float).eps * d * (d + 2.0 * p_max))
    _close(got, ref, tuple(n for n in NEW if n not in along), rel=1e-7, abs_=1e-9)
    _close(got, ref, along, rel=1e-7, abs_=max(1e-9, 4.0 * resolution))


def test_without_position_or_effort_the_reference_reports_nan():
    t = np.arange(5.0)
    m = metrics_from_trajectory(t, np.zeros((5, 3)), np.zeros((5, 3)))
    assert all(math.isnan(m[k]) for k in NEW)


def test_offset_and_late_vehicle_on_a_line_by_hand():
    """Navigation point 0.3 m right of, 0.2 m below and 1.5 s behind a north-east line at 1.25 m/s:
    xtrack 0.3, vtrack 0.2, along -1.875 m, over the whole window and its second half."""
    V, lag = 1.25, 1.5
    d = np.array([math.cos(0.3), math.sin(0.3), 0.0])
    line = Line(start=(2.0, -1.0, 5.0), velocity=tuple(V * d))
    right = np.array([-d[1], d[0], 0.0])
    t = np.arange(2001) * 0.01
    position = line.evaluate(t - lag)[0] + 0.3 * right + np.array([0.0, 0.0, 0.2])
    for m in (run_accumulator(t, position, line, np.zeros((t.size, 3)), 2.0, 18.0),
              metrics_from_trajectory(t, np.zeros((t.size, 3)), np.zeros((t.size, 3)), 2.0, 18.0,
                                      position=position, path=line, effort=np.zeros((t.size, 3)))):
        for suffix in ("", "_late"):
            assert m[f"xtrack_rmse{suffix}"] == pytest.approx(0.3, abs=1e-9)
            assert m[f"xtrack_max{suffix}"] == pytest.approx(0.3, abs=1e-9)
            assert m[f"vtrack_rmse{suffix}"] == pytest.approx(0.2, abs=1e-9)
            assert m[f"along_rmse{suffix}"] == pytest.approx(V * lag, abs=1e-9)


def test_the_late_half_is_the_second_half_of_the_window():
    """A cross-track error that is 1 m before t = 6 and 0 after: window [2, 10): the whole window's RMSE is
    sqrt(4 / 8), the second half's (from 6 s) is 0."""
    line = Line(start=(0.0, 0.0, 0.0), velocity=(1.0, 0.0, 0.0))
    t = np.arange(1201) * 0.01
    position = line.evaluate(t)[0] + np.where(t < 6.0 - 1e-9, 1.0, 0.0)[:, None] * np.array([0.0, 1.0, 0.0])
    m = run_accumulator(t, position, line, np.zeros((t.size, 3)), 2.0, 10.0)
    assert m["xtrack_rmse"] == pytest.approx(math.sqrt(0.5), rel=1e-12)
    assert m["xtrack_max"] == 1.0
    assert m["xtrack_rmse_late"] == 0.0 and m["xtrack_max_late"] == 0.0


def test_actuator_use_by_hand():
    """Fractions A |sin(2 pi f t)| clipped at 1 (A = 1.25): the time at the limit, the RMS and the rate
    (total variation per second of |sin| over whole half-periods: 4 f min(A, 1) ... computed on the samples)."""
    t = np.arange(10001) * 1e-3  # 10 s
    f = 0.5
    raw = 1.25 * np.abs(np.sin(2 * np.pi * f * t))
    frac = np.minimum(raw, 1.0)
    effort = np.column_stack([frac, 0.5 * np.ones_like(t), np.zeros_like(t)])
    m = run_accumulator(t, np.zeros((t.size, 3)), Line(velocity=(1.0, 0.0, 0.0)), effort)
    at_limit = np.sum(np.diff(t)[frac[:-1] >= 1.0 - LIMIT_TOL])
    # |sin x| >= 0.8 on a fraction 1 - 2 asin(0.8) / pi of the time
    assert m["t_act_limit_u"] == pytest.approx(at_limit, abs=1e-12)
    assert m["t_act_limit_u"] == pytest.approx(10.0 * (1 - 2 * math.asin(0.8) / math.pi), abs=0.02)
    assert m["act_max_u"] == 1.0 and m["act_max_q"] == 0.5 and m["act_max_r"] == 0.0
    assert m["act_rms_q"] == pytest.approx(0.5, rel=1e-12) and m["t_act_limit_q"] == 0.0
    # each half period (1 s) rises from 0 to 1 and falls back: total variation 2 per second
    assert m["act_rate_u"] == pytest.approx(2.0, rel=0.01)
    assert m["act_rate_q"] == 0.0


@pytest.mark.parametrize("overrides", [
    ["controller.kind=ftsmc", "sim.duration=4", "sim.log_dt=0.001", "actuator.tau_max=[400, 150, 150]"],
    ["controller.kind=pid", "sim.duration=3", "sim.dt=0.002", "sim.log_dt=0.002", "metrics.window=[1, 2.5]",
     "reference.kind=lawnmower", "reference.speed=0.5", "reference.leg_length=20.0", "reference.spacing=20.0",
     "initial.eta=[1.0, 0.2, 5.1, 0, 0]"],
])
def test_a_run_reports_the_reference_metrics_of_its_own_trajectory(overrides):
    """Logged every step, a run's path and actuator metrics are the NumPy reference's on its trajectory."""
    res = auvtrack.simulate(paper_scenario_path(), overrides)
    sc = res.scenario
    from auvtrack.reference import build_reference

    ref = build_reference(sc["reference"])
    tau = np.column_stack([res["tau_u"], res["tau_q"], res["tau_r"]])
    effort = np.abs(tau) / np.array([float(v) for v in sc["actuator"]["tau_max"]])
    t0, t1 = sc["metrics"]["window"]
    want = metrics_from_trajectory(res.t, np.zeros((res.t.size, 3)), tau, float(t0), float(t1),
                                   position=np.column_stack([res["x"], res["y"], res["z"]]), path=ref, effort=effort)
    _close(res.metrics, want, NEW, rel=1e-7, abs_=1e-9)
    assert res.ok and res.metrics["xtrack_rmse"] > 0.0


def test_a_6dof_run_reports_its_fins_and_propeller_use():
    """Open-loop rudder commanded to its limit on Fossen's REMUS: its first-order lag (T = 0.1 s) brings it
    within LIMIT_TOL of the limit after T ln(1 / LIMIT_TOL), where it stays; the stern planes never move;
    the engine's numbers are the reference's on the log."""
    sc = {"name": "rudder", "vehicle": {"preset": "remus100"}, "plant": {"model": "6dof", "preset": "remus100_fossen"},
          "reference": {"kind": "line", "velocity": [1.2, 0.0, 0.0], "start": [1.0, 0.0, 5.0]},
          "initial": {"eta": [0.0, 0.0, 5.0, 0.0, 0.0], "nu": [1.2, 0.0, 0.0, 0.0, 0.0]},
          "controller": {"kind": "open_loop_actuators", "rpm_trim": True, "delta_r": math.radians(15.0)},
          "sim": {"duration": 6.0, "dt": 0.002, "log_dt": 0.002}, "disturbance": []}
    res = auvtrack.simulate(sc)
    lim = res.scenario["resolved"]["plant"]["actuators"]
    effort = np.column_stack([np.abs(res["rpm"]) / lim["n_max"], np.abs(res["delta_s"]) / lim["delta_max"],
                              np.abs(res["delta_r"]) / lim["delta_max"]])
    want = metrics_from_trajectory(res.t, np.zeros((res.t.size, 3)), np.zeros((res.t.size, 3)),
                                   effort=effort)
    _close(res.metrics, want, [n for n in NEW if n.startswith(("act_", "t_act"))], rel=1e-12)
    assert res.metrics["act_max_r"] == pytest.approx(1.0, abs=1e-12) and res.metrics["act_max_q"] == 0.0
    assert lim["T_delta"] == 0.1 and lim["delta_max"] == math.radians(15.0)
    assert res.metrics["t_act_limit_r"] == pytest.approx(6.0 - 0.1 * math.log(1.0 / LIMIT_TOL), abs=0.01)
    assert all(math.isfinite(res.metrics[k]) for k in PATH_NAMES)


@pytest.mark.parametrize("kind", ["pid", "ftsmc", "backstepping", "sta"])
@pytest.mark.parametrize("ell", [0.5, 1.0])
def test_a_virtual_point_tracker_trails_the_reference_by_its_lever(kind, ell):
    """The path metrics measure the navigation point; a tracking law puts the virtual point (ell ahead of it)
    on eta_d(t).  Converged on a straight line (nominal plant, no disturbance, started off the path), the
    navigation point is therefore on the path, ell behind the reference: along-track error -ell, no
    cross- or vertical-track error (docs/metrics.md, "Path following at the navigation point")."""
    sc = {"name": "lever", "vehicle": {"l": ell}, "uncertainty": {"C": 0.0, "D": 0.0, "M": 0.0, "G": 0.0},
          "reference": {"kind": "line", "velocity": [1.0, 0.0, 0.0], "start": [0.0, 0.0, 5.0]},
          "initial": {"eta": [-ell - 0.3, 0.4, 5.2, 0.0, 0.05], "nu": [1.0, 0.0, 0.0, 0.0, 0.0]},
          "controller": {"kind": kind}, "sim": {"duration": 40.0}, "disturbance": []}
    res = auvtrack.simulate(sc)
    m = res.metrics
    assert res.ok
    assert m["along_rmse_late"] == pytest.approx(ell, abs=1e-5)
    assert m["xtrack_rmse_late"] < 1e-3 and m["vtrack_rmse_late"] < 1e-3
    assert m["xtrack_rmse"] > 10 * m["xtrack_rmse_late"]  # it started off the path and converged

"""Feasibility of a scenario (auvtrack.feasibility): every verdict against a direct simulation.

The steady states come from a root solver on the plant's own equations; these tests check them
against simulations of the same equations (the 6-DOF truth's Python reference integrator, a
closed loop around it, RK4 of the 5-DOF eq. 1), the reference demands against finite
differences and hand-computed cases, and the current's worst case by hand and by sampling.
"""
import contextlib
import io
import math
from pathlib import Path
from unittest import mock

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import auvtrack
from auvtrack.cli import main
from auvtrack.vehicle.dynamics import nu_dot
from auvtrack.feasibility import assess, current_bound, reference_demands, tightest_turn, water_relative
from auvtrack.feasibility.demands import horizontal_curvature
from auvtrack.feasibility.steady import steady_turn
from auvtrack.feasibility.steady5 import Steady5
from auvtrack.feasibility.steady6 import Steady6
from auvtrack.vehicle.kinematics import attitude, eta_dot
from auvtrack.vehicle.presets import vehicle_arrays
from auvtrack.plant.sixdof.layout import NX6, P_DMAX
from auvtrack.plant.sixdof.truth import MODELS, integrate_open_loop, pack_truth, trim_rpm
from auvtrack.reference import build_reference
from auvtrack.scenario import load_scenario
from auvtrack.studies.manoeuvres import turning_circle_metrics

ROOT = Path(__file__).resolve().parents[2]
REMUS = ROOT / "scenarios" / "remus100.toml"
# the preset's fin limit and the thesis's 13.6 deg (P01 Table 2.2): every verdict must hold for both
FIN_LIMITS = [None, math.radians(13.6)]


def _scenario(reference, preset="remus100_prestero", delta_max=None, currents=()):
    plant = {"model": "6dof", "preset": preset, **({"delta_max": delta_max} if delta_max else {})}
    return {"reference": reference, "plant": plant, "disturbance": list(currents), "sim": {"duration": 100.0}}


def _line(speed):
    return {"kind": "line", "velocity": [speed, 0.0, 0.0], "start": [0.0, 0.0, 10.0]}


def _circle(radius, speed):
    return {"kind": "circle", "radius": radius, "omega": speed / radius, "depth": 10.0}


def _check(feas, name):
    (c,) = [c for c in feas.checks if c.name == name]
    return c


# --- what the reference asks ------------------------------------------------------------------

def test_demands_of_the_analytic_kinds_are_the_hand_computed_ones():
    helix = reference_demands(build_reference({"kind": "helix", "radius": 4.0, "omega": 0.1, "climb": -0.1}), 100.0)
    np.testing.assert_allclose(helix.speed, math.hypot(0.4, 0.1), rtol=1e-12)
    np.testing.assert_allclose(helix.depth_rate, -0.1, rtol=1e-12)
    np.testing.assert_allclose(helix.curvature, 1.0 / 4.0, rtol=1e-12)  # omega > 0: north -> east, starboard
    port = reference_demands(build_reference(_circle(7.0, 1.0) | {"omega": -1.0 / 7.0}), 50.0)
    np.testing.assert_allclose(port.curvature, -1.0 / 7.0, rtol=1e-12)
    line = reference_demands(build_reference({"kind": "line", "velocity": [0.6, 0.8, 0.1]}), 20.0)
    assert np.all(line.curvature == 0.0) and np.allclose(line.horizontal_speed, 1.0, rtol=1e-14)
    mower = reference_demands(build_reference({"kind": "lawnmower", "spacing": 10.0, "speed": 1.0, "legs": 4}), 300.0)
    k = np.unique(np.round(mower.curvature, 12))
    assert set(k) == {-0.2, 0.0, 0.2}  # legs, and turns of radius spacing / 2 alternating sides


@settings(max_examples=10)
@given(points=st.lists(st.tuples(*[st.floats(-50, 50)] * 3), min_size=3, max_size=6, unique=True),
       speed=st.floats(0.3, 3.0))
def test_demands_of_a_spline_match_finite_differences_of_its_path(points, speed):
    pts = np.array(points)
    if np.min(np.linalg.norm(np.diff(pts, axis=0), axis=1)) < 1.0:
        return
    ref = build_reference({"kind": "waypoints", "points": pts.tolist(), "speed": speed})
    dem = reference_demands(ref, float(min(ref.duration, 200.0)))
    t, h = dem.t[1:-1], 1e-3
    p0, p1, p2 = ref.evaluate(t - h)[0], ref.evaluate(t)[0], ref.evaluate(t + h)[0]
    v, a = (p2 - p0) / (2 * h), (p2 - 2 * p1 + p0) / h ** 2
    # finite differences need a smooth path: away from the joints, where the third derivative jumps;
    # and curvature is ill-conditioned where the horizontal path stops
    joints = np.asarray(ref.breakpoints)
    smooth = np.min(np.abs(t[:, None] - joints[None, :]), axis=1) > 3 * h
    ok = smooth & (np.hypot(v[:, 0], v[:, 1]) > 0.05 * speed)
    k_fd, k = horizontal_curvature(v, a)[ok], dem.curvature[1:-1][ok]
    assert np.max(np.abs(k_fd - k)) <= 1e-5 * max(1.0, np.max(np.abs(k)))
    np.testing.assert_allclose(dem.speed[1:-1][smooth], np.linalg.norm(v, axis=1)[smooth], rtol=1e-6, atol=1e-8)


def test_water_relative_turn_on_a_ground_circle_is_the_hand_computed_trochoid():
    U, R, V = 1.0, 30.0, 0.2
    uw, kw = water_relative(U, 0.0, U * U / R, V, np.array([0.0, math.pi, math.pi / 2]))
    np.testing.assert_allclose(uw, [0.8, 1.2, math.sqrt(1.04)], rtol=1e-14)
    np.testing.assert_allclose(1.0 / kw[:2], [R * 0.8 ** 2, R * 1.2 ** 2], rtol=1e-13)  # 19.2 m, 43.2 m
    np.testing.assert_allclose(kw[2], (U * U / R) * U / 1.04 ** 1.5, rtol=1e-13)


@settings(max_examples=50)
@given(U=st.floats(0.2, 3.0), R=st.floats(1.0, 500.0), ratio=st.floats(0.0, 0.95))
def test_the_following_current_is_the_worst_on_a_ground_circle(U, R, ratio):
    """|v_w| >= U - V and |v_w| >= a give kappa_w <= U^2 / (R (U - V)^2), attained at beta = 0."""
    V = ratio * U
    beta = np.linspace(0.0, 2.0 * np.pi, 2001)
    _, kw = water_relative(U, 0.0, U * U / R, V, beta)
    worst = U * U / (R * (U - V) ** 2)
    assert np.max(kw) <= worst * (1 + 1e-12) and kw[0] == pytest.approx(worst, rel=1e-12)


def test_gauss_markov_worst_case_is_mean_plus_k_sigma_hand_computed():
    cur = [{"kind": "current", "mean": [0.1, 0.1, 0.02], "sigma": [0.05, 0.02, 0.01]},
           {"kind": "current", "mean": [0.05, -0.05, 0.0], "sigma": [0.0, 0.06, 0.01]},
           {"kind": "paper"}]
    b = current_bound(cur)
    sy = math.sqrt(0.02 ** 2 + 0.06 ** 2)
    assert b.horizontal == pytest.approx(math.hypot(0.15, 0.05) + 3 * sy, rel=1e-14)
    assert b.vertical == pytest.approx(0.02 + 3 * math.sqrt(2) * 0.01, rel=1e-14)
    assert current_bound(cur, sigmas=0.0).horizontal == pytest.approx(math.hypot(0.15, 0.05), rel=1e-14)


def test_the_worst_case_bounds_the_sampled_current_as_documented():
    """Along a fixed direction the stationary current exceeds mean + 3 sigma_max with probability <= 0.135 %."""
    from auvtrack.environment import GaussMarkovCurrent  # after auvtrack.plant: the two packages import each other

    gm = GaussMarkovCurrent(mean=(0.1, 0.0, 0.0), sigma=(0.05, 0.03, 0.0), tau=1.0, sample_dt=10.0)
    s = gm.sample(2_000_000.0, np.random.default_rng(7))[:, 1:3]  # 200 001 nearly independent draws
    b = current_bound([{"kind": "current", **gm.describe()}])
    along_x = s[:, 0] - 0.1
    n = along_x.size
    p = 0.00135
    assert np.mean(along_x > b.horizontal - 0.1) <= p + 5 * math.sqrt(p / n)
    assert np.mean(np.hypot(s[:, 0], s[:, 1]) > b.horizontal) <= 0.003  # the magnitude, any direction


# --- 6-DOF: Prestero's trim -------------------------------------------------------------------

@pytest.mark.parametrize("delta_max", FIN_LIMITS, ids=["preset", "13.6deg"])
def test_prestero_level_flight_is_infeasible_at_1_and_within_the_fin_limit_at_1_25(delta_max):
    slow = assess(_scenario(_line(1.0), delta_max=delta_max))
    fin = _check(slow, "stern plane, straight")
    assert slow.verdict == "infeasible" and fin.status == "infeasible" and fin.limit == "plant.delta_max"
    limit = math.degrees(delta_max or pack_truth("remus100_prestero")[P_DMAX])
    assert fin.available == pytest.approx(limit, rel=1e-12) and fin.required > limit
    fast = assess(_scenario(_line(1.25), delta_max=delta_max))
    assert fast.verdict != "infeasible"
    assert _check(fast, "stern plane, straight").required < limit


def test_prestero_trim_is_an_equilibrium_of_the_integrated_truth():
    """Open loop from the trim with the trim commands: depth and speed held.

    P01's REMUS is open-loop unstable (e-folding about 1 s): 20 s pins the equilibrium, not its reachability.
    """
    m = Steady6("remus100_prestero")
    s = m.solve(1.25, 0.0, 0.0)
    x0 = m.state_of(s.z)
    x0[2] = 10.0
    out = integrate_open_loop("remus100_prestero", tuple(x0[12:15]), 20.0, 0.01, x0=x0, pp=m.pp)["final"]
    assert abs(out[2] - 10.0) < 1e-6 and abs(np.linalg.norm(out[6:9]) - 1.25) < 1e-6
    assert np.max(np.abs(out[3:12] - x0[3:12])) < 1e-6


def _depth_loop(pp, speed, t_end=150.0, dt=0.01, depth=10.0):
    """RK4 of the Prestero truth under a PI depth, speed and heading loop with the actuators at their limits.

    The loop is test scaffolding: pitch command from the depth error and its integral, stern
    plane from the pitch error, rudder from the heading, propeller from the speed error and its
    integral; the truth's actuator model clips the fins at pp's delta_max.  Returns the logged
    (t, depth error, applied stern plane (rad), rpm, speed) every 0.5 s.
    """
    model = MODELS["remus100_prestero"]
    n0 = trim_rpm("remus100_prestero", pp, speed)
    x = np.zeros(NX6)
    x[2], x[6], x[14] = depth, speed, n0
    cmd = np.zeros(6)

    def f(x, xi, dx):
        ez, eu = x[2] - depth, speed - math.sqrt(x[6] ** 2 + x[7] ** 2 + x[8] ** 2)
        theta_c = min(0.4, max(-0.4, 0.3 * ez + 0.02 * xi[0]))  # too deep: nose up
        cmd[0] = 2.0 * x[5] + 2.0 * x[11]                        # P01: delta_r > 0 turns to port
        cmd[1] = 3.0 * (x[4] - theta_c) + 2.0 * x[10]            # delta_s > 0 pitches nose down
        cmd[2] = n0 + 800.0 * eu + 100.0 * xi[1]
        model.derivative(x, attitude(x[4], x[5]), (0.0, 0.0, 0.0), (0.0,) * 6, cmd, pp, dx)
        return np.array([ez, eu])
    xi, k = np.zeros(2), [np.zeros(NX6) for _ in range(4)]
    log = []
    for i in range(int(round(t_end / dt))):
        d1 = f(x, xi, k[0])
        d2 = f(x + 0.5 * dt * k[0], xi + 0.5 * dt * d1, k[1])
        d3 = f(x + 0.5 * dt * k[1], xi + 0.5 * dt * d2, k[2])
        d4 = f(x + dt * k[2], xi + dt * d3, k[3])
        x = x + dt / 6.0 * (k[0] + 2 * k[1] + 2 * k[2] + k[3])
        xi = xi + dt / 6.0 * (d1 + 2 * d2 + 2 * d3 + d4)
        if (i + 1) % 50 == 0:
            log.append(((i + 1) * dt, x[2] - depth, min(max(x[13], -pp[P_DMAX]), pp[P_DMAX]), x[14],
                        math.sqrt(x[6] ** 2 + x[7] ** 2 + x[8] ** 2)))
    return np.array(log)


@pytest.mark.parametrize("delta_max", FIN_LIMITS, ids=["preset", "13.6deg"])
def test_prestero_depth_loop_settles_on_the_trim_at_1_25_and_cannot_hold_depth_at_1(delta_max):
    pp = pack_truth("remus100_prestero", {"delta_max": delta_max} if delta_max else None)
    m = Steady6("remus100_prestero", {"delta_max": delta_max} if delta_max else None)
    log = _depth_loop(pp, 1.25)
    last = log[log[:, 0] >= 120.0]
    trim = m.solve(1.25, 0.0, 0.0).inputs
    assert np.max(np.abs(last[:, 1])) < 0.01 and np.max(np.abs(last[:, 4] - 1.25)) < 1e-3  # depth and speed held
    assert math.degrees(np.mean(last[:, 2])) == pytest.approx(trim["delta_s"], abs=0.02)  # on the solver's trim
    assert np.mean(last[:, 3]) == pytest.approx(trim["rpm"], abs=0.5)
    log = _depth_loop(pp, 1.0)
    late = log[log[:, 0] >= 50.0]
    assert np.all(np.abs(late[:, 2]) >= pp[P_DMAX] * (1 - 1e-9))  # the stern plane sits at its limit
    assert abs(log[-1, 1]) > 2.0 and abs(log[-1, 1]) > abs(log[len(log) // 2, 1])  # and depth is lost
    assert np.max(np.abs(late[:, 4] - 1.0)) < 0.1  # at the speed asked for


def test_the_same_depth_loop_holds_1_m_s_with_fins_that_reach_the_trim():
    """What fails at 1 m/s is the fin limit, not the loop: with 20 deg fins it settles on the solver's -17.1 deg."""
    overrides = {"delta_max": math.radians(20.0)}
    log = _depth_loop(pack_truth("remus100_prestero", overrides), 1.0)
    last = log[log[:, 0] >= 120.0]
    trim = Steady6("remus100_prestero", overrides).solve(1.0, 0.0, 0.0).inputs
    assert trim["delta_s"] < -15.0 and np.max(np.abs(last[:, 1])) < 0.01
    assert math.degrees(np.mean(last[:, 2])) == pytest.approx(trim["delta_s"], abs=0.02)


@settings(max_examples=4)
@given(speed=st.floats(0.6, 2.0), slope=st.floats(-0.15, 0.15))
def test_trim_solver_matches_the_open_loop_fossen_truth(speed, slope):
    """Fossen's REMUS is open-loop stable: from level flight the trim commands settle on the solver's trim."""
    m = Steady6("remus100_fossen")
    s = m.solve(speed, slope * speed, 0.0)
    xs = m.state_of(s.z)
    x0 = np.zeros(NX6)
    x0[6], x0[12:15] = speed, xs[12:15]
    # the fins unlimited, as in the solver: the trim is compared whether or not it is inside the limits
    xf = integrate_open_loop("remus100_fossen", tuple(xs[12:15]), 200.0, 0.05, x0=x0, pp=m.pp_free)["final"]
    # roll, pitch, u, w, p, q, r; not the heading (neutral: it keeps the transient's turn) nor the sway
    # velocity, whose linear damping fades as exp(-3 U) and leaves quadratic drag: algebraic decay
    keep = [3, 4, 6, 8, 9, 10, 11]
    np.testing.assert_allclose(xf[keep], xs[keep], atol=1e-4)


# --- 6-DOF: Fossen's turns ----------------------------------------------------------------------

def test_fossen_turn_of_20_m_at_1_m_s_is_infeasible_and_35_m_feasible():
    tight = assess(_scenario(_circle(20.0, 1.0), "remus100_fossen"))
    turn = _check(tight, "turn to starboard")
    assert tight.verdict == "infeasible" and turn.status == "infeasible" and turn.limit == "plant.delta_max"
    assert turn.required == pytest.approx(20.0, rel=1e-9)
    wide = assess(_scenario(_circle(35.0, 1.0), "remus100_fossen"))
    assert wide.verdict == "feasible" and _check(wide, "turn to starboard").available == turn.available


@pytest.mark.parametrize("direction", [1.0, -1.0])
def test_fossen_tightest_turn_matches_a_full_rudder_turning_circle(direction):
    m = Steady6("remus100_fossen")
    t = tightest_turn(m, 1.0, 0.0, direction)
    s = t.state
    assert t.limit == "delta_r" and abs(s.inputs["delta_r"]) == pytest.approx(15.0, rel=1e-5)
    cmds = tuple(m.state_of(s.z)[12:15])
    x0 = np.zeros(NX6)
    x0[6], x0[14] = 1.0, cmds[2]
    times = tuple(np.round(np.arange(0.0, 450.0 + 1e-9, 0.5), 9))[1:]
    res = integrate_open_loop("remus100_fossen", cmds, 450.0, 0.02, x0=x0, times=times, pp=m.pp)
    X = np.array([res[t] for t in times])
    tc = turning_circle_metrics(np.array(times), X[:, 0], X[:, 1], X[:, 5], X[:, 6], X[:, 7], X[:, 11], t0=200.0)
    assert tc["turn_direction"] == direction
    assert tc["steady_diameter"] / 2.0 == pytest.approx(t.radius, rel=1e-4)
    assert np.linalg.norm(X[-1, 6:9]) == pytest.approx(1.0, abs=1e-4)  # the speed that the rpm holds


def test_tightest_turn_is_where_the_first_limit_is_reached():
    m = Steady6("remus100_prestero")
    t = tightest_turn(m, 1.25, 0.0, 1.0)
    assert t.limit == "rpm" and t.state.usage["rpm"] == pytest.approx(1.0, abs=1e-5)
    inside = steady_turn(m, 1.25, 0.0, t.curvature * (1 - 1e-3))
    beyond = steady_turn(m, 1.25, 0.0, t.curvature * (1 + 1e-3))
    assert inside.worst[1] < 1.0 < beyond.usage["rpm"]


def test_turn_in_a_current_a_30_m_ground_circle_is_beyond_fossens_rudder():
    calm = assess(_scenario(_circle(30.0, 1.0), "remus100_fossen"))
    assert calm.verdict != "infeasible"
    cur = [{"kind": "current", "mean": [0.2, 0.0, 0.0], "sigma": [0.0, 0.0, 0.0]}]
    drift = assess(_scenario(_circle(30.0, 1.0), "remus100_fossen", currents=cur))
    turn = _check(drift, "turn to starboard")
    assert drift.verdict == "infeasible" and turn.limit == "plant.delta_max"
    assert turn.required == pytest.approx(30.0 * 0.8 ** 2, rel=1e-9)  # the following-current point
    assert turn.available == pytest.approx(tightest_turn(Steady6("remus100_fossen"), 0.8, 0.0, 1.0).radius, rel=1e-9)


def test_water_relative_curvature_of_the_truth_in_a_current_is_its_still_water_curvature():
    """Prestero's model acts on the water-relative velocity (constant current): eq. (3) on its ground track
    recovers the still-water turn at every instant."""
    name, V, dt = "remus100_prestero", np.array([0.3, 0.1, 0.0]), 0.01
    cmds = (math.radians(-10.0), math.radians(-12.0), 1400.0)
    pp = pack_truth(name)
    x0 = np.zeros(NX6)
    x0[2], x0[6], x0[12:15] = 10.0, 1.2, cmds
    x1 = x0.copy()
    x1[6:9] += V  # same water-relative start (heading 0, level)
    times = tuple(np.round(np.arange(10.0, 30.0 + 1e-9, dt), 9))

    def ground(vc, x):
        res = integrate_open_loop(name, cmds, 30.0, dt, x0=x, vc=tuple(vc), times=times, pp=pp)
        dx, cmd, vel = np.zeros(NX6), np.zeros(6), []
        cmd[0:3] = cmds
        for t in times:
            MODELS[name].derivative(res[t], attitude(res[t][4], res[t][5]), tuple(vc), (0.0,) * 6, cmd, pp, dx)
            vel.append(dx[0:3].copy())
        vel = np.array(vel)
        return vel, np.gradient(vel, dt, axis=0, edge_order=2)
    v0, a0 = ground(np.zeros(3), x0)
    v1, a1 = ground(V, x1)
    uh = np.hypot(v1[:, 0], v1[:, 1])
    tx, ty = v1[:, 0] / uh, v1[:, 1] / uh
    at, an = a1[:, 0] * tx + a1[:, 1] * ty, -a1[:, 0] * ty + a1[:, 1] * tx
    uw, kw = water_relative(uh, at, an, math.hypot(V[0], V[1]), math.atan2(V[1], V[0]) - np.arctan2(ty, tx))
    k0 = horizontal_curvature(v0, a0)
    assert np.ptp(k0) > 0.01  # an unsteady turn, not a trivial case
    np.testing.assert_allclose(kw[2:-2], k0[2:-2], atol=1e-7)
    np.testing.assert_allclose(uw[2:-2], np.hypot(v0[2:-2, 0], v0[2:-2, 1]), atol=1e-7)


# --- 5-DOF plant --------------------------------------------------------------------------------

@settings(max_examples=20)
@given(speed=st.floats(0.1, 3.0), slope=st.floats(-0.5, 0.5), radius=st.floats(2.0, 200.0),
       side=st.sampled_from([-1.0, 1.0]), preset=st.sampled_from(["paper", "remus100"]))
def test_5dof_steady_state_solves_eq1(speed, slope, radius, side, preset):
    _, vp, _ = vehicle_arrays(load_scenario({"vehicle": {"preset": preset}}))
    m = Steady5(vp)
    zd = slope * speed
    s = steady_turn(m, speed, zd, side / radius)
    if s is None:
        return
    u, v, r, theta = s.z
    att = attitude(theta, 0.0)
    nu = (u, v, 0.0, 0.0, r)
    acc = nu_dot(att, nu, (s.inputs["tau_u"], s.inputs["tau_q"], s.inputs["tau_r"]), (0.0,) * 5, vp)
    assert np.max(np.abs(acc)) < 1e-9
    ed = eta_dot(att, nu)
    assert ed[2] == pytest.approx(zd, abs=1e-9) and math.hypot(u, v) == pytest.approx(speed, rel=1e-9)
    assert ed[4] == pytest.approx(side / radius * math.hypot(ed[0], ed[1]), rel=1e-8, abs=1e-12)
    straight = m.solve(speed, zd, 0.0).inputs  # hand-computed: tau_u = d11 U, tau_q = wgml sin(theta)
    assert straight["tau_u"] == pytest.approx(vp[5] * speed, rel=1e-9)
    assert straight["tau_q"] == pytest.approx(-vp[10] * zd / speed, rel=1e-9, abs=1e-12)


def test_5dof_turn_matches_a_simulation_of_eq1():
    """The paper vehicle (true plant) is yaw-stable at 0.4 m/s: constant tau settles on the solver's turn."""
    _, vp, _ = vehicle_arrays(load_scenario({}))
    s = steady_turn(Steady5(vp), 0.412, -0.1, 0.25)
    tau = (s.inputs["tau_u"], s.inputs["tau_q"], s.inputs["tau_r"])

    def f(x):
        att, nu = attitude(x[3], x[4]), tuple(x[5:10])
        return np.array([*eta_dot(att, nu), *nu_dot(att, nu, tau, (0.0,) * 5, vp)])
    x, dt = np.zeros(10), 0.05
    x[5] = 0.412
    for _ in range(int(300.0 / dt)):
        k1 = f(x)
        k2 = f(x + dt / 2 * k1)
        k3 = f(x + dt / 2 * k2)
        k4 = f(x + dt * k3)
        x = x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    u, v, r, theta = s.z
    np.testing.assert_allclose([x[5], x[6], x[9], x[3]], [u, v, r, theta], atol=1e-7)


def test_5dof_limits_are_the_actuator_tau_max():
    sc = {"actuator": {"tau_max": [50.0, 5.0, 3.0]}, "disturbance": []}
    f = assess(sc)
    _, vp, _ = vehicle_arrays(load_scenario(sc))
    q = _check(f, "pitch moment, straight")  # helix: climb 0.1 m/s at 0.412 m/s, tau_q = wgml sin(theta)
    assert q.required == pytest.approx(vp[10] * 0.1 / math.hypot(0.4, 0.1), rel=1e-9)
    assert q.available == 5.0 and q.limit == "actuator.tau_max.1" and f.verdict == "infeasible"
    t = tightest_turn(Steady5(vp, (50.0, 100.0, 3.0)), 0.412, -0.1, 1.0)
    assert t.limit == "tau_r" and abs(t.state.inputs["tau_r"]) == pytest.approx(3.0, rel=1e-5)


# --- interface ----------------------------------------------------------------------------------

def test_check_prints_the_assessment_and_run_warns_in_one_line(tmp_path):
    sets = ["--set", "plant.model=6dof", "--set", "reference.kind=line", "--set", "reference.velocity=[1, 0, 0]"]
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        assert main(["check", str(REMUS), *sets]) == 0
    assert "feasibility: infeasible" in out.getvalue() and "stern plane, straight" in out.getvalue()

    class Ran(Exception):
        pass
    for args, warned in ((sets, True), ([], False)):
        err = io.StringIO()
        with mock.patch("auvtrack.simulation.compiling.ensure_compiled"), \
                mock.patch("auvtrack.simulation.pipeline.run_prepared", side_effect=Ran), \
                contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err), pytest.raises(Ran):
            main(["run", str(REMUS), "--out", str(tmp_path / "r"), *args])  # the run still starts
        lines = [ln for ln in err.getvalue().splitlines() if "feasibility" in ln]
        assert len(lines) == (1 if warned else 0), err.getvalue()
        if warned:
            assert lines[0].startswith("warning: feasibility: infeasible: stern plane, straight")


def test_the_numbers_in_the_docs_are_the_codes():
    from tools import feasibility_doc as doc
    text = doc.DOC.read_text()
    assert doc.render_text(text) == text, "python -m tools.feasibility_doc render"


def test_api_and_bad_input_are_one_line():
    from auvtrack import feasibility

    assert feasibility.assess is assess
    with pytest.raises(ValueError, match=r"^sigmas: must be a finite number >= 0 \(got -1\)$"):
        assess({}, sigmas=-1)
    with pytest.raises(ValueError, match=r"^marginal: must be a number in \(0, 1\] \(got 0\)$"):
        assess({}, marginal=0)
    m = Steady6("remus100_fossen")
    with pytest.raises(ValueError, match=r"^speed: must be a finite number > 0 m/s \(got -1.0\)$"):
        m.solve(-1.0, 0.0, 0.0)
    with pytest.raises(ValueError, match=r"^depth_rate: \|depth_rate\| must be < speed = 1 m/s \(got 1.0\)$"):
        tightest_turn(m, 1.0, 1.0, 1.0)
    with pytest.raises(ValueError, match=r"^direction: must be \+1 \(starboard\) or -1 \(port\) \(got 0.5\)$"):
        tightest_turn(m, 1.0, 0.0, 0.5)
    with pytest.raises(ValueError, match="plant.delta_max"):
        assess(_scenario(_line(1.0), delta_max=-1.0))

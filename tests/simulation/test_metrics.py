"""Metrics: compiled accumulator vs NumPy reference, analytic cases, window and 10 ms grid rules."""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from auvtrack.metrics import (METRIC_NAMES, METRICS_SIZE, TV_GRID, metrics_finalize,
                                         metrics_from_trajectory, metrics_init, metrics_update)


def run_accumulator(t, e, tau, t0=0.0, t1=math.inf, engine_t1=False):
    """Feed the compiled accumulator step by step, as the engine does (left-point values)."""
    acc = np.zeros(METRICS_SIZE)
    metrics_init(acc)
    t = np.asarray(t, float)
    e = np.ascontiguousarray(e, float)
    tau = np.ascontiguousarray(tau, float)
    t1_arg = 1e300 if (engine_t1 and math.isinf(t1)) else t1
    for k in range(t.size - 1):
        metrics_update(acc, t[k], t[k + 1] - t[k], e[k], tau[k], t0, t1_arg)
    t_end = min(t1, t[-1]) if t.size else t0
    return metrics_finalize(acc, t0, t_end)


def assert_metrics_close(a, b, rel=1e-12, abs_=1e-300):
    assert list(a) == list(METRIC_NAMES) and list(b) == list(METRIC_NAMES)
    for name in METRIC_NAMES:
        x, y = a[name], b[name]
        if math.isnan(x) or math.isnan(y):
            assert math.isnan(x) and math.isnan(y), name
        elif math.isinf(x) or math.isinf(y):
            assert x == y, name
        else:
            assert math.isclose(x, y, rel_tol=rel, abs_tol=abs_), (name, x, y)


def signals(t, e_fn, tau_fn=None):
    e = np.column_stack([e_fn(t)] * 3) if e_fn is not None else np.zeros((t.size, 3))
    tau = np.column_stack([tau_fn(t)] * 3) if tau_fn is not None else np.zeros((t.size, 3))
    return e, tau


# ------------------------------------------------------------------ structure
def test_names_and_size():
    assert len(METRIC_NAMES) == 53 and len(set(METRIC_NAMES)) == 53
    for a in "xyz":
        for k in ("rmse", "iae", "itae", "max_abs", "settle_5cm", "settle_1cm", "settle_1mm"):
            assert f"{k}_{a}" in METRIC_NAMES
    for j in "uqr":
        for k in ("max_abs_tau", "energy_tau", "tv_tau", "t_sat_tau", "act_rms", "act_max", "act_rate", "t_act_limit"):
            assert f"{k}_{j}" in METRIC_NAMES
    # the path-following metrics come after the 33 of the virtual point (appended: stored orders unchanged)
    assert METRIC_NAMES[33:41] == ("xtrack_rmse", "xtrack_max", "vtrack_rmse", "along_rmse", "xtrack_rmse_late",
                                   "xtrack_max_late", "vtrack_rmse_late", "along_rmse_late")
    acc = np.full(METRICS_SIZE, 7.0)
    metrics_init(acc)
    assert np.all((acc == 0) | np.isnan(acc))
    assert np.isnan(acc[49])  # the path parameter: none before the first step


# ------------------------------------------------------------------ compiled == reference
@st.composite
def trajectories(draw):
    n = draw(st.integers(2, 250))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    if draw(st.booleans()):
        dt = draw(st.sampled_from([1e-3, 2e-3, 2.5e-3, 3e-3, 5e-3, 0.01, 0.02]))
        t = np.arange(n) * dt
    else:
        t = np.concatenate([[0.0], np.cumsum(rng.uniform(1e-4, 0.03, n - 1))])
    t = t + draw(st.sampled_from([0.0, 0.5, 3.0]))
    scale = draw(st.sampled_from([1e-3, 0.05, 1.0, 100.0]))
    e = rng.normal(0.0, scale, (n, 3))
    tau = rng.normal(0.0, 50.0, (n, 3))
    span = t[-1] - t[0]
    t0 = t[0] + draw(st.sampled_from([0.0, 0.1, 0.37, 0.5])) * span
    t1 = draw(st.sampled_from([math.inf, t0 + 0.3 * span, t0 + 0.8 * span, t[-1]]))
    if draw(st.booleans()):  # window bounds exactly on samples
        i0 = draw(st.integers(0, n - 1))
        t0 = t[i0]
    return t, e, tau, t0, t1


@given(trajectories())
def test_compiled_matches_reference(case):
    t, e, tau, t0, t1 = case
    assert_metrics_close(run_accumulator(t, e, tau, t0, t1), metrics_from_trajectory(t, e, tau, t0, t1))


def test_engine_style_infinite_window():
    """The engine passes t1 = 1e300 for an infinite window: same result as inf."""
    t = np.arange(501) * 2e-3
    rng = np.random.default_rng(1)
    e, tau = rng.normal(size=(501, 3)), rng.normal(size=(501, 3))
    assert_metrics_close(run_accumulator(t, e, tau, 0.2, math.inf, engine_t1=True),
                         metrics_from_trajectory(t, e, tau, 0.2, math.inf))


# ------------------------------------------------------------------ analytic cases
@pytest.mark.parametrize("c", [0.3, -0.02])
def test_constant_error(c):
    dt, t0, t1 = 1e-3, 2.0, 7.0
    t = np.arange(0, 10000 + 1) * dt
    e, tau = signals(t, lambda s: np.full_like(s, c))
    m = metrics_from_trajectory(t, e, tau, t0, t1)
    T = t1 - t0
    for a in "xyz":
        assert m[f"rmse_{a}"] == pytest.approx(abs(c), rel=1e-12)
        assert m[f"iae_{a}"] == pytest.approx(abs(c) * T, rel=1e-9)
        # left rectangle rule: exact value minus half a step's bias
        assert m[f"itae_{a}"] == pytest.approx(abs(c) * (t1**2 - t0**2) / 2, abs=abs(c) * dt * T)
        assert m[f"max_abs_{a}"] == pytest.approx(abs(c))
    assert_metrics_close(run_accumulator(t, e, tau, t0, t1), m)


def test_sine_rmse():
    A, w = 0.8, 2 * np.pi / 5.0
    t = np.arange(0, 20001) * 1e-3  # 20 s = 4 periods
    e, tau = signals(t, lambda s: A * np.sin(w * s))
    m = metrics_from_trajectory(t, e, tau)
    assert m["rmse_x"] == pytest.approx(A / math.sqrt(2), rel=1e-9)
    assert m["max_abs_y"] == pytest.approx(A, rel=1e-6)
    assert m["iae_z"] == pytest.approx(4 * 2 * 2 * A / w, rel=1e-6)  # 2A/w per half period


@pytest.mark.parametrize("dt", [1e-3, 4e-3])
def test_settling_exponential(dt):
    e0, lam = 1.0, 0.5
    t = np.arange(0, round(20 / dt) + 1) * dt
    e, tau = signals(t, lambda s: e0 * np.exp(-lam * s))
    m = metrics_from_trajectory(t, e, tau)
    for lab, thr in (("5cm", 0.05), ("1cm", 0.01), ("1mm", 0.001)):
        exact = math.log(e0 / thr) / lam
        assert abs(m[f"settle_{lab}_x"] - exact) <= dt * (1 + 1e-9)
    assert_metrics_close(run_accumulator(t, e, tau), m)


def test_settling_never_exceeded_and_still_above():
    t = np.arange(0, 1001) * 1e-2
    e = np.column_stack([np.full(t.size, 1e-4),  # never above any threshold -> t0
                         np.full(t.size, 0.02),  # above 1 cm / 1 mm at the end -> inf
                         np.where(t < 3.0, 1.0, 0.0)])  # drops below at t = 3
    tau = np.zeros((t.size, 3))
    m = metrics_from_trajectory(t, e, tau, t0=1.0)
    assert m["settle_5cm_x"] == m["settle_1mm_x"] == 1.0
    assert m["settle_5cm_y"] == 1.0
    assert m["settle_1cm_y"] == math.inf and m["settle_1mm_y"] == math.inf
    assert m["settle_1mm_z"] == pytest.approx(3.0, abs=1e-12)
    assert_metrics_close(run_accumulator(t, e, tau, 1.0), m)


def test_tv_sine_whole_periods():
    A, f = 2.0, 0.5  # peaks at 0.5 s + k/2 lie on the 10 ms grid: exact
    t = np.arange(0, 4001) * 1e-3
    e, tau = signals(t, None, lambda s: A * np.sin(2 * np.pi * f * s))
    m = metrics_from_trajectory(t, e, tau)
    # the grid covers [0, 4): the last 10 ms (tau(4) - tau(3.99)) is outside, a bias <= 10 ms / T
    assert m["tv_tau_u"] == pytest.approx(4 * f * A, rel=0.01)
    missing = A * abs(math.sin(2 * np.pi * f * 3.99))
    assert m["tv_tau_u"] * 4.0 == pytest.approx(4 * A * 2 - missing, rel=1e-12)
    # extend the window by one step so the grid point t = 4 s is sampled: exactly 2 periods of TV
    t_long = np.arange(0, 4101) * 1e-3
    e_l, tau_l = signals(t_long, None, lambda s: A * np.sin(2 * np.pi * f * s))
    m_l = metrics_from_trajectory(t_long, e_l, tau_l, 0.0, 4.001)
    assert m_l["tv_tau_u"] * 4.001 == pytest.approx(4 * A * 2, rel=1e-12)
    # energy: A^2 T / 2 over whole periods
    assert m["energy_tau_q"] == pytest.approx(A**2 * 4.0 / 2, rel=1e-9)
    assert m["max_abs_tau_r"] == pytest.approx(A)
    # frequency not aligned with the grid: close, never above the true TV
    f2 = 0.37
    t2 = np.arange(0, round(4 / f2 / 1e-3) + 1) * 1e-3
    e2, tau2 = signals(t2, None, lambda s: A * np.sin(2 * np.pi * f2 * s))
    tv = metrics_from_trajectory(t2, e2, tau2)["tv_tau_u"]
    assert tv == pytest.approx(4 * f2 * A, rel=2e-3)


def test_tv_independent_of_dt_when_grid_points_coincide():
    fn = lambda s: 3.0 * np.sin(2 * np.pi * 1.3 * s) + 0.5 * np.cos(17.0 * s)  # noqa: E731
    out = []
    for dt in (1e-3, 5e-4, 2e-3, 1e-2):
        t = np.arange(0, round(5.0 / dt) + 1) * dt
        e, tau = signals(t, None, fn)
        m_ref = metrics_from_trajectory(t, e, tau)
        m_acc = run_accumulator(t, e, tau)
        assert m_acc["tv_tau_u"] == pytest.approx(m_ref["tv_tau_u"], rel=1e-12)
        out.append(m_ref["tv_tau_u"])
    assert np.allclose(out, out[0], rtol=1e-12, atol=0)
    # a step that does not divide 10 ms samples late: close but not identical
    t = np.arange(0, round(5.0 / 3e-3) + 1) * 3e-3
    e, tau = signals(t, None, fn)
    assert metrics_from_trajectory(t, e, tau)["tv_tau_u"] == pytest.approx(out[0], rel=0.05)


def test_tv_dt_coarser_than_grid_uses_every_step():
    dt = 0.025
    t = np.arange(0, 201) * dt
    rng = np.random.default_rng(3)
    tau = rng.normal(size=(t.size, 3))
    m = metrics_from_trajectory(t, np.zeros((t.size, 3)), tau)
    expected = np.sum(np.abs(np.diff(tau[:-1, 0]))) / (dt * (t.size - 1))
    assert m["tv_tau_u"] == pytest.approx(expected, rel=1e-12)
    assert_metrics_close(run_accumulator(t, np.zeros((t.size, 3)), tau), m)


def test_tv_grid_sampling_rule():
    """tau is sampled at the first step with t >= t0 + k * 10 ms (window start t0 = 0.003)."""
    dt = 4e-3
    t = np.arange(0, 101) * dt
    tau = np.zeros((t.size, 3))
    tau[:, 0] = np.arange(t.size) ** 2  # distinct increments reveal which samples are used
    m = metrics_from_trajectory(t, np.zeros((t.size, 3)), tau, t0=0.003)
    tw = t[:-1][t[:-1] >= 0.003]
    used = sorted({int(np.argmax(tw >= 0.003 + k * TV_GRID - 1e-12)) for k in range(200)
                   if 0.003 + k * TV_GRID <= tw[-1] + 1e-12})
    vals = tau[:-1, 0][t[:-1] >= 0.003][used]
    assert m["tv_tau_u"] == pytest.approx(np.sum(np.abs(np.diff(vals))) / (tw.size * dt), rel=1e-12)


# ------------------------------------------------------------------ window handling
def test_window_ignores_outside_samples():
    t = np.arange(0, 3001) * 1e-3
    rng = np.random.default_rng(7)
    e, tau = rng.normal(size=(t.size, 3)), rng.normal(size=(t.size, 3))
    m = metrics_from_trajectory(t, e, tau, 1.0, 2.0)
    e2, tau2 = e.copy(), tau.copy()
    outside = (t < 1.0 - 1e-9) | (t >= 2.0 - 1e-9)
    e2[outside] = 1e3
    tau2[outside] = -1e3
    assert_metrics_close(metrics_from_trajectory(t, e2, tau2, 1.0, 2.0), m, rel=0, abs_=0)
    assert_metrics_close(run_accumulator(t, e2, tau2, 1.0, 2.0), m)
    # the window [1, 2) holds exactly 1000 steps
    c = metrics_from_trajectory(t, np.ones((t.size, 3)), tau, 1.0, 2.0)
    assert c["iae_x"] == pytest.approx(1.0, rel=1e-12)


def test_infinite_window_equals_end():
    t = np.arange(0, 1001) * 1e-3
    rng = np.random.default_rng(11)
    e, tau = rng.normal(size=(t.size, 3)), rng.normal(size=(t.size, 3))
    assert_metrics_close(metrics_from_trajectory(t, e, tau, 0.25, math.inf),
                         metrics_from_trajectory(t, e, tau, 0.25, 5.0), rel=0, abs_=0)


def test_empty_window_gives_nan():
    t = np.arange(0, 11) * 0.1
    z = np.zeros((t.size, 3))
    m = metrics_from_trajectory(t, z, z, 5.0, 6.0)
    assert all(math.isnan(v) for v in m.values())
    assert_metrics_close(run_accumulator(t, z, z, 5.0, 6.0), m)
    acc = np.zeros(METRICS_SIZE)
    metrics_init(acc)
    assert all(math.isnan(v) for v in metrics_finalize(acc, 0.0, 10.0).values())
    assert all(math.isnan(v) for v in metrics_from_trajectory(t[:1], z[:1], z[:1]).values())


def test_reference_rejects_bad_input():
    with pytest.raises(ValueError):
        metrics_from_trajectory(np.arange(5.0), np.zeros((4, 3)), np.zeros((5, 3)))
    with pytest.raises(ValueError):
        metrics_from_trajectory(np.array([0.0, 1.0, 1.0]), np.zeros((3, 3)), np.zeros((3, 3)))

"""External disturbances: paper sinusoids, pulses, Gauss-Markov current (auvtrack.environment)."""
import json
import math

import numba
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from auvtrack._seeding import rng
from auvtrack.environment import (DISTURBANCES, GaussMarkovCurrent, PaperDisturbance, Pulse,
                                  build_disturbance, eval_disturbance, pack_disturbances)
from auvtrack.vehicle.presets import pack_vehicle

# distinct damping per axis so a wrong axis mapping cannot pass
VP = pack_vehicle(m=[200, 250, 260, 80, 90], d=[70.0, 100.0, 130.0, 50.0, 60.0], wgml=30.0, l=0.5)


def paper_formula(t, a=1.0, p=0.0):
    """The printed Section 4 disturbance, written out independently."""
    w2, w1 = 0.2 * np.pi * t + p, 0.1 * np.pi * t + p
    return a * np.array([3 * np.sin(w2), np.sin(w2), np.cos(w1), np.cos(w2), np.sin(w1) + np.cos(w1)])


def j1_numpy(theta, psi):
    """J1 with roll = 0 as the product Rz(psi) Ry(theta)."""
    rz = np.array([[np.cos(psi), -np.sin(psi), 0], [np.sin(psi), np.cos(psi), 0], [0, 0, 1]])
    ry = np.array([[np.cos(theta), 0, np.sin(theta)], [0, 1, 0], [-np.sin(theta), 0, np.cos(theta)]])
    return rz @ ry


# --- paper disturbance -------------------------------------------------------------------------

@pytest.mark.parametrize("t", [0.0, 1.25, 2.5, 7.3])
def test_paper_values(t):
    tab = pack_disturbances([PaperDisturbance()], 10.0, 0)
    np.testing.assert_allclose(tab.evaluate(t), paper_formula(t), atol=1e-13)


def test_paper_hand_values_at_zero_and_2_5():
    tab = pack_disturbances([PaperDisturbance()], 10.0, 0)
    np.testing.assert_allclose(tab.evaluate(0.0), [0, 0, 1, 1, 1], atol=1e-15)
    # t = 2.5: 0.2 pi t = pi/2, 0.1 pi t = pi/4
    r = math.sqrt(0.5)
    np.testing.assert_allclose(tab.evaluate(2.5), [3, 1, r, 0, 2 * r], atol=1e-14)


@settings(max_examples=40)
@given(st.floats(0, 5), st.floats(-math.pi, math.pi), st.floats(0, 200))
def test_paper_amplitude_and_phase(a, p, t):
    tab = pack_disturbances([PaperDisturbance(amplitude=a, phase=p)], 1.0, 0)
    np.testing.assert_allclose(tab.evaluate(t), paper_formula(t, a, p), atol=1e-12)


# --- pulse ---------------------------------------------------------------------------------------

def test_pulse_edges():
    f = [1.0, -2.0, 3.0, -4.0, 5.0]
    tab = pack_disturbances([Pulse(start=2.0, duration=0.5, force=f)], 5.0, 0)
    np.testing.assert_array_equal(tab.evaluate(2.0), f)          # t = start: on
    np.testing.assert_array_equal(tab.evaluate(2.25), f)
    np.testing.assert_array_equal(tab.evaluate(2.5), np.zeros(5))  # t = start + duration: off
    np.testing.assert_array_equal(tab.evaluate(np.nextafter(2.0, 0)), np.zeros(5))
    np.testing.assert_array_equal(tab.evaluate(np.nextafter(2.5, 0)), f)


def test_step_is_infinite_pulse():
    tab = pack_disturbances([Pulse(start=1.0, duration=math.inf, force=[0, 0, 0, 0, 2.0])], 5.0, 0)
    assert tab.evaluate(0.5)[4] == 0.0
    assert tab.evaluate(1.0)[4] == 2.0 and tab.evaluate(1e9)[4] == 2.0


# --- current -------------------------------------------------------------------------------------

def test_current_seeded_determinism_and_streams():
    c = GaussMarkovCurrent(mean=(0.1, -0.2, 0.0), sigma=(0.05, 0.05, 0.02), tau=20.0)
    a = pack_disturbances([c], 50.0, 7).current
    b = pack_disturbances([c], 50.0, 7).current
    d = pack_disturbances([c], 50.0, 8).current
    np.testing.assert_array_equal(a, b)
    assert not np.allclose(a[:, 1:], d[:, 1:])
    # seeding rule: the i-th current uses rng(seed, f"current/{i}"), other components do not count
    pulse = Pulse(start=0.0, duration=1.0, force=[1, 0, 0, 0, 0])
    tab = pack_disturbances([pulse, c, PaperDisturbance(), c], 50.0, 7)
    np.testing.assert_array_equal(tab.current_samples(0), a)
    np.testing.assert_array_equal(tab.current_samples(1), c.sample(50.0, rng(7, "current/1")))
    assert not np.array_equal(tab.current_samples(0), tab.current_samples(1))


def test_current_grid_covers_duration():
    c = GaussMarkovCurrent(sample_dt=0.1)
    s = pack_disturbances([c], 3.0, 0).current
    assert s.shape == (31, 4) and s[-1, 0] >= 3.0 - 1e-12
    np.testing.assert_allclose(np.diff(s[:, 0]), 0.1, rtol=1e-12)


@pytest.mark.parametrize("tau, h, seed", [(1.0, 0.1, 11), (2.0, 0.5, 12), (30.0, 1.0, 13)])
def test_current_statistics(tau, h, seed):
    """Mean, std and lag-1 autocorrelation of a long series, within ~5 standard errors of AR(1)."""
    mean, sigma = np.array([0.2, -0.1, 0.05]), np.array([0.05, 0.1, 0.02])
    c = GaussMarkovCurrent(mean=mean, sigma=sigma, tau=tau, sample_dt=h)
    n_target = 300_000
    V = pack_disturbances([c], n_target * h, seed).current[:, 1:]
    n = V.shape[0]
    a = math.exp(-h / tau)
    # large-sample standard errors for a stationary AR(1) with coefficient a
    se_mean = sigma * math.sqrt((1 + a) / (1 - a) / n)
    se_std_rel = math.sqrt((1 + a * a) / (1 - a * a) / (2 * n))
    se_rho = math.sqrt((1 - a * a) / n)
    dev = V - V.mean(axis=0)
    rho = (dev[1:] * dev[:-1]).sum(axis=0) / (dev * dev).sum(axis=0)
    assert np.all(np.abs(V.mean(axis=0) - mean) < 5 * se_mean)
    assert np.all(np.abs(V.std(axis=0) / sigma - 1) < 5 * se_std_rel)
    assert np.all(np.abs(rho - a) < 5 * se_rho + 2 / n)  # 2/n: O(1/n) bias of the estimator


def test_current_initial_value_is_stationary():
    """V_0 ~ N(mean, sigma^2) across seeds (not started at the mean)."""
    c = GaussMarkovCurrent(mean=(0.3, 0.0, -0.1), sigma=(0.1, 0.05, 0.2), tau=60.0)
    v0 = np.array([c.sample(0.0, rng(s, "current/0"))[0, 1:] for s in range(4000)])
    sig = np.array(c.sigma)
    assert np.all(np.abs(v0.mean(axis=0) - c.mean) < 5 * sig / math.sqrt(4000))
    assert np.all(np.abs(v0.std(axis=0) / sig - 1) < 5 / math.sqrt(2 * 4000))


def test_zero_sigma_is_constant_current():
    c = GaussMarkovCurrent(mean=(0.3, -0.2, 0.1), sigma=(0.0, 0.0, 0.0))
    tab = pack_disturbances([c], 10.0, 3)
    np.testing.assert_array_equal(tab.current[:, 1:], np.tile([0.3, -0.2, 0.1], (tab.current.shape[0], 1)))


@settings(max_examples=30)
@given(st.floats(-1.3, 1.3), st.floats(-3.1, 3.1), st.floats(0, 20))
def test_current_force_mapping(theta, psi, t):
    """omega[0:3] = diag(d11, d22, d33) J1^T V_c(t), moments zero, damping from the vp passed."""
    c = GaussMarkovCurrent(mean=(0.4, -0.3, 0.1), sigma=(0.1, 0.1, 0.05), tau=5.0)
    tab = pack_disturbances([c], 20.0, 5)
    eta = np.array([1.0, 2.0, 3.0, theta, psi])
    nu = np.array([1.0, 0.1, -0.1, 0.05, 0.02])
    vc = tab.current_velocity(t)
    expected = np.diag(VP[5:8]) @ j1_numpy(theta, psi).T @ vc
    got = tab.evaluate(t, eta=eta, nu=nu, vp=VP)
    np.testing.assert_allclose(got[:3], expected, rtol=1e-12, atol=1e-12)
    assert got[3] == 0.0 and got[4] == 0.0
    got2 = tab.evaluate(t, eta=eta, nu=nu, vp=np.where(np.arange(VP.size) < 8, 2 * VP, VP))
    np.testing.assert_allclose(got2[:3], 2 * expected, rtol=1e-12, atol=1e-12)


def test_current_force_at_zero_attitude():
    c = GaussMarkovCurrent(mean=(0.5, 0.0, 0.0), sigma=(0.0, 0.0, 0.0))
    tab = pack_disturbances([c], 1.0, 0)
    np.testing.assert_allclose(tab.evaluate(0.3, vp=VP), [35.0, 0, 0, 0, 0])
    # heading east (psi = 90 deg): a northward current pushes the vehicle to port (-v)
    eta = np.array([0, 0, 0, 0, math.pi / 2])
    np.testing.assert_allclose(tab.evaluate(0.3, eta=eta, vp=VP), [0, -50.0, 0, 0, 0], atol=1e-12)


def test_current_interpolation_and_hold():
    c = GaussMarkovCurrent(sigma=(0.1, 0.1, 0.1), sample_dt=0.5)
    tab = pack_disturbances([c], 10.0, 2)
    s = tab.current_samples(0)
    np.testing.assert_allclose(tab.current_velocity(3.0), s[6, 1:], rtol=1e-12)
    np.testing.assert_allclose(tab.current_velocity(3.25), 0.5 * (s[6, 1:] + s[7, 1:]), rtol=1e-12)
    np.testing.assert_allclose(tab.current_velocity(3.1), 0.8 * s[6, 1:] + 0.2 * s[7, 1:], rtol=1e-10)
    np.testing.assert_array_equal(tab.current_velocity(10.0), s[-1, 1:])
    np.testing.assert_array_equal(tab.current_velocity(1e6), s[-1, 1:])   # held beyond the grid
    np.testing.assert_array_equal(tab.current_velocity(-1.0), s[0, 1:])   # and before it


# --- sums, empty list, typing ----------------------------------------------------------------------

def test_sum_equals_sum_of_evaluations():
    comps = [PaperDisturbance(amplitude=0.7, phase=0.3),
             Pulse(start=1.0, duration=4.0, force=[5, 0, -1, 0.5, 0]),
             GaussMarkovCurrent(mean=(0.2, 0.1, 0.0), tau=10.0),
             GaussMarkovCurrent(sigma=(0.1, 0.0, 0.1), tau=3.0, sample_dt=0.2)]
    eta = np.array([0, 0, 5, 0.2, -0.7])
    whole = pack_disturbances(comps, 30.0, 9)
    ts = np.linspace(0, 35, 71)
    total = whole.evaluate(ts, eta=eta, vp=VP)
    # each alone; the second current alone is stream current/0, so pin its samples via the seed rule
    parts = [pack_disturbances([c], 30.0, 9).evaluate(ts, eta=eta, vp=VP) for c in comps[:3]]
    lone = pack_disturbances([comps[3]], 30.0, 9)
    lone.current[:] = whole.current_samples(1)
    parts.append(lone.evaluate(ts, eta=eta, vp=VP))
    np.testing.assert_allclose(total, sum(parts), rtol=1e-12, atol=1e-12)
    for i, t in enumerate(ts[::10]):  # vectorised and scalar evaluation agree
        np.testing.assert_array_equal(whole.evaluate(t, eta=eta, vp=VP), total[10 * i])


def test_empty_list_is_zero():
    tab = pack_disturbances([], 10.0, 0)
    assert tab.rows.shape == (0, 8) and tab.current.shape == (1, 4)
    np.testing.assert_array_equal(tab.evaluate(3.0, vp=VP), np.zeros(5))
    out = np.full(5, 9.0)
    eval_disturbance(tab.rows, tab.current, 1.0, np.zeros(5), np.zeros(5), VP, out)
    np.testing.assert_array_equal(out, np.zeros(5))


def test_one_compiled_specialisation_serves_every_combination():
    for comps in ([], [PaperDisturbance()], [Pulse(start=0, duration=1, force=[1] * 5)],
                  [GaussMarkovCurrent()], [PaperDisturbance(), GaussMarkovCurrent()]):
        tab = pack_disturbances(comps, 2.0, 0)
        assert tab.rows.dtype == np.float64 and tab.rows.flags.c_contiguous and tab.rows.ndim == 2
        assert tab.current.dtype == np.float64 and tab.current.flags.c_contiguous
        tab.evaluate(0.5, vp=VP)
    # exactly one specialisation with array-typed state serves every combination; the engine, if
    # compiled earlier in this session, adds its own with tuple-typed state (eta = argument 3)
    from_python = [sig for sig in eval_disturbance.signatures if isinstance(sig[3], numba.types.Array)]
    assert len(from_python) == 1
    assert len(eval_disturbance.signatures) <= 2  # at most the engine's one besides


def test_unknown_kind_code_gives_nan():
    tab = pack_disturbances([PaperDisturbance()], 1.0, 0)
    rows = tab.rows.copy()
    rows[0, 0] = 99.0
    out = np.zeros(5)
    eval_disturbance(rows, tab.current, 0.0, np.zeros(5), np.zeros(5), VP, out)
    assert np.all(np.isnan(out))


def test_current_needs_vp():
    tab = pack_disturbances([GaussMarkovCurrent()], 1.0, 0)
    with pytest.raises(ValueError, match="vp"):
        tab.evaluate(0.0)


# --- validation, description, registry -------------------------------------------------------------

@pytest.mark.parametrize("cls, kwargs, field", [
    (PaperDisturbance, {"amplitude": -1.0}, "amplitude"),
    (PaperDisturbance, {"amplitude": math.nan}, "amplitude"),
    (PaperDisturbance, {"phase": math.inf}, "phase"),
    (Pulse, {"start": -1.0, "duration": 1.0, "force": [0] * 5}, "start"),
    (Pulse, {"start": 0.0, "duration": 0.0, "force": [0] * 5}, "duration"),
    (Pulse, {"start": 0.0, "duration": math.nan, "force": [0] * 5}, "duration"),
    (Pulse, {"start": 0.0, "duration": 1.0, "force": [0] * 4}, "force"),
    (Pulse, {"start": 0.0, "duration": 1.0, "force": [0, 0, math.nan, 0, 0]}, "force"),
    (GaussMarkovCurrent, {"sigma": (0.1, -0.1, 0.0)}, "sigma"),
    (GaussMarkovCurrent, {"mean": (0.1, 0.0)}, "mean"),
    (GaussMarkovCurrent, {"tau": 0.0}, "tau"),
    (GaussMarkovCurrent, {"tau": math.inf}, "tau"),
    (GaussMarkovCurrent, {"sample_dt": -0.1}, "sample_dt"),
])
def test_invalid_values_raise(cls, kwargs, field):
    with pytest.raises(ValueError, match=rf"\.{field} must be") as exc:
        cls(**kwargs)
    assert "\n" not in str(exc.value)


def test_positional_construction_is_refused():
    with pytest.raises(TypeError):
        Pulse(0.0, 1.0, [0] * 5)


def test_pack_rejects_bad_input():
    with pytest.raises(ValueError, match="duration"):
        pack_disturbances([], math.inf, 0)
    with pytest.raises(ValueError, match="component"):
        pack_disturbances([{"kind": "paper"}], 1.0, 0)


@pytest.mark.parametrize("comp", [
    PaperDisturbance(), PaperDisturbance(amplitude=2.0, phase=-0.5),
    Pulse(start=3.0, duration=2.0, force=[1, 2, 3, 4, 5]),
    Pulse(start=0.0, duration=math.inf, force=[0, 0, 0, 0, 1]),
    GaussMarkovCurrent(), GaussMarkovCurrent(mean=(0.1, 0.2, 0.0), sigma=(0, 0, 0.01), tau=5, sample_dt=0.5),
])
def test_describe_roundtrip_and_json(comp):
    d = comp.describe()
    assert d["kind"] in ("paper", "pulse", "current") and DISTURBANCES[d["kind"]] is type(comp)
    text = json.dumps(d, allow_nan=False)  # strict JSON (infinite duration written as "inf")
    assert build_disturbance(json.loads(text)) == comp


def test_tables_describe_names_streams_not_samples():
    tab = pack_disturbances([PaperDisturbance(), GaussMarkovCurrent()], 5.0, 4)
    d = tab.describe()
    json.dumps(d, allow_nan=False)
    assert d["components"][1]["stream"] == "current/0" and "samples" not in json.dumps(d)
    assert [build_disturbance(c) for c in d["components"]] == list(tab.components)


def test_build_disturbance_errors():
    with pytest.raises(ValueError, match="kind"):
        build_disturbance({"kind": "wind"})
    with pytest.raises(ValueError, match="unknown field"):
        build_disturbance({"kind": "paper", "amplitud": 1.0})
    with pytest.raises(ValueError, match="pulse"):
        build_disturbance({"kind": "pulse", "start": 1.0})
    assert build_disturbance({"kind": "paper"}) == PaperDisturbance()

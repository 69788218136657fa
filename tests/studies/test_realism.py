"""Realism ingredients (actuator saturation and rate limits, sensor noise) and the realism study."""
import json
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from auvtrack.environment.sensors import measure, noise_table
from auvtrack.plant.actuators import pack_actuator, rate_limit, saturate

finite = st.floats(-1e4, 1e4, allow_nan=False)
limit = st.one_of(st.floats(1e-3, 1e4), st.just(math.inf))


@given(st.tuples(finite, finite, finite), st.tuples(limit, limit, limit))
def test_saturation_is_the_projection_on_the_box(tau, lim):
    act = pack_actuator(lim, (math.inf,) * 3)
    out = saturate(tau, act, 0)
    for x, y, m in zip(tau, out, lim):
        assert abs(y) <= m
        assert y == (x if abs(x) <= m else math.copysign(m, x))


@given(st.tuples(finite, finite, finite), st.tuples(finite, finite, finite), st.tuples(limit, limit, limit),
       st.floats(1e-3, 0.1))
def test_rate_limit_moves_at_most_rate_times_h_and_exactly_when_it_can(cmd, prev, rate, h):
    act = pack_actuator((math.inf,) * 3, rate)
    out = rate_limit(cmd, prev, act, 0, h)
    for c, p, y, r in zip(cmd, prev, out, rate):
        ulp = 4 * np.finfo(float).eps * max(abs(p), abs(c))  # p +- r h is rounded once
        assert abs(y - p) <= r * h * (1 + 1e-12) + ulp
        if abs(c - p) <= r * h:
            assert y == c
        else:
            assert math.copysign(1.0, y - p) == math.copysign(1.0, c - p)


def test_pack_actuator_refuses_bad_limits():
    with pytest.raises(ValueError, match="must be > 0"):
        pack_actuator((1.0, 0.0, 1.0), (1.0, 1.0, 1.0))
    with pytest.raises(ValueError, match="3 values each"):
        pack_actuator((1.0, 1.0), (1.0, 1.0, 1.0))


def test_noise_is_seeded_scaled_and_independent_per_channel():
    sigma = np.array([0.01, 0.02, 0.03, 0.001, 0.002, 0.1, 0.2, 0.3, 0.01, 0.02])
    a, b = noise_table(7, 40_000, sigma), noise_table(7, 40_000, sigma)
    assert a.shape == (40_000, 10) and np.array_equal(a, b)
    assert not np.array_equal(a, noise_table(8, 40_000, sigma))
    np.testing.assert_allclose(a.std(axis=0), sigma, rtol=0.015)  # 40k samples: ~0.35 % std error
    np.testing.assert_allclose(a.mean(axis=0) / sigma, 0.0, atol=0.02)
    corr = np.corrcoef(a.T) - np.eye(10)
    assert np.abs(corr).max() < 0.03
    assert noise_table(7, 100, np.zeros(10)).shape == (0, 10)
    with pytest.raises(ValueError, match="sigma needs 10"):
        noise_table(7, 100, -sigma)


def test_measure_adds_row_k_and_nothing_without_noise():
    X = np.arange(12.0)
    noise = noise_table(3, 5, np.full(10, 0.5))
    eta, nu = measure(tuple(X[:5]), tuple(X[5:10]), noise, 2)
    np.testing.assert_array_equal(np.array(eta + nu), X[:10] + noise[2])
    eta, nu = measure(tuple(X[:5]), tuple(X[5:10]), np.zeros((0, 10)), 2)
    np.testing.assert_array_equal(np.array(eta + nu), X[:10])


# --- in the closed loop ---------------------------------------------------------------------------

import auvtrack  # noqa: E402

SHORT = ["sim.duration=3", "sim.log_dt=0.001"]


def test_saturation_bounds_the_applied_input_in_both_modes():
    free = auvtrack.simulate({}, SHORT, warn=False)
    assert max(abs(free["tau_u"])) > 300  # the Section 4 start asks for large inputs
    for mode in ([], ["sim.control_rate=100"]):
        res = auvtrack.simulate({}, SHORT + mode + ["actuator.tau_max=[300, 40, 40]"], warn=False)
        for ch, m in zip(("tau_u", "tau_q", "tau_r"), (300, 40, 40)):
            assert np.max(np.abs(res[ch])) <= m
        assert np.max(np.abs(res["tau_u"])) == 300  # the limit is reached, not just respected


def test_rate_limit_holds_between_samples_and_starts_from_rest():
    h, rate = 0.01, 500.0
    res = auvtrack.simulate({}, SHORT + ["sim.control_rate=100", f"actuator.rate_max=[{rate}, {rate}, {rate}]"],
                            warn=False)
    tau = res.to_pandas()[["tau_u", "tau_q", "tau_r"]].to_numpy()
    samples = tau[::10]  # log every 1 ms, control every 10 ms: the held value of each sample
    steps = np.abs(np.diff(np.vstack([np.zeros(3), samples]), axis=0))
    assert steps.max() <= rate * h * (1 + 1e-12)
    assert steps[:, 0].max() == pytest.approx(rate * h)  # it binds
    assert np.all(tau[:10] == samples[0])  # zero-order hold inside a sample


def test_sensor_noise_is_seeded_and_only_the_controller_sees_it():
    base = SHORT + ["sim.control_rate=100", "controller.kind=ftsmc"]
    clean = auvtrack.simulate({}, base, warn=False)
    noisy = base + ["sensor.sigma_eta=[0.001, 0.001, 0.001, 0.0, 0.0]"]
    a, b = auvtrack.simulate({}, noisy, warn=False), auvtrack.simulate({}, noisy, warn=False)
    c = auvtrack.simulate({}, noisy + ["seed=1"], warn=False)
    np.testing.assert_array_equal(a["tau_u"], b["tau_u"])
    assert not np.array_equal(a["tau_u"], clean["tau_u"]) and not np.array_equal(a["tau_u"], c["tau_u"])
    assert np.array_equal(a["t"], clean["t"]) and np.all(np.isfinite(a["x"]))
    # the logged error is eq. (2) of the logged state (ell = 1 m), to rounding
    th, ps = a["theta"], a["psi"]
    np.testing.assert_allclose(a["ex"], a["x"] + np.cos(th) * np.cos(ps) - a["xd"], rtol=0, atol=1e-12)
    np.testing.assert_allclose(a["ez"], a["z"] - np.sin(th) - a["zd"], rtol=0, atol=1e-12)
    # and that state is the true one: under 5 cm of position noise per 10 ms sample the logged
    # x, y still move by at most the vehicle's own ~1.2 mm per 1 ms row (noise would jump by cm)
    loud = auvtrack.simulate({}, base + ["sensor.sigma_eta=[0.05, 0.05, 0.0, 0.0, 0.0]"], warn=False)
    assert loud.status == "ok"
    assert np.abs(np.diff(loud["x"])).max() < 0.005 and np.abs(np.diff(loud["y"])).max() < 0.005


def test_ideal_actuator_and_sensor_change_nothing():
    """The defaults (inf limits, zero noise) reproduce the run without the sections bit for bit."""
    a = auvtrack.simulate({}, ["sim.duration=2", "sim.control_rate=100"], warn=False)
    b = auvtrack.simulate({}, ["sim.duration=2", "sim.control_rate=100", "actuator.tau_max=[inf, inf, inf]",
                               "actuator.rate_max=[inf, inf, inf]", "sensor.sigma_nu=[0, 0, 0, 0, 0]"], warn=False)
    for ch in ("x", "tau_u", "tau_q", "ez"):
        np.testing.assert_array_equal(a[ch], b[ch])


def test_realism_study_quick(tmp_path):
    from auvtrack.studies.realism import FACTORS, VEHICLES, run

    report = run(tmp_path, quick=True)
    doc = json.loads((tmp_path / "results.json").read_text())
    rows = doc["rows"]
    assert len(rows) == len(VEHICLES) * 2 * (1 + 2 * len(FACTORS))
    assert {r["vehicle"] for r in rows} == set(VEHICLES) == {"paper", "remus100"}
    assert {r["factor"] for r in rows} == {"ideal", *(f.name for f in FACTORS)}
    for r in rows:
        assert r["status"] in ("ok", "failed") and (r["status"] == "ok") == (r["cause"] is None)
    ideal = [r for r in rows if r["factor"] == "ideal"]
    assert all(r["status"] == "ok" for r in ideal)
    assert all(r["rmse"] < 0.05 for r in ideal if r["vehicle"] == "paper")
    text = report.read_text()
    assert "Failures by cause" in text and (tmp_path / "figures" / "degradation_remus100.png").exists()


@pytest.mark.parametrize("override, field", [
    ("actuator.rate_max=[100, 100, 100]", "actuator.rate_max"),
    ("sensor.sigma_eta=[0.001, 0, 0, 0, 0]", "sensor"),
    ("sensor.sigma_nu=[0, 0, 0, 0, 0.01]", "sensor"),
])
def test_rate_limit_and_noise_need_a_control_rate(override, field):
    from auvtrack.scenario import ScenarioError, load_scenario

    with pytest.raises(ScenarioError) as err:
        load_scenario({}, [override])
    msg = str(err.value)
    assert "\n" not in msg and field in msg and "control_rate > 0" in msg
    load_scenario({}, [override, "sim.control_rate=100"])  # with sampled control it is accepted


def test_actuator_limits_broadcast_round_trip_and_refuse_non_positive():
    from auvtrack.scenario import ScenarioError, load_scenario

    sc = load_scenario({}, ["actuator.tau_max=200"])
    assert sc.actuator.tau_max == (200.0, 200.0, 200.0) and sc.actuator.rate_max == (math.inf,) * 3
    d = sc.to_dict()
    assert d["actuator"]["rate_max"] == ["inf"] * 3 and load_scenario(d) == sc
    for bad in ("actuator.tau_max=[0, 1, 1]", "actuator.rate_max=[1, -1, 1]", "actuator.tau_max=[nan, 1, 1]"):
        with pytest.raises(ScenarioError, match="actuator"):
            load_scenario({}, [bad])


@pytest.mark.parametrize("kind", ["ftsmc", "fxtntsmc"])
def test_sampled_law_uses_the_attitude_of_the_measured_state(kind):
    """The engine hands the law attitude(measured theta, psi), not that of the true state."""
    from auvtrack.control.contract import WORK_SIZE
    from auvtrack.vehicle.kinematics import attitude
    from auvtrack.scenario import load_scenario
    from auvtrack.simulation.pipeline import prepare, run_prepared
    from auvtrack.control.contract import UNLIMITED, LawArgs, LawOutputs, Measured
    from auvtrack.user_modules import load_module

    sc = load_scenario({}, ["sim.duration=0.05", "sim.control_rate=100", f"controller.kind={kind}",
                            "sensor.sigma_eta=[0, 0, 0, 0.05, 0.05]"])
    p = prepare(sc)
    first = run_prepared(p).to_pandas().iloc[0]  # the input applied on [0, 10 ms) is the law at sample 0
    x0 = p.plant.x0
    eta, nu = measure(tuple(x0[:5]), tuple(x0[5:10]), p.noise, 0)
    control = load_module(p.key.law).control

    def law(att):
        tau, dxc, aux, work = np.zeros(3), np.zeros(p.controller.x0.size), np.zeros(64), np.zeros(WORK_SIZE)
        args = LawArgs(_ref0(p), p.ref_p, p.cp, p.vp_nom, *UNLIMITED, (0.0, 0.0, 0.0), 0.0, work)
        assert control(0.0, Measured(eta, nu, att), p.controller.x0, args, LawOutputs(tau, dxc, aux)) == 0
        return tau

    measured, true = law(attitude(eta[3], eta[4])), law(attitude(x0[3], x0[4]))
    applied = first[["tau_u", "tau_q", "tau_r"]].to_numpy(float)
    np.testing.assert_array_equal(applied, measured)
    assert np.abs(measured - true).max() > 1e-6 * np.abs(measured).max()  # the test can tell them apart


def _ref0(p):
    from auvtrack.reference import eval_reference

    refm = np.zeros((3, 3))
    eval_reference(p.ref_p, 0.0, refm)
    return refm

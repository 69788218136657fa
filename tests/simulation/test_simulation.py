"""The compiled closed-loop engine: integrator order, modes, logging, determinism, failures."""

import numpy as np
import pytest

import auvtrack
from auvtrack.simulation.pipeline import prepare, run_prepared
from auvtrack.scenario import load_scenario

PAPER = "scenarios/paper.toml"
OPEN_LOOP = ["controller.kind=open_loop", "controller.tau0=[100, 0, 2]", "controller.amplitude=[20, 1, 1]",
             "controller.frequency=[0.5, 0.3, 0.2]", "disturbance=[]", "sim.duration=2"]


def _final_state(overrides):
    res = run_prepared(prepare(load_scenario(PAPER, overrides)))
    assert res.ok, res.failure
    return np.array([res[n][-1] for n in ("x", "y", "z", "theta", "psi", "u", "v", "w", "q", "r")])


@pytest.mark.parametrize("rate", [0, 10])
def test_rk4_is_fourth_order_on_the_real_engine(rate):
    """Halving dt divides the global error by ~16, continuous and sampled-data (ZOH) alike."""
    common = OPEN_LOOP + ["sim.log_dt=0.1", f"sim.control_rate={rate}"]
    ref = _final_state(common + ["sim.dt=0.00078125"])
    errs = [np.abs(_final_state(common + [f"sim.dt={dt}"]) - ref).max() for dt in (0.025, 0.0125, 0.00625)]
    ratios = [errs[i] / errs[i + 1] for i in range(2)]
    assert all(13.0 < r < 19.0 for r in ratios), (errs, ratios)


def test_logging_is_decimated_on_an_exact_grid():
    res = auvtrack.simulate(PAPER, ["controller.kind=ftsmc", "sim.duration=3", "sim.log_dt=0.05"])
    assert len(res.t) == 61
    np.testing.assert_allclose(res.t, np.arange(61) * 0.05, rtol=0, atol=1e-12)
    assert res.names[:20] == ("t", "x", "y", "z", "theta", "psi", "u", "v", "w", "q", "r", "tau_u", "tau_q",
                              "tau_r", "xd", "yd", "zd", "ex", "ey", "ez")


def test_logged_error_and_reference_are_consistent():
    """ex = x + ell cos(theta) cos(psi) - xd etc. (eq. 2), and xd is the paper's helix."""
    res = auvtrack.simulate(PAPER, ["controller.kind=ftsmc", "sim.duration=5"])
    th, ps = res["theta"], res["psi"]
    np.testing.assert_allclose(res["xd"], 4 * np.cos(0.1 * res.t), atol=1e-12)
    np.testing.assert_allclose(res["zd"], -0.1 * res.t, atol=1e-12)
    np.testing.assert_allclose(res["ex"], res["x"] + np.cos(th) * np.cos(ps) - res["xd"], atol=1e-12)
    np.testing.assert_allclose(res["ez"], res["z"] - np.sin(th) - res["zd"], atol=1e-12)


def test_seeded_runs_are_identical_and_seeds_matter(tmp_path):
    over = ["controller.kind=ftsmc", "sim.duration=5", "disturbance.1.kind=current", "disturbance.1.sigma=[0.1, 0.1, 0.05]",
            "disturbance.1.tau=5"]
    a = auvtrack.simulate(PAPER, over + ["seed=7"]).save(tmp_path / "a")
    b = auvtrack.simulate(PAPER, over + ["seed=7"]).save(tmp_path / "b")
    c = auvtrack.simulate(PAPER, over + ["seed=8"]).save(tmp_path / "c")
    assert (a / "trajectory.csv").read_bytes() == (b / "trajectory.csv").read_bytes()
    assert (a / "trajectory.csv").read_bytes() != (c / "trajectory.csv").read_bytes()


def test_divergence_stops_with_a_diagnostic_and_keeps_the_partial_result():
    """A constant 200 N m pitch moment against ~30 N m of restoring moment tips the vehicle over."""
    res = auvtrack.simulate(PAPER, ["controller.kind=open_loop", "controller.tau0=[0, 200, 0]", "sim.duration=30"])
    assert res.status == "failed"
    f = res.failure
    assert f["cause"] == "pitch_limit"
    assert 0 < f["time"] < 30
    assert abs(f["state"]["theta"]) > np.radians(85)
    assert 0 < len(res.t) < 3001 and res.t[-1] <= f["time"]
    assert np.all(np.isfinite(res["theta"]))


def test_state_limit_and_nonfinite_are_caught():
    res = auvtrack.simulate(PAPER, ["controller.kind=open_loop", "controller.tau0=[2000, 0, 0]", "sim.state_limit=5",
                                    "sim.duration=30"])
    assert res.failure["cause"] == "state_limit"
    # zero damping and a huge yaw moment: r grows without bound until it overflows or hits the limit
    res = auvtrack.simulate(PAPER, ["controller.kind=open_loop", "controller.tau0=[0, 0, 1e306]", "sim.duration=5",
                                    "sim.state_limit=1e308"])
    assert res.status == "failed" and res.failure["cause"] in ("nonfinite", "state_limit")


def test_ftsmc_tracks_the_section4_helix():
    """The baseline closes the loop: steady-state error far below 1 cm (ERRATA 16)."""
    res = auvtrack.simulate(PAPER, ["controller.kind=ftsmc", "metrics.window=[40, 100]"])
    assert res.ok
    for a in "xyz":
        assert res.metrics[f"max_abs_{a}"] < 1e-4
        assert res.metrics[f"settle_1mm_{a}"] == 40.0  # below 1 mm for the whole window


def test_sampled_data_mode_runs_and_holds_the_input():
    res = auvtrack.simulate(PAPER, ["controller.kind=ftsmc", "sim.control_rate=20", "sim.duration=10",
                                    "sim.log_dt=0.001"])
    assert res.ok
    tau = res["tau_u"]
    # the input changes only at the 50 ms sample instants
    changes = np.flatnonzero(np.diff(tau) != 0) + 1
    assert len(changes) == 200 and np.all(changes % 50 == 0)


def test_metrics_match_the_reference_implementation_when_logging_every_step():
    from auvtrack.metrics import metrics_from_trajectory
    from auvtrack.reference import build_reference

    res = auvtrack.simulate(PAPER, ["controller.kind=ftsmc", "sim.duration=4", "sim.log_dt=0.001"])
    e = np.column_stack([res["ex"], res["ey"], res["ez"]])
    tau = np.column_stack([res["tau_u"], res["tau_q"], res["tau_r"]])
    ref = metrics_from_trajectory(res.t, e, tau, 0.0, np.inf, position=np.column_stack([res["x"], res["y"], res["z"]]),
                                  path=build_reference(res.scenario["reference"]), effort=np.zeros_like(tau))
    for k, v in ref.items():
        # the path metrics: two projection algorithms (Newton vs. Brent), the run starting at the helix's
        # centre of curvature, where every point of the circle is about as close (1e-9 relative apart)
        rel = 1e-7 if k.startswith(("xtrack", "vtrack", "along")) else 1e-9
        assert res.metrics[k] == pytest.approx(v, rel=rel, abs=1e-12), k


def test_uncertainty_changes_only_the_true_plant():
    sc = load_scenario(PAPER, ["uncertainty.M=0.2", "uncertainty.C=0.3", "uncertainty.D=-0.1"])
    p = prepare(sc)
    np.testing.assert_allclose(p.pp[0:5], 1.2 * p.vp_nom[0:5])
    np.testing.assert_allclose(p.pp[5:10], 0.9 * p.vp_nom[5:10])
    assert p.pp[12] == pytest.approx(1.3) and p.vp_nom[12] == 1.0


def test_true_lumped_disturbance_vanishes_on_the_nominal_plant():
    res = auvtrack.simulate(PAPER, ["controller.kind=ftsmc", "uncertainty.C=0", "uncertainty.D=0", "disturbance=[]",
                                    "sim.duration=3"])
    for a in "xyz":
        assert np.abs(res[f"chi_{a}"]).max() < 1e-12



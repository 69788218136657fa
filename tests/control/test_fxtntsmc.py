"""The paper's controller in corrected form: closed-loop identities and Section 4 behaviour."""
import warnings

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import auvtrack
from auvtrack.control.fxtntsmc import StartOutsideEnvelope, surface, switch
from auvtrack.scenario import load_scenario
from auvtrack.simulation.pipeline import prepare

PAPER = "scenarios/paper.toml"
IDEAL = ["uncertainty.C=0", "uncertainty.D=0", "disturbance=[]", "estimator.kind=none",
         "initial.nu=[0, 1.0, 0, 0, 0]"]  # moving outwards on y: the envelope trigger acts


def _quiet(*args):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return auvtrack.simulate(*args)


def _reaching_law_residual(res, gains=(0.005, 0.8, 0.6)):
    """max |S(t+h) - S(t-h) - Simpson integral of the reaching law| / (2h (1 + |law|)).

    Stencils where S changes sign or a C1 switch (|z| = z_switch, |S_e| = sigma, trigger band
    edges) is crossed are skipped: the law is continuous there but not smooth, and central
    quadrature is only first-order accurate across such a kink.
    """
    k1, k2, k3 = gains
    h = res.t[1] - res.t[0]
    worst, used = 0.0, 0
    for a in "xyz":
        S, z, g = res[f"sliding_{a}"], res[f"zeta_{a}"], res[f"g_{a}"]
        se = np.array([surface(v, 0.8, 0.8, 0.8, 2.0, False, 0.01, 1e-6)[0] for v in z])
        law = -k1 * np.sign(S) - k2 * S**3 - k3 * S
        ok = np.ones(len(S) - 2, bool)
        for lab in (np.sign(S), np.abs(z) > 0.01, np.abs(se) > 0.005, (g > 0).astype(int) + (g >= 1)):
            ok &= (lab[2:] == lab[:-2]) & (lab[1:-1] == lab[2:])
        err = np.abs(S[2:] - S[:-2] - h / 3 * (law[:-2] + 4 * law[1:-1] + law[2:])) / (2 * h * (1 + np.abs(law[1:-1])))
        worst = max(worst, err[ok].max())
        used += ok.sum()
    return worst, used


@pytest.mark.parametrize("envelope", ["none", "rigid", "reactive"])
def test_sliding_variable_obeys_its_reaching_law(envelope):
    """Nominal plant, no disturbance, no estimator: S_dot = -k1 sign S - k2 S^3 - k3 S (ERRATA 13)."""
    res = _quiet(PAPER, IDEAL + [f"envelope.kind={envelope}", "sim.duration=3", "sim.log_dt=0.001"])
    worst, used = _reaching_law_residual(res)
    assert used > 8500
    assert worst < 1e-4
    if envelope == "reactive":
        assert (res["g_y"] > 0).sum() > 100  # the trigger (and so loop 2) was active


def test_reaching_law_holds_with_the_proactive_risk_monitor_and_converges():
    """Both algebraic loops (ERRATA 10) solved exactly: the residual shrinks with dt.

    While the risk indicator sweeps its band the solution is less smooth, so the quadrature
    residual is larger; it must fall by > 4x per halving of dt (a wrong loop leaves O(1)).
    """
    out = []
    for dt in (1e-3, 5e-4, 2.5e-4):
        res = _quiet(PAPER, IDEAL + ["envelope.kind=proactive", "sim.duration=1", f"sim.dt={dt}", f"sim.log_dt={dt}"])
        assert (res["g_y"] > 0).sum() > 50
        out.append(_reaching_law_residual(res)[0])
    assert out[0] / out[1] > 4 and out[1] / out[2] > 4, out
    assert out[2] < 1e-4


@pytest.fixture(scope="module")
def section4():
    return _quiet(PAPER)


def test_section4_errors_stay_inside_the_envelope(section4):
    assert section4.ok
    for a in "xyz":
        assert np.all(np.abs(section4[f"e{a}"]) < section4[f"rho_{a}"])
        assert np.all(section4[f"rho_{a}"] >= section4[f"rho1_{a}"])  # rho_bar >= 0 (Remark 1)


def test_section4_reaches_submillimetre_error_with_bounded_torques(section4):
    """ERRATA: sub-millimetre tracking within about 10 s; torques finite and bounded afterwards."""
    t = section4.t
    late = t >= 20
    for a in "xyz":
        assert section4.metrics[f"settle_1mm_{a}"] < 12.0
        assert np.abs(section4[f"e{a}"][late]).max() < 1e-3
    for j, bound in (("tau_u", 100.0), ("tau_q", 30.0), ("tau_r", 30.0)):
        assert np.all(np.isfinite(section4[j]))
        assert np.abs(section4[j][late]).max() < bound


def test_estimator_tracks_the_true_lumped_disturbance(section4):
    late = section4.t >= 20
    for a in "xyz":
        chi, chat = section4[f"chi_{a}"][late], section4[f"chi_hat_{a}"][late]
        assert np.sqrt(np.mean((chi - chat) ** 2)) < 0.1 * np.sqrt(np.mean(chi**2))


def test_initial_widening_is_exact_and_announced():
    sc = load_scenario(PAPER)
    p = prepare(sc)
    assert any("widened" in n and "rho_bar_y" in n for n in p.notes)
    rb0 = p.resolved["controller"]["rho_bar0"]
    assert rb0[0] == 0.0 and rb0[2] == 0.0  # x and z start well inside
    e_y0 = 0.5  # eta(0) = [0, 0.5, 0, 0, 0], eta_d(0) = [4, 0, 0]
    assert e_y0 / (0.5 + rb0[1]) == pytest.approx(sc.envelope.xi0, abs=1e-14)
    res = auvtrack.simulate(PAPER, ["sim.duration=0.01"])
    assert any("widened" in n and "rho_bar_y" in n for n in res.notes)


def test_a_start_on_the_envelope_is_refused_without_the_treatment():
    with pytest.raises(StartOutsideEnvelope, match="axis y"):
        prepare(load_scenario(PAPER, ["envelope.widen_start=false"]))
    # inside the envelope, no treatment is needed and none is applied
    p = prepare(load_scenario(PAPER, ["envelope.widen_start=false", "initial.eta=[0, 0.2, 0, 0, 0]"]))
    assert p.notes == () and p.resolved["controller"]["rho_bar0"] == [0.0, 0.0, 0.0]


def test_printed_eq24_fails_cleanly():
    """ERRATA 7: the printed baseline collapses to 0 at T; the run reports a failure, no crash."""
    res = _quiet(PAPER, ["envelope.baseline=printed"])
    assert res.status == "failed"
    assert res.failure["cause"] == "controller" and "envelope" in res.failure["detail"]
    assert 10.0 < res.failure["time"] < 15.0
    assert len(res.t) > 1000  # the partial trajectory is kept


def test_printed_surface_spikes_grow_as_its_floor_shrinks():
    """ERRATA 12: z_z(0) = 0 with z_dot != 0; the printed |z|^(a2-1) needs a floor and the pitch
    torque peak grows as the floor shrinks, while the C1 surface stays bounded."""
    base = ["sim.duration=2", "sim.log_dt=0.001"]
    peak = {}
    for name, extra in (("c1", []), ("1e-6", ["controller.surface=printed", "controller.z_floor=1e-6"]),
                        ("1e-9", ["controller.surface=printed", "controller.z_floor=1e-9"])):
        res = _quiet(PAPER, base + extra)
        assert res.ok
        peak[name] = np.abs(res["tau_q"]).max()
    assert peak["c1"] < 500.0
    assert peak["1e-6"] > 2 * peak["c1"]
    assert peak["1e-9"] > 2 * peak["1e-6"]


@pytest.mark.parametrize("kind", ["printed", "none"])
def test_other_estimators_run(kind):
    res = _quiet(PAPER, [f"estimator.kind={kind}", "sim.duration=30"])
    assert res.ok
    if kind == "none":
        assert np.all(res["chi_hat_x"] == 0)


def test_surface_and_switch_are_c1():
    for zs in (0.01, 0.1):
        for f in (lambda v: surface(v, 0.8, 0.8, 0.8, 2.0, False, zs, 1e-6), lambda v: switch(v, 0.6, zs)):
            lo, hi = f(zs * (1 - 1e-9)), f(zs * (1 + 1e-9))
            assert lo[0] == pytest.approx(hi[0], rel=1e-7) and lo[1] == pytest.approx(hi[1], rel=1e-6)
    assert np.isfinite(surface(0.0, 0.8, 0.8, 0.8, 2.0, False, 0.01, 1e-6)[1])  # nonsingular at z = 0
    assert surface(0.0, 0.8, 0.8, 0.8, 2.0, True, 0.01, 1e-6)[1] == pytest.approx(0.8 * 0.8 * 1e-6 ** -0.2)


def test_run_json_records_the_start_treatment(tmp_path):
    res = _quiet(PAPER, ["sim.duration=0.5"])
    folder = res.save(tmp_path / "r")
    loaded = auvtrack.Result.load(folder)
    assert loaded.scenario["resolved"]["controller"]["rho_bar0"][1] > 0
    assert any("widened" in n for n in loaded.meta["notes"])


def _surface_eq28(z, a1, a2, a3, a4, printed, zs, zfloor):
    """Eq. (28) written with a pow per term (reference for the one-pow compiled form)."""
    az, s = abs(z), np.sign(z)
    if not printed and az <= zs:
        c1, c2 = (2 - a2) * zs ** (a2 - 1), (a2 - 1) * zs ** (a2 - 2)
        g, dg = c1 * z + c2 * s * z * z, c1 + 2 * c2 * az
    else:
        g, dg = s * az**a2, a2 * max(az, zfloor) ** (a2 - 1)
    return a1 * g + a3 * s * az**a4, a1 * dg + a3 * a4 * az ** (a4 - 1)


def _switch_eq27(se, alpha, sigma):
    a = abs(se)
    if a > sigma:
        return np.sign(se) * a**alpha, alpha * a ** (alpha - 1)
    b1, b2 = (2 - alpha) * sigma ** (alpha - 1), (alpha - 1) * sigma ** (alpha - 2)
    return b1 * se + b2 * np.sign(se) * se * se, b1 + 2 * b2 * a


def test_one_pow_forms_match_eq27_eq28():
    """surface/switch compute x^p as x x^(p-1) with precomputed coefficients: same to ~1e-12."""
    rng = np.random.default_rng(1)
    zs_ = np.concatenate([rng.uniform(-3, 3, 400), rng.uniform(-0.02, 0.02, 400),
                          [0.0, 1e-7, -1e-7, 0.01, -0.01]])
    for a2, a4, printed in ((0.8, 2.0, False), (0.6, 1.7, False), (0.8, 2.0, True), (0.55, 3.0, True)):
        for z in zs_:
            args = (z, 0.8, a2, 0.7, a4, printed, 0.01, 1e-6)
            np.testing.assert_allclose(surface(*args), _surface_eq28(*args), rtol=1e-12, atol=1e-300)
    for alpha in (0.6, 0.9, 1.5):
        for se in np.concatenate([zs_, rng.uniform(-0.006, 0.006, 200)]):
            np.testing.assert_allclose(switch(se, alpha, 0.005), _switch_eq27(se, alpha, 0.005),
                                       rtol=1e-12, atol=1e-300)


def test_setup_packs_the_precomputed_coefficients():
    from auvtrack.control import fxtntsmc as F
    p = prepare(load_scenario(PAPER, ["sim.duration=0.1", "controller.a2=0.7", "controller.alpha=0.65"]))
    assert p.cp[F.GAINS.c1] == pytest.approx((2 - 0.7) * 0.01 ** (0.7 - 1), rel=1e-15)
    assert p.cp[F.GAINS.c2] == pytest.approx((0.7 - 1) * 0.01 ** (0.7 - 2), rel=1e-15)
    assert p.cp[F.GAINS.beta1] == pytest.approx((2 - 0.65) * 0.005 ** (0.65 - 1), rel=1e-15)
    assert p.cp[F.GAINS.beta2] == pytest.approx((0.65 - 1) * 0.005 ** (0.65 - 2), rel=1e-15)
    # Section 4: effective-gain law (default), 7 neurons
    assert p.cp[F.GAINS.estimator] == 3 and p.cp[F.GAINS.neurons] == 7


def test_ftsmc_sig_pair_matches_two_sig_calls():
    from auvtrack.control.tracking import sig, sig_pair
    for gam in (1.1, 1.5, 1.9):
        for x in (0.0, 1e-300, -1e-200, 1e-8, -0.3, 2.5, -1e3, 1e150):
            got, ref = sig_pair(x, gam), (sig(x, gam), sig(x, 2.0 - gam))
            np.testing.assert_allclose(got, ref, rtol=1e-12, atol=0)


@given(st.floats(-1e3, 1e3), st.floats(0, 10), st.floats(0, 10), st.floats(0, 10))
def test_reaching_law_is_eq32(S, k1, k2, k3):
    from auvtrack.control.fxtntsmc import reaching_law
    from auvtrack.control.tracking import sig, sign

    want = -k1 * sign(S) - k2 * sig(S, 3.0) - k3 * S
    assert reaching_law(S, k1, k2, k3) == pytest.approx(want, rel=1e-12, abs=1e-300)


def test_the_network_may_fill_the_whole_scratch_array():
    """The basis of eq. (12) is written to work[0:m], m up to WORK_SIZE, eight neurons per vector exp."""
    from auvtrack.control.contract import WORK_SIZE

    res = _quiet(PAPER, [f"estimator.neurons={WORK_SIZE}", "sim.duration=0.05"])
    assert res.ok and np.isfinite(res["chi_hat_x"]).all()
    with pytest.raises(ValueError, match=f"estimator.neurons: at most {WORK_SIZE}"):
        prepare(load_scenario(PAPER, [f"estimator.neurons={WORK_SIZE + 1}", "sim.duration=0.05"]))

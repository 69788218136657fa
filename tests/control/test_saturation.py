"""The actuators' reach fed back to the laws: the compensated forms against their design laws.

* Without saturation the compensated form is the published one, bit for bit (Section 4).
* At seeded states with a finite reach, each compensated law's state derivative and command are
  its design law (docs/derivation.md section 7), with the error acceleration the reach removes,
  d_a, computed independently (central differences of the kinematic e_dot along the nominal
  dynamics with the command and with the command clipped to the reach).
* In closed loop on the nominal plant with a saturating start: the PPC's transformed error of the
  compensated error follows its linear law exactly, the FXTNTSMC's sliding variable its reaching
  law.
* The reach cut in mid-run (a plug-in plant, ``reach_cut_plant.py``): each law's integral or
  estimator state stays bounded and recovers with the compensated form; the published form winds
  up (or fails).
* On a 6-DOF truth the PID's back-calculation now gets the allocation's reach.
"""
from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import auvtrack
from auvtrack.control import backstepping, fxtntsmc, ppc, sta
from auvtrack.control.contract import evaluate
from auvtrack.control.fxtntsmc.envelopes import baseline
from auvtrack.control.tracking import error_state
from auvtrack.scenario import load_scenario, paper_scenario_path
from auvtrack.simulation.pipeline import prepare
from auvtrack.vehicle.kinematics import attitude, virtual_point
from auvtrack.vehicle.params import VP

from test_baselines import VP_NOM, _close, _initial_errors, _linear_solution, _state, e_ddot_nominal
from test_fxtntsmc import IDEAL as FXT_IDEAL
from test_fxtntsmc import _reaching_law_residual

PAPER = str(paper_scenario_path())
IDEAL = ["uncertainty.C=0", "uncertainty.D=0", "disturbance=[]"]
REACH = ((-50.0, -5.0, -5.0), (50.0, 5.0, 5.0))
CUT_PLANT = str(Path(__file__).with_name("reach_cut_plant.py"))
LAWS = ("pid", "sta", "backstepping", "ppc", "fxtntsmc")


def _sim(extra, scenario=PAPER):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return auvtrack.simulate(scenario, list(extra))


def _prepared(kind, saturation, extra=()):
    return prepare(load_scenario(PAPER, [f'controller={{kind="{kind}", saturation="{saturation}"}}', *extra]))


def _lost(eta, nu, tau, refm, reach=REACH):
    """d_a: e_ddot with the command clipped to the reach, less e_ddot with the command (nominal model)."""
    clipped = np.clip(tau, reach[0], reach[1])
    return e_ddot_nominal(eta, nu, clipped, refm) - e_ddot_nominal(eta, nu, tau, refm)


# --------------------------------------------------------------------------- no saturation: identical

@pytest.mark.parametrize("kind", LAWS)
def test_compensated_form_is_the_published_one_bit_for_bit_without_saturation(kind):
    """Section 4 (model error, the paper's disturbance), no actuator limit: every shared channel equal."""
    runs = {s: _sim([f'controller={{kind="{kind}", saturation="{s}"}}', "sim.duration=10"])
            for s in ("published", "compensated")}
    pub, comp = runs["published"], runs["compensated"]
    assert pub.ok and comp.ok
    for name in pub.channels:
        assert np.array_equal(pub[name], comp[name], equal_nan=True), name
    extra = set(comp.channels) - set(pub.channels)
    assert extra == ({"sat_comp_x", "sat_comp_y", "sat_comp_z"} if kind in ("ppc", "fxtntsmc") else set())
    for name in extra:
        assert not comp[name].any()  # the auxiliary system never left 0


# --------------------------------------------------------------------------- at given states

@settings(max_examples=40)
@given(st.integers(0, 2**32 - 1))
def test_sta_integral_is_conditioned_on_the_reach(seed):
    """v_dot = -k2 sign(s) + kaw d_a (eq. S3c), d_a the e_ddot the reach removes."""
    rng, eta, nu, att, refm, t = _state(seed)
    prep = _prepared("sta", "compensated", ["controller.kaw=0.7"])
    xc = rng.normal(0.0, 0.5, 3)
    _, tau, dxc, _ = evaluate(sta.control, t, eta, nu, xc, refm, prep.cp, VP_NOM, n_aux=6, lo=REACH[0], hi=REACH[1])
    e, ed, _ = (np.array(v) for v in error_state(eta, att, nu, refm, VP_NOM))
    s = ed + e  # lam = 1
    p = sta.Params()
    _close(dxc, -p.k2 * np.sign(s) + 0.7 * _lost(eta, nu, tau, refm), 1e-6)


@settings(max_examples=40)
@given(st.integers(0, 2**32 - 1))
def test_backstepping_bias_is_conditioned_on_the_reach(seed):
    """b_hat_dot = gamma z2 - sigma b_hat - kaw d_a (eq. B3c)."""
    rng, eta, nu, att, refm, t = _state(seed)
    prep = _prepared("backstepping", "compensated", ["controller.kaw=0.6", "controller.sigma=0.2"])
    xc = rng.normal(0.0, 0.5, 3)
    _, tau, dxc, _ = evaluate(backstepping.control, t, eta, nu, xc, refm, prep.cp, VP_NOM, n_aux=6,
                              lo=REACH[0], hi=REACH[1])
    e, ed, _ = (np.array(v) for v in error_state(eta, att, nu, refm, VP_NOM))
    p = backstepping.Params()
    _close(dxc, p.gamma * (ed + p.c1 * e) - 0.2 * xc - 0.6 * _lost(eta, nu, tau, refm), 1e-6)


def _auxiliary_case(seed, rho):
    """A state, a reference putting the compensated error e~ = e - lam inside ``rho`` (m, per axis), and (lam, lam_dot)."""
    rng, eta, nu, att, _, _ = _state(seed)
    p1 = np.array(virtual_point(eta, att, VP_NOM[VP.ell]))
    lam, lamd = rng.normal(0.0, 0.5, 3), rng.normal(0.0, 0.2, 3)
    etil = rng.uniform(-0.6, 0.6, 3) * rho
    refm = np.vstack([p1 - lam - etil, rng.normal(0.0, 0.5, 3), rng.normal(0.0, 0.1, 3)])
    return eta, nu, att, refm, lam, lamd


def _shifted(refm, lam, lamd):
    """The reference that makes the published law see e~ = e - lam, e~_dot = e_dot - lam_dot."""
    out = refm.copy()
    out[0] += lam
    out[1] += lamd
    return out


@settings(max_examples=30)
@given(st.integers(0, 2**32 - 1))
def test_compensated_ppc_is_the_published_law_on_the_compensated_error(seed):
    """a = e_ddot*(e~, e~_dot) - 2 k lam_dot - k^2 lam (R6); lam_ddot = -2 k lam_dot - k^2 lam + d_a (R5)."""
    t = 2.0
    p = ppc.Params()
    rho = np.array([ppc.envelope(t, p.rho0[i], p.rho_inf[i], p.l)[0] for i in range(3)])
    eta, nu, att, refm, lam, lamd = _auxiliary_case(seed, rho)
    k = 0.8
    comp = _prepared("ppc", "compensated", [f"controller.k_aux={k}"])
    pub = _prepared("ppc", "published")
    xc = np.concatenate([lam, lamd])
    st_c, tau_c, dxc, aux_c = evaluate(ppc.control, t, eta, nu, xc, refm, comp.cp, VP_NOM, n_aux=9,
                                       lo=REACH[0], hi=REACH[1])
    st_p, tau_p, _, aux_p = evaluate(ppc.control, t, eta, nu, np.zeros(0), _shifted(refm, lam, lamd), pub.cp,
                                     VP_NOM, n_aux=6)
    assert st_c == st_p == 0
    b = -2.0 * k * lamd - k * k * lam
    _close(e_ddot_nominal(eta, nu, tau_c, refm) - e_ddot_nominal(eta, nu, tau_p, refm), b, 1e-6)
    _close(dxc, np.concatenate([lamd, b + _lost(eta, nu, tau_c, refm)]), 1e-6)
    _close(aux_c, np.concatenate([aux_p, lam]), 1e-9)


@settings(max_examples=30)
@given(st.integers(0, 2**32 - 1))
def test_compensated_fxtntsmc_is_the_published_law_on_the_compensated_error(seed):
    """(C2): the published law (envelope, surface, estimator) at e~, plus the auxiliary part; (C1) for lam."""
    t = 1.0
    pub = _prepared("fxtntsmc", "published")
    sc = pub.scenario
    rho = np.array([baseline(t, sc.envelope.rho0[i], sc.envelope.rho_inf[i], sc.envelope.T, False)[0]
                    for i in range(3)]) + pub.controller.x0[:3]
    eta, nu, att, refm, lam, lamd = _auxiliary_case(seed, rho)
    k = 1.3
    comp = _prepared("fxtntsmc", "compensated", [f"controller.k_aux={k}"])
    x_pub = pub.controller.x0.copy()
    x_pub[fxtntsmc.STATE.rho_bar:fxtntsmc.STATE.rho_bar + 3] += np.random.default_rng(seed).uniform(0, 0.1, 3)
    x_comp = np.concatenate([x_pub, lam, lamd])
    n = len(fxtntsmc.AUX_NAMES)
    st_c, tau_c, dxc_c, aux_c = evaluate(fxtntsmc.control, t, eta, nu, x_comp, refm, comp.cp, VP_NOM, n_aux=n + 3,
                                         lo=REACH[0], hi=REACH[1])
    st_p, tau_p, dxc_p, aux_p = evaluate(fxtntsmc.control, t, eta, nu, x_pub, _shifted(refm, lam, lamd), pub.cp,
                                         VP_NOM, n_aux=n)
    assert st_c == st_p == 0
    b = -2.0 * k * lamd - k * k * lam
    _close(e_ddot_nominal(eta, nu, tau_c, refm) - e_ddot_nominal(eta, nu, tau_p, refm), b, 1e-6)
    _close(dxc_c[:x_pub.size], dxc_p, 1e-8)  # envelope filters and weights: the published law's (e~ rounded apart)
    _close(dxc_c[x_pub.size:], np.concatenate([lamd, b + _lost(eta, nu, tau_c, refm)]), 1e-6)
    _close(aux_c[:n], aux_p, 1e-8)
    np.testing.assert_array_equal(aux_c[n:], lam)


# --------------------------------------------------------------------------- closed loop with saturation

SATURATING = ["actuator.tau_max=[150, 40, 40]"]  # the Section 4 start (e_x(0) = -3 m) saturates


def test_compensated_ppc_transformed_error_stays_linear_while_the_start_saturates():
    """eps of e~ = e - lam obeys eps_ddot = -kp eps - kd eps_dot exactly, saturation or not; published fails."""
    kp, kd, lrate = 4.0, 3.0, 0.3
    gains = [f"controller.kp={kp}", f"controller.kd={kd}", f"controller.l={lrate}"]
    res = _sim([f'controller={{kind="ppc", saturation="compensated"}}', *IDEAL, *SATURATING, "sim.duration=20", *gains])
    assert res.ok
    assert np.abs(res["sat_comp_x"]).max() > 0.1  # the auxiliary system carried part of the error
    assert (np.abs(res["tau_u"]) >= 150.0).sum() > 10
    pub = _sim([f'controller={{kind="ppc", saturation="published"}}', *IDEAL, *SATURATING, "sim.duration=20", *gains])
    e0, ed0 = _initial_errors(res)
    A = np.array([[0.0, 1.0], [-kp, -kd]])
    for i, (a, r0) in enumerate(zip("xyz", ppc.Params().rho0)):
        rho, rhod, _ = ppc.envelope(0.0, r0, 0.005, lrate)
        eps0 = math.atanh(e0[i] / rho)
        epsd0 = (rho * ed0[i] - rhod * e0[i]) / (rho**2 - e0[i] ** 2)
        want = _linear_solution(A, np.array([eps0, epsd0]), res.t)[:, 0]
        np.testing.assert_allclose(res[f"eps_{a}"], want, rtol=0, atol=1e-8)
        if a == "x":  # the published law's eps leaves the linear law while tau_u saturates
            assert np.abs(pub["eps_x"][:want.size] - want[:pub.t.size]).max() > 1e-2


def test_compensated_fxtntsmc_sliding_variable_keeps_its_reaching_law_while_saturated():
    """S of e~ obeys S_dot = -k1 sign S - k2 S^3 - k3 S while the actuators saturate (nominal plant, no estimator).

    e~ = e - lam is smooth, but e and lam each jump in their second derivative where an axis enters
    or leaves saturation, and the RK4 step combines them only to first order there: the quadrature
    residual must fall by > 4x per halving of dt (a wrong auxiliary system leaves O(1)).
    """
    out = []
    for dt in (1e-3, 5e-4, 2.5e-4):
        res = _sim(['controller={kind="fxtntsmc", saturation="compensated"}', *FXT_IDEAL,
                    "actuator.tau_max=[300, 20, 20]", "sim.duration=3", f"sim.dt={dt}", f"sim.log_dt={dt}"])
        assert res.ok
        assert np.abs(res["sat_comp_y"]).max() > 1e-3 and (np.abs(res["tau_q"]) >= 20.0).mean() > 0.1
        worst, used = _reaching_law_residual(res)
        assert used > 0.99 * 3 * res.t.size
        out.append(worst)
    assert out[0] / out[1] > 4 and out[1] / out[2] > 4, out
    assert out[2] < 1e-4


# --------------------------------------------------------------------------- the reach cut in mid-run

T_ON, T_OFF, T_END = 20.0, 35.0, 70.0
FULL, CUT = (150.0, 40.0, 40.0), (15.0, 3.5, 1.5)  # Section 4 holds ~ (31, 7.3, 3.1) in steady state
STATE = {"pid": "I", "sta": "integral", "backstepping": "b_hat", "fxtntsmc": "chi_hat", "ppc": None}


def _cut_run(kind, saturation):
    plant = f'plant={{model="plugin", module="{CUT_PLANT}", params={{tau_max={list(FULL)}, cut={list(CUT)}, ' \
            f't_on={T_ON}, t_off={T_OFF}}}}}'
    return _sim([f'controller={{kind="{kind}", saturation="{saturation}"}}', *IDEAL, f"sim.duration={T_END}",
                 "sim.log_dt=0.05", plant])


def _peak(res, names, t0, t1):
    m = (res.t >= t0) & (res.t < t1)
    return max(np.abs(res[n][m]).max() for n in names) if m.any() else math.inf


@pytest.mark.parametrize("kind", LAWS)
def test_reach_cut_mid_run_integral_bounded_and_recovering_published_winds_up(kind):
    """The reach drops to about half what the helix needs for 15 s, then comes back.

    Compensated: the run completes, the law's integral / estimator state (PPC: its auxiliary
    state) stays bounded during the cut and returns to its undisturbed value (0 on the nominal
    plant, chi = 0) with the error, which is < 1 cm 15 s after the reach is back (the slowest
    nominal pole, the backstepping's at -0.55/s, takes the ~2.5 m the cut left to ~1 mm).  Published:
    the state winds up (more than twice as far) and the error is still > 0.1 m then, or the run
    fails (the PPC leaves its envelope, the FXTNTSMC's estimator diverges).
    """
    comp, pub = _cut_run(kind, "compensated"), _cut_run(kind, "published")
    errors = ("ex", "ey", "ez")
    state = [f"{STATE[kind]}_{a}" for a in "xyz"] if STATE[kind] else [f"sat_comp_{a}" for a in "xyz"]
    assert comp.ok, comp.failure
    assert _peak(comp, errors, T_ON, T_OFF) > 0.5  # the cut bites: the helix cannot be held
    assert _peak(comp, errors, T_OFF + 15.0, T_END) < 1e-2
    assert _peak(comp, state, T_OFF + 15.0, T_END) < 1e-2
    bounded = _peak(comp, state, T_ON, T_OFF + 15.0)
    assert math.isfinite(bounded)
    if pub.ok:
        assert _peak(pub, state, T_ON, T_OFF + 15.0) > 2.0 * bounded
        assert _peak(pub, errors, T_OFF + 15.0, T_END) > 0.1
    else:
        assert kind in ("ppc", "fxtntsmc"), pub.failure
        assert T_ON <= pub.failure["time"] < T_OFF + 15.0


# --------------------------------------------------------------------------- a 6-DOF truth

def test_pid_back_calculation_gets_the_allocations_reach_on_a_6dof_truth():
    """Prestero's REMUS, the model-gap lawnmower, the PID's default gains: with the fins' and the
    propeller's reach fed back (compensated, the PID's default) it tracks; without (published, the
    textbook PID) its integrator winds up and the error grows to metres."""
    from auvtrack.studies import model_gap as mg

    out = {}
    for s in ("compensated", "published"):
        d = mg.scenario("pid", "prestero", "lawnmower", False, 60.0)
        d["controller"] = {"kind": "pid", "preset": "defaults", "saturation": s}
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            out[s] = auvtrack.simulate(d)
    late = out["compensated"].t >= 30.0
    e_comp = np.sqrt(sum(out["compensated"][f"e{a}"][late] ** 2 for a in "xyz")).max()
    e_pub = np.sqrt(sum(out["published"][f"e{a}"][out["published"].t >= 30.0] ** 2 for a in "xyz")).max()
    assert out["compensated"].ok and e_comp < 0.1, e_comp
    assert e_pub > 1.0, e_pub

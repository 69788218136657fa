"""Gains designed for the vehicle (auvtrack.control.design, auvtrack.scenario.designed).

* (D1): each designed law's gains, scaled by omega^n with n their time dimension, scale its
  nominal closed loop in time: e_omega(t) = e_1(omega t), a_omega(t) = omega^2 a_1(omega t).  A
  wrong exponent breaks it.
* (D3): the peak demand of each law's defaults from e_ref, against the hand-computed a(0).
* (D2), (D4): the designed demand equals the reach's share, the defaults are the upper end.
* The reach of the remus100 preset: Prestero's fin moments and thrust at U0, by hand.
* Which gains a scenario gets (the table of auvtrack.scenario.designed), the round trip through
  to_dict, run.json's record, one-line errors.
"""
from __future__ import annotations

import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from auvtrack.cli import EXIT_BAD_INPUT, main
from auvtrack.control import CONTROLLERS, backstepping, design, ftsmc, pid, ppc, sta
from auvtrack.scenario import load_scenario
from auvtrack.vehicle.presets import get_preset
from auvtrack.vehicle.truth_presets import load_preset6

MODULES = {m.NAME: m for m in (pid, backstepping, sta, ftsmc, ppc)}


def _trajectory(kind, params, h, n):
    """(e, a) of the nominal closed loop of one axis (the design module's dynamics), RK4 step h, n steps."""
    f, x0 = CONTROLLERS[kind].nominal_axis(params, 1, design.DESIGN_ERROR)
    x, t, es, acc = np.array(x0, float), 0.0, [], []
    for _ in range(n):
        k1, a = f(t, x)
        es.append(x[0])
        acc.append(a)
        k2 = f(t + h / 2, x + h / 2 * k1)[0]
        k3 = f(t + h / 2, x + h / 2 * k2)[0]
        k4 = f(t + h, x + h * k3)[0]
        x, t = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4), t + h
    return np.array(es), np.array(acc)


@settings(max_examples=8)
@given(st.sampled_from(design.designed_kinds()), st.floats(0.2, 0.9))
def test_scaled_gains_scale_the_closed_loop_in_time(kind, omega):
    """e_omega(t) = e_1(omega t) and a_omega = omega^2 a_1 (D1), on the grid t = k h / omega."""
    h, n = 0.01, 1500
    base = MODULES[kind].Params()
    scaled = base.model_copy(update=design.scaled_gains(kind, omega))
    e1, a1 = _trajectory(kind, base, h, n)
    ew, aw = _trajectory(kind, scaled, h / omega, n)
    np.testing.assert_allclose(ew, e1, rtol=0, atol=1e-9)
    np.testing.assert_allclose(aw, omega**2 * a1, rtol=0, atol=1e-9 * max(1.0, np.abs(a1).max()))


def test_peak_demand_of_the_defaults_is_their_demand_at_the_start():
    """From e = e_ref at rest the default laws ask most at t = 0: by hand, a(0) of (P1), (B2), (S2) and the FTSMC's law."""
    e = design.DESIGN_ERROR
    p = {k: MODULES[k].Params() for k in MODULES}
    want = {"pid": p["pid"].kp * e,
            "backstepping": (p["backstepping"].k0 + p["backstepping"].c1 * p["backstepping"].c2) * e,
            "sta": p["sta"].k1 * math.sqrt(p["sta"].lam * e),
            "ftsmc": p["ftsmc"].k1 + p["ftsmc"].k2 * e}
    for kind, w in want.items():
        assert design.peak_demand(kind) == pytest.approx(w, rel=1e-12), kind
    q = p["ppc"]  # the PPC: at least its demand at t = 0 on every axis
    for r0 in q.rho0:
        r = ppc.envelope(0.0, r0, q.rho_inf[0], q.l)
        assert design.peak_demand("ppc") >= abs(ppc.axis(e, 0.0, r[0], r[1], r[2], q.kp, q.kd)[2])


@pytest.mark.parametrize("kind", design.designed_kinds())
def test_designed_demand_is_the_reach_and_the_defaults_cap_it(kind):
    m, ell = (30.0, 60.0, 60.0, 8.0, 9.0), 1.2
    small = design.design(kind, m, ell, (4.0, 1.0, 1.5))
    A = min(ell * 1.0 / 8.0, ell * 1.5 / 9.0)
    assert small.accel == pytest.approx(A)
    assert small.omega < 1.0
    assert small.omega**2 * small.peak == pytest.approx(design.REACH_FRACTION * A, rel=1e-12)
    big = design.design(kind, m, ell, (4.0, 2e4, 3e4))
    assert big.omega == 1.0
    defaults = MODULES[kind].Params()
    assert all(big.gains[k] == getattr(defaults, k) for k in CONTROLLERS[kind].time_exponents)
    assert ("saturation" in small.gains) == ("saturation" in MODULES[kind].Params.model_fields)


def test_remus100_reach_is_prestero_fins_and_propeller_at_u0():
    """tau_q = |M_uu_ds| U0^2 delta_max, tau_r = |N_uu_dr| U0^2 delta_max, tau_u = X_prop (n_max / n0)^2."""
    v = load_preset6("remus100_prestero").values
    for u0 in (0.8, 1.25, 1.5):
        r = get_preset("remus100", u0=u0).reach
        dm = v["actuators.delta_max"]
        assert r[1] == pytest.approx(abs(v["fins.M_uuds"]) * u0**2 * dm, rel=1e-12)
        assert r[2] == pytest.approx(abs(v["fins.N_uudr"]) * u0**2 * dm, rel=1e-12)
        assert r[0] == pytest.approx(v["propeller.X_prop"] * (v["actuators.n_max"] / v["propeller.n0"]) ** 2, rel=1e-12)
    assert get_preset("paper").reach is None
    assert "source" in get_preset("remus100", u0=1.25).sources["reach"]


def test_fossen_reach_is_the_allocations_edge():
    """A Fossen-type preset's reach: the allocation produces it just inside and flags it just outside."""
    from auvtrack.plant.sixdof import fossen
    from auvtrack.plant.sixdof.truth import pack_truth

    u0 = 1.25
    r = get_preset("remus100_fossen", u0=u0).reach
    pp, cmd = pack_truth("remus100_fossen"), np.zeros(6)
    for j, bit in ((1, 2), (2, 4)):
        tau = [0.0, 0.0, 0.0]
        tau[j] = 0.999 * r[j]
        assert fossen.allocate_tau(*tau, u0, 0.0, 0.0, pp, cmd) & bit == 0
        tau[j] = 1.001 * r[j]
        assert fossen.allocate_tau(*tau, u0, 0.0, 0.0, pp, cmd) & bit == bit


# --------------------------------------------------------------------------- which gains a scenario gets

def _ctrl(*overrides, base=("vehicle.preset=remus100", "vehicle.u0=1.25")):
    return load_scenario({}, [*base, *overrides]).controller


def test_a_vehicle_with_a_reach_gets_designed_gains_and_the_compensated_form():
    pre = get_preset("remus100", u0=1.25)
    want = design.design("pid", pre.m, pre.l, pre.reach)
    c = _ctrl("controller.kind=pid")
    assert want.omega < 1.0
    assert {k: getattr(c, k) for k in want.gains} == want.gains and c.saturation == "compensated"
    c = _ctrl('controller={kind="sta", saturation="published"}')  # saturation alone keeps the design
    assert c.saturation == "published" and c.k2 == design.design("sta", pre.m, pre.l, pre.reach).gains["k2"]
    c = _ctrl("controller.kind=fxtntsmc")  # the paper's gains, the compensated form
    assert c.saturation == "compensated" and c.kappa3 == 0.6


@pytest.mark.parametrize("overrides, kp, saturation", [
    (("controller.kind=pid", "controller.preset=defaults"), 3.0, "compensated"),
    (("controller.kind=pid", "controller.kp=2.0"), 2.0, "compensated"),  # any gain: the law's defaults for the rest
    (("controller.kind=pid", "controller.preset=pid_tuned"), 2.212, "compensated"),
])
def test_the_design_gives_way_to_given_gains_and_presets(overrides, kp, saturation):
    c = _ctrl(*overrides)
    assert c.kp == kp and c.ki == (pid.Params().ki if "pid_tuned" not in overrides[-1] else 0.0001016)
    assert c.saturation == saturation


def test_the_paper_vehicle_keeps_the_defaults():
    for kind, mod in MODULES.items():
        assert load_scenario({}, [f"controller.kind={kind}"]).controller == mod.Params()
    assert load_scenario({}, ["controller.kind=fxtntsmc"]).controller.saturation == "published"


def test_designed_gains_survive_the_round_trip_and_reach_run_json(tmp_path):
    sc = load_scenario({}, ["vehicle.preset=remus100", "controller.kind=backstepping", "sim.duration=0.5"])
    assert load_scenario(sc.to_dict()) == sc
    import auvtrack

    res = auvtrack.simulate(sc)
    res.save(tmp_path / "run")
    rec = json.loads((tmp_path / "run" / "run.json").read_text())
    text = json.dumps(rec)
    assert '"gain_design"' in text and '"applied": true' in text
    assert '"reach"' in text


def test_designed_on_a_vehicle_without_a_reach_is_a_one_line_error(capsys):
    code = main(["check", "--set", "controller.kind=pid", "--set", "controller.preset=designed",
                 "scenarios/paper.toml"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == EXIT_BAD_INPUT and len(err) == 1 and "controller.preset" in err[0] and "reach" in err[0]


def test_the_studies_that_keep_stored_results_pin_the_defaults():
    """realism and robustness run remus100 with the law's fixed defaults (their stored results stay as they are)."""
    from auvtrack.studies import realism, robustness

    s = robustness.draw_samples(1, 3)[0]
    assert load_scenario(robustness.sample_scenario(s, "remus100", "ftsmc", None, 2.0, 0.002)).controller == ftsmc.Params()
    prep = realism._prepare(("remus100", "ftsmc", "sampling", 100.0, ["sim.duration=0.1"]))
    assert prep.scenario.controller == ftsmc.Params()


def test_generated_design_table_in_docs_controllers_md_is_current():
    from tools import gain_design

    text = gain_design.DOC.read_text()
    names = [m.group("name") for m in gain_design.BLOCK_RE.finditer(text) if m.group("name") in gain_design.blocks()]
    assert names == ["gain-design"]
    assert gain_design.render_text(text) == text, "stale: python -m tools.gain_design render"


def test_a_gain_design_is_declared_by_the_law_and_checked_at_registration(tmp_path):
    """The design reads each law's own declaration; a wrong one is one line naming the file."""
    from auvtrack.control.registry import check_controller

    assert set(design.designed_kinds()) == {"pid", "backstepping", "sta", "ftsmc", "ppc"}
    assert "fxtntsmc" in design.designable_kinds() and "fxtntsmc" not in design.designed_kinds()
    assert "los_autopilot" not in design.designable_kinds()

    class Fake:
        pass

    for bad, expect in ((dict(TIME_EXPONENTS={"kq": 2}), "TIME_EXPONENTS.kq: not a field"),
                        (dict(TIME_EXPONENTS={"kp": "two"}), "TIME_EXPONENTS.kp: must be a finite number"),
                        (dict(nominal_axis=None, TIME_EXPONENTS={"kp": 2}), "defines both TIME_EXPONENTS")):
        mod = type(pid)("fake_pid")
        mod.__dict__.update({k: getattr(pid, k) for k in dir(pid) if not k.startswith("__")})
        mod.__file__ = str(tmp_path / "fake_pid.py")
        for k, v in bad.items():
            setattr(mod, k, v)
        with pytest.raises(ValueError, match=expect):
            check_controller(mod)

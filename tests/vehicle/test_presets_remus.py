"""The remus100 vehicle preset: data, reduction arithmetic, scenario, a short closed loop."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from auvtrack.vehicle.presets import available, get_preset
from auvtrack.scenario import load_scenario
from auvtrack.simulation.pipeline import prepare, run_prepared

# Prestero (2001) numbers the preset is reduced from (docs/vehicles.md, section remus100)
MASS, IYY, IZZ = 30.48, 3.45, 3.45
XUDOT, YVDOT, ZWDOT, MQDOT, NRDOT = -0.93, -35.5, -35.5, -4.88, -4.88
XUU, YUV, ZUW, MUQ, NUR = -1.62, -28.6, -28.6, -2.00, -2.00
W, ZG, U0 = 299.0, 0.0196, 1.5

ROOT = Path(__file__).resolve().parents[2]


def test_preset_is_registered_and_positive():
    assert "remus100" in available()
    p = get_preset("remus100")
    assert len(p.m) == 5 and len(p.d) == 5
    assert all(x > 0 for x in (*p.m, *p.d, p.wgml, p.l))
    for key in ("m", "d", "wgml", "l"):
        assert p.sources[key]["source"] and p.sources[key]["unit"]


def test_reduction_arithmetic():
    p = get_preset("remus100")
    expected_m = (MASS - XUDOT, MASS - YVDOT, MASS - ZWDOT, IYY - MQDOT, IZZ - NRDOT)
    # remus100.toml stores the reduced numbers rounded to 2 decimals: at most 5e-3 off
    assert p.m == pytest.approx(expected_m, abs=5e-3)
    expected_d = (-2 * XUU * U0, -YUV * U0, -ZUW * U0, -MUQ * U0, -NUR * U0)
    assert p.d == pytest.approx(expected_d, abs=5e-3)
    assert p.wgml == pytest.approx(W * ZG, abs=5e-3)


def test_remus_scenario_loads_and_short_run_stays_finite():
    for kind in ("fxtntsmc", "ftsmc"):
        sc = load_scenario(ROOT / "scenarios" / "remus100.toml", [f"controller.kind={kind}", "sim.duration=5"])
        assert sc.vehicle.preset == "remus100"
        res = run_prepared(prepare(sc))
        assert res.status == "ok", res.failure
        for name in ("x", "y", "z", "theta", "psi", "u", "v", "w", "q", "r", "tau_u", "tau_q", "tau_r"):
            assert np.all(np.isfinite(res.channels[name]))
        assert np.max(np.abs(res.channels["theta"])) < math.radians(60)
        # the error shrinks from its initial value
        e0 = abs(res.channels["ex"][0])
        assert abs(res.channels["ex"][-1]) < e0


def test_every_shipped_preset_is_available():
    from auvtrack.vehicle.presets import SHIPPED
    assert set(SHIPPED) <= set(available())
    for name in SHIPPED:
        get_preset(name)


# --- the reduction of remus100_prestero at a speed U0 (issue 13, point 6) -------------------------

def test_reduction_is_computed_from_the_6dof_data_at_u0():
    from auvtrack.vehicle.truth_presets import load_preset6
    from auvtrack.vehicle.reduction import reduce_prestero
    v = load_preset6("remus100_prestero").values
    for u0 in (0.3, 0.41, 1.5, 2.0):
        red = reduce_prestero(u0)
        assert red["d"] == pytest.approx((-2 * v["drag.X_uu"] * u0, -v["combined.Y_uv"] * u0,
                                          -v["combined.Z_uw"] * u0, -v["combined.M_uq"] * u0,
                                          -v["combined.N_ur"] * u0), rel=1e-15)
        assert get_preset("remus100", u0=u0).d == red["d"]
    assert get_preset("remus100").u0 == U0  # without a scenario: P01's trial speed


def test_scenario_linearises_remus100_at_the_reference_speed():
    from auvtrack.vehicle.reduction import reference_speed
    from auvtrack.reference import build_reference
    sc = load_scenario(ROOT / "scenarios" / "remus100.toml")
    helix = build_reference(sc.reference)
    u_ref = reference_speed(helix, sc.sim.duration)
    assert sc.vehicle.u0 == pytest.approx(u_ref, rel=1e-12)
    assert u_ref == pytest.approx(0.4123, abs=1e-4)  # Section 4 helix: |eta_d_dot| = sqrt(0.4^2 + 0.1^2)
    assert sc.vehicle.d == get_preset("remus100", u0=sc.vehicle.u0).d
    assert sc.vehicle.resolve()["u0"] == sc.vehicle.u0
    assert load_scenario(sc.to_dict()) == sc
    sc2 = load_scenario(ROOT / "scenarios" / "remus100.toml", ["vehicle.u0=1.5"])
    assert sc2.vehicle.d == pytest.approx(get_preset("remus100").d)


def test_u0_bad_input():
    from auvtrack.scenario import ScenarioError
    with pytest.raises(ScenarioError, match=r"vehicle.u0: only a reduced preset"):
        load_scenario({"vehicle": {"preset": "paper", "u0": 1.0}})
    with pytest.raises(ScenarioError, match=r"vehicle.u0"):
        load_scenario({"vehicle": {"preset": "remus100", "u0": 9.0}})
    with pytest.raises(ScenarioError, match=r"vehicle.u0: the reference's mean speed"):
        load_scenario({"vehicle": {"preset": "remus100"},
                       "reference": {"kind": "line", "velocity": [0.0, 0.0, 0.0]}})

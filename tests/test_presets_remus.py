"""The remus100 vehicle preset: data, reduction arithmetic, scenario, a short closed loop."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from auvtrack.plant.presets import available, get_preset
from auvtrack.scenario import load_scenario
from auvtrack.simulation.api import prepare, run_prepared

# Prestero (2001) numbers the preset is reduced from (docs/vehicles.md, section remus100)
MASS, IYY, IZZ = 30.48, 3.45, 3.45
XUDOT, YVDOT, ZWDOT, MQDOT, NRDOT = -0.93, -35.5, -35.5, -4.88, -4.88
XUU, YUV, ZUW, MUQ, NUR = -1.62, -28.6, -28.6, -2.00, -2.00
W, ZG, U0 = 299.0, 0.0196, 1.5

ROOT = Path(__file__).resolve().parents[1]


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
    from auvtrack.plant.presets import SHIPPED
    assert set(SHIPPED) <= set(available())
    for name in SHIPPED:
        get_preset(name)

"""Open-loop runs report manoeuvre metrics: on an exact circle (radius R at speed U after the
execute time) advance = transfer = R, tactical and steady diameter = 2R; a zig-zag gives its
reversals and overshoots; a run that never turns 90 deg reports none."""
from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from auvtrack.channels import BASE_CHANNELS
from auvtrack.simulation.manoeuvre import manoeuvre_line, manoeuvre_metrics
from auvtrack.simulation.result import Result

R, U, T0 = 40.0, 1.5, 5.0


def _run(psi_of_t, n=20001, dt=0.05) -> Result:
    """A planar run: straight at U until T0, then heading psi_of_t(t - T0) at constant speed U."""
    t = np.arange(n) * dt
    ch = {name: np.zeros(n) for name in BASE_CHANNELS}
    ch["t"] = t
    s = np.maximum(t - T0, 0.0)
    psi = psi_of_t(s)
    r = np.gradient(psi, t)
    ch["psi"], ch["r"], ch["u"] = psi, r, np.full(n, U)
    # position: integrate U (cos psi, sin psi) exactly enough with the trapezoid rule on a fine grid
    vx, vy = U * np.cos(psi), U * np.sin(psi)
    ch["x"] = np.concatenate([[0.0], np.cumsum(0.5 * (vx[1:] + vx[:-1]) * dt)])
    ch["y"] = np.concatenate([[0.0], np.cumsum(0.5 * (vy[1:] + vy[:-1]) * dt)])
    return Result(ch, {}, "ok", None, {})


def test_an_exact_turning_circle_gives_its_radius():
    res = _run(lambda s: U / R * s)
    m = manoeuvre_metrics(res, SimpleNamespace(t_execute=T0, zigzag_psi=0.0))
    assert m["manoeuvre"] == "turning_circle" and m["turn"] == "starboard"
    assert m["advance_m"] == pytest.approx(R, rel=1e-3) and m["transfer_m"] == pytest.approx(R, rel=1e-3)
    assert m["tactical_diameter_m"] == pytest.approx(2 * R, rel=1e-3)
    assert m["steady_diameter_m"] == pytest.approx(2 * R, rel=1e-3)
    line = manoeuvre_line(m)
    assert line.startswith("turning circle (starboard): advance 40 m, transfer 40 m, tactical diameter 80 m")


def test_a_zigzag_and_a_straight_run():
    amp, w = math.radians(30.0), 0.1  # heading swings +-30 deg: reversals at +-20 deg, overshoot 10 deg
    res = _run(lambda s: amp * np.sin(w * s))
    m = manoeuvre_metrics(res, SimpleNamespace(t_execute=T0, zigzag_psi=math.radians(20.0)))
    assert m["manoeuvre"] == "zigzag" and m["reversals"] >= 3
    assert m["overshoot_1_deg"] == pytest.approx(10.0, abs=0.01) and m["overshoot_2_deg"] == pytest.approx(10.0, abs=0.01)
    assert m["period_s"] == pytest.approx(2 * math.pi / w, rel=1e-3)
    assert "overshoots 10 deg, 10 deg" in manoeuvre_line(m)
    assert manoeuvre_metrics(_run(lambda s: 0.01 * s / (1 + s)), SimpleNamespace(t_execute=T0)) is None

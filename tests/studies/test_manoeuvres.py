"""Manoeuvre metrics against exact answers of synthetic records."""
from __future__ import annotations

import math

import numpy as np
import pytest

from auvtrack.studies.manoeuvres import turning_circle_metrics, zigzag_metrics


@pytest.mark.parametrize("side", [1.0, -1.0])
def test_turning_circle_of_an_exact_circle(side):
    R, U = 7.0, 1.5
    w = U / R
    t = np.linspace(0.0, 80.0, 40001)
    psi0 = 0.3
    psi = psi0 + side * w * t
    # circle through the origin with initial heading psi0, turning to starboard (side = +1) or port
    h, n = np.array([math.cos(psi0), math.sin(psi0)]), side * np.array([-math.sin(psi0), math.cos(psi0)])
    p = np.outer(R * np.sin(w * t), h) + np.outer(R * (1 - np.cos(w * t)), n)
    m = turning_circle_metrics(t, p[:, 0], p[:, 1], psi, np.full_like(t, U), 0 * t, side * w + 0 * t)
    assert m["advance"] == pytest.approx(R, rel=1e-6) and m["transfer"] == pytest.approx(R, rel=1e-6)
    assert m["tactical_diameter"] == pytest.approx(2 * R, rel=1e-6)
    assert m["steady_diameter"] == pytest.approx(2 * R, rel=1e-12)
    assert m["time_90"] == pytest.approx(math.pi / 2 / w, rel=1e-6) and m["turn_direction"] == side


def test_zigzag_of_a_sine_heading():
    A, s, w = 0.3, 0.2, 0.25
    t = np.linspace(0.0, 80.0, 80001)
    psi = A * np.sin(w * t)
    m = zigzag_metrics(t, psi, np.sign(np.cos(w * t)), s)
    t1 = math.asin(s / A) / w
    assert m["initial_turning_time"] == pytest.approx(t1, abs=1e-5)
    assert m["period"] == pytest.approx(2 * math.pi / w, abs=1e-5)
    assert m["overshoot_1"] == pytest.approx(A - s, abs=1e-8) and m["overshoot_2"] == pytest.approx(A - s, abs=1e-8)
    assert m["reversals"] >= 4


def test_the_quick_study_report_shows_its_own_scenarios_fins_and_rpm(tmp_path):
    """The report closes with the manoeuvre scenarios (not the paper's Section 4), plots the fins and
    the propeller of every run, and is marked quick."""
    import json

    from auvtrack.report import QUICK_BANNER
    from auvtrack.studies.registry import get_study, run_study

    report = run_study(get_study("manoeuvres"), tmp_path, quick=True)
    text = report.read_text()
    assert QUICK_BANNER in text and json.loads((tmp_path / "results.json").read_text())["quick"] is True
    assert "fins and propeller of every run" in text and (tmp_path / "figures" / "actuators.png").is_file()
    closing = text[text.index("## Scenario and version"):]
    assert 'name = "remus100_turning_circle"' in closing and 'name = "remus100_zigzag"' in closing
    assert "Section 4" not in closing

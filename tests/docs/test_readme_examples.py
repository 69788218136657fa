"""What the README shows a newcomer holds (its numbers and claims come from these runs)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

import auvtrack

PAPER = str(Path(__file__).resolve().parents[2] / "scenarios" / "paper.toml")
PULSE = ["sim.duration=40", "disturbance.1.kind=pulse", "disturbance.1.start=20",
         "disturbance.1.duration=1", "disturbance.1.force=[0, 8000, 0, 0, 0]"]


def test_readme_text_matches_this_example():
    text = (Path(__file__).resolve().parents[2] / "README.md").read_text()
    assert all(o in text for o in ('"sim.duration=40"', '"disturbance.1.force=[0, 8000, 0, 0, 0]"',
                                   '"envelope.kind=rigid"'))


def test_the_rigid_envelope_fails_the_pulse_the_flexible_one_survives():
    res = auvtrack.simulate(PAPER, PULSE, warn=False)
    rigid = auvtrack.simulate(PAPER, [*PULSE, "envelope.kind=rigid"], warn=False)
    assert res.ok
    assert rigid.failure["cause"] == "controller" and rigid.failure["detail"].startswith("envelope violated")
    assert 20.0 <= rigid.failure["time"] < 21.0  # during the pulse
    assert max(np.max(res[f"g_{a}"]) for a in "xyz") > 0  # the risk monitor acted


def test_without_a_disturbance_the_rigid_envelope_changes_nothing():
    """Why the README needs a pulse: in Section 4 the trigger stays 0, so rigid = proactive bit for bit."""
    res = auvtrack.simulate(PAPER, ["sim.duration=30"], warn=False)
    rigid = auvtrack.simulate(PAPER, ["sim.duration=30", "envelope.kind=rigid"], warn=False)
    assert max(np.max(res[f"g_{a}"]) for a in "xyz") == 0.0
    for name in res.names:
        np.testing.assert_array_equal(res[name], rigid[name])

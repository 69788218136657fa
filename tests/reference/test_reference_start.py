"""Starting a run on its reference: the start construction, the warning, the example scenarios.

From Section 4's default start, a reference at another depth drives the pitch to its limit
within seconds; the run is warned about beforehand, with the ``initial.eta`` that fixes it.
"""
from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

import auvtrack
from auvtrack.cli import EXIT_SIM_FAILED, main
from auvtrack.reference import build_reference
from auvtrack.reference.start import DEPTH_STEP_WARN, NOTE_PREFIX, start_note, start_on_reference
from auvtrack.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[2]
PAPER = str(ROOT / "scenarios" / "paper.toml")
CIRCLE = 'reference={kind="circle", radius=4.0, omega=0.1, depth=%g}'
SPECS = [{"kind": "helix"}, {"kind": "circle", "radius": 3.0, "omega": -0.2, "depth": 7.0, "phase": 1.0},
         {"kind": "line", "velocity": [0.3, -0.4, 0.1]}, {"kind": "lawnmower", "heading": 0.7},
         {"kind": "waypoints", "points": [[0, 0, 2], [5, 5, 3], [10, 0, 2]]}]


def _vp(eta, ell):
    x, y, z, th, ps = eta
    return np.array([x + ell * math.cos(th) * math.cos(ps), y + ell * math.cos(th) * math.sin(ps), z - ell * math.sin(th)])


@pytest.mark.parametrize("spec", SPECS, ids=lambda s: s["kind"])
@pytest.mark.parametrize("ell", [1.0, 0.3])
def test_start_on_reference_puts_the_virtual_point_on_eta_d_heading_along_it(spec, ell):
    ref = build_reference(spec)
    eta = start_on_reference(ref, ell)
    p, v, _ = ref.evaluate(0.0)
    np.testing.assert_allclose(_vp(eta, ell), p, rtol=0, atol=1e-12)
    assert eta[3] == 0.0
    np.testing.assert_allclose([math.cos(eta[4]), math.sin(eta[4])], v[:2] / np.hypot(v[0], v[1]), atol=1e-12)
    assert start_note(ref, _vp(eta, ell), ell) is None


def test_section4_start_gets_no_warning_and_a_deep_start_gets_the_fix():
    sc = load_scenario(PAPER)
    assert start_note(build_reference(dict(sc.reference)), _vp(sc.initial.eta, 1.0), 1.0) is None
    ref = build_reference({"kind": "lawnmower"})
    note = start_note(ref, _vp(sc.initial.eta, 1.0), 1.0)
    assert note.startswith(NOTE_PREFIX) and "5 m above it" in note and "sim.theta_limit" in note
    fix = [float(x) for x in re.search(r"initial\.eta = \[([^\]]+)\]", note).group(1).split(",")]
    np.testing.assert_allclose(fix, start_on_reference(ref, 1.0), atol=1e-6)
    # the threshold is on the depth offset only: 3 m sideways is Section 4's own start
    assert start_note(ref, [3.0, 0.0, 5.0 - DEPTH_STEP_WARN + 0.01], 1.0) is None
    assert start_note(ref, [0.0, 0.0, 5.0 + DEPTH_STEP_WARN + 0.01], 1.0) is not None


@pytest.mark.parametrize("kind", ["fxtntsmc", "ftsmc"])
def test_the_depth_steps_the_docs_quote(kind):
    """docs/scenarios.md: a 2 m step is tracked, 2.5 m ends at the pitch limit within 3 s, 5 m within 1.5 s."""
    def run(depth, duration):
        return auvtrack.simulate(PAPER, [f"controller.kind={kind}", f"sim.duration={duration}", CIRCLE % depth],
                                 warn=False)

    for depth in (2.0, -2.0):
        assert run(depth, 10).ok
    for depth, within in ((2.5, 3.0), (5.0, 1.5)):
        res = run(depth, 5)
        assert res.failure["cause"] == "pitch_limit" and res.failure["time"] < within, res.failure
        assert any(n.startswith(NOTE_PREFIX) for n in res.meta["notes"])  # it was warned about


@pytest.mark.parametrize("name", ["circle", "lawnmower"])
@pytest.mark.parametrize("kind", ["fxtntsmc", "ftsmc"])
def test_example_scenarios_start_on_their_reference_and_complete(name, kind):
    path = ROOT / "scenarios" / f"{name}.toml"
    sc = load_scenario(path, [f"controller.kind={kind}"])
    ref = build_reference(dict(sc.reference))
    np.testing.assert_allclose(sc.initial.eta, start_on_reference(ref, 1.0), rtol=0, atol=1e-12)
    res = auvtrack.simulate(path, [f"controller.kind={kind}"], warn=False)
    assert res.ok and res.t[-1] == pytest.approx(sc.sim.duration)
    assert max(res.metrics[f"max_abs_{a}"] for a in "xyz") < 0.5  # it tracks from the first second
    if name == "lawnmower":
        assert sc.sim.duration > ref.duration  # the whole pattern


def test_cli_warns_with_the_fix_and_the_fix_runs(tmp_path, capsys):
    args = ["run", PAPER, "--set", "reference.kind=lawnmower", "--set", "sim.duration=3"]
    assert main([*args, "--out", str(tmp_path / "a")]) == EXIT_SIM_FAILED
    err = capsys.readouterr().err
    assert "warning: start: the virtual point starts" in err and "pitch_limit" in err
    fix = re.search(r"--set '(initial\.eta=\[[^\]]+\])'", err).group(1)
    assert main([*args, "--set", fix, "--out", str(tmp_path / "b")]) == 0

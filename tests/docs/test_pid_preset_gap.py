"""The tuned-PID section of docs/tuning.md: rendered from its stored runs, which are the benchmark's own.

``tools/pid_preset_gap.py`` flies the PID presets on the runs of ``auvtrack tune`` and ``auvtrack
compare`` and stores a summary (``docs/results/pid-preset-gap.json``); the doc's block is rendered
from it.  Here: the block matches the stored result, the stored runs of the shipped preset are those
the comparison and the tuning recorded (the same median on the cell as the stored comparison, the
same training score as the preset's provenance), and the rendering refuses a result that no longer
shows what the prose says.
"""
from __future__ import annotations

import copy
import json

import pytest

from tools import findings, pid_preset_gap as gap


@pytest.fixture(scope="module")
def stored() -> dict:
    return json.loads(gap.RESULT.read_text())


def test_the_doc_block_is_the_stored_result(capsys):
    assert gap.main(["check"]) == 0, capsys.readouterr().err


def test_the_stored_variants_fly_the_installed_presets(stored):
    from auvtrack.control.gain_presets import get_gain_preset

    v = stored["variants"]
    for label, preset in (("shipped", gap.SHIPPED), ("old", gap.OLD)):
        assert v[label]["table"] == {"kind": "pid", "preset": preset}
        for k, x in get_gain_preset(preset).gains.items():
            assert v[label]["gains"][k] == x, (label, k)
    assert set(v) == set(gap.variants(stored["trials"]))
    assert stored["suite"]["name"] == gap.SUITE and tuple(stored["cell"]) == gap.CELL


def test_the_shipped_runs_are_the_comparisons_and_the_tunings(stored):
    """The cell's median on the evaluation seeds is the stored comparison's; the mean run score over the
    training split is the one `auvtrack tune` recorded in the preset."""
    from auvtrack.control.gain_presets import get_gain_preset

    sh = stored["variants"]["shipped"]
    cv = findings.load("compare-v2")
    task, tier = gap.CELL
    cell = next(c for c in cv["cells"] if (c["task"], c["tier"], c["controller"]) == (task, tier, "pid"))
    assert sh["cell_evaluation"]["median"]["xtrack_rmse"] == pytest.approx(cell["xtrack_rmse"]["median"], rel=1e-12)
    assert sh["cell_evaluation"]["runs"] == cell["n"] and sh["cell_evaluation"]["failures"] == cell["failures"]
    assert sh["training"]["score_mean"] == pytest.approx(get_gain_preset(gap.SHIPPED).provenance["train_score"],
                                                         rel=1e-9)


def test_the_reading_is_refused_when_the_result_no_longer_shows_it(stored):
    assert "**The budget decides the cell.**" in gap.block(stored)
    moved = copy.deepcopy(stored)
    moved["variants"]["shipped"]["cell_evaluation"]["median"]["xtrack_rmse"] = gap.XTRACK_TARGET * 2
    with pytest.raises(ValueError, match="no longer holds"):
        gap.block(moved)
    failing = copy.deepcopy(stored)
    failing["variants"]["shipped"]["training"]["failures"] = 1
    with pytest.raises(ValueError, match="no longer holds"):
        gap.block(failing)


def test_the_stored_study_is_the_shipped_presets_and_the_early_gains_its_best_early_trial(stored):
    """The stored trials' best completed trial holds the shipped gains; the early variant flies the best
    completed trial among the first :data:`EARLY_BUDGET`, which is not the shipped one."""
    from auvtrack.control.gain_presets import get_gain_preset

    trials = stored["trials"]
    shipped = get_gain_preset(gap.SHIPPED)
    assert len(trials) == shipped.provenance["budget_trials"]
    best = min((t for t in trials if t["state"] == "COMPLETE"), key=lambda t: t["value"])
    assert best["value"] == shipped.provenance["train_score"]
    assert all(shipped.gains[k] == x for k, x in best["params"].items())
    early = gap.first_best(trials)
    assert early["number"] < gap.EARLY_BUDGET and early["value"] > best["value"]
    assert all(stored["variants"]["early"]["gains"][k] == x for k, x in early["params"].items())

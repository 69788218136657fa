"""The model-gap acceptance check of the shipped presets: its runs are the study's calm truth runs."""
from __future__ import annotations

import pytest

from auvtrack.benchmark.suite import tracking_kinds
from auvtrack.control import gain_presets
from auvtrack.studies import model_gap
from auvtrack.studies.preset_acceptance import acceptance, acceptance_runs


def test_the_check_flies_every_controller_on_both_truths_and_every_reference_calm():
    runs = acceptance_runs("auv-track-v2")
    assert len(runs) == len(tracking_kinds()) * 2 * len(model_gap.REFERENCES)
    assert {t for _, _, t, _ in runs} == {"prestero", "fossen"} and "5dof" in model_gap.TRUTHS
    assert all(p == f"{k}_remus100_auv-track-v2" for k, p, _, _ in runs)


def test_a_run_flies_the_presets_controller_in_the_studys_scenario(monkeypatch, tmp_path):
    # one preset shipped: the others are reported missing, not flown on other gains
    (tmp_path / "pid_remus100_x.toml").write_text('kind = "pid"\n[gains]\nkp = 0.5\nki = 0.01\nkd = 1.5\n'
                                                  'kaw = 0.5\nsaturation = "compensated"\n')
    monkeypatch.setattr(gain_presets, "_gains_root", lambda: tmp_path)
    rows = acceptance("x", quick=True, duration=2.0)
    flown = [r for r in rows if r.status not in ("no preset", "infeasible")]
    assert {r.controller for r in flown} == {"pid"} and len(flown) == 2
    assert {r.status for r in rows if r.controller != "pid"} == {"no preset"}
    assert all(r.row["controller"] == "pid" and r.row["truth"] == r.truth and r.row["duration_run"] > 0 for r in flown)


@pytest.mark.slow
def test_the_shipped_v2_presets_complete_every_feasible_calm_truth_run():
    rows = acceptance("auv-track-v2")
    failed = [(r.controller, r.truth, r.reference, r.cause, r.fail_time) for r in rows if r.status == "failed"]
    assert not failed, failed

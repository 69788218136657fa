"""``auvtrack tune`` on the command line and what it writes: the preset (usable as controller.preset), results.json."""
from __future__ import annotations

import json

import pytest
from click.testing import CliRunner

from auvtrack.cli import cli
from auvtrack.control import gain_presets
from auvtrack.scenario.loader import load_scenario, paper_scenario_path
from tiny_suite import TINY
from tuning_suite import SPLITS


@pytest.fixture(scope="module")
def tuned(tmp_path_factory):
    root = tmp_path_factory.mktemp("cli")
    (root / "tiny.toml").write_text(TINY + SPLITS)
    r = CliRunner().invoke(cli, ["tune", "--controller", "pid", "--suite", str(root / "tiny.toml"), "--budget", "3",
                                 "--out", str(root / "out"), "--quiet"])
    assert r.exit_code == 0, r.output
    return root, r.output


def test_the_summary_states_the_cost_and_both_scores(tuned):
    _, output = tuned
    for word in ("trials: 3", "runs:", "RK4 steps:", "CPU", "wall", "best training score:", "validation-split score:"):
        assert word in output


def test_the_preset_is_usable_as_controller_preset(tuned, monkeypatch):
    root, _ = tuned
    out = root / "out"
    monkeypatch.setattr(gain_presets, "_gains_root", lambda: out)
    preset = gain_presets.get_gain_preset("pid_remus100_tiny")
    results = json.loads((out / "results.json").read_text())
    table = results["result"]["table"]  # the searched gains and every other field of the tuned controller
    assert preset.kind == "pid" and preset.gains == {k: v for k, v in table.items() if k != "kind"}
    assert {k: preset.gains[k] for k in results["result"]["best_params"]} == results["result"]["best_params"]
    assert preset.gains["saturation"] == "compensated"  # the designed form of the REMUS, not the law's default
    for key in ("suite", "split", "budget_runs", "sampler", "sampler_seed", "optuna", "auvtrack", "source_hash",
                "train_score", "validation_score", "cpu_s", "wall_s", "study_runs", "study_rk4_steps", "suite_version"):
        assert key in preset.provenance, key
    assert preset.provenance["budget_runs"] == 3 * preset.provenance["runs_per_trial"]
    sc = load_scenario(paper_scenario_path(), ['controller={kind="pid", preset="pid_remus100_tiny"}'])
    assert sc.controller.kp == preset.gains["kp"]
    assert (out / "report.html").is_file() and len(results["trials"]) == 3
    val = results["result"]["validation_runs"]  # the best gains' runs on [splits.validation]: line x 2 tiers x 1 seed
    assert [(r["task"], r["seed_index"]) for r in val] == [("line", 20), ("line", 20)]
    assert "validation runs" in (out / "report.md").read_text()


@pytest.mark.parametrize("args, field", [
    (["--controller", "open_loop", "--budget", "2"], "controller:"),
    (["--controller", "pid", "--budget", "0"], "--budget:"),
    (["--controller", "pid", "--budget", "2", "--scheduler", "tcp://127.0.0.1:1"], "--scheduler:"),
    (["--controller", "pid", "--budget", "2", "--parallel", "0"], "--parallel"),
])
def test_bad_input_is_one_line(tuned, tmp_path, args, field):
    root, _ = tuned
    r = CliRunner().invoke(cli, ["tune", "--suite", str(root / "tiny.toml"), "--out", str(tmp_path / "x"), *args])
    assert r.exit_code == 2 and field in r.output and "Traceback" not in r.output
    assert not (tmp_path / "x").exists()  # refused before anything is stored


def test_the_slices_are_the_studys_trials(tuned):
    import optuna

    from auvtrack.tuning.slices import slice_points

    root, _ = tuned
    out = root / "out"
    study = optuna.load_study(study_name="tune", storage=f"sqlite:///{out / 'study.db'}")
    points = slice_points(study)
    trials = json.loads((out / "results.json").read_text())["trials"]
    assert list(points) == ["kp", "ki", "kd", "kaw"]
    for name, pts in points.items():  # every finished trial once per gain, at its value and score
        finished = [t for t in trials if t["state"] in ("COMPLETE", "PRUNED")]
        assert [(p.trial, p.value) for p in pts] == [(t["number"], t["params"][name]) for t in finished]
        for p, t in zip(pts, finished):
            if t["state"] == "COMPLETE":
                assert p.score == t["value"] and p.state == ("refused" if t["user_attrs"]["violations"] else "complete")
            else:
                assert p.state == "pruned"
    assert (out / "figures" / "slices.png").is_file() and "figures/slices.png" in (out / "report.md").read_text()

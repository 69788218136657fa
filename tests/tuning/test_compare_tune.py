"""``auvtrack compare --tune``: a plug-in newcomer tuned on the training split, then compared with its best gains."""
from __future__ import annotations

import json
import shlex
from pathlib import Path

import pandas as pd
import pytest

from auvtrack.benchmark.suite import load_suite
from auvtrack.cli import EXIT_BAD_INPUT, main
from auvtrack.cli.compare import resume_command
from auvtrack.control import gain_presets
from auvtrack.tuning.newcomer import shared_budget, tune_folder
from tiny_suite import TINY

from tuning_suite import SPLITS

PLUGIN = Path(__file__).resolve().parents[2] / "examples" / "plugin_controller.py"


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    path = tmp_path_factory.mktemp("suite") / "tiny.toml"
    path.write_text(TINY + SPLITS)
    return path


@pytest.mark.slow
def test_a_plugin_is_tuned_then_compared_with_its_best_gains(tiny, tmp_path, capsys):
    out = tmp_path / "c"
    assert main(["compare", "--suite", str(tiny), "--quick", "--controllers", "pid", "--plugin", str(PLUGIN),
                 "--tune", "2", "--out", str(out), "--quiet"]) == 0
    tuned = json.loads((tune_folder(out) / "plugin_controller" / "results.json").read_text())
    best = tuned["result"]["best_params"]
    assert tuned["result"]["trials"] == 2 and set(best) == {"kp", "kd"}
    doc = json.loads((out / "results.json").read_text())
    entry = next(c for c in doc["controllers"] if c["label"] == "plugin_controller")
    assert entry["table"] == {"kind": "plugin", "module": str(PLUGIN), "params": best}
    assert "tuned by auvtrack tune" in entry["gains"]
    pid = next(c for c in doc["controllers"] if c["label"] == "pid")
    assert "params" not in pid["table"]  # built-ins keep their gains
    runs = pd.read_parquet(out / "runs.parquet")
    assert (runs["controller"] == "plugin_controller").sum() == 2 * 2 * 2
    # seed indices flown in tuning (training 10, 11) are not the compared ones (0, 1)
    assert set(runs["seed_index"]) == {0, 1}
    assert "plugin_controller: plug-in plugin_controller.py: tuned" in capsys.readouterr().out


def test_the_resume_command_keeps_the_tuning(tmp_path):
    cmd = resume_command("s.toml", True, ["pid"], ("p.py",), tmp_path / "o", None, None, None, None, "suite")
    assert shlex.split(cmd)[-4:] == ["--tune", "--out", str(tmp_path / "o"), "--resume"]
    assert "--tune 7 " in resume_command("s", False, None, ("p.py",), tmp_path, None, None, None, None, "7")


@pytest.mark.parametrize("args, words", [
    (["--controllers", "pid", "--tune", "2"], "--tune: tunes the --plugin newcomers"),
    (["--plugin", str(PLUGIN), "--tune", "x"], "--tune: must be a number of trials"),
    (["--plugin", str(PLUGIN), "--tune"], "--tune: no preset tuned on tiny"),
])
def test_bad_tune_input_is_one_line(tiny, tmp_path, capsys, args, words):
    assert main(["compare", "--suite", str(tiny), "--quick", "--out", str(tmp_path / "x"), "--quiet", *args]) \
        == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert words in err and "Traceback" not in err and len(err.strip().splitlines()) == 1


def _preset(folder, name, suite, trials, version=1):
    (folder / f"{name}.toml").write_text(
        f'kind = "pid"\ndescription = "x"\n[gains]\nkp = 1.0\n[provenance]\ntool = "auvtrack tune"\n'
        f'suite = "{suite}"\nsuite_version = {version}\nbudget_trials = {trials}\n')


def test_the_shared_budget_is_the_suite_presets_trials(tiny, tmp_path, monkeypatch):
    monkeypatch.setattr(gain_presets, "_gains_root", lambda: tmp_path)
    suite = load_suite(tiny)
    _preset(tmp_path, "pid_remus100_tiny", "tiny", 6)
    _preset(tmp_path, "pid_remus100_other", "other", 9)  # another suite's budget does not count
    _preset(tmp_path, "pid_remus100_tiny2", "tiny", 7, version=2)  # nor another version's
    _preset(tmp_path, "pid_remus100_tinyv1", "tiny v1", 8)  # a suite label "name vN" is not the name
    assert shared_budget(suite) == 6
    _preset(tmp_path, "ftsmc_remus100_tiny", "tiny", 5)
    with pytest.raises(ValueError, match="different budgets"):
        shared_budget(suite)


@pytest.mark.parametrize("name", ["auv-track-v1", "auv-track-v2"])
def test_every_shipped_suite_with_tuned_presets_has_one_shared_budget(name):
    from auvtrack.benchmark.suite import tracking_kinds

    suite = load_suite(name, check=False)
    trials = shared_budget(suite)  # refuses presets of one suite tuned at different budgets
    shipped = [k for k in tracking_kinds() if f"{k}_remus100_{name}" in gain_presets.available_gain_presets()]
    assert trials >= 1 and shipped
    for k in shipped:
        preset = gain_presets.get_gain_preset(f"{k}_remus100_{name}")
        assert preset.kind == k and preset.provenance["split"] == "training"
        assert preset.provenance["budget_runs"] == trials * preset.provenance["runs_per_trial"]


def test_the_v2_suite_flies_its_own_presets_and_names_a_missing_one(tmp_path, monkeypatch):
    from auvtrack.benchmark.suite import resolve_controllers, tracking_kinds

    suite = load_suite("auv-track-v2", check=False)
    assert suite.file.gain_preset == "{kind}_remus100_auv-track-v2"
    for e in resolve_controllers(None, gain_preset=suite.file.gain_preset):
        name = f"{e.label}_remus100_auv-track-v2"
        if name in gain_presets.available_gain_presets():
            assert e.table == {"kind": e.label, "preset": name}
            assert gain_presets.get_gain_preset(name).provenance["suite"] == suite.name
        else:  # flown untuned, and the entry says which preset is missing
            assert e.table == {"kind": e.label} and f"no gain preset {name!r} is installed" in e.gains
    monkeypatch.setattr(gain_presets, "_gains_root", lambda: tmp_path)  # none installed: every entry says so
    assert all("is installed" in e.gains for e in resolve_controllers(None, gain_preset=suite.file.gain_preset))
    assert len(tracking_kinds()) == len(resolve_controllers(None, gain_preset=suite.file.gain_preset))

"""Packaged scenarios by name, from any folder; a name and a path are never confused."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from auvtrack.cli import EXIT_BAD_INPUT, main
from auvtrack.scenario import ScenarioError, load_scenario
from auvtrack.scenario.catalog import (NAME_PATTERN, available_scenarios, copy_scenario, is_scenario_name,
                                       scenario_path, scenario_summary)

ROOT = Path(__file__).resolve().parents[2]
PACKAGED = ROOT / "auvtrack" / "data" / "scenarios"


def test_every_packaged_file_is_a_name_and_loads():
    names = available_scenarios()
    assert names == sorted(p.stem for p in PACKAGED.glob("*.toml"))
    assert {"paper", "circle", "lawnmower", "remus100"} <= set(names)
    for name in names:
        assert is_scenario_name(name)
        assert load_scenario(name) == load_scenario(PACKAGED / f"{name}.toml")
        assert scenario_summary(name), name  # `auvtrack scenarios list` has a line for each


def test_the_repository_scenarios_are_the_packaged_files():
    """scenarios/*.toml (but the sweep study) link to the packaged files: one copy of each."""
    for p in sorted((ROOT / "scenarios").glob("*.toml")):
        if p.name == "sweep_example.toml":
            continue
        assert p.is_symlink() and p.resolve() == (PACKAGED / p.name).resolve(), p


@given(text=st.text(max_size=20))
@settings(max_examples=300, deadline=None)
def test_a_name_never_looks_like_a_path(text):
    """Whatever the string: a name has no separator and no dot, and anything with one is a path."""
    if is_scenario_name(text):
        assert not ({"/", "\\", ".", "\0"} & set(text)) and text and not text.startswith("-")
        assert Path(text).name == text and Path(text).suffix == ""
    if {"/", "\\", "."} & set(text):
        assert not is_scenario_name(text)


def test_a_path_object_is_never_a_name(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert not is_scenario_name(Path("paper"))
    with pytest.raises(ScenarioError) as info:
        load_scenario(Path("paper"))
    assert str(info.value) == "paper: file not found (a packaged scenario has that name: give the string 'paper')"


def test_a_file_named_like_a_packaged_scenario_is_reached_as_a_path(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    Path("paper").write_text('name = "local"\n')
    assert load_scenario("paper").name == "paper"  # the name: always the packaged file
    assert load_scenario("./paper").name == "local"  # the path
    assert load_scenario(str(tmp_path / "paper")).name == "local"


def test_unknown_names_and_near_misses_are_one_line(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(ScenarioError) as info:
        load_scenario("papre")
    assert str(info.value) == (f"papre: unknown packaged scenario (packaged: {', '.join(available_scenarios())}; "
                               "a file path has a '/' or a '.': ./papre)")
    with pytest.raises(ScenarioError) as info:
        load_scenario("scenarios/paper.toml")  # the README's old path, outside the clone
    assert str(info.value) == ("scenarios/paper.toml: file not found (a packaged scenario has that name: give the "
                               "string 'paper')")


def test_names_work_from_any_folder(tmp_path):
    """The README's Python and command lines, from a folder that is not the clone."""
    code = ("import auvtrack; sc = auvtrack.load_scenario('lawnmower', 'sim.duration=10'); "
            "print(sc.reference['kind'], sc.sim.duration)")
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    p = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, env=env,
                       timeout=300)
    assert p.returncode == 0 and p.stdout.split() == ["lawnmower", "10.0"], p.stderr
    p = subprocess.run([sys.executable, "-m", "auvtrack.cli", "check", "circle"], cwd=tmp_path,
                       capture_output=True, text=True, env=env, timeout=300)
    assert p.returncode == 0 and p.stdout.startswith("ok: circle ("), p.stderr


def test_copy_is_byte_for_byte_and_never_overwrites_unasked(tmp_path):
    out = copy_scenario("paper", tmp_path / "mine.toml")
    assert out.read_bytes() == scenario_path("paper").read_bytes()
    assert load_scenario(out) == load_scenario("paper")
    with pytest.raises(ScenarioError, match="exists; choose another destination"):
        copy_scenario("circle", out)
    assert out.read_bytes() == scenario_path("paper").read_bytes()
    assert copy_scenario("circle", out, overwrite=True).read_bytes() == scenario_path("circle").read_bytes()
    assert copy_scenario("lawnmower", tmp_path) == tmp_path / "lawnmower.toml"  # into a folder
    os.symlink(out, tmp_path / "link.toml")
    with pytest.raises(ScenarioError, match="not a regular file"):
        copy_scenario("paper", tmp_path / "link.toml", overwrite=True)


def test_the_scenarios_command(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["scenarios", "list"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert [ln.split()[0] for ln in lines] == available_scenarios()
    assert all(scenario_summary(ln.split()[0]) in ln for ln in lines)
    assert main(["scenarios", "copy", "lawnmower"]) == 0
    assert capsys.readouterr().out.strip() == "written: lawnmower.toml"
    assert Path("lawnmower.toml").read_bytes() == scenario_path("lawnmower").read_bytes()
    for args, expect in ((["scenarios", "copy", "lawnmower"], "lawnmower.toml: exists"),
                         (["scenarios", "copy", "nope"], "nope: unknown packaged scenario"),
                         (["scenarios", "copy", "paper", str(tmp_path / "no" / "dir" / "x.toml")], "cannot write")):
        assert main(args) == EXIT_BAD_INPUT
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and err.startswith(f"auvtrack: error: ") and expect in err, err
    assert main(["scenarios", "copy", "paper", "lawnmower.toml", "--force"]) == 0
    assert Path("lawnmower.toml").read_bytes() == scenario_path("paper").read_bytes()


def test_top_level_help_points_to_no_file_of_the_clone(capsys):
    """Outside the clone there is no docs/ folder: the help names commands instead."""
    assert main(["--help"]) == 0
    out = capsys.readouterr().out
    assert "docs/" not in out and "scenarios copy" in out


def test_the_name_rule_is_the_documented_one():
    doc = (ROOT / "docs" / "scenarios.md").read_text()
    assert "letters, digits, `_` and `-` only" in doc and NAME_PATTERN.pattern == r"[A-Za-z0-9_][A-Za-z0-9_-]*"


def test_a_sweep_study_takes_a_packaged_name(tmp_path):
    """``scenario = "<name>"`` in a study file is the packaged scenario, as everywhere else."""
    from auvtrack.batch.sweep_spec import StudyError, load_study

    study = tmp_path / "s.toml"
    study.write_text('scenario = "lawnmower"\nset = ["sim.duration=10"]\n')
    spec = load_study(study)
    assert load_scenario(spec.base) == load_scenario("lawnmower", ["sim.duration=10"])
    study.write_text('scenario = "lawnmowr"\n')
    with pytest.raises(StudyError, match=r"scenario: must be a packaged scenario's name or a readable scenario "
                                         r"TOML file \(lawnmowr: unknown packaged scenario"):
        load_study(study)

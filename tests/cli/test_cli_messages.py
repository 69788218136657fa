"""Messages name what the user gave: the option (not a scenario key it became), one line, exit 2, nothing run."""
from __future__ import annotations

from pathlib import Path

import pytest

from auvtrack.cli import EXIT_BAD_INPUT, main

ROOT = Path(__file__).resolve().parents[2]
PAPER = ROOT / "scenarios" / "paper.toml"


def _nothing_runs(monkeypatch):
    """Any compile, benchmark or study run fails the test: a refused option runs nothing."""
    from auvtrack.perf import bench
    from auvtrack.simulation import compiling
    from auvtrack.studies import ablation

    def boom(*a, **k):
        raise AssertionError("something ran")

    for mod, name in ((compiling, "warmup"), (bench, "bench_singles"), (bench, "bench_plant"), (bench, "bench_all"),
                      (ablation, "compile_first"), (ablation, "_pool_map")):
        monkeypatch.setattr(mod, name, boom)


def _one_line(capsys, args) -> str:
    assert main(args) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("auvtrack: error: ") and "Traceback" not in err, err
    return err.strip()[len("auvtrack: error: "):]


@pytest.mark.parametrize("args, expect", [
    (["warmup", "--controller", "bogus"], "--controller: unknown controller 'bogus' (allowed: fxtntsmc, "),
    (["warmup", "--plant", "bogus"], "--plant: unknown plant 'bogus' (allowed: 5dof, 6dof)"),
    (["warmup", "--controller", "plugin"], "--controller: unknown controller 'plugin'"),
    (["warmup", "--controller", "open_loop_actuators", "--plant", "5dof"],
     "--controller, --plant: nothing to compile: no controller given runs on a plant given"),
    (["bench", "--controller", "bogus"], "--controller: unknown controller 'bogus'"),
    (["bench", "--controller", "open_loop_actuators"], "--controller: open_loop_actuators does not run on --plant 5dof"),
    (["bench", "--duration", "inf"], "--duration: must be a finite number > 0 s (got inf)"),
    (["bench", "--duration", "nan"], "--duration: must be a finite number > 0 s (got nan)"),
    (["bench", "--duration", "1e12"], "--duration: a 1e+12 s run is refused: sim.duration: sim.duration / sim.dt = "),
    (["bench", "--duration", "0.0015"], "--duration: a 0.0015 s run is refused: sim.duration: must be an integer "
                                        "multiple of dt"),
    (["bench", "--plant", "6dof", "--duration", "0.001"], "--duration: a 0.001 s run is refused: "),
    (["bench", "--all", "--duration", "5"], "--duration: not used by --all"),
    (["bench", "--all", "--controller", "pid", "--plant", "6dof"], "--controller, --plant: not used by --all"),
    (["bench", "--out", "x"], "--out: only --all writes results"),
    (["study", "ablation", "--quick", "--pulse-start", "1e12"],
     "--pulse-start: a pulse at 1e+12 s makes each pulse run last 1e+12 s, which is refused: sim.duration: "),
    (["study", "ablation", "--pulse-start", "20.0005"],
     "--pulse-start: a pulse at 20.0005 s makes each pulse run last 40.0005 s, which is refused: sim.duration: "
     "must be an integer multiple of dt"),
])
def test_the_option_is_named_and_nothing_runs(args, expect, capsys, monkeypatch):
    _nothing_runs(monkeypatch)
    msg = _one_line(capsys, args)
    assert msg.startswith(expect), msg
    assert "set by override" not in msg and "--set limits" not in msg and "paper.toml" not in msg


def test_a_valid_pulse_start_passes_the_check():
    """The check refuses only what the runs would: a pulse start on the time grid is taken as given."""
    from auvtrack.studies.ablation import settings_for

    st = settings_for(quick=True, pulse_start=12.5)
    assert st.pulse_start == 12.5 and st.horizon == 12.5 + st.pulse_duration + st.recovery


def test_save_into_a_folder_holding_other_files(tmp_path, capsys, monkeypatch):
    """``Result.save`` raises FolderError (an OSError) with a one-line message and writes nothing;
    ``auvtrack run --out`` says the same line before simulating, exit 2."""
    import auvtrack
    from auvtrack.simulation.result import FolderError

    folder = tmp_path / "mine"
    folder.mkdir()
    (folder / "thesis.tex").write_text("keep me")
    res = auvtrack.simulate("paper", ["sim.duration=0.05"], warn=False)
    with pytest.raises(FolderError) as info:
        res.save(folder)
    assert isinstance(info.value, OSError) and "\n" not in str(info.value)
    assert str(info.value).startswith(f"{folder}: holds 1 entry that a run folder does not (thesis.tex)")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mine"]  # no temporary folder left

    from auvtrack.simulation import pipeline

    monkeypatch.setattr(pipeline, "run_prepared", lambda prep: (_ for _ in ()).throw(AssertionError("ran")))
    msg = _one_line(capsys, ["run", str(PAPER), "--out", str(folder), "--set", "sim.duration=1"])
    assert msg == f"--out: {info.value}"
    assert sorted(p.name for p in folder.iterdir()) == ["thesis.tex"] and (folder / "thesis.tex").read_text() == "keep me"


def test_result_save_documents_folder_error():
    from auvtrack.simulation.result import Result

    assert "FolderError" in Result.save.__doc__
    doc = (ROOT / "docs" / "metrics.md").read_text()
    assert "`auvtrack.simulation.result.FolderError`" in doc


@pytest.mark.parametrize("command", ["check", "run"])
@pytest.mark.parametrize("path, points_to", [
    (ROOT / "scenarios" / "sweep_example.toml", "a sweep's study file (keys scenario, grid, random, ...), not a "
                                                "scenario: run it with `auvtrack sweep {path}` (docs/sweeps.md)"),
    (ROOT / "auvtrack" / "data" / "benchmarks" / "auv-track-v2.toml",
     "a benchmark suite (keys tasks, tiers, seeds, ...), not a scenario: run it with `auvtrack compare --suite {path}` (docs/benchmark.md)"),
])
def test_a_sweep_or_suite_file_given_as_a_scenario_names_its_command(capsys, monkeypatch, command, path, points_to):
    _nothing_runs(monkeypatch)
    assert _one_line(capsys, [command, str(path)]) == f"{path}: " + points_to.format(path=path)


def test_a_scenario_with_one_sweep_key_is_still_a_scenario_error(tmp_path, capsys, monkeypatch):
    """Only a file whose every key is a study file's is called one: a scenario with a stray key keeps its message."""
    _nothing_runs(monkeypatch)
    path = tmp_path / "sc.toml"
    path.write_text('name = "x"\nsamples = 3\n[sim]\nduration = 1.0\n')
    assert _one_line(capsys, ["check", str(path)]).startswith(f"{path}: samples: unknown key (allowed: name, ")

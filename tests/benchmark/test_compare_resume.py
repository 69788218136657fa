"""``auvtrack compare``: resume verifies and repairs, the printed command resumes, plans and competitors checked up front."""
from __future__ import annotations

import json
import shlex
import shutil
import time
from pathlib import Path

import pandas as pd
import pytest

from auvtrack.benchmark import execute as runner
from auvtrack.benchmark.compare import compare
from auvtrack.benchmark.suite import ControllerEntry, SuiteError, load_suite, resolve_controllers, tracking_kinds
from auvtrack.cli import EXIT_BAD_INPUT, main
from tiny_suite import TINY as SUITE

RUNS = 2 * 2 * 2  # tiers x tasks x quick seeds, one controller


def _suite(folder: Path, name: str = "tiny.toml", seed: int = 5) -> Path:
    path = folder / name
    path.write_text(SUITE.replace("seed = 5", f"seed = {seed}", 1))
    return path


def _results(out: Path) -> dict:
    doc = json.loads((out / "results.json").read_text())
    doc.pop("timing")
    doc["suite"].pop("source")  # the suite file's path
    return doc


def _run(suite: Path, out: Path, **kw):
    notes: list[str] = []
    res = compare(suite, quick=True, controllers=["ftsmc"], out=out, progress=False, chunk_size=1, notify=notes.append,
                  **kw)
    return res, notes


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    folder = tmp_path_factory.mktemp("ref")
    res, notes = _run(_suite(folder), folder / "ref")
    assert res.complete and res.execution.chunks_run == RUNS and notes == []
    return folder / "ref"


def test_resume_recomputes_tampered_chunks_and_never_mixes_two_comparisons(tmp_path, reference):
    suite = _suite(tmp_path)
    other, _ = _run(_suite(tmp_path, "other.toml", seed=6), tmp_path / "other")  # another suite seed
    assert other.complete
    out = tmp_path / "c"
    part, _ = _run(suite, out, max_chunks=6)
    assert not part.complete
    chunk = [runner.chunk_path(out, c) for c in range(RUNS)]
    shutil.copy(runner.chunk_path(tmp_path / "other", 0), chunk[0])  # the same chunk of another suite seed
    chunk[1].write_bytes(chunk[1].read_bytes()[:100])  # truncated
    chunk[2].write_bytes(b"")  # empty
    shutil.copy(chunk[4], chunk[3])  # duplicated
    res, notes = _run(suite, out, resume=True)
    assert res.complete and res.execution.chunks_redone == (0, 1, 2, 3)
    assert res.execution.chunks_skipped == 2 and res.execution.chunks_run == 6  # 4 repaired, 2 missing
    assert len(notes) == 4 and all("\n" not in n and "recomputing chunk" in n for n in notes)
    assert "belongs to another run" in notes[0] and "not a readable Parquet file" in notes[1]
    assert "is empty" in notes[2] and "is a copy of chunk 4" in notes[3]
    assert _results(out) == _results(reference)
    pd.testing.assert_frame_equal(pd.read_parquet(out / "runs.parquet"), pd.read_parquet(reference / "runs.parquet"))
    assert _results(tmp_path / "other") != _results(reference)  # the foreign chunk would have shown


def test_the_printed_resume_command_works_verbatim(tmp_path, capsys):
    suite = tmp_path / "many.toml"
    suite.write_text(SUITE.replace("[quick]\nseeds = 2", "[quick]\nseeds = 13"))  # 52 runs: two chunks of 48
    out = tmp_path / "c"
    code = main(["compare", "--suite", str(suite), "--quick", "--controllers", "ftsmc", "--out", str(out),
                 "--max-chunks", "1", "--quiet"])
    assert code == 0
    line = capsys.readouterr().out.strip().splitlines()[-1]
    assert line.startswith("stopped after 1 chunks; finish with: "), line
    argv = shlex.split(line.split("finish with: ", 1)[1])
    assert argv[:2] == ["auvtrack", "compare"] and argv[-1] == "--resume"
    assert argv[argv.index("--controllers") + 1] == "ftsmc"  # the option the printed command used to drop
    assert main(argv[1:]) == 0, capsys.readouterr().err
    whole = compare(suite, quick=True, controllers=["ftsmc"], out=tmp_path / "whole", progress=False)
    assert whole.complete and whole.execution.runs == 52
    assert _results(out) == _results(tmp_path / "whole")
    pd.testing.assert_frame_equal(pd.read_parquet(out / "runs.parquet"),
                                  pd.read_parquet(tmp_path / "whole" / "runs.parquet"))


def test_a_hundred_thousand_seeds_are_refused_before_anything_is_planned(tmp_path, capsys):
    from auvtrack.benchmark import suite as suite_mod

    shipped = Path(suite_mod.__file__).parent.parent / "data" / "benchmarks" / "auv-track-v1.toml"
    text = shipped.read_text()
    assert "\nseeds = 100 " in text
    path = tmp_path / "big.toml"
    text = text.replace("\nseeds = 100 ", "\nseeds = 100000 ", 1)
    # the splits stay disjoint from the 100000 evaluation seeds
    text = text.replace("seeds = [1000, 1008]", "seeds = [200000, 200008]")
    path.write_text(text.replace("seeds = [2000, 2004]", "seeds = [300000, 300004]"))
    big = load_suite(path)
    t0 = time.monotonic()
    with pytest.raises(runner.CompareError) as info:
        compare(big, out=tmp_path / "o", progress=False)
    took = time.monotonic() - t0
    n = 5 * 4 * 100_000 * len(tracking_kinds())
    assert str(info.value) == (f"{path}: seeds: 100000 seeds x 4 tasks x 5 tiers x {len(tracking_kinds())} controllers = "
                               f"{n} runs, more than --max-runs = 100000 (raise it deliberately with --max-runs N, "
                               "up to 1000000)")
    assert took < 5.0, took  # resolving the controllers and one multiplication
    assert not (tmp_path / "o").exists()
    t0 = time.monotonic()
    assert main(["compare", "--suite", str(path), "--out", str(tmp_path / "o"), "--quiet"]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--max-runs = 100000" in err
    print(f"12 million runs refused in {took:.2f} s (API, suite loaded), {time.monotonic() - t0:.1f} s (CLI, with "
          "loading and checking the suite)")


@pytest.mark.parametrize("args, expect", [
    (["--controllers", ""], "--controllers: names no controller (got '')"),
    (["--controllers", " , "], "--controllers: names no controller"),
    (["--controllers", "ftsmc,open_loop"], "--controllers: 'open_loop' does not track a reference"),
    (["--controllers", "open_loop_actuators"], "--controllers: 'open_loop_actuators' does not track a reference"),
    (["--max-runs", "0"], "--max-runs: must be an integer in [1, 1000000] (got 0)"),
    (["--max-runs", "2000000"], "--max-runs: must be an integer in [1, 1000000] (got 2000000)"),
    (["--max-runs", "3"], "runs, more than --max-runs = 3"),
])
def test_competitors_and_plan_options_are_checked_up_front(args, expect, tmp_path, capsys):
    suite = _suite(tmp_path)
    assert main(["compare", "--suite", str(suite), "--quick", "--out", str(tmp_path / "x"), "--quiet", *args]) == 2
    err = capsys.readouterr().err
    assert err.startswith("auvtrack: error: ") and expect in err and err.count("\n") == 1, err
    assert not (tmp_path / "x").exists()


def test_the_api_refuses_an_empty_list_and_open_loop_entries(tmp_path):
    suite = _suite(tmp_path)
    with pytest.raises(SuiteError, match="names no controller"):
        compare(suite, quick=True, controllers=[], out=tmp_path / "x", progress=False)
    crash = ControllerEntry("crash", {"kind": "open_loop", "tau0": [0.0, 300.0, 0.0]}, "open loop")
    with pytest.raises(SuiteError, match="'open_loop' does not track a reference"):
        compare(suite, quick=True, entries=[*resolve_controllers(["ftsmc"]), crash], out=tmp_path / "x",
                progress=False)
    assert not (tmp_path / "x").exists()


PLUGIN = Path(__file__).resolve().parents[2] / "examples" / "plugin_controller.py"


@pytest.mark.parametrize("source, expect", [
    ("import numpy\nraise ImportError('no module named nothere')\n", "cannot import"),
    ("def broken(:\n", "cannot import"),
    ("AUX_NAMES = ()\n", "does not define Params, control, setup"),  # imports, breaks the contract
    (PLUGIN.read_text() + "\nTRACKS = False\n", "does not track a reference (TRACKS = False)"),
])
def test_a_plugin_that_does_not_import_or_track_is_refused_before_anything_runs(source, expect, tmp_path, capsys):
    bad = tmp_path / "my_law.py"
    bad.write_text(source)
    t0 = time.monotonic()
    code = main(["compare", "--suite", str(_suite(tmp_path)), "--quick", "--controllers", "ftsmc", "--plugin", str(bad),
                 "--out", str(tmp_path / "x"), "--quiet"])
    err = capsys.readouterr().err
    assert code == 2 and err.startswith("auvtrack: error: --plugin: ") and expect in err, err
    assert err.count(str(bad)) == 1, err
    assert err.count("\n") == 1 and not (tmp_path / "x").exists() and time.monotonic() - t0 < 60


def test_a_plugin_whose_setup_breaks_is_refused_before_anything_runs(tmp_path, capsys):
    broken = tmp_path / "broken_setup.py"
    broken.write_text(PLUGIN.read_text() + "\n\ndef setup(params, ctx):\n    raise KeyError('gains')\n")
    code = main(["compare", "--suite", str(_suite(tmp_path)), "--quick", "--controllers", "ftsmc", "--plugin",
                 str(broken), "--out", str(tmp_path / "x"), "--quiet"])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "Traceback" not in err, err
    assert err.startswith(f"auvtrack: error: --plugin: {broken}: its set-up fails on task helix, tier calm: KeyError"), err
    assert not (tmp_path / "x").exists()


def test_a_plugin_writing_out_of_bounds_is_refused_by_its_probe_before_anything_runs(tmp_path, capsys):
    """compare probes the plug-in's law on its first run as check and run do: the index error, its file
    and line, the time and the task are named in one line, exit 2, and no folder is written."""
    law = PLUGIN.read_text()
    body = "    out.aux[0], out.aux[1], out.aux[2] = a\n    return 0\n"
    assert law.count(body) == 1
    bad = tmp_path / "oob_law.py"
    bad.write_text(law.replace(body, "    out.aux[0], out.aux[1], out.aux[2] = a\n    if t > 0.5:\n"
                                     "        out.u[100000] = 1.0\n    return 0\n"))
    line = bad.read_text().splitlines().index("        out.u[100000] = 1.0") + 1
    code = main(["compare", "--suite", str(_suite(tmp_path)), "--quick", "--controllers", "ftsmc", "--plugin", str(bad),
                 "--out", str(tmp_path / "x"), "--quiet"])
    err = [ln for ln in capsys.readouterr().err.splitlines() if not ln.startswith("compiling kernels")]
    assert code == EXIT_BAD_INPUT and len(err) == 1 and "Traceback" not in err[0], err
    assert err[0].startswith(f"auvtrack: error: --plugin: {bad}:{line}: control raised IndexError: index 100000 is "
                             "out of bounds"), err
    assert "in the step from t = 0.5" in err[0] and err[0].endswith("on task helix, tier calm"), err
    assert not (tmp_path / "x").exists()


def test_a_plugin_s_exception_in_a_run_is_that_run_s_setup_failure(tmp_path):
    broken = tmp_path / "broken_setup.py"
    broken.write_text(PLUGIN.read_text() + "\n\ndef setup(params, ctx):\n    raise KeyError('gains')\n")
    entry = ControllerEntry("broken", {"kind": "plugin", "module": str(broken)}, "")
    spec, = runner.plan_runs(load_suite(_suite(tmp_path)), [entry], range(1))
    assert runner._prepare(spec) == "KeyError: 'gains'"  # recorded as the run's set-up failure, not raised


def test_an_out_folder_of_the_user_s_own_files_is_refused_and_left_alone(tmp_path, capsys):
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "thesis.tex").write_text("mine")
    for extra in ([], ["--resume"]):
        assert main(["compare", "--suite", str(_suite(tmp_path)), "--quick", "--controllers", "ftsmc", "--out",
                     str(mine), "--quiet", *extra]) == 2
        err = capsys.readouterr().err
        assert f"--out: {mine} already holds files that are not an auvtrack comparison (thesis.tex)" in err, err
    assert [p.name for p in mine.iterdir()] == ["thesis.tex"]


def test_the_plan_bounds_of_the_docs_are_the_code_s():
    text = (Path(__file__).resolve().parents[2] / "docs" / "benchmark.md").read_text()
    ratio = round(runner.DEFAULT_MAX_RUNS / runner.plan_size(load_suite(), resolve_controllers()))
    assert (f"`--max-runs` (default {runner.DEFAULT_MAX_RUNS}, about {ratio} × the default suite; at most "
            f"{runner.MAX_RUNS})" in text)
    from auvtrack.batch.executor import MAX_WORKERS

    assert f"`--workers`\n  is at most {MAX_WORKERS}." in text


def test_any_range_of_runs_is_planned_as_the_whole_plan_plans_it(tmp_path):
    from hypothesis import given, settings
    from hypothesis import strategies as st

    suite = load_suite(_suite(tmp_path))
    entries = resolve_controllers(["ftsmc", "pid", "sta"])
    whole = runner.plan_runs(suite, entries)
    assert len(whole) == runner.plan_size(suite, entries) == 2 * 2 * 3 * 3
    assert [s.run for s in whole] == list(range(len(whole)))

    @settings(max_examples=40, deadline=None)
    @given(st.integers(0, len(whole)), st.integers(0, len(whole)))
    def check(a, b):
        assert runner.plan_runs(suite, entries, range(min(a, b), max(a, b))) == whole[min(a, b):max(a, b)]

    check()
    with pytest.raises(IndexError):
        runner.plan_runs(suite, entries, range(len(whole), len(whole) + 1))


def test_the_warm_up_flies_the_first_run_of_every_controller_tier_and_plant_preset():
    suite = load_suite().quick_variant()
    entries = resolve_controllers()
    first: dict[tuple, runner.RunSpec] = {}
    for s in runner.plan_runs(suite, entries):
        first.setdefault((s.controller, s.tier, s.overrides.get("plant.preset")), s)
    warm = runner._warm_specs(suite, entries)
    assert {(s.controller, s.tier, s.overrides.get("plant.preset")): s for s in warm} == first
    assert {k[2] for k in first if k[1] == "truth6"} == {"remus100_prestero", "remus100_fossen"}


def test_a_run_lost_with_its_worker_is_a_failed_row_of_the_schema(tmp_path):
    job = runner.CompareJob(load_suite(_suite(tmp_path)), resolve_controllers(["ftsmc"]), 4, None)
    t = job.lost_rows(range(2, 4), "the worker process died")
    assert t.schema.equals(job.schema()) and t.column("run").to_pylist() == [2, 3]
    assert set(t.column("status").to_pylist()) == {"failed"} and set(t.column("cause").to_pylist()) == {"worker_died"}
    planned = runner.plan_runs(job.suite, job.entries, range(2, 4))
    assert t.column("seed").to_pylist() == [int(s.raw["seed"]) for s in planned]


def test_a_comparison_on_a_cluster_without_workers_stops_with_a_diagnostic(tmp_path, monkeypatch):
    from distributed import Client, LocalCluster

    from auvtrack.batch import dask_wait

    monkeypatch.setattr(dask_wait, "WORKER_GRACE_S", 1.0)
    with LocalCluster(n_workers=0, processes=False, dashboard_address=":0") as cluster, Client(cluster) as client:
        t0 = time.monotonic()
        with pytest.raises(runner.CompareError, match=r"no worker for 1 s .* 0 of 8 chunks are kept .*--resume"):
            _run(_suite(tmp_path), tmp_path / "o", client=client)
        assert time.monotonic() - t0 < 30

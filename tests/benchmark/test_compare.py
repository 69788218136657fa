"""``auvtrack compare`` end to end: the quick path, determinism, resume, Dask, a failing controller, bad input."""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from auvtrack.cli import EXIT_BAD_INPUT, main
from auvtrack.benchmark import execute as runner
from auvtrack.benchmark.compare import compare
from auvtrack.benchmark.suite import (ControllerEntry, SuiteError, load_suite, resolve_controllers, tracking_kinds)
from report_check import check_html_report
from tiny_suite import TINY


@pytest.fixture(scope="module")
def tiny(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("suite") / "tiny.toml"
    path.write_text(TINY)
    return path


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    """``auvtrack compare --quick`` through the command line, once for the module."""
    out = tmp_path_factory.mktemp("quick") / "q"
    assert main(["compare", "--quick", "--out", str(out), "--quiet"]) == 0
    return out


def _results(out: Path) -> dict:
    doc = json.loads((out / "results.json").read_text())
    doc.pop("timing")
    return doc


def test_quick_path_every_controller_and_tier_and_the_report_files(quick):
    from auvtrack import __version__
    from auvtrack.control import BUILTIN_NAMES
    from auvtrack.control.gain_presets import available_gain_presets

    suite = load_suite().quick_variant()
    doc = json.loads((quick / "results.json").read_text())
    kinds = tracking_kinds()
    assert kinds == [k for k in BUILTIN_NAMES if not k.startswith("open_loop")] and len(kinds) >= 6
    assert sorted(r["controller"] for r in doc["leaderboard"]) == sorted(kinds)
    assert {c["tier"] for c in doc["cells"]} == set(suite.tiers)
    assert {c["task"] for c in doc["cells"]} == set(suite.tasks)
    assert len(doc["cells"]) == len(kinds) * len(suite.tasks) * len(suite.tiers)
    runs = pd.read_parquet(quick / "runs.parquet")
    assert len(runs) == len(kinds) * len(suite.tasks) * len(suite.tiers) * suite.seeds
    assert set(runs["controller"]) == set(kinds) and set(runs["tier"]) == set(suite.tiers)
    md = (quick / "report.md").read_text()
    for name in kinds + suite.tiers:
        assert name in md
    for t in suite.skipped_tiers:
        assert f"`{t}`" in md  # a tier this build cannot run is named, with the reason
    for fig in ["leaderboard", "failure_rates", *(f"dist_{m}" for m in ("rmse", "tv")), "traj_helix"]:
        assert (quick / "figures" / f"{fig}.png").is_file()
    html = check_html_report(quick)
    assert "Leaderboard" in html and suite.name in html
    # every built-in enters with its tuned preset, or with its defaults and the report says so
    assert [c["label"] for c in doc["controllers"]] == kinds
    for c in doc["controllers"]:
        preset = f"{c['label']}_tuned"
        if preset in available_gain_presets():
            assert c["table"] == {"kind": c["label"], "preset": preset} and preset in md
        else:
            assert c["table"] == {"kind": c["label"]} and "package defaults" in c["gains"] and "package defaults" in md
    # comparable reports: suite version, every setting, package version and sources
    assert doc["suite"]["name"] == "auv-track-v1" and doc["suite"]["quick"] is True
    assert doc["suite"]["version"] == suite.file.version and doc["suite"]["file"] == suite.file.model_dump(mode="json")
    assert doc["suite"] == json.loads(json.dumps(suite.settings()))
    assert doc["auvtrack_version"] == __version__ and len(doc["source_hash"]) == 64
    assert f"auvtrack {__version__}" in md and f"version {suite.file.version}" in md and suite.fingerprint()[:16] in md
    t = doc["timing"]
    assert t["runs"] == len(runs) and t["cpu_count"] and t["compile_seconds"] >= 0 and "load average" in md


def test_quick_path_truth6_flies_both_6dof_presets(quick):
    """The truth6 tier cycles the two shipped 6-DOF truth plants over the seeds; every controller flies both,
    and a truth6 row is the single run of its scenario on that 6-DOF plant."""
    from auvtrack.vehicle.truth_presets import SHIPPED6
    from auvtrack.scenario import load_scenario
    from auvtrack.simulation.pipeline import simulate

    suite = load_suite().quick_variant()
    assert "truth6" in suite.tiers and not suite.skipped_tiers
    runs = pd.read_parquet(quick / "runs.parquet")
    truth = runs[runs["tier"] == "truth6"].assign(preset=lambda d: d["draws"].map(lambda x: json.loads(x)["plant.preset"]))
    assert set(truth["preset"]) == set(SHIPPED6)
    for (controller, preset), g in truth.groupby(["controller", "preset"]):
        assert (g["cause"] != "setup").all() and (g["steps"] > 0).all(), (controller, preset)
    assert set(truth.groupby(["controller", "preset"]).groups) == {(c, p) for c in tracking_kinds() for p in SHIPPED6}
    entries = {e.label: e for e in resolve_controllers()}
    row = truth[(truth["preset"] == "remus100_fossen") & (truth["status"] == "ok")].iloc[0]
    raw, ov, _ = suite.scenario(entries[row.controller], row.task, "truth6", int(row.seed_index))
    sc = load_scenario(raw, ov)
    assert sc.plant.model == "6dof" and sc.plant.preset == "remus100_fossen"
    res = simulate(sc)
    assert res.status == row.status and res.metrics["rmse_x"] == row["rmse_x"] and res.metrics["itae_z"] == row["itae_z"]


def test_controllers_without_a_tuned_preset_run_on_defaults_and_the_report_says_so(tiny, tmp_path):
    path = tmp_path / "untuned.toml"
    path.write_text(TINY.replace('seed = 5', 'seed = 5\ngain_preset = "{kind}_untuned"', 1))
    entry, = resolve_controllers(["ftsmc"], gain_preset="{kind}_untuned")
    assert entry.table == {"kind": "ftsmc"} and "package defaults" in entry.gains
    res = compare(path, quick=True, controllers=["ftsmc"], out=tmp_path / "u", progress=False)
    doc = json.loads((tmp_path / "u" / "results.json").read_text())
    assert doc["controllers"] == [entry.to_dict()]
    md = res.report.read_text()
    assert "package defaults" in md and "without a tuned gain preset" in md


def test_quick_path_numbers_are_the_runs_numbers(quick):
    """A row of runs.parquet is the single-run result of its scenario (the batch runner's guarantee)."""
    from auvtrack.scenario import load_scenario
    from auvtrack.simulation.pipeline import simulate

    runs = pd.read_parquet(quick / "runs.parquet")
    suite = load_suite().quick_variant()
    entries = {e.label: e for e in resolve_controllers()}
    row = runs.iloc[len(runs) // 3]
    raw, ov, drawn = suite.scenario(entries[row.controller], row.task, row.tier, int(row.seed_index))
    res = simulate(load_scenario(raw, ov))
    assert res.status == row.status
    for m in ("rmse_x", "itae_z", "energy_tau_u", "tv_tau_r", "settle_5cm_y"):
        assert res.metrics[m] == row[m] or (math.isnan(res.metrics[m]) and math.isnan(row[m]))
    assert json.loads(row.draws) == pytest.approx(drawn)


def test_simd_back_end_compiles_its_lane_kernels_before_the_timed_runs(tiny, tmp_path, monkeypatch):
    """With ``backend="simd"`` the warm-up flies a full block of lanes per signature, so no lane kernel
    compiles inside the timed runs; the numbers are those of the thread back end."""
    from auvtrack.batch import runner as batch_mod

    timed = {"on": False, "compiled_while_timed": [], "warm": set(), "timed": set()}
    real = batch_mod._LaneGroup.compile

    def watch(self):
        before = len(self.module.run_lanes.signatures)
        real(self)
        timed["timed" if timed["on"] else "warm"].add(self.ps[0].key.name)
        if timed["on"] and len(self.module.run_lanes.signatures) > before:
            timed["compiled_while_timed"].append(self.ps[0].key.name)

    real_warm = runner.warm_runs

    def warm_then_time(*a, **k):
        out = real_warm(*a, **k)
        timed["on"] = True
        return out

    monkeypatch.setattr(batch_mod._LaneGroup, "compile", watch)
    monkeypatch.setattr(runner, "warm_runs", warm_then_time)
    a = compare(tiny, controllers=["ftsmc"], out=tmp_path / "simd", progress=False, backend="simd")
    assert timed["on"] and timed["compiled_while_timed"] == []
    assert timed["timed"] and timed["timed"] <= timed["warm"]  # every lane kernel the runs used was set up in the warm-up
    b = compare(tiny, controllers=["ftsmc"], out=tmp_path / "threads", progress=False, backend="threads")
    assert a.complete and b.complete
    pd.testing.assert_frame_equal(pd.read_parquet(tmp_path / "simd" / "runs.parquet"),
                                  pd.read_parquet(tmp_path / "threads" / "runs.parquet"))


def test_same_suite_same_seeds_identical_numbers(tiny, tmp_path):
    a = compare(tiny, out=tmp_path / "a", progress=False)
    b = compare(tiny, out=tmp_path / "b", progress=False, chunk_size=5, backend="serial")  # nor chunks, back end
    assert a.complete and b.complete
    assert _results(tmp_path / "a") == _results(tmp_path / "b")
    ra, rb = pd.read_parquet(tmp_path / "a" / "runs.parquet"), pd.read_parquet(tmp_path / "b" / "runs.parquet")
    pd.testing.assert_frame_equal(ra, rb)
    # every controller met the same conditions: seeds and draws do not depend on the controller
    per = ra.groupby(["tier", "task", "seed_index"])
    assert (per["seed"].nunique() == 1).all() and (per["draws"].nunique() == 1).all()
    # the start offsets' unit draws are shared by the tiers (scaled by each tier's half-width)
    d = ra.assign(lat=ra["draws"].map(lambda s: json.loads(s)["start.lateral"]))
    calm = d[d.tier == "calm"].set_index(["task", "seed_index", "controller"])["lat"]
    model = d[d.tier == "model"].set_index(["task", "seed_index", "controller"])["lat"]
    np.testing.assert_allclose(model.sort_index().to_numpy(), calm.sort_index().to_numpy() / 0.3, rtol=1e-12)


def test_interrupted_comparison_resumes_to_identical_numbers(tiny, tmp_path):
    ref = compare(tiny, out=tmp_path / "ref", progress=False, chunk_size=4)
    part = compare(tiny, out=tmp_path / "part", progress=False, chunk_size=4, max_chunks=2)
    assert not part.complete and part.execution.chunks_run == 2
    with pytest.raises(runner.CompareError, match="--resume"):
        compare(tiny, out=tmp_path / "part", progress=False, chunk_size=4)
    done = compare(tiny, out=tmp_path / "part", progress=False, chunk_size=4, resume=True)
    assert done.complete and done.execution.chunks_skipped == 2
    assert _results(tmp_path / "part") == _results(tmp_path / "ref")
    with pytest.raises(runner.CompareError, match="another comparison"):
        compare(tiny, out=tmp_path / "part", progress=False, chunk_size=4, controllers=["ftsmc"], resume=True)


def test_a_failing_controller_is_ranked_not_dropped(tiny, tmp_path):
    # poles near -1e4 rad/s: RK4 at dt = 2 ms is unstable (|lambda dt| = 20 > 2.8), every run diverges
    entries = resolve_controllers(["ftsmc"]) + [
        ControllerEntry("crash", {"kind": "pid", "kp": 1e8, "kd": 1e4, "ki": 0.0}, "PID far beyond RK4's stability")]
    res = compare(tiny, out=tmp_path / "f", progress=False, entries=entries)
    doc = json.loads((tmp_path / "f" / "results.json").read_text())
    board = [r["controller"] for r in doc["leaderboard"]]
    assert board == ["ftsmc", "crash"]
    crash = next(r for r in doc["pooled"] if r["controller"] == "crash")
    assert crash["failure_rate"] == 1.0 and crash["causes"] and crash["failure_ci"][0] > 0.5
    cells = [c for c in doc["cells"] if c["controller"] == "crash"]
    assert len(cells) == 4 and all(c["rmse"]["median"] is None for c in cells)  # inf in strict JSON
    assert "crash" in res.report.read_text()


def test_dask_scheduler_gives_the_local_numbers(tiny, tmp_path):
    from distributed import Client, LocalCluster

    local = compare(tiny, out=tmp_path / "local", progress=False, quick=True)
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=":0") as cluster, \
            Client(cluster) as client:
        dask = compare(tiny, out=tmp_path / "dask", progress=False, quick=True, client=client)
    assert local.complete and dask.complete
    pd.testing.assert_frame_equal(pd.read_parquet(tmp_path / "local" / "runs.parquet"),
                                  pd.read_parquet(tmp_path / "dask" / "runs.parquet"))


def test_plan_is_every_controller_task_tier_and_seed(tiny):
    suite = load_suite(tiny)
    entries = resolve_controllers()
    specs = runner.plan_runs(suite, entries)
    assert len(specs) == len(entries) * 2 * 2 * 3
    assert {(s.controller, s.task, s.tier, s.index) for s in specs} == {
        (e.label, k, t, i) for e in entries for k in suite.tasks for t in suite.tiers for i in range(3)}
    q = suite.quick_variant()
    assert q.seeds == 2 and q.duration("helix") == 1.0 and q.fingerprint() != suite.fingerprint()


@pytest.mark.parametrize("args, expect", [
    (["--suite", "nope"], "--suite: unknown suite 'nope'"),
    (["--controllers", "pid2"], "--controllers: unknown controller 'pid2'"),
    (["--plugin", "missing.py"], "--plugin: must be an existing .py file"),
    (["--workers", "0"], "--workers: must be an integer in [1, 256] (got 0)"),
    (["--workers", "100000"], "--workers: must be an integer in [1, 256] (got 100000)"),
    (["--backend", "nope"], "--backend: must be one of threads"),
])
def test_bad_options_exit_2_with_one_line(args, expect, tmp_path, capsys):
    assert main(["compare", "--out", str(tmp_path / "x"), "--quiet", *args]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err.strip()
    assert err.startswith("auvtrack: error: ") and expect in err and "\n" not in err


@pytest.mark.parametrize("old, new, expect", [
    ("seeds = 3", "seeds = 0", "seeds: must be >= 1"),
    ('[tiers.calm]', '[tiers.calm]\nbogus = 1', "tiers.calm.bogus: unknown key"),
    ('"uncertainty.M" = { dist = "uniform", low = -0.2, high = 0.2 }',
     '"uncertainty.M" = { dist = "uniform", low = -0.2, high = 5.0 }', "tiers.model.random.uncertainty.M"),
    ("duration = 2.0", "duration = -2.0", "tasks.line.duration: must be > 0"),
])
def test_invalid_suite_file_one_line(tmp_path, old, new, expect):
    path = tmp_path / "bad.toml"
    assert old in TINY
    path.write_text(TINY.replace(old, new, 1))
    with pytest.raises(SuiteError) as info:
        load_suite(path)
    assert expect in str(info.value) and "\n" not in str(info.value)


def test_shipped_suite_is_sized_for_its_failure_interval():
    """auv-track-v1: a ±5 % failure-rate interval per controller and tier, whatever the rate; a cell without
    failure bounded below 5 %."""
    suite = load_suite()
    h = suite.failure_halfwidths()
    assert h["tier"] <= suite.file.failure_halfwidth and h["zero_failures"] <= suite.file.failure_halfwidth
    assert set(suite.file.tiers) == {"ideal", "digital", "ocean", "model", "truth6"}
    assert set(suite.tasks) == {"helix", "circle", "lawnmower", "waypoints"}


def test_ctrl_c_keeps_the_finished_chunks_and_resume_finishes(tiny, tmp_path):
    import os
    import shlex
    import signal
    import subprocess
    import sys
    import time

    path = tmp_path / "long.toml"
    path.write_text(TINY.replace("seeds = 3", "seeds = 60").replace("duration = 3.0", "duration = 20.0"))
    out = tmp_path / "c"
    root = Path(__file__).resolve().parents[2]
    env = dict(os.environ, PYTHONPATH=str(root))
    p = subprocess.Popen([sys.executable, "-m", "auvtrack.cli", "compare", "--suite", str(path), "--out", str(out),
                          "--quiet"], env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 600
    while not runner.chunk_path(out, 0).exists() and p.poll() is None and time.monotonic() < deadline:
        time.sleep(0.05)
    p.send_signal(signal.SIGINT)
    _, err = p.communicate(timeout=600)
    assert p.returncode == 130, err
    assert "--resume" in err and "Traceback" not in err
    kept = sorted((out / "chunks").glob("chunk-*.parquet"))
    assert 1 <= len(kept) < 10 and not (out / "runs.parquet").exists()
    command = err.strip().splitlines()[-1].split("the finished chunks are kept: ", 1)[1]
    argv = shlex.split(command)  # the printed command, run verbatim
    assert argv[:2] == ["auvtrack", "compare"] and argv[-1] == "--resume"
    assert main(argv[1:]) == 0
    assert json.loads((out / "results.json").read_text())["timing"]["chunks_resumed"] == len(kept)
    runs = pd.read_parquet(out / "runs.parquet")
    assert sorted(runs["run"]) == list(range(len(resolve_controllers()) * 2 * 2 * 60))


def test_the_sizing_numbers_of_the_docs_are_the_suite_s():
    h = load_suite().failure_halfwidths()
    text = (Path(__file__).resolve().parents[2] / "docs" / "benchmark.md").read_text()
    assert f"{h['tier']:.4f}" in text and f"{h['zero_failures']:.3f}" in text and f"±{h['cell']:.3f}" in text


def test_a_plugin_enters_the_leaderboard_with_one_flag(tiny, tmp_path):
    plugin = Path(__file__).resolve().parents[2] / "examples" / "plugin_controller.py"
    out = tmp_path / "p"
    assert main(["compare", "--suite", str(tiny), "--quick", "--controllers", "ftsmc", "--plugin", str(plugin),
                 "--out", str(out), "--quiet"]) == 0
    doc = json.loads((out / "results.json").read_text())
    assert sorted(r["controller"] for r in doc["leaderboard"]) == ["ftsmc", "plugin_controller"]
    entry = next(c for c in doc["controllers"] if c["label"] == "plugin_controller")
    assert entry["table"] == {"kind": "plugin", "module": str(plugin)} and len(entry["digest"]) == 64
    runs = pd.read_parquet(out / "runs.parquet")
    mine = runs[runs["controller"] == "plugin_controller"]
    assert len(mine) == 2 * 2 * 2 and (mine["cause"] != "setup").all()
    assert "plugin_controller" in (out / "report.md").read_text()

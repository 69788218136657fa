"""Benchmark plumbing (what is reported, not how fast: speed lives in benchmarks/results.md)."""
import json

import pytest
from click.testing import CliRunner

from auvtrack.cli import cli
from auvtrack.perf.bench import bench_singles
from auvtrack.perf.sweep_bench import BREAKDOWN, bench_breakdown


def test_bench_singles_reports_each_controller_in_order():
    rows = bench_singles(("ftsmc", "fxtntsmc"), repeat=2, duration=0.05)
    assert [r["controller"] for r in rows] == ["ftsmc", "fxtntsmc"]
    for r in rows:
        assert r["status"] == "ok" and r["steps"] == 50 and r["repeat"] == 2
        assert 0 < r["min_us_per_step"] <= r["us_per_step"]


def test_breakdown_has_one_row_per_variant():
    rows = bench_breakdown(repeat=1, duration=0.02)
    assert [r["variant"] for r in rows] == [label for label, _ in BREAKDOWN]
    assert all(r["cpu_us_per_step"] > 0 for r in rows)


def test_cli_bench_prints_one_json_line_per_controller():
    out = CliRunner().invoke(cli, ["bench", "--controller", "ftsmc", "--repeat", "1", "--duration", "0.02"])
    assert out.exit_code == 0, out.output
    lines = [json.loads(x) for x in out.output.strip().splitlines()]
    assert [x["controller"] for x in lines] == ["ftsmc"]


def test_results_name_the_vector_math_back_end(tmp_path):
    """Results depend on the vector-math back end (auvtrack.jit.vecmath), so the record says which."""
    from pathlib import Path

    from auvtrack.jit import vecmath as _vecmath
    from auvtrack.perf.bench import machine
    from auvtrack.perf.sweep_bench import write_results

    m = machine()
    assert m["vector_math"] == _vecmath.BACKEND
    doc = json.loads(Path("benchmarks/results.json").read_text())  # a real record, re-written with this machine
    doc.pop("date")
    doc["machine"] = m
    write_results(doc, tmp_path)
    assert f"vector math {_vecmath.BACKEND} " in (tmp_path / "results.md").read_text()
    assert json.loads((tmp_path / "results.json").read_text())["machine"]["vector_math"] == _vecmath.BACKEND


def test_batch_rows_cover_every_controller_and_back_end():
    from auvtrack.perf.sweep_bench import bench_batch

    rows = bench_batch(repeat=2, runs=3, duration=0.02)
    assert [(r["controller"], r["backend"]) for r in rows] == [
        (k, b) for k in ("ftsmc", "fxtntsmc") for b in ("serial", "threads", "simd", "prange")]
    for r in rows:
        assert r["runs"] == 3 and r["repeat"] == 2 and 0 < r["runs_per_s"] <= r["max_runs_per_s"]


def test_batch_efficiency_is_throughput_relative_to_single_runs():
    """A core running 10 s runs (10^4 steps) of 1 us per step does 100 runs/s: efficiency 1."""
    from auvtrack.perf.sweep_bench import batch_efficiency

    row = {"runs_per_s": 200.0, "cores": 2, "run_seconds": 10.0}
    assert batch_efficiency(row, us_per_step=1.0) == pytest.approx(1.0)
    assert batch_efficiency({**row, "runs_per_s": 500.0}, us_per_step=1.0) == pytest.approx(2.5)


def test_simd_over_serial_compares_the_same_runs_and_cpu_efficiency_divides_by_the_single_run():
    """8 ms per run serial and 3.2 ms in lanes: 2.5; a single run of 10^4 steps at 0.9 CPU us per step
    (9 ms) over 3.6 ms per batch run: CPU efficiency 2.5."""
    from auvtrack.perf.sweep_bench import batch_cpu_efficiency, simd_over_serial

    batch = {("fxtntsmc", "serial"): {"cpu_ms_per_run": 8.0}, ("fxtntsmc", "simd"): {"cpu_ms_per_run": 3.2}}
    assert simd_over_serial(batch, "fxtntsmc") == pytest.approx(2.5)
    assert batch_cpu_efficiency({"run_seconds": 10.0, "cpu_ms_per_run": 3.6}, cpu_us_per_step=0.9) == pytest.approx(2.5)


def test_warmup_simd_flag_reaches_the_lane_kernel_compile(monkeypatch, capsys):
    """``auvtrack warmup --simd`` asks for the SIMD batch kernels too; without the flag it does not."""
    import json

    from auvtrack.cli import main
    from auvtrack.engine import kernels

    asked = []
    monkeypatch.setattr(kernels, "warmup",
                        lambda keys, progress=False, lanes=False, notice=None: asked.append(lanes) or [])
    for extra in (["--simd"], []):
        assert main(["warmup", "--controller", "pid", "--plant", "5dof", *extra]) == 0
        assert json.loads(capsys.readouterr().out.strip().splitlines()[-1])["kernels"] == ["pid on 5dof"]
    assert asked == [True, False]


def test_cold_start_compiles_only_the_kernel_it_needs():
    """The cold run is timed in a new process with an empty cache; it compiles the one kernel of the run."""
    from auvtrack.perf.sweep_bench import bench_cold_start

    doc = bench_cold_start(duration=0.01)
    assert doc["kernels_compiled"] == ["k_fxtntsmc__five_dof"]
    assert 0 < doc["compile_seconds"] < doc["seconds"]


@pytest.mark.slow
@pytest.mark.timeout(2700)  # compiles every kernel from an empty cache: ~15 min on a loaded 2-core machine
def test_bench_all_leaves_the_working_tree_unchanged(tmp_path):
    """`auvtrack bench --all` run from a clone writes to a user folder, and its Dask shutdown is quiet."""
    import os
    import subprocess
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parents[2]
    skip = {".git", "__pycache__", ".pytest_cache", ".hypothesis"}

    def snapshot():
        return {p.relative_to(root).as_posix(): (p.stat().st_size, p.stat().st_mtime_ns)
                for p in root.rglob("*") if p.is_file() and not skip & set(p.relative_to(root).parts)}

    before = snapshot()
    env = {**os.environ, "XDG_DATA_HOME": str(tmp_path / "data"), "PYTHONPATH": str(root)}
    p = subprocess.run([sys.executable, "-m", "auvtrack.cli", "bench", "--all", "--repeat", "1"], cwd=root, env=env,
                       capture_output=True, text=True, timeout=2600)
    assert p.returncode == 0, p.stderr[-3000:]
    assert snapshot() == before  # nothing written, created or touched in the repository
    (folder,) = (tmp_path / "data" / "auvtrack" / "bench").iterdir()
    doc = json.loads((folder / "results.json").read_text())
    assert {"single", "batch", "sweep"} <= set(doc) and (folder / "results.md").exists()
    assert f"written: {folder / 'results.json'}" in p.stdout
    assert "Traceback" not in p.stderr and "heartbeat" not in p.stderr, p.stderr[-3000:]


def test_warmup_covers_every_builtin_controller_on_every_plant_it_runs_on():
    """Warmup's default pairs come from the capabilities: each built-in controller on every built-in
    plant that accepts what it commands (the actuator-commanding one on the 6-DOF plant only), one
    kernel per pair whatever the preset."""
    from auvtrack.control import BUILTIN_NAMES, CONTROLLERS
    from auvtrack.plant import BUILTIN_NAMES as PLANT_NAMES
    from auvtrack.plant import PLANTS
    from auvtrack.simulation.compiling import builtin_pairs, kernel_keys

    pairs = builtin_pairs()
    assert {c for c, _ in pairs} == set(BUILTIN_NAMES)
    for c in BUILTIN_NAMES:
        plants = {p for k, p in pairs if k == c}
        assert plants == {p for p in PLANT_NAMES if set(CONTROLLERS[c].commands) & set(PLANTS[p].accepts)}
    assert {p for k, p in pairs if k == "open_loop_actuators"} == {"6dof"}
    assert len(kernel_keys(pairs)) == len(pairs)
    assert builtin_pairs(("ftsmc",), ("5dof",)) == [("ftsmc", "5dof")]

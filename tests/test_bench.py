"""Benchmark plumbing (what is reported, not how fast: speed lives in benchmarks/results.md)."""
import json

from click.testing import CliRunner

from auvtrack.cli import cli
from auvtrack.studies.bench import bench_singles
from auvtrack.studies.sweep_bench import BREAKDOWN, bench_breakdown


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

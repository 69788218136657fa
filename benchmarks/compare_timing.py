"""Wall time of ``auvtrack compare`` on this machine: ``--quick`` and the default suite, after compilation.

Usage: ``python benchmarks/compare_timing.py [--suite NAME] [--skip-default | --default-from DIR] [--workers N]
[--out DIR] [--backend B ...]``
(another suite than the default writes ``compare_timing-<suite>.{json,md}``).

A first ``--quick`` comparison compiles every kernel the disk cache lacks, or loads it, and is timed as
"cold" (its compile/load column says which happened); then, in the
same process, ``--quick`` and the default suite run again with everything compiled.  The numbers
written to ``benchmarks/compare_timing.{json,md}`` are the reports' own timing blocks
(``results.json`` -> ``timing``: runs, compilation, analysis, load averages) plus the wall time of
each ``compare`` call, for each batch back end asked for (``--backend``, default ``threads``; with
``simd`` the cold row also compiles the lane kernels the disk cache lacks).  The machine may be
shared: the load averages are part of the result.  ``--default-from DIR`` takes the default row
from a finished, not resumed, default comparison in ``DIR`` (its own timing block, the same numbers;
its wall-time column is then empty) instead of running it again.
Never used as a timed unit test.
"""
from __future__ import annotations

import argparse
import datetime as dt
import json
import os
import platform
import tempfile
import time
from pathlib import Path

import pandas as pd

from auvtrack import __version__
from auvtrack.benchmark.compare import compare
from auvtrack.benchmark.suite import DEFAULT_SUITE

HERE = Path(__file__).resolve().parent
TARGETS = {"quick (cold)": None, "quick": 120.0, "default": 900.0}  # s after compilation, issue 16


def _one(label: str, out: Path, quick: bool, workers: int | None, backend: str = "threads",
         suite: str = DEFAULT_SUITE) -> dict:
    t0 = time.perf_counter()
    res = compare(suite=suite, quick=quick, out=out, workers=workers, progress=True, backend=backend)
    return _row(label, out, time.perf_counter() - t0, res.complete)


def _row(label: str, out: Path, wall: float | None, complete: bool) -> dict:
    """The timing row of the comparison in ``out`` (its ``results.json`` -> ``timing``); ``wall``: the call's wall time."""
    doc = json.loads((out / "results.json").read_text())
    timing = doc["timing"]
    after = timing["runs_seconds"] + timing["analysis_seconds"]
    target = TARGETS[label]
    label = f"{label}, `{timing['batch_backend']}`"
    runs = pd.read_parquet(out / "runs.parquet", columns=["task", "steps"])
    dt_ = float(doc["suite"]["file"]["base"].get("sim.dt", 0.002))
    full = runs["task"].map(lambda t: round(doc["suite"]["durations"][t] / dt_)).sum()
    return {"variant": label, "out": _folder(out), "runs": timing["runs"], "seeds": doc["suite"]["seeds"],
            "controllers": len(doc["controllers"]), "tiers": len(doc["suite"]["file"]["tiers"]) -
            len(doc["suite"]["skipped_tiers"]), "wall_seconds": wall, "after_compilation_seconds": after,
            "target_seconds": target, "meets_target": None if target is None else after <= target,
            "steps": int(runs["steps"].sum()), "steps_full": int(full), "source_hash": doc["source_hash"],
            "complete": complete, "measured_in": "this call" if wall is not None else "--default-from", **timing}


def _folder(out: Path) -> str:
    """The comparison's folder as its last two parts (``simd/quick``): a record, not a path on this machine."""
    return "/".join(Path(out).parts[-2:])


def _existing_default(folder: Path, suite: str) -> dict:
    """The default row from a finished comparison of ``suite`` in ``folder`` (``--default-from``)."""
    doc = json.loads((folder / "results.json").read_text())
    if doc["suite"]["quick"] or doc["suite"]["name"] != Path(suite).stem:
        raise SystemExit(f"--default-from: {folder} holds {doc['suite']['name']}"
                         f"{' --quick' if doc['suite']['quick'] else ''}, not the default {suite}")
    if doc["timing"]["chunks_resumed"]:
        raise SystemExit(f"--default-from: {folder} was resumed ({doc['timing']['chunks_resumed']} chunks): "
                         "its runs time is partial")
    return _row("default", folder, None, True)


def _cpu() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.system()


def _markdown(doc: dict) -> str:
    lines = ["# `auvtrack compare` wall time", "",
             f"Written by `python benchmarks/compare_timing.py` at {doc['measured']} on {doc['machine']} "
             f"({doc['cpu_count']} cores, a shared machine: see the load averages), auvtrack {doc['version']}, "
             f"sources {doc['rows'][0]['source_hash'][:12]}.  \"After compilation\" = runs + statistics and "
             "report (the `timing` block of each report's `results.json`); the cold row also compiles or loads "
             "the kernels.", "",
             "| variant | runs | runs (s) | compile/load (s) | statistics + report (s) | after compilation (s) "
             "| target (s) | meets | RK4 steps flown / at full durations | load avg at start | load avg at end |",
             "|" + "---|" * 11]
    for r in doc["rows"]:
        tgt = "" if r["target_seconds"] is None else f"{r['target_seconds']:.0f}"
        ok = "" if r["meets_target"] is None else ("yes" if r["meets_target"] else "**no**")
        la = "/".join(f"{x:.2f}" for x in r["load_average_start"] or [])
        lb = "/".join(f"{x:.2f}" for x in r["load_average_end"] or [])
        lines.append(f"| {r['variant']} | {r['runs']} | {r['runs_seconds']:.1f} | {r['compile_seconds']:.1f} | "
                     f"{r['analysis_seconds']:.1f} | {r['after_compilation_seconds']:.1f} | {tgt} | {ok} | "
                     f"{r['steps'] / r['steps_full']:.2f} | {la} | "
                     f"{lb} |")
    head = doc["rows"][0]["source_hash"]
    notes = [f"* {r['variant']}: " + ", ".join(
        ([f"read from the finished comparison `{r['out']}` (`--default-from`), not run by this call"]
         if r.get("measured_in") == "--default-from" else [])
        + ([f"sources {r['source_hash'][:12]}"] if r["source_hash"] != head else []))
        for r in doc["rows"] if r.get("measured_in") == "--default-from" or r["source_hash"] != head]
    return "\n".join(lines + ([""] + notes if notes else [])) + "\n"


def main() -> None:
    """Run the comparisons and write ``compare_timing.json`` and ``compare_timing.md`` next to this script."""
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--skip-default", action="store_true", help="only the --quick rows")
    ap.add_argument("--default-from", type=Path, default=None,
                    help="the default row from this finished comparison's results.json instead of a new run")
    ap.add_argument("--workers", type=int, default=None, help="local threads (default: every core)")
    ap.add_argument("--out", type=Path, default=None, help="folder of the comparisons (default: a new temp dir)")
    ap.add_argument("--backend", action="append", default=None,
                    help="batch back end of the comparisons (repeatable; default: threads)")
    ap.add_argument("--suite", default=DEFAULT_SUITE, help="suite to time (default: the default suite)")
    args = ap.parse_args()
    root = args.out or Path(tempfile.mkdtemp(prefix="auvtrack-compare-timing-"))
    rows = []
    for be in args.backend or ["threads"]:
        rows += [_one("quick (cold)", root / be / "quick-cold", True, args.workers, be, args.suite),
                 _one("quick", root / be / "quick", True, args.workers, be, args.suite)]
        if not (args.skip_default or args.default_from):
            rows.append(_one("default", root / be / "default", False, args.workers, be, args.suite))
    if args.default_from and not args.skip_default:
        rows.append(_existing_default(args.default_from, args.suite))
    doc = {"measured": dt.datetime.now(dt.timezone.utc).isoformat(timespec="minutes"),
           "machine": f"{platform.machine()} / {_cpu()} / Python "
                      f"{platform.python_version()}", "cpu_count": os.cpu_count(), "version": __version__,
           "rows": rows}
    stem = "compare_timing" if args.suite == DEFAULT_SUITE else f"compare_timing-{Path(args.suite).stem}"
    doc["suite"] = args.suite
    (HERE / f"{stem}.json").write_text(json.dumps(doc, indent=2) + "\n")
    (HERE / f"{stem}.md").write_text(_markdown(doc))
    print(_markdown(doc))


if __name__ == "__main__":
    main()

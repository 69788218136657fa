"""Paired A/B timing of two source trees of auvtrack (for judging a speed change).

Usage::

    git worktree add /tmp/base main          # the tree to compare against
    python benchmarks/ab.py /tmp/base .       # [--runs 150] [--simd N] [--set key=value ...]

Two long-lived worker processes, one per tree (``PYTHONPATH`` set to it, its own Numba cache),
time single metrics-only runs of the Section 4 scenario (10 s by default) in alternation, so
each pair of runs is milliseconds apart. The report is the median of the per-pair ratios
B / A and its quartiles. On this shared machine, whose speed drifts by up to 2x for seconds at a
time, unpaired medians or minima of separate sessions differ by more than most changes do; paired
ratios repeat to about 1 %. It also says whether the two trees give bit-identical metrics.
The workers run in a scratch folder: Python puts the current folder first on ``sys.path``, so a
worker started inside a checkout would import that checkout whatever ``PYTHONPATH`` says.
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

WORKER = r"""
import json, sys, time
from auvtrack.scenario import load_scenario, paper_scenario_path
try:
    from auvtrack.simulation.pipeline import prepare
    from auvtrack.batch.runner import run_batch, run_metrics
except ImportError:  # a tree of the 0.1 layout
    from auvtrack.simulation.api import prepare
    from auvtrack.runner.batch import run_batch, run_metrics
import auvtrack
overrides, batch = json.loads(sys.argv[1]), int(sys.argv[2])
print(json.dumps(auvtrack.__file__), flush=True)
if batch:
    preps = [prepare(load_scenario(paper_scenario_path(), {**overrides, "seed": i})) for i in range(batch)]
    work = lambda: run_batch(preps, backend="simd", workers=1)
    first = work()[0].metrics
else:
    prep = prepare(load_scenario(paper_scenario_path(), overrides))
    work = lambda: run_metrics(prep)
    first = work().metrics  # compiles or loads the cache
print(json.dumps(first), flush=True)
for _ in sys.stdin:
    t0 = time.thread_time()
    work()
    print(time.thread_time() - t0, flush=True)
"""


def _worker(root: Path, overrides: dict, batch: int) -> subprocess.Popen:
    base = Path(os.environ.get("AUVTRACK_AB_CACHE", Path(tempfile.gettempdir()) / "auvtrack-ab"))
    cache = base / str(root.resolve()).strip("/").replace("/", "_")
    env = {**os.environ, "PYTHONPATH": str(root.resolve()), "AUVTRACK_CACHE_DIR": str(cache)}
    return subprocess.Popen([sys.executable, "-c", WORKER, json.dumps(overrides), str(batch)], stdin=subprocess.PIPE,
                            stdout=subprocess.PIPE, text=True, env=env, cwd=tempfile.gettempdir())


def main() -> None:
    """Compare two trees and print their per-run times and the paired ratio."""
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("a", type=Path, help="tree A (the base)")
    ap.add_argument("b", type=Path, help="tree B (the change)")
    ap.add_argument("--runs", type=int, default=150, help="timed runs per tree (default 150)")
    ap.add_argument("--simd", type=int, default=0, metavar="N",
                    help="time a SIMD batch of N runs (seeds 0 .. N-1, one thread) instead of one run")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="scenario override (JSON value), e.g. --set controller.kind='\"ftsmc\"'")
    args = ap.parse_args()
    overrides = {"sim.duration": 10.0}
    for item in args.set:
        key, _, value = item.partition("=")
        overrides[key] = json.loads(value)
    procs = [_worker(args.a, overrides, args.simd), _worker(args.b, overrides, args.simd)]
    files = [json.loads(p.stdout.readline()) for p in procs]  # which package each worker imported
    if files[0] == files[1]:
        raise SystemExit(f"both workers imported {files[0]}: compare two different trees")
    metrics = [json.loads(p.stdout.readline()) for p in procs]
    times: list[list[float]] = [[], []]
    for i in range(args.runs):
        for j in ((0, 1) if i % 2 == 0 else (1, 0)):  # alternate who goes first
            procs[j].stdin.write("go\n")
            procs[j].stdin.flush()
            times[j].append(float(procs[j].stdout.readline()))
    for p in procs:
        p.stdin.close()
        p.wait()
    for name, t in zip(files, times):
        t = sorted(1e3 * x for x in t)
        what = f"batch of {args.simd}" if args.simd else "run"
        print(f"{name}: min {t[0]:.2f}  p10 {t[len(t) // 10]:.2f}  median {statistics.median(t):.2f} ms per {what}")
    ratio = sorted(b / a for a, b in zip(*times))
    n = len(ratio)
    common = sorted(set(metrics[0]) & set(metrics[1]))
    differ = [k for k in common if metrics[0][k] != metrics[1][k]]
    only = [sorted(set(m) - set(common)) for m in metrics]
    print(f"load average {os.getloadavg()[0]:.2f}")
    print(f"B / A: median {statistics.median(ratio):.3f} (quartiles {ratio[n // 4]:.3f}, {ratio[3 * n // 4]:.3f}); "
          f"metrics bit-identical: {not differ and not any(only)}"
          + (f"; the {len(common)} common metrics identical" if not differ else f"; differing: {differ}")
          + "".join(f"; only in {t}: {o}" for t, o in zip("AB", only) if o))


if __name__ == "__main__":
    main()

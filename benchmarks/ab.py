"""Paired A/B timing of two source trees of auvtrack (for judging a speed change).

Usage::

    git worktree add /tmp/base main          # the tree to compare against
    python benchmarks/ab.py /tmp/base .       # [--runs 150] [--simd N] [--set key=value ...]
    python benchmarks/ab.py . . --set-b metrics.path=false   # one tree, two settings


Two long-lived worker processes, one per tree (``PYTHONPATH`` set to it, its own Numba cache),
time single metrics-only runs of the Section 4 scenario (10 s by default), or SIMD batches of N
runs, in alternation (who goes first alternates too), so each pair of runs is milliseconds apart.
The time of one run is the CPU time of the worker process over all its threads
(``time.process_time``): the SIMD back end runs its blocks in a worker thread, whose time the
calling thread's own clock does not see.  The report is the median of the per-pair ratios B / A
and its quartiles.  On this shared machine, whose speed drifts by up to 2x for seconds at a time,
unpaired medians or minima of separate sessions differ by more than most changes do; paired
ratios repeat to about 1 %.  It also says whether the two trees give bit-identical metrics.

The figures are printed and written to a Markdown file (``--out``, default ``benchmarks/ab.md``):
one section per configuration (controller, plant, duration, batch size, overrides), replaced when
that configuration is measured again, with the date, both trees' commits, the load average at the
start and the end, the number of pairs, the medians and quartiles of each tree's times and of the
paired ratio.  ``--set-a`` / ``--set-b`` apply an override to one tree only: the same tree twice
with different settings times what a setting costs (e.g. ``metrics.path = false``).

The workers run in a scratch folder: Python puts the current folder first on ``sys.path``, so a
worker started inside a checkout would import that checkout whatever ``PYTHONPATH`` says.
"""
from __future__ import annotations

import argparse
import datetime
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent

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
    t0 = time.process_time()
    work()
    print(time.process_time() - t0, flush=True)
"""


def _worker(root: Path, overrides: dict, batch: int) -> subprocess.Popen:
    """A worker timing runs of ``root`` with ``overrides`` (Numba cache per tree)."""
    base = Path(os.environ.get("AUVTRACK_AB_CACHE", Path(tempfile.gettempdir()) / "auvtrack-ab"))
    cache = base / str(root.resolve()).strip("/").replace("/", "_")
    env = {**os.environ, "PYTHONPATH": str(root.resolve()), "AUVTRACK_CACHE_DIR": str(cache)}
    return subprocess.Popen([sys.executable, "-c", WORKER, json.dumps(overrides), str(batch)], stdin=subprocess.PIPE,
                            stdout=subprocess.PIPE, text=True, env=env, cwd=tempfile.gettempdir())


def commit_of(root: Path) -> str:
    """The short commit of a git tree, with ``+ uncommitted changes`` when its tracked files differ from it.

    Parameters
    ----------
    root : pathlib.Path
        A checkout (or worktree) of the repository.

    Returns
    -------
    str
        E.g. ``"45d52f0"``; ``"unknown"`` outside git.
    """
    try:
        head = subprocess.run(["git", "-C", str(root), "rev-parse", "--short", "HEAD"], capture_output=True,
                              text=True, check=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", str(root), "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"
    return head + (" + uncommitted changes" if dirty else "")


def quartiles(values: list[float]) -> tuple[float, float, float]:
    """(first quartile, median, third quartile) of a sample (``statistics.quantiles``, exclusive method).

    Parameters
    ----------
    values : list of float
        At least two values.

    Returns
    -------
    tuple of 3 float
    """
    q1, q2, q3 = statistics.quantiles(values, n=4)
    return q1, q2, q3


def measure(a: Path, b: Path, overrides: tuple[dict, dict], batch: int, runs: int) -> dict:
    """Time ``runs`` interleaved pairs of runs (or SIMD batches of ``batch`` runs) of trees ``a`` and ``b``.

    Parameters
    ----------
    a, b : pathlib.Path
        The two trees (A the base, B the change).
    overrides : tuple of 2 dict
        Scenario overrides (dotted keys) applied to the Section 4 scenario, for A and for B.
    batch : int
        0 for single metrics-only runs, else the size of the SIMD batch timed.
    runs : int
        Number of pairs.

    Returns
    -------
    dict
        ``times`` (two lists of seconds), ``ratio`` (the per-pair ratios B / A), ``load`` (1-minute
        load average at the start and the end), ``metrics_note`` and ``files``.
    """
    load0 = os.getloadavg()[0]
    procs = [_worker(a, overrides[0], batch), _worker(b, overrides[1], batch)]
    files = [json.loads(p.stdout.readline()) for p in procs]  # which package each worker imported
    if files[0] == files[1] and overrides[0] == overrides[1]:
        raise SystemExit(f"both workers imported {files[0]} with the same settings: compare two different trees "
                         "or give one of them --set-a / --set-b")
    metrics = [json.loads(p.stdout.readline()) for p in procs]
    times: list[list[float]] = [[], []]
    for i in range(runs):
        for j in ((0, 1) if i % 2 == 0 else (1, 0)):  # alternate who goes first
            procs[j].stdin.write("go\n")
            procs[j].stdin.flush()
            times[j].append(float(procs[j].stdout.readline()))
    for p in procs:
        p.stdin.close()
        p.wait()
    return {"times": times, "ratio": [y / x for x, y in zip(*times)], "load": (load0, os.getloadavg()[0]),
            "metrics_note": metrics_note(*metrics), "files": files}


def metrics_note(a: dict, b: dict) -> str:
    """What the two trees' metrics have in common: a sentence for the report, counted from them.

    Parameters
    ----------
    a, b : dict
        The metrics of tree A's and tree B's first run (name -> value).

    Returns
    -------
    str
        E.g. ``"the 33 metrics both trees return are bit-identical; only in B: xtrack_rmse"``; a
        metric NaN in one tree only (a metric that setting switches off) is counted apart.
    """
    common = sorted(set(a) & set(b))
    differ = [k for k in common if not _same(a[k], b[k])]
    nan = {t: [k for k in differ if m[k] != m[k]] for t, m in zip("AB", (a, b))}
    other = [k for k in differ if k not in nan["A"] + nan["B"]]
    same = len(common) - len(differ)
    if not differ:
        note = f"the {len(common)} metrics both trees return are bit-identical"
    else:
        note = f"of the {len(common)} metrics both trees return, {same} are bit-identical"
        note += "".join(f", {len(v)} NaN in {t} only ({', '.join(v)})" for t, v in nan.items() if v)
        note += f", {len(other)} differ ({', '.join(other)})" if other else ""
    only = [sorted(set(m) - set(common)) for m in (a, b)]
    return note + "".join(f"; only in {t}: {', '.join(o)}" for t, o in zip("AB", only) if o)


def _same(x, y) -> bool:
    """Equal, NaN equal to NaN (JSON carries NaN as NaN)."""
    return x == y or (x != x and y != y)


def config_key(overrides: dict, batch: int, per_tree: tuple[dict, dict] = ({}, {}), one_tree: bool = False) -> str:
    """A short name of what was timed, e.g. ``fxtntsmc 10 s, single run``.

    ``overrides`` are those of both trees, ``per_tree`` those of A only and of B only; ``one_tree``
    when A and B are the same tree (what a setting costs, not a change of the code).
    """
    kind = overrides.get("controller.kind", "fxtntsmc (scenario)")
    rest = {k: v for k, v in overrides.items() if k not in ("controller.kind", "sim.duration")}
    what = f"SIMD batch of {batch}" if batch else "single run"
    extra = "".join(f", {k}={json.dumps(v)}" for k, v in sorted(rest.items()))
    extra += "".join(f", {t}: {k}={json.dumps(v)}" for t, o in zip("AB", per_tree) for k, v in sorted(o.items()))
    return f"{kind}, {overrides.get('sim.duration')} s, {what}{extra}" + (", one tree" if one_tree else "")


def section(key: str, res: dict, commits: tuple[str, str], runs: int) -> str:
    """The Markdown section of one measurement."""
    unit = "batch" if "SIMD" in key else "run"
    rows = []
    for name, commit, t in zip("AB", commits, res["times"]):
        q1, q2, q3 = quartiles([1e3 * x for x in t])
        rows.append(f"| {name} | {commit} | {q2:.2f} | {q1:.2f} | {q3:.2f} |")
    r1, r2, r3 = quartiles(res["ratio"])
    now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    return "\n".join([
        f"<!-- ab: {key} -->",
        f"### {key}",
        "",
        f"{now}; {runs} interleaved pairs; 1-minute load average {res['load'][0]:.2f} at the start, "
        f"{res['load'][1]:.2f} at the end (2 cores, shared); CPU time per {unit} of the worker process.",
        "",
        f"| tree | commit | median (ms per {unit}) | first quartile | third quartile |",
        "|---|---|---|---|---|",
        *rows,
        "",
        f"Paired ratio B / A: median **{r2:.3f}**, quartiles {r1:.3f} and {r3:.3f}. "
        f"Metrics: {res['metrics_note']}.",
        f"<!-- /ab: {key} -->",
    ])


def write_section(path: Path, key: str, text: str) -> None:
    """Put ``text`` in ``path``, replacing the section of the same ``key`` (or appending it)."""
    head = ("# Paired A/B timings (`benchmarks/ab.py`)\n\nWritten by `python benchmarks/ab.py A B`; one section per "
            "configuration, the latest measurement of each. A is the base tree, B the change; in a section marked "
            "\"one tree\", A and B are the same tree and B differs only by the setting named (what that setting "
            "costs).\n")
    old = path.read_text() if path.exists() else head
    pattern = re.compile(rf"<!-- ab: {re.escape(key)} -->.*?<!-- /ab: {re.escape(key)} -->", re.S)
    new = pattern.sub(lambda _m: text, old) if pattern.search(old) else old.rstrip("\n") + "\n\n" + text
    path.write_text(new.rstrip("\n") + "\n")


def parse_overrides(items: list[str]) -> dict:
    """``KEY=VALUE`` strings (VALUE in JSON) -> {key: value}.

    Parameters
    ----------
    items : list of str
        E.g. ``["metrics.path=false"]``.

    Returns
    -------
    dict
    """
    out = {}
    for item in items:
        key, _, value = item.partition("=")
        out[key] = json.loads(value)
    return out


def main() -> None:
    """Compare two trees: print their per-run times and the paired ratio, and record them (``--out``)."""
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("a", type=Path, help="tree A (the base)")
    ap.add_argument("b", type=Path, help="tree B (the change)")
    ap.add_argument("--runs", type=int, default=150, help="timed pairs (default 150)")
    ap.add_argument("--simd", type=int, default=0, metavar="N",
                    help="time a SIMD batch of N runs (seeds 0 .. N-1, one thread) instead of one run")
    ap.add_argument("--duration", type=float, default=10.0, help="simulated seconds (default 10)")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="scenario override (JSON value), e.g. --set controller.kind='\"ftsmc\"'")
    ap.add_argument("--set-a", action="append", default=[], metavar="KEY=VALUE",
                    help="scenario override for tree A only")
    ap.add_argument("--set-b", action="append", default=[], metavar="KEY=VALUE",
                    help="scenario override for tree B only (e.g. the same tree with metrics.path=false)")
    ap.add_argument("--out", type=Path, default=HERE / "ab.md", help="Markdown record (default benchmarks/ab.md)")
    args = ap.parse_args()
    if args.runs < 4:
        raise SystemExit("--runs: must be >= 4 (quartiles of the paired ratio)")
    overrides = {"sim.duration": args.duration, **parse_overrides(args.set)}
    per_tree = (parse_overrides(args.set_a), parse_overrides(args.set_b))
    res = measure(args.a, args.b, ({**overrides, **per_tree[0]}, {**overrides, **per_tree[1]}), args.simd, args.runs)
    what = f"batch of {args.simd}" if args.simd else "run"
    for name, t in zip(res["files"], res["times"]):
        q1, q2, q3 = quartiles([1e3 * x for x in t])
        print(f"{name}: median {q2:.2f} (quartiles {q1:.2f}, {q3:.2f}) ms per {what}")
    r1, r2, r3 = quartiles(res["ratio"])
    print(f"load average {res['load'][0]:.2f} -> {res['load'][1]:.2f}")
    print(f"B / A: median {r2:.3f} (quartiles {r1:.3f}, {r3:.3f}); metrics: {res['metrics_note']}")
    key = config_key(overrides, args.simd, per_tree, one_tree=args.a.resolve() == args.b.resolve())
    write_section(args.out, key, section(key, res, (commit_of(args.a), commit_of(args.b)), args.runs))
    print(f"recorded in {args.out}")


if __name__ == "__main__":
    main()

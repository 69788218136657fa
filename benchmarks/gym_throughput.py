"""Throughput of the vector environment: env steps/s at N = 1, 64, 1024, and the cost of a reset.

Usage::

    python benchmarks/gym_throughput.py                   # writes benchmarks/gym_throughput.json
    python benchmarks/gym_throughput.py --sizes 1,64 --repeat 3 --out /tmp/g.json

The step rows are :func:`auvtrack.perf.gym_bench.bench_gym` (``auvtrack bench --gym``): one suite
cell (auv-track-v2, lawnmower, design tier: the 5-DOF REMUS 100), 10 RK4 sub-steps per env step,
random actions drawn before timing, medians over ``--repeat`` timings of ``--steps`` env steps, and
the ratio of the env's RK4 steps/s to the batch runner's on the same episodes.  The reset rows
time :meth:`~auvtrack.gym.vector.TrackVectorEnv.reset` of N envs on seed indices not seen before
(``cold``: every episode prepared) and on the same indices again (``warm``: the prepared rows
kept), medians over ``--repeat``.  ``reset_paired`` alternates the set-up before the plug-in probe
was cached and now in one process; ``paired_against_revision`` alternates fresh processes running the
code of ``--against`` (default the branch point, 7de3f7a) and this tree on a cold reset and on an
episode loop (episodes of 10 env steps, autoreset preparing a new seed index per episode): medians
and the median paired ratio.  The load average is recorded before and after: on a shared machine
the numbers move with it.  The issue's target is 300 000 env steps/s at N = 1024.
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent


def reset_rows(sizes: tuple[int, ...], repeat: int, suite: str = "auv-track-v2", task: str = "lawnmower",
               tier: str = "design") -> list[dict]:
    """Seconds per reset of N envs, on new seed indices (cold) and on the same ones again (warm).

    Parameters
    ----------
    sizes : tuple of int
        Numbers of environments N.
    repeat : int
        Timings per N (median reported).
    suite, task, tier : str, optional
        The cell.

    Returns
    -------
    list of dict
        One row per N: ``cold_s``, ``warm_s`` and the per-env cold time in ms.
    """
    from auvtrack.gym.vector import TrackVectorEnv

    rows = []
    for n in sizes:
        venv = TrackVectorEnv(n, suite, task, tier)
        venv.reset(seed=10**6)  # compile or load, and the cell's one-off set-up
        cold, warm = [], []
        for r in range(repeat):
            venv = TrackVectorEnv(n, suite, task, tier)
            seed = 10**7 * (r + 1)
            t0 = time.perf_counter()
            venv.reset(seed=seed)
            cold.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            venv.reset(seed=seed)
            warm.append(time.perf_counter() - t0)
        rows.append({"num_envs": n, "cold_s": round(statistics.median(cold), 4),
                     "cold_ms_per_env": round(1e3 * statistics.median(cold) / n, 3),
                     "warm_s": round(statistics.median(warm), 5), "repeat": repeat})
    return rows


class _Forgetful(dict):
    """A probe cache that keeps nothing: the set-up before the probe was cached (every episode recompiled it)."""

    def __setitem__(self, key, value) -> None:
        pass


def reset_paired(n: int, repeat: int, suite: str = "auv-track-v2", task: str = "lawnmower",
                 tier: str = "design") -> dict:
    """Paired cold-reset times of N envs: the plug-in probe recompiled per episode (before) and cached (now).

    Parameters
    ----------
    n : int
        Environments.
    repeat : int
        Pairs (median of the per-pair ratios reported).
    suite, task, tier : str, optional
        The cell.

    Returns
    -------
    dict
        ``before_s``, ``now_s`` (medians) and ``ratio`` (median of before / now over the pairs).
    """
    from auvtrack.control import plugin
    from auvtrack.gym.vector import TrackVectorEnv

    TrackVectorEnv(n, suite, task, tier).reset(seed=10**6)
    cached = plugin._PROBED
    before, now, ratios = [], [], []
    for r in range(repeat):
        times = []
        for mode, seed in (("before", 2 * 10**7 * (r + 1)), ("now", 2 * 10**7 * (r + 1) + 10**6)):
            plugin._PROBED = _Forgetful() if mode == "before" else cached
            venv = TrackVectorEnv(n, suite, task, tier)
            t0 = time.perf_counter()
            venv.reset(seed=seed)
            times.append(time.perf_counter() - t0)
        plugin._PROBED = cached
        before.append(times[0])
        now.append(times[1])
        ratios.append(times[0] / times[1])
    return {"num_envs": n, "before_s": round(statistics.median(before), 4), "now_s": round(statistics.median(now), 4),
            "ratio": round(statistics.median(ratios), 2), "repeat": repeat,
            "before": "the replay law's bounds-checked probe compiled at every episode's set-up (commit 7de3f7a)"}


def child_measure(task: str, n: int, seed: int, steps: int) -> float:
    """One timing in this process (the ``--child`` mode): seconds of a cold reset, or env steps/s of a loop.

    Parameters
    ----------
    task : str
        ``"reset"``: a reset of N envs on new seed indices; ``"loop"``: ``steps`` env steps of N envs
        with episodes of 10 env steps (0.2 s), autoreset preparing a new seed index per episode.
    n : int
        Environments.
    seed : int
        Seed index of env 0 (new indices for every timing).
    steps : int
        Env steps of the loop.

    Returns
    -------
    float
        Seconds (reset) or env steps/s (loop).
    """
    import numpy as np

    from auvtrack.gym.vector import TrackVectorEnv

    duration = 0.2 if task == "loop" else None
    TrackVectorEnv(1, "auv-track-v2", "lawnmower", "design", duration=duration).reset(seed=10**9)  # compile/load
    venv = TrackVectorEnv(n, "auv-track-v2", "lawnmower", "design", duration=duration)
    if task == "reset":
        t0 = time.perf_counter()
        venv.reset(seed=seed)
        return time.perf_counter() - t0
    acts = np.random.default_rng(0).uniform(-1, 1, (steps, n, 3))
    t0 = time.perf_counter()
    venv.reset(seed=seed)
    for k in range(steps):
        venv.step(acts[k])
    return n * steps / (time.perf_counter() - t0)


def paired_against(rev: str, task: str, n: int, steps: int, repeat: int) -> dict:
    """Paired timings of ``task`` (:func:`child_measure`) with the code of git revision ``rev`` and with this tree.

    Each pair runs two fresh processes, the revision's then this tree's, on the same new seed
    indices; the ratio is this tree's speed over the revision's (median over the pairs).

    Parameters
    ----------
    rev : str
        A git revision (its tree is exported with ``git archive`` to a temporary folder).
    task : str
        ``"reset"`` or ``"loop"``.
    n, steps, repeat : int
        Environments, loop steps, pairs.

    Returns
    -------
    dict
        The medians of both, the median paired ratio and the revision.
    """
    root = HERE.parent
    commit = subprocess.run(["git", "-C", str(root), "rev-parse", rev], capture_output=True, text=True,
                            check=True).stdout.strip()
    with tempfile.TemporaryDirectory() as tmp:
        archive = subprocess.run(["git", "-C", str(root), "archive", commit, "auvtrack"], capture_output=True,
                                 check=True).stdout
        subprocess.run(["tar", "-x", "-C", tmp], input=archive, check=True)

        def one(tree: str, seed: int) -> float:
            env = {**os.environ, "PYTHONPATH": tree}
            out = subprocess.run([sys.executable, __file__, "--child", task, "--child-n", str(n), "--child-seed",
                                  str(seed), "--steps", str(steps)], capture_output=True, text=True, env=env,
                                 check=True, cwd=tree)
            return float(out.stdout.strip().splitlines()[-1])

        before, now, ratios = [], [], []
        for r in range(repeat):
            seed = 3 * 10**7 * (r + 1)
            b, c = one(tmp, seed), one(str(root), seed)
            before.append(b)
            now.append(c)
            ratios.append(b / c if task == "reset" else c / b)
    unit = "s" if task == "reset" else "env_steps_per_s"
    return {"task": task, "num_envs": n, "steps": steps if task == "loop" else None, "unit": unit,
            "before": round(statistics.median(before), 4), "now": round(statistics.median(now), 4),
            "speedup": round(statistics.median(ratios), 2), "repeat": repeat, "before_rev": commit}


def main() -> None:
    """Measure and write the JSON record."""
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sizes", default="1,64,1024")
    ap.add_argument("--reset-sizes", default="1,64,256")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--steps", type=int, default=50)
    ap.add_argument("--paired-envs", type=int, default=8, help="N of the paired before/now reset timing (0: skip)")
    ap.add_argument("--out", default=str(HERE / "gym_throughput.json"))
    ap.add_argument("--against", default="7de3f7a",
                    help="git revision for the paired reset / episode-loop timings ('' to skip)")
    ap.add_argument("--paired-n", type=int, default=16, help="N of the paired timings against --against")
    ap.add_argument("--paired-steps", type=int, default=30, help="env steps of the paired episode loop")
    ap.add_argument("--paired-repeat", type=int, default=3, help="pairs of the timings against --against")
    ap.add_argument("--child", default=None, help=argparse.SUPPRESS)
    ap.add_argument("--child-n", type=int, default=1, help=argparse.SUPPRESS)
    ap.add_argument("--child-seed", type=int, default=0, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        print(child_measure(args.child, args.child_n, args.child_seed, args.steps))
        return
    from auvtrack.perf.bench import machine
    from auvtrack.perf.gym_bench import bench_gym

    sizes = tuple(int(s) for s in args.sizes.split(","))
    before = machine()["load_avg_1_5_15"]
    t0 = time.perf_counter()
    doc = bench_gym(sizes=sizes, repeat=args.repeat, steps=args.steps)
    doc["reset"] = reset_rows(tuple(int(s) for s in args.reset_sizes.split(",") if s), args.repeat)
    doc["reset_paired"] = reset_paired(args.paired_envs, args.repeat) if args.paired_envs else None
    doc["paired_against_revision"] = [] if not args.against else [
        paired_against(args.against, "reset", args.paired_n, 0, args.paired_repeat),
        paired_against(args.against, "loop", args.paired_n, args.paired_steps, args.paired_repeat)]
    doc["load_avg_before"] = before
    doc["load_avg_end"] = machine()["load_avg_1_5_15"]
    doc["seconds"] = round(time.perf_counter() - t0, 1)
    doc["command"] = "python benchmarks/gym_throughput.py " + " ".join(
        f"--{k.replace('_', '-')} {v}" for k, v in vars(args).items() if k != "out" and not k.startswith("child"))
    doc["target_env_steps_per_s_at_1024"] = 300_000
    Path(args.out).write_text(json.dumps(doc, indent=2) + "\n")
    for r in doc["rows"]:
        print(f"N={r['num_envs']:5d}: {r['env_steps_per_s']:>12,.0f} env steps/s  (x{r['ratio_to_batch']} of batch)")
    for r in doc["reset"]:
        print(f"reset N={r['num_envs']:5d}: cold {r['cold_s']:.3f} s ({r['cold_ms_per_env']} ms/env), warm {r['warm_s']} s")
    if doc["reset_paired"]:
        p = doc["reset_paired"]
        print(f"reset N={p['num_envs']} paired: before {p['before_s']} s, now {p['now_s']} s, x{p['ratio']}")
    for p in doc["paired_against_revision"]:
        print(f"{p['task']} N={p['num_envs']} vs {p['before_rev'][:7]}: before {p['before']}, now {p['now']} "
              f"({p['unit']}), x{p['speedup']}")
    print(f"load {before} -> {doc['load_avg_end']}; written {args.out}")


if __name__ == "__main__":
    main()

"""Throughput of the vector environment against the batch runner on the same plant and law (``auvtrack bench --gym``).

The environment: :class:`~auvtrack.gym.vector.TrackVectorEnv` of one suite cell (default
``auv-track-v2``, lawnmower, design tier: the 5-DOF REMUS 100), N envs, ``substeps`` RK4 steps
per env step, random actions drawn before timing; env steps/s = N x steps / wall time of the
``step`` calls (the Python of the step included).  The reference: the batch runner
(:func:`auvtrack.batch.runner.run_batch`, back end ``prange``) flying the same episodes (the
replay law, the same plant) from start to end, RK4 steps/s.  The ratio is env RK4 steps/s over
batch RK4 steps/s.  Medians over ``repeat`` timings, with the load average.
"""
from __future__ import annotations

import math
import statistics
import time

import numpy as np

__all__ = ["bench_gym"]


def bench_gym(*, sizes: tuple[int, ...] = (1, 64, 1024), repeat: int = 5, steps: int = 50, substeps: int = 10,
              suite: str = "auv-track-v2", task: str = "lawnmower", tier: str = "design") -> dict:
    """Env steps/s of the vector environment at each N, and the ratio to the batch runner.

    Parameters
    ----------
    sizes : tuple of int, optional
        Numbers of environments N.
    repeat : int, optional
        Timings per N (median reported).
    steps : int, optional
        Env steps per timing.
    substeps : int, optional
        RK4 steps per env step.
    suite, task, tier : str, optional
        The cell.

    Returns
    -------
    dict
        ``rows`` (one per N: ``env_steps_per_s``, ``rk4_steps_per_s``, ``ratio_to_batch``),
        ``batch`` (the batch runner's RK4 steps/s on the largest N's episodes) and ``machine``.
    """
    from ..batch.runner import run_batch
    from ..gym.vector import TrackVectorEnv
    from .bench import machine

    mach = machine()
    duration = 0.1 * math.ceil(10 * (steps + 2) * substeps * 0.002 + 1)  # no episode ends while timed (the suite's dt)
    rows = []
    largest = None
    for n in sizes:
        venv = TrackVectorEnv(n, suite, task, tier, substeps=substeps, duration=duration)
        rng = np.random.default_rng(0)
        acts = rng.uniform(-1, 1, (steps, n, 3))
        venv.reset(seed=0)
        venv.step(acts[0])  # compile or load
        rates = []
        for _ in range(repeat):
            venv.reset(seed=0)
            t0 = time.perf_counter()
            for k in range(steps):
                venv.step(acts[k])
            rates.append(n * steps / (time.perf_counter() - t0))
        rows.append({"num_envs": n, "substeps": substeps, "env_steps_per_s": round(statistics.median(rates), 1),
                     "rk4_steps_per_s": round(substeps * statistics.median(rates), 1), "repeat": repeat,
                     "steps": steps})
        largest = venv
    preps = []
    for i in range(largest.num_envs):
        largest.one.reset(seed=int(largest.seed_indices[i]))
        preps.append(largest.one.prep)
    run_batch(preps[:2], backend="prange")  # compile or load
    batch_rates = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        res = run_batch(preps, backend="prange")
        wall = time.perf_counter() - t0
        batch_rates.append(sum(p.n_steps for p in preps) / wall)
    batch = statistics.median(batch_rates)
    for r in rows:
        r["ratio_to_batch"] = round(r["rk4_steps_per_s"] / batch, 3)
    return {"cell": {"suite": suite, "task": task, "tier": tier}, "rows": rows,
            "batch": {"backend": "prange", "runs": len(preps), "rk4_steps_per_s": round(batch, 1),
                      "statuses": sorted({r.status for r in res})},
            "machine": mach, "load_avg_after": machine()["load_avg_1_5_15"]}


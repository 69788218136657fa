"""Cost of ``auvtrack tune``: trials per second and the share of the time spent outside the compiled kernels.

Usage::

    python benchmarks/tune_timing.py --controller pid --suite auv-track-v1 --budget 200 --out /tmp/tune-timing

Runs one tuning (after a warm-up that compiles the kernels) and times every call of the batch
runner (:func:`auvtrack.batch.runner.run_batch`, which runs the compiled kernels; its own Python
set-up is small and counted as inside).  Prints a JSON record: trials, runs, RK4 steps, wall and
CPU seconds, trials/s, the kernel share and the share outside the kernels (Optuna, SQLite, run
planning, scenario validation, set-up, scoring), with the load average before and after.
"""
from __future__ import annotations

import argparse
import json
import os
import time


def main() -> None:
    """Time one tuning and print the record."""
    from auvtrack.batch import runner
    from auvtrack.tuning import tune

    ap = argparse.ArgumentParser()
    ap.add_argument("--controller", default="pid")
    ap.add_argument("--suite", default="auv-track-v1")
    ap.add_argument("--budget", type=int, default=200)
    ap.add_argument("--out", required=True)
    ap.add_argument("--workers", type=int, default=1)
    a = ap.parse_args()
    inside = [0.0]
    real = runner.run_batch

    def timed(*args, **kw):
        t = time.perf_counter()
        try:
            return real(*args, **kw)
        finally:
            inside[0] += time.perf_counter() - t

    runner.run_batch = timed  # run_chunk imports it from the module at each call
    load0 = os.getloadavg()
    t0 = time.perf_counter()
    res = tune(a.controller, a.suite, trials=a.budget, out=a.out, workers=a.workers, validate=False)
    wall = time.perf_counter() - t0
    print(json.dumps({"controller": a.controller, "suite": a.suite, "trials": res.trials, "complete": res.complete,
                      "pruned": res.pruned, "refused": res.refused, "runs": res.runs, "steps": res.steps,
                      "wall_s": round(wall, 2), "cpu_s": round(res.cpu_s, 2),
                      "trials_per_s": round(res.trials / wall, 4), "kernel_share": round(inside[0] / wall, 3),
                      "outside_share": round(1 - inside[0] / wall, 3), "load_before": load0,
                      "load_after": os.getloadavg()}, indent=1))


if __name__ == "__main__":
    main()

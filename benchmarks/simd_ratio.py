"""Paired CPU-time ratio of the serial and SIMD batch back ends on one core (for judging a SIMD change).

Usage::

    python benchmarks/simd_ratio.py                    # [--controller fxtntsmc] [--runs 16] [--repeat 7]
    python benchmarks/simd_ratio.py --breakdown        # the variants of `auvtrack bench --all`'s breakdown

One process alternates ``run_batch(backend="serial")`` and ``run_batch(backend="simd", workers=1)``
over the same prepared 10 s Section 4 runs and reports the median over repetitions of
(serial CPU time) / (SIMD CPU time): the per-core efficiency of the lanes, from process CPU time,
so that other processes on a shared machine disturb it less than wall time.  It also checks that
both back ends give the same metrics bit for bit.
"""
from __future__ import annotations

import argparse
import statistics
import time


def ratio(overrides: dict, *, runs: int = 16, repeat: int = 7, duration: float = 10.0) -> dict:
    """Median serial / SIMD CPU-time ratio of ``runs`` runs of the Section 4 scenario with ``overrides``."""
    import numpy as np

    from auvtrack.batch.runner import run_batch
    from auvtrack.scenario import load_scenario, paper_scenario_path
    from auvtrack.simulation.pipeline import prepare
    from auvtrack.metrics import METRIC_NAMES

    preps = [prepare(load_scenario(paper_scenario_path(), {"sim.duration": duration, "seed": i,
                                                           "uncertainty.D": 0.005 * i, **overrides}))
             for i in range(runs)]
    a = run_batch(preps, backend="serial")  # compile / load, and the reference results
    b = run_batch(preps, backend="simd", workers=1)
    same = all(np.array_equal([x.metrics[k] for k in METRIC_NAMES], [y.metrics[k] for k in METRIC_NAMES],
                              equal_nan=True) and x.failure == y.failure for x, y in zip(a, b))
    ratios, serial, simd = [], [], []
    for _ in range(repeat):
        c0 = time.process_time()
        run_batch(preps, backend="serial")
        c1 = time.process_time()
        run_batch(preps, backend="simd", workers=1)
        c2 = time.process_time()
        serial.append(c1 - c0)
        simd.append(c2 - c1)
        ratios.append((c1 - c0) / (c2 - c1))
    steps = runs * int(preps[0].si[0])
    return {"ratio": statistics.median(ratios), "serial_us_per_step": 1e6 * statistics.median(serial) / steps,
            "simd_us_per_run_step": 1e6 * statistics.median(simd) / steps, "bit_identical": same}


def main() -> None:
    """Print the ratio for one controller, or for every breakdown variant."""
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--controller", default="fxtntsmc")
    ap.add_argument("--runs", type=int, default=16)
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--breakdown", action="store_true")
    args = ap.parse_args()
    if args.breakdown:
        from auvtrack.perf.sweep_bench import BREAKDOWN

        cases = [(label, ov) for label, ov in BREAKDOWN]
    else:
        cases = [(args.controller, {"controller.kind": args.controller})]
    for label, ov in cases:
        r = ratio(ov, runs=args.runs, repeat=args.repeat)
        print(f"{label:50s} serial {r['serial_us_per_step']:.3f} us/step, simd {r['simd_us_per_run_step']:.3f} "
              f"us/run-step, serial/simd CPU {r['ratio']:.2f}, bit-identical {r['bit_identical']}", flush=True)


if __name__ == "__main__":
    main()

"""Benchmark the compiled closed loop and write benchmarks/results.{json,md}.

Usage: ``python benchmarks/run.py [--repeat 7] [--duration 20]``.  Reports medians (this machine
is shared and noisy) and the ratio FXTNTSMC / FTSMC; never used as a timed unit test.
"""
from __future__ import annotations

import argparse
import datetime
import json
from pathlib import Path

from auvtrack.studies.bench import bench_single, machine


def main() -> None:
    """Run the benchmarks and write the results files next to this script."""
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--duration", type=float, default=20.0)
    args = ap.parse_args()
    rows = [bench_single(k, repeat=args.repeat, duration=args.duration) for k in ("open_loop", "ftsmc", "fxtntsmc")]
    here = Path(__file__).resolve().parent
    doc = {"date": datetime.date.today().isoformat(), "machine": machine(), "repeat": args.repeat,
           "duration_s": args.duration, "results": rows,
           "ratio_fxtntsmc_ftsmc": rows[2]["us_per_step"] / rows[1]["us_per_step"]}
    (here / "results.json").write_text(json.dumps(doc, indent=2))
    lines = ["# Benchmark results", "", f"{doc['date']}, {doc['machine']}, median of {args.repeat} runs of "
             f"{args.duration:g} s at dt = 1 ms (controller at every RK4 stage).", "",
             "| controller | median µs / RK4 step | min µs / step |", "|---|---|---|"]
    lines += [f"| {r['controller']} | {r['us_per_step']:.2f} | {r['min_us_per_step']:.2f} |" for r in rows]
    lines += ["", f"FXTNTSMC / FTSMC ratio: {doc['ratio_fxtntsmc_ftsmc']:.2f}", ""]
    (here / "results.md").write_text("\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()

"""Run the full benchmark suite and write benchmarks/results.{json,md}.

Usage: ``python benchmarks/run.py [--repeat 7]`` (the same as ``auvtrack bench --all --out benchmarks``).  Reports
medians (this machine is shared and noisy) and ratios; never used as a timed unit test.
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

from auvtrack.perf.bench import bench_all


def main() -> None:
    """Run the benchmarks and write the results files next to this script."""
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--repeat", type=int, default=7)
    args = ap.parse_args()
    doc = bench_all(repeat=args.repeat, out=Path(__file__).resolve().parent, progress=True)
    print(json.dumps(doc, indent=2))


if __name__ == "__main__":
    main()

"""Tune every built-in tracking controller with the same budget and ship the presets.

    python tools/tune_presets.py --suite auv-track-v2 --budget 200 --parallel 2 --out tune-presets [--install]

Each controller is tuned by :func:`auvtrack.tuning.tune` on the suite's training split with the
same sampler, seed and number of trials (the budget is trials x training runs, the same for all),
in ``<out>/<kind>`` (a stopped run resumes); ``--install`` copies each preset
(``<kind>_<vehicle>_<suite>.toml``) into ``auvtrack/data/gains/`` as soon as it is finished.
"""
from __future__ import annotations

import argparse
import shutil
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def main(argv: list[str] | None = None) -> int:
    """Tune the controllers one after the other; return 0."""
    from auvtrack.benchmark.suite import tracking_kinds
    from auvtrack.tuning import tune

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--suite", default="auv-track-v2")
    ap.add_argument("--budget", type=int, required=True, help="trials per controller")
    ap.add_argument("--out", default="tune-presets")
    ap.add_argument("--sampler", default="tpe")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--controllers", default=",".join(tracking_kinds()))
    ap.add_argument("--workers", type=int, default=None,
                    help="threads of the batch runner inside a trial (default: tune's, every core)")
    ap.add_argument("--parallel", type=int, default=1, help="trials flown at once (local processes)")
    ap.add_argument("--install", action="store_true", help="copy each preset into auvtrack/data/gains/")
    a = ap.parse_args(argv)
    for kind in [k for k in a.controllers.split(",") if k]:
        res = tune(kind, a.suite, trials=a.budget, out=Path(a.out) / kind, sampler=a.sampler, seed=a.seed,
                   workers=a.workers, parallel=a.parallel)
        print(f"{kind}: {res.trials} trials ({res.complete} complete, {res.pruned} pruned, {res.refused} refused), "
              f"{res.runs} runs, {res.steps} steps, {res.cpu_s:.0f} CPU s, {res.wall_s:.0f} s; "
              f"train {res.best_score:.4g}, validation {res.validation_score:.4g}", flush=True)
        if a.install and "preset" in res.outputs:
            shutil.copy(res.outputs["preset"], ROOT / "auvtrack" / "data" / "gains" / res.outputs["preset"].name)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

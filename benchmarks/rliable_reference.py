"""rliable's own numbers on random data: the reference ``tests/benchmark/test_aggregates.py`` checks against.

Usage (rliable is not a dependency of auvtrack; a throw-away virtual environment)::

    python -m venv /tmp/rl && /tmp/rl/bin/pip install rliable "pandas<3"
    /tmp/rl/bin/python benchmarks/rliable_reference.py [--out tests/data/rliable_reference.json]

(``pandas<3``: rliable 1.2.0 pins ``arch < 8``, and arch 7.2.0 fails at import with pandas 3.)
This script does not import auvtrack.  It draws error matrices (runs x tasks, lower is better,
values rounded to create ties, some failures) for three controllers and records, computed by
rliable:

* ``points``: ``aggregate_iqm``, ``aggregate_median``, ``aggregate_mean`` of the errors;
  ``aggregate_optimality_gap`` of the reciprocal score ``1 / e`` at ``1 / gamma``;
  ``probability_of_improvement`` of ``-e_x`` over ``-e_y`` (rliable counts higher as better);
  the run-score distribution ``mean(e > tau)`` of ``create_performance_profile``;
* ``intervals`` (finite data: rliable interpolates its percentiles linearly, which is undefined
  between two infinities): ``get_interval_estimates`` of the four aggregates and of the
  probability of improvement, and the bands of ``create_performance_profile``, each after
  ``numpy.random.seed(seed)`` -- rliable's ``StratifiedBootstrap`` draws its indices from
  NumPy's global generator and ignores ``random_state`` -- with the seed stored, so that a test
  can regenerate rliable's resampled indices with ``numpy.random.RandomState(seed)`` (checked
  here, before writing).

Failures (``inf``) are written as ``null``: the file is strict JSON.
"""
from __future__ import annotations

import argparse
import importlib.metadata as md
import json
from pathlib import Path

import numpy as np
from rliable import library as rly
from rliable import metrics

ROOT = Path(__file__).resolve().parents[1]
CONTROLLERS = {"A": 0.0, "B": 0.25, "C": -0.1}   # log-scale offsets of the error medians
RUNS, TASKS = 12, 5
REPS = 300
GAMMAS = (1.0, 0.7)
TAUS = [0.0, 0.25, 0.5, 0.75, 1.0, 1.25, 1.5, 2.0, 3.0, 5.0]
FAILURES = {"A": [(0, 1)], "B": [(2, 0), (5, 3), (7, 3)], "C": []}   # (run, task) of failed runs


def errors(rng: np.random.Generator, offset: float) -> np.ndarray:
    """Lognormal errors per (run, task), a task effect shared by the controllers, rounded for ties."""
    task_effect = np.linspace(-0.3, 0.3, TASKS)
    return np.round(np.exp(offset + task_effect + 0.4 * rng.standard_normal((RUNS, TASKS))), 1)


def _json(a) -> list:
    return [[None if not np.isfinite(v) else float(v) for v in row] for row in np.atleast_2d(a)]


def _seeded(seed: int, fn):
    np.random.seed(seed)
    return fn()


def _check_legacy_stream(x: np.ndarray, seed: int) -> None:
    """rliable's resampled indices are numpy.random.RandomState(seed).choice(runs, (runs, tasks)) per replicate."""
    bs = rly.StratifiedBootstrap(x)
    seen = []
    draw = bs.update_indices

    def recording():
        idx = draw()
        seen.append(idx[0].copy())
        return idx

    bs.update_indices = recording
    np.random.seed(seed)
    bs.conf_int(lambda s: np.array([metrics.aggregate_iqm(s)]), reps=20, method="percentile")
    rs = np.random.RandomState(seed)
    assert len(seen) == 20 and all(np.array_equal(i, rs.choice(x.shape[0], x.shape, replace=True)) for i in seen)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=ROOT / "tests/data/rliable_reference.json")
    args = ap.parse_args()
    rng = np.random.default_rng(20211206)
    clean = {c: errors(rng, off) for c, off in CONTROLLERS.items()}
    failing = {c: e.copy() for c, e in clean.items()}
    for c, cells in FAILURES.items():
        for i, j in cells:
            failing[c][i, j] = np.inf
    _check_legacy_stream(clean["A"], 1)

    def points(data: dict[str, np.ndarray]) -> dict:
        out = {"iqm": {}, "median": {}, "mean": {}, "optimality_gap": {}, "profile": {}, "poi": {}}
        for c, e in data.items():
            out["iqm"][c] = float(metrics.aggregate_iqm(e))
            out["median"][c] = float(metrics.aggregate_median(e))
            out["mean"][c] = float(metrics.aggregate_mean(e))
            with np.errstate(divide="ignore"):
                out["optimality_gap"][c] = {str(g): float(metrics.aggregate_optimality_gap(1.0 / e, 1.0 / g))
                                            for g in GAMMAS}
            out["profile"][c] = [float(v) for v in rly.score_distributions(e, TAUS)]
        for x in data:
            for y in data:
                if x != y:
                    out["poi"][f"{x},{y}"] = float(metrics.probability_of_improvement(-data[x], -data[y]))
        return {k: {kk: (None if isinstance(vv, float) and not np.isfinite(vv) else vv) for kk, vv in v.items()}
                for k, v in out.items()}

    aggs = {"iqm": metrics.aggregate_iqm, "median": metrics.aggregate_median, "mean": metrics.aggregate_mean,
            "optimality_gap": lambda s: metrics.aggregate_optimality_gap(1.0 / s, 1.0)}
    intervals: dict = {"aggregates": {}, "poi": {}, "profile": {}}
    seed = 100
    for a, f in aggs.items():
        for c, e in clean.items():
            seed += 1
            _, ci = _seeded(seed, lambda: rly.get_interval_estimates({c: e}, lambda s: np.array([f(s)]), reps=REPS))
            intervals["aggregates"][f"{a}/{c}"] = {"seed": seed, "ci": [float(v) for v in np.ravel(ci[c])]}
    for x in clean:
        for y in clean:
            if x < y:
                seed += 1
                fn = lambda p, q: np.array([metrics.probability_of_improvement(p, q)])
                _, ci = _seeded(seed, lambda: rly.get_interval_estimates({"p": [-clean[x], -clean[y]]}, fn, reps=REPS))
                intervals["poi"][f"{x},{y}"] = {"seed": seed, "ci": [float(v) for v in np.ravel(ci["p"])]}
    for c, e in clean.items():
        seed += 1
        _, ci = _seeded(seed, lambda: rly.create_performance_profile({c: e}, TAUS, reps=REPS))
        intervals["profile"][c] = {"seed": seed, "low": [float(v) for v in ci[c][0]], "high": [float(v) for v in ci[c][1]]}

    record = {
        "about": "rliable's numbers on errors (lower is better); written by benchmarks/rliable_reference.py",
        "versions": {p: md.version(p) for p in ("rliable", "arch", "numpy", "scipy")},
        "runs": RUNS, "tasks": TASKS, "reps": REPS, "gammas": list(GAMMAS), "taus": TAUS, "confidence": 0.95,
        "interval_method": "percentile, numpy.percentile linear interpolation (arch)",
        "clean": {c: _json(e) for c, e in clean.items()},
        "failing": {c: _json(e) for c, e in failing.items()},
        "points": {"clean": points(clean), "failing": points(failing)},
        "intervals": intervals,
    }
    args.out.write_text(json.dumps(record, indent=1, allow_nan=False) + "\n")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()

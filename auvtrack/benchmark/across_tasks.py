"""The aggregates across tasks of a comparison: normalised scores, IQM, performance profiles, P(X < Y).

:func:`aggregate_analysis` applies :mod:`auvtrack.benchmark.aggregates` to a comparison's runs
(``docs/benchmark.md``, "Aggregates across tasks"):

* **score**: the suite's primary metric (its largest ``[scoring]`` weight:
  :meth:`~auvtrack.benchmark.suite.Scoring.primary`; ``xtrack_rmse`` in v2, ``rmse`` in v1),
  failures ``inf``;
* **normalisation** r = e / m(cell), per (task, tier) cell: m = the reference controller's
  median (the LOS autopilot, the vehicle-level baseline) when it is a competitor with a finite,
  positive median in every cell; otherwise the metric's ``[run_score]`` scale (one value for
  every cell); with neither, no aggregate (the reason is recorded);
* **cap** of the median and mean of task means: a failed run counts as the error at which the
  suite's run score saturates, ``[run_score]`` cap x the metric's scale (10 x 0.5 m = 5 m of
  ``xtrack_rmse`` in v2), divided by its cell's divisor like every run; a completed run above it
  is capped there too.  Without a scale for the metric: ``cap`` times the divisor.  The median
  and mean stay finite when runs fail, and the failure rate of each controller is recorded next
  to them (``failure_rate``);
* **intervals**: the stratified bootstrap with strata = tasks (the tiers of a task share their
  seeds), one set of draws for every controller (paired), the suite's confidence and bootstrap
  size, generators ``SeedSequence([seed, crc32("aggregates/<statistic>")])``.
"""
from __future__ import annotations

import math
from typing import Any, Sequence

import numpy as np

from . import aggregates as ag
from .leaderboard import _rng, metric_info

__all__ = ["aggregate_analysis", "REFERENCE", "normalisation", "failure_caps", "profile_taus"]

REFERENCE = "los_autopilot"
"""The reference controller of the normalisation: the LOS autopilot, the baseline real AUVs fly."""
CELLS = ("task", "tier")
STRATA = ("task",)


def normalisation(df, score: str, controllers: Sequence[str], scale: float | None,
                  reference: str = REFERENCE) -> tuple[dict[tuple, float] | None, str]:
    """The divisor of each (task, tier) cell and how it was chosen.

    Parameters
    ----------
    df : pandas.DataFrame
        Runs with the derived metrics.
    score : str
        The metric normalised.
    controllers : sequence of str
        The competitors.
    scale : float or None
        The metric's ``[run_score]`` scale (the fallback), or None.
    reference : str, optional
        The reference controller.

    Returns
    -------
    (dict or None, str)
        ``{(task, tier): divisor}`` (None: no normalisation is possible) and a one-line
        description of the rule applied (for the report).
    """
    why = f"`{reference}` is not a competitor"
    if reference in controllers:
        try:
            return (ag.reference_scales(df, score, reference, cells=CELLS),
                    f"each run's `{score}` divided by the median `{score}` of `{reference}` on the same (task, tier) "
                    "cell (1 = the LOS autopilot's typical run)")
        except ValueError as exc:
            why = str(exc)
    cells = sorted(set(df[list(CELLS)].itertuples(index=False, name=None)), key=lambda k: tuple(map(str, k)))
    if scale is not None and math.isfinite(scale) and scale > 0:
        return ({k: float(scale) for k in cells},
                f"each run's `{score}` divided by its `[run_score]` scale {scale:g}, the same in every cell "
                f"(the LOS autopilot's medians cannot serve: {why})")
    return None, f"no normalisation: the LOS autopilot's medians cannot serve ({why}) and `{score}` has no scale"


def failure_caps(scales: dict[tuple, float], score: str, run_score) -> tuple[dict[tuple, float], str]:
    """The cap of each cell's normalised scores in the median and mean of task means, and the rule.

    Parameters
    ----------
    scales : dict
        ``{(task, tier): divisor}`` (:func:`normalisation`).
    score : str
        The metric normalised.
    run_score : auvtrack.benchmark.suite.RunScore
        The suite's ``[run_score]`` (its ``cap`` and ``scales``).

    Returns
    -------
    (dict, str)
        ``{(task, tier): cap}`` (finite, > 0) and a one-line description of the rule (for the report).
    """
    scale = run_score.scales.get(score)
    if scale is not None:
        ceiling = float(run_score.cap) * float(scale)
        unit = metric_info(score)[1]
        return ({k: ceiling / v for k, v in scales.items()},
                f"a failed run counts as `{score}` = {ceiling:g} {unit} (where the run score saturates: `[run_score]` "
                f"cap {run_score.cap:g} x scale {scale:g} {unit}), divided by its cell's divisor like every run; a "
                "completed run above it counts as it too")
    return ({k: float(run_score.cap) for k in scales},
            f"a failed run counts as {run_score.cap:g} (the `[run_score]` cap) times its cell's divisor; a completed "
            "run above it counts as it too")


def profile_taus(values: np.ndarray, n: int = 61) -> np.ndarray:
    """The tau grid of the performance profiles: ``n`` points on [0, tau_max].

    tau_max is the 95th percentile of the finite normalised scores rounded up to a half, at
    least 2 (twice the reference) and at most 20.

    Parameters
    ----------
    values : numpy.ndarray
        Every normalised score (``inf`` for failures).
    n : int, optional
        Points.

    Returns
    -------
    numpy.ndarray
        Increasing, from 0.
    """
    fin = values[np.isfinite(values)]
    top = float(np.quantile(fin, 0.95)) if fin.size else 2.0
    return np.linspace(0.0, min(20.0, max(2.0, math.ceil(2.0 * top) / 2.0)), n)


def aggregate_analysis(df, suite, controllers: Sequence[str]) -> dict[str, Any]:
    """Every aggregate across tasks of a comparison, as plain data (``results.json`` -> ``aggregates``).

    Parameters
    ----------
    df : pandas.DataFrame
        Runs with the derived metrics (:func:`auvtrack.benchmark.leaderboard.derive_metrics`).
    suite : Suite
        The suite (seed, confidence, bootstrap size, scoring and run-score scales).
    controllers : sequence of str
        Competitors in report order.

    Returns
    -------
    dict
        ``score``, ``normalisation`` (the rule), ``scales`` (``{"task/tier": divisor}``),
        ``strata``, ``n_resamples``, ``confidence``, ``cap`` (``{"task/tier": cap}`` of the
        median and mean of task means) and ``cap_rule`` (its description), ``failure_rate``
        (``{controller: failed runs / runs}``), ``estimates`` (``{aggregate: {controller:
        {"point", "low", "high"}}}``), ``profiles`` (``{controller: {"taus", "fraction", "low",
        "high"}}``) and ``improvement`` (``[{"x", "y", "point", "low", "high"}]``, every ordered
        pair); without a normalisation only ``score``, ``normalisation`` and ``estimates = None``.
    """
    f = suite.file
    score = f.scoring.primary()
    scale = f.run_score.scales.get(score)
    scales, rule = normalisation(df, score, controllers, scale)
    out: dict[str, Any] = {"score": score, "normalisation": rule}
    if scales is None:
        return out | {"estimates": None}
    runs = df[["controller", "seed_index", "status", *CELLS]].copy()
    runs["norm"] = ag.normalise(df, score, scales, cells=CELLS).to_numpy()
    sm = ag.score_matrices(runs, "norm", cells=CELLS, strata=STRATA, controllers=list(controllers))
    n, level = suite.bootstrap_resamples, f.confidence
    caps, cap_rule = failure_caps(scales, score, f.run_score)
    est = ag.aggregate_estimates(sm, _rng(f.seed, "aggregates/estimates"), cap=[caps[c] for c in sm.cells],
                                 n_resamples=n, confidence=level)
    failed = {c: float((runs.loc[runs["controller"] == c, "status"] != "ok").mean()) for c in sm.scores}
    taus = profile_taus(runs["norm"].to_numpy(dtype=float))
    prof = ag.performance_profiles(sm, taus, _rng(f.seed, "aggregates/profiles"), n_resamples=n, confidence=level)
    poi = ag.improvement_probabilities(sm, _rng(f.seed, "aggregates/improvement"), n_resamples=n, confidence=level)
    return out | {
        "scales": {f"{k[0]}/{k[1]}": v for k, v in scales.items()}, "strata": list(STRATA), "n_resamples": n,
        "confidence": level, "cap": {f"{k[0]}/{k[1]}": v for k, v in caps.items()}, "cap_rule": cap_rule,
        "failure_rate": failed, "estimates": est.to_dict(),
        "profiles": {c: p.to_dict() for c, p in prof.items()},
        "improvement": [{"x": x, "y": y, **e.to_dict()} for (x, y), e in poi.items()],
    }

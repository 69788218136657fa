"""The score of one run: what ``auvtrack tune`` minimises, and a number every run of a comparison gets.

A suite's ``[run_score]`` table (docs/tuning.md, "The objective") gives each criterion c a weight
w_c and a scale s_c (the value of the criterion that scores 1, in its unit).  Lower is better:

    completed run:  score = sum_c w_c min(m_c / s_c, cap) / sum_c w_c          (0 <= score <= cap)
    failed run:     score = cap + 1 + (1 - t_stop / T)                          (cap + 1 <= score <= cap + 2)

m_c is the run's value of criterion c: one of the benchmark's derived metrics
(:data:`auvtrack.benchmark.suite.METRICS`, :func:`auvtrack.benchmark.leaderboard.derive_metrics`)
or one of the engine's metrics (:data:`auvtrack.metrics.METRIC_NAMES`, e.g. ``xtrack_rmse``);
T is the task's duration and t_stop the time the run stopped.  Every failed run scores worse than
every completed one (failure first), and a run that fails later scores better than one that fails
sooner, so a tuner can climb out of a region where every candidate fails.  The cap keeps one
wild run from outweighing the rest of a mean; a criterion that is NaN or infinite on a completed
run scores the cap.
"""
from __future__ import annotations

import math
from typing import Any, Mapping

__all__ = ["run_score", "run_score_terms", "failure_floor"]


def failure_floor(cap: float) -> float:
    """The lowest score a failed run can get (every completed run scores at most ``cap``)."""
    return cap + 1.0


def run_score(values: Mapping[str, Any], weights: Mapping[str, float], scales: Mapping[str, float], *,
              cap: float, duration: float) -> float:
    """Score of one run (lower is better; module docstring for the formula).

    Parameters
    ----------
    values : mapping
        The run: ``status`` (``"ok"`` when it completed), ``t_stop`` (s) and each criterion of
        ``weights`` by name.
    weights : mapping of str to float
        Criterion -> weight (>= 0, some > 0).
    scales : mapping of str to float
        Criterion -> the value that scores 1 (> 0, in the criterion's unit); one per weighted criterion.
    cap : float
        Largest score of one criterion of a completed run (> 0).
    duration : float
        The task's duration T (s, > 0).

    Returns
    -------
    float
        In [0, cap] for a completed run, in [cap + 1, cap + 2] for a failed one.

    Raises
    ------
    ValueError
        A weighted criterion without a scale, or no positive weight.
    """
    total = sum(w for w in weights.values() if w > 0)
    if total <= 0:
        raise ValueError("run_score: weights: at least one criterion needs a weight > 0")
    if values.get("status") != "ok":
        t_stop = float(values.get("t_stop") or 0.0)
        frac = min(max(t_stop / duration, 0.0), 1.0) if math.isfinite(t_stop) else 0.0
        return failure_floor(cap) + (1.0 - frac)
    score = 0.0
    for c, term in run_score_terms(values, weights, scales, cap=cap).items():
        score += weights[c] * term
    return min(score / total, cap)  # the weighted mean of capped terms, rounding kept inside the cap


def run_score_terms(values: Mapping[str, Any], weights: Mapping[str, float], scales: Mapping[str, float], *,
                    cap: float) -> dict[str, float]:
    """The capped term of each weighted criterion of a completed run: min(m_c / s_c, cap), in [0, cap].

    :func:`run_score` of a completed run is the weighted mean of these terms; a criterion that is
    NaN or infinite scores the cap.

    Parameters
    ----------
    values : mapping
        The run's value of each criterion of ``weights`` by name.
    weights : mapping of str to float
        Criterion -> weight; the criteria with a weight > 0 get a term.
    scales : mapping of str to float
        Criterion -> the value that scores 1.
    cap : float
        Largest term.

    Returns
    -------
    dict of str to float
        Criterion -> term, in the order of ``weights``.

    Raises
    ------
    ValueError
        A weighted criterion without a scale.
    """
    terms: dict[str, float] = {}
    for c, w in weights.items():
        if w <= 0:
            continue
        if c not in scales:
            raise ValueError(f"run_score: scales.{c}: missing (the value of {c} that scores 1)")
        m = float(values[c])
        term = min(m / scales[c], cap) if math.isfinite(m) else cap
        terms[c] = max(term, 0.0)
    return terms

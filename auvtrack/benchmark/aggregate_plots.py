"""Figures of the aggregates across tasks (:mod:`auvtrack.benchmark.aggregates`), for the benchmark report.

Matplotlib ``Figure`` objects (no pyplot, as :mod:`auvtrack.benchmark.report`): performance
profiles with their bootstrap bands, probabilities of improvement with their intervals, and
the interval estimates of the aggregates.  Infinite values (aggregates of controllers that fail
often) are drawn at the right edge of their panel with an arrow and labelled ``inf``.
"""
from __future__ import annotations

import math
from typing import Any, Mapping, Sequence

import numpy as np

from .aggregates import AggregateEstimates, Estimate, Profile

__all__ = ["figure_performance_profiles", "figure_improvement_probabilities", "figure_aggregate_intervals"]

AGGREGATE_LABELS = {
    "iqm": "IQM",
    "median": "median of task means",
    "mean": "mean of task means",
    "optimality_gap": "optimality gap",
}
"""Aggregate name -> panel title."""


def _colors(names: Sequence[str]) -> dict[str, Any]:
    from matplotlib import colormaps

    cmap = colormaps["tab10"]
    return {n: cmap(i % 10) for i, n in enumerate(names)}


def figure_performance_profiles(profiles: Mapping[str, Profile], *, xlabel: str = "normalised error tau",
                                log_x: bool = False, reference: float | None = 1.0):
    """Performance profiles, one step curve per controller with its pointwise bootstrap band.

    Parameters
    ----------
    profiles : mapping of str to Profile
        From :func:`auvtrack.benchmark.aggregates.performance_profiles`.
    xlabel : str, optional
        Label of the tau axis.
    log_x : bool, optional
        Logarithmic tau axis (the taus must then be > 0).
    reference : float or None, optional
        Tau marked by a dashed line (1: the reference's median), or None.

    Returns
    -------
    matplotlib.figure.Figure
        The figure: higher curves are better (more runs below each error).
    """
    from matplotlib.figure import Figure

    if not profiles:
        raise ValueError("profiles: need at least one controller")
    colors = _colors(list(profiles))
    fig = Figure(figsize=(6.4, 4.2))
    ax = fig.subplots()
    for name, p in profiles.items():
        ax.step(p.taus, p.fraction, where="post", color=colors[name], label=name, lw=1.6)
        ax.fill_between(p.taus, p.low, p.high, step="post", color=colors[name], alpha=0.2, lw=0)
    if reference is not None:
        ax.axvline(reference, color="0.4", ls="--", lw=0.8)
    if log_x:
        ax.set_xscale("log")
    ax.set_ylim(-0.02, 1.02)
    ax.set_xlabel(xlabel)
    ax.set_ylabel("fraction of runs with error <= tau")
    level = next(iter(profiles.values())).confidence
    ax.set_title(f"performance profiles, {100 * level:g} % stratified-bootstrap bands (failures above every tau)",
                 fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="lower right")
    fig.tight_layout()
    return fig


def _finite_edge(values: Sequence[float], low: float = 0.0) -> float:
    fin = [v for v in values if math.isfinite(v)]
    top = max(fin) if fin else 1.0
    span = top - min(min(fin), low) if fin else 1.0
    return top + 0.15 * (span if span > 0 else 1.0)


def _interval_row(ax, y: float, est: Estimate, color, edge: float) -> None:
    lo, hi, pt = (min(v, edge) for v in (est.low, est.high, est.point))
    ax.plot([lo, hi], [y, y], color=color, lw=5, alpha=0.45, solid_capstyle="butt")
    ax.plot([pt], [y], "|", color="k", ms=12, mew=2)
    if math.isinf(est.high):
        ax.plot([edge], [y], ">", color=color, ms=8)
        ax.annotate("inf", (edge, y), xytext=(4, 4), textcoords="offset points", fontsize=7)


def figure_improvement_probabilities(probabilities: Mapping[tuple[str, str], Estimate], *,
                                     pairs: Sequence[tuple[str, str]] | None = None):
    """P(X < Y) of pairs of controllers with their paired-bootstrap intervals.

    Parameters
    ----------
    probabilities : mapping
        ``{(X, Y): Estimate}`` from :func:`auvtrack.benchmark.aggregates.improvement_probabilities`.
    pairs : sequence of (str, str), optional
        Pairs to show, top to bottom (default: each unordered pair once, as given).

    Returns
    -------
    matplotlib.figure.Figure
        One row per pair on [0, 1] with the line of no difference at 1/2; right of it, X has the
        smaller error more often than not.
    """
    from matplotlib.figure import Figure

    if pairs is None:
        pairs = []
        for x, y in probabilities:
            if (y, x) not in pairs:
                pairs.append((x, y))
    missing = [p for p in pairs if tuple(p) not in probabilities]
    if missing or not pairs:
        raise ValueError(f"pairs: need pairs among the probabilities (missing {missing})")
    colors = _colors(list(dict.fromkeys(x for x, _ in pairs)))
    n = len(pairs)
    fig = Figure(figsize=(6.4, 0.42 * n + 1.3))
    ax = fig.subplots()
    ys = np.arange(n)[::-1]
    for y, (a, b) in zip(ys, pairs):
        _interval_row(ax, float(y), probabilities[(a, b)], colors[a], 1.0)
    ax.axvline(0.5, color="0.4", ls="--", lw=0.8)
    ax.set_yticks(ys, [f"{a} < {b}" for a, b in pairs])
    ax.set_xlim(0.0, 1.0)
    ax.set_xlabel("P(X < Y): probability that X's error is smaller (lower is better)")
    ax.grid(axis="x", alpha=0.3)
    fig.tight_layout()
    return fig


def figure_aggregate_intervals(estimates: AggregateEstimates, *, aggregates: Sequence[str] | None = None,
                               controllers: Sequence[str] | None = None, titles: Mapping[str, str] | None = None):
    """Interval estimates of the aggregates: one panel per aggregate, one row per controller.

    Parameters
    ----------
    estimates : AggregateEstimates
        From :func:`auvtrack.benchmark.aggregates.aggregate_estimates`.
    aggregates : sequence of str, optional
        Panels, left to right (default: every aggregate in ``estimates``).
    controllers : sequence of str, optional
        Rows, top to bottom (default: the order of ``estimates``).
    titles : mapping of str to str, optional
        Panel titles by aggregate (default: :data:`AGGREGATE_LABELS`).

    Returns
    -------
    matplotlib.figure.Figure
        Bars: the bootstrap intervals; ticks: the point estimates (lower is better everywhere).
    """
    from matplotlib.figure import Figure

    aggs = list(aggregates) if aggregates is not None else list(estimates.estimates)
    bad = [a for a in aggs if a not in estimates.estimates]
    if bad or not aggs:
        raise ValueError(f"aggregates: names among {list(estimates.estimates)} (got {aggs})")
    names = list(controllers) if controllers is not None else list(estimates.estimates[aggs[0]])
    colors = _colors(names)
    fig = Figure(figsize=(2.6 * len(aggs) + 1.4, 0.4 * len(names) + 1.4))
    axes = np.atleast_1d(fig.subplots(1, len(aggs), sharey=True))
    ys = np.arange(len(names))[::-1]
    for ax, a in zip(axes, aggs):
        per = estimates.estimates[a]
        unknown = [c for c in names if c not in per]
        if unknown:
            raise ValueError(f"controllers: {unknown} not in the estimates")
        edge = _finite_edge([v for c in names for v in (per[c].low, per[c].high, per[c].point)])
        for y, c in zip(ys, names):
            _interval_row(ax, float(y), per[c], colors[c], edge)
        ax.set_title({**AGGREGATE_LABELS, **(titles or {})}.get(a, a), fontsize=9)
        ax.set_xlim(right=edge * 1.08 if edge > 0 else edge + 0.1)
        ax.grid(axis="x", alpha=0.3)
    axes[0].set_yticks(ys, names)
    fig.supxlabel(f"normalised score (lower is better), {100 * estimates.confidence:g} % stratified-bootstrap intervals",
                  fontsize=9)
    fig.tight_layout()
    return fig

"""The report's section on the aggregates across tasks (:mod:`auvtrack.benchmark.across_tasks`).

Rebuilds the estimates and profiles of ``results.json`` -> ``aggregates`` for the figures of
:mod:`auvtrack.benchmark.aggregate_plots` and writes a table and three figures.
"""
from __future__ import annotations

from typing import Any, Mapping, Sequence

import numpy as np

from ..report import fmt
from .aggregate_plots import (AGGREGATE_LABELS, figure_aggregate_intervals, figure_improvement_probabilities,
                              figure_performance_profiles)
from .aggregates import CAPPED, AggregateEstimates, Estimate, Profile

__all__ = ["write_aggregates_section"]


def _estimate(d: Mapping[str, float], level: float) -> Estimate:
    return Estimate(float(d["point"]), float(d["low"]), float(d["high"]), level, np.empty(0))


def _interval(d: Mapping[str, float]) -> str:
    return f"{fmt(d['point'], 3)} [{fmt(d['low'], 3)}, {fmt(d['high'], 3)}]"


def write_aggregates_section(rep: Any, agg: Mapping[str, Any], order: Sequence[str]) -> None:
    """Write the "Aggregates across tasks" section into a report.

    Parameters
    ----------
    rep : auvtrack.report.Report
        The report being written.
    agg : mapping
        ``analysis["aggregates"]`` (:func:`auvtrack.benchmark.across_tasks.aggregate_analysis`).
    order : sequence of str
        Controllers, leaderboard order.
    """
    rep.heading("Aggregates across tasks")
    score = agg["score"]
    rep.paragraph(f"Score: `{score}`, normalised: {agg['normalisation']}. Lower is better; a failed run is `inf`.")
    if agg.get("estimates") is None:
        return
    level = float(agg["confidence"])
    pct = f"{100 * level:g} %"
    capped = agg.get("cap_rule")
    means = (f"the median and mean of the per-cell means of capped scores ({capped}; so one failure does not "
             "make them `inf`, and the failure rate stands next to them)" if capped
             else "the median and mean of the per-cell means")
    rep.paragraph(f"After Agarwal et al. (2021, `rliable`): the interquartile mean (IQM) of every normalised run "
                  f"(finite while at most a quarter of a controller's runs fail), {means}, and the optimality gap "
                  f"at 1 (the mean of max(0, 1 - 1/r)); {pct} stratified-"
                  f"bootstrap intervals ({agg['n_resamples']} replicates, strata = {', '.join(agg['strata'])}: "
                  "the tiers of a task share their seeds), the same resampled seeds for every controller "
                  "(paired). Definitions: `docs/benchmark.md`.")
    est = agg["estimates"]
    aggs = list(est)
    rates = agg.get("failure_rate")
    titles = {a: f"{AGGREGATE_LABELS.get(a, a)}{' (capped)' if capped and a in CAPPED else ''}" for a in aggs}
    rep.table(["controller"] + [f"{titles[a]} [{pct}]" for a in aggs] + (["failure rate"] if rates else []),
              [[c] + [_interval(est[a][c]) for a in aggs] + ([f"{100 * rates[c]:.1f} %"] if rates else [])
               for c in order])
    objects = AggregateEstimates({a: {c: _estimate(est[a][c], level) for c in order} for a in aggs}, level)
    rep.figure(figure_aggregate_intervals(objects, controllers=list(order), titles=titles), "aggregates",
               f"Aggregates of the normalised `{score}` with {pct} stratified-bootstrap intervals")
    profiles = {c: Profile(*(np.asarray(agg["profiles"][c][k], dtype=float)
                             for k in ("taus", "fraction", "low", "high")), level) for c in order}
    rep.figure(figure_performance_profiles(profiles, xlabel=f"normalised {score} tau"), "performance_profiles",
               f"Performance profiles: the fraction of runs with normalised `{score}` <= tau, {pct} bands")
    poi = {(r["x"], r["y"]): _estimate(r, level) for r in agg["improvement"]}
    pos = {c: i for i, c in enumerate(order)}
    pairs = sorted({tuple(sorted((x, y), key=pos.get)) for x, y in poi}, key=lambda p: (pos[p[0]], pos[p[1]]))
    if pairs:
        rep.figure(figure_improvement_probabilities(poi, pairs=pairs), "improvement",
                   f"Probability of improvement P(X < Y) of `{score}` per cell, averaged over the cells, "
                   f"{pct} paired-bootstrap intervals")

"""The benchmark's analysis: per-run metrics, cell statistics, paired tests, ranks and the leaderboard.

Definitions (``docs/benchmark.md``):

* **Per-run metrics** (:func:`derive_metrics`) from the engine's per-axis metrics
  (``docs/metrics.md``, whole run): ``rmse`` = sqrt(sum_a rmse_a^2) (m, the RMS of |e|),
  ``itae`` = sum_a itae_a (m s^2), ``max_error`` = max_a max|e_a| (m), ``settling`` = max_a
  settle_<thr>_a (s; inf if an axis never stays below the threshold), ``energy`` = sum_j
  energy_tau_j and ``tv`` = sum_j tv_tau_j over the inputs u, q, r; a suite's ``[scoring]`` can
  name engine metrics (``xtrack_rmse``, ``act_rate_q``, ...) as criteria too.  A run that did not
  complete (any failure) has ``inf`` in every metric: it is worse than every completed run.
* **Cells** (:func:`cell_statistics`): per tier x task x controller, the failure rate with its
  Wilson interval and the failures by cause, and the median of each metric over *all* seeds
  (failures as ``inf``) with its percentile-bootstrap interval.
* **Scoring rule** (:func:`score_table`): in every (tier, task) cell the controllers are ranked
  on each criterion -- the failure rate and the median of each metric, smaller is better, ties
  sharing their average rank -- and the cell score is the weighted mean of these ranks (weights
  from the suite's ``[scoring]``).  A tier's score is the mean of its cell scores over the
  tasks, the overall score the mean of the tier scores; lower is better, rank 1 is the best.
  A controller that fails everywhere is ranked (last on every criterion), never dropped.
* **Rank uncertainty** (:func:`rank_bootstrap`): the seed indices are resampled with
  replacement (the same resample for every controller and cell: the design is paired) and the
  whole rule is recomputed; the report gives each controller's 95 % interval of its overall rank.
* **Paired comparisons** (:func:`paired_comparisons`): per tier, each pair of controllers on the
  same (task, seed index) pairs: the Wilcoxon signed-rank test and the sign test of each metric
  and the exact sign (McNemar) test of failures, with Holm's adjustment over the pairs of a tier.
"""
from __future__ import annotations

import itertools
import math
import zlib
from typing import Any, Mapping, Sequence

import numpy as np

from . import statistics as st
from .suite import CRITERIA, METRICS

__all__ = ["derive_metrics", "cell_statistics", "pooled_failures", "criteria_table", "score_table",
           "rank_bootstrap", "paired_comparisons", "METRIC_INFO", "metric_info"]

METRIC_INFO: dict[str, tuple[str, str]] = {
    "rmse": ("RMSE of |e|", "m"),
    "itae": ("ITAE, sum over axes", "m s^2"),
    "max_error": ("max |e_a| over axes", "m"),
    "settling": ("settling time (every axis)", "s"),
    "energy": ("control energy, sum over inputs", "N^2 s + (N m)^2 s"),
    "tv": ("total variation of tau per second, sum over inputs", "N/s + N m/s"),
}
"""Metric name -> (description, unit)."""

_ENGINE_INFO: dict[str, str] = {
    "xtrack_rmse": "RMS cross-track (horizontal) distance of the navigation point to the path",
    "xtrack_max": "largest cross-track distance to the path",
    "vtrack_rmse": "RMS vertical distance to the path",
    "along_rmse": "RMS along-path timing error of the navigation point (a virtual-point tracker trails by "
                  "its lever l by design)",
    "act_rms": "RMS position of the {}", "act_max": "largest position of the {}",
    "act_rate": "rate of the {}", "t_act_limit": "time at the limit of the {}",
}
"""Descriptions of the engine metrics a suite can score (``docs/metrics.md``); ``{}``: the actuator."""
_ACTUATORS = {"u": "propeller", "q": "stern planes", "r": "rudder"}


def metric_info(name: str) -> tuple[str, str]:
    """Description and unit of a criterion: a derived metric (:data:`METRIC_INFO`) or an engine metric.

    Parameters
    ----------
    name : str
        A metric name (``rmse``, ``xtrack_rmse``, ``xtrack_rmse_late``, ``act_rate_q``, ...).

    Returns
    -------
    (str, str)
        Description and unit (engine metrics: ``docs/metrics.md``; the name itself when it has
        no description here).
    """
    from ..metrics import METRIC_UNITS

    if name in METRIC_INFO:
        return METRIC_INFO[name]
    base, late = (name[:-5], " (second half of the run)") if name.endswith("_late") else (name, "")
    if base in _ENGINE_INFO:
        return _ENGINE_INFO[base] + late, METRIC_UNITS[base]
    family, _, j = base.rpartition("_")
    if family in _ENGINE_INFO and j in _ACTUATORS:
        return _ENGINE_INFO[family].format(_ACTUATORS[j]), METRIC_UNITS[family]
    unit = next((u for k, u in METRIC_UNITS.items() if family.startswith(k)), "")
    return name, unit


def _rng(seed: int, purpose: str) -> np.random.Generator:
    return np.random.default_rng(np.random.SeedSequence([int(seed), zlib.crc32(purpose.encode())]))


def derive_metrics(runs, settle: str = "5cm", criteria: Sequence[str] = ()):
    """Add the benchmark's per-run metrics (:data:`METRIC_INFO`) to a runs table.

    Parameters
    ----------
    runs : pandas.DataFrame
        One row per run with ``status`` and the engine's metric columns (``rmse_x``, ...).
    settle : str, optional
        Settling threshold label (``5cm``, ``1cm``, ``1mm``).
    criteria : sequence of str, optional
        Engine metric columns the suite scores (its ``[scoring]``): set to ``inf`` for a failed
        run (and a ``nan`` value), like the derived metrics.

    Returns
    -------
    pandas.DataFrame
        A copy with the columns :data:`auvtrack.benchmark.suite.METRICS` (``inf`` for every run
        whose status is not ``ok``).
    """
    df = runs.copy()
    axes, inputs = ("x", "y", "z"), ("u", "q", "r")
    df["rmse"] = np.sqrt(sum(df[f"rmse_{a}"] ** 2 for a in axes))
    df["itae"] = sum(df[f"itae_{a}"] for a in axes)
    df["max_error"] = np.maximum.reduce([df[f"max_abs_{a}"].to_numpy() for a in axes])
    df["settling"] = np.maximum.reduce([df[f"settle_{settle}_{a}"].to_numpy() for a in axes])
    df["energy"] = sum(df[f"energy_tau_{j}"] for j in inputs)
    df["tv"] = sum(df[f"tv_tau_{j}"] for j in inputs)
    bad = (df["status"] != "ok").to_numpy()
    for m in dict.fromkeys((*METRICS, *(c for c in criteria if c != "failure"))):
        col = df[m].to_numpy(dtype=float, copy=True)
        col[bad | np.isnan(col)] = math.inf
        df[m] = col
    return df


def _causes(group) -> dict[str, int]:
    failed = group[group["status"] != "ok"]
    return {str(k): int(v) for k, v in sorted(failed["cause"].replace("", "unknown").value_counts().items())}


def cell_statistics(df, *, seed: int, confidence: float = 0.95, n_resamples: int = 2000,
                    metrics: Sequence[str] = METRICS) -> list[dict]:
    """Failure rate (Wilson interval), causes and bootstrapped medians per tier x task x controller.

    Parameters
    ----------
    df : pandas.DataFrame
        Runs with the derived metrics (:func:`derive_metrics`).
    seed : int
        Suite seed; the bootstrap generator of a cell and metric is
        ``SeedSequence([seed, crc32("bootstrap/<tier>/<task>/<controller>/<metric>")])``.
    confidence : float, optional
        Level of the intervals.
    n_resamples : int, optional
        Bootstrap resamples.
    metrics : sequence of str, optional
        The metrics whose medians are estimated (the suite's weighted criteria).

    Returns
    -------
    list of dict
        One record per cell: ``tier``, ``task``, ``controller``, ``n``, ``failures``,
        ``failure_rate``, ``failure_ci``, ``causes``, and per metric
        ``{"median", "low", "high", "n", "median_ok"}`` (``median_ok``: over completed runs only).
    """
    out = []
    for (tier, task, ctrl), g in df.groupby(["tier", "task", "controller"], sort=False):
        n = len(g)
        k = int((g["status"] != "ok").sum())
        rec: dict[str, Any] = {"tier": tier, "task": task, "controller": ctrl, "n": n, "failures": k,
                               "failure_rate": k / n, "failure_ci": list(st.wilson_interval(k, n, confidence)),
                               "causes": _causes(g)}
        ok = g["status"] == "ok"
        for m in metrics:
            vals = g[m].to_numpy(dtype=float)
            est = st.bootstrap_median(vals, _rng(seed, f"bootstrap/{tier}/{task}/{ctrl}/{m}"),
                                      confidence=confidence, n_resamples=n_resamples)
            d = est.to_dict()
            d["median_ok"] = st.median(vals[ok.to_numpy()]) if ok.any() else math.nan
            rec[m] = d
        out.append(rec)
    return out


def pooled_failures(df, by: Sequence[str], confidence: float = 0.95) -> list[dict]:
    """Failure rate with its Wilson interval and causes, pooled over everything but ``by``.

    Parameters
    ----------
    df : pandas.DataFrame
        Runs.
    by : sequence of str
        Grouping columns, e.g. ``("tier", "controller")``.
    confidence : float, optional
        Level.

    Returns
    -------
    list of dict
        One record per group: the ``by`` values, ``n``, ``failures``, ``failure_rate``,
        ``failure_ci``, ``causes``.
    """
    out = []
    for key, g in df.groupby(list(by), sort=False):
        key = key if isinstance(key, tuple) else (key,)
        n, k = len(g), int((g["status"] != "ok").sum())
        out.append({**dict(zip(by, key)), "n": n, "failures": k, "failure_rate": k / n,
                    "failure_ci": list(st.wilson_interval(k, n, confidence)), "causes": _causes(g)})
    return out


def criteria_table(cells: Sequence[Mapping], metrics: Sequence[str] = METRICS
                   ) -> dict[tuple[str, str], dict[str, dict[str, float]]]:
    """``{(tier, task): {controller: {criterion: value}}}`` from :func:`cell_statistics` records.

    Parameters
    ----------
    cells : sequence of dict
        Cell records.
    metrics : sequence of str, optional
        The metrics of the records (as given to :func:`cell_statistics`).

    Returns
    -------
    dict
        The criteria the scoring rule ranks: the failure rate and each metric's median.
    """
    table: dict[tuple[str, str], dict[str, dict[str, float]]] = {}
    for c in cells:
        row = {"failure": float(c["failure_rate"])} | {m: float(c[m]["median"]) for m in metrics}
        table.setdefault((c["tier"], c["task"]), {})[c["controller"]] = row
    return table


def score_table(table: Mapping[tuple[str, str], Mapping[str, Mapping[str, float]]],
                weights: Mapping[str, float]) -> dict[str, Any]:
    """The scoring rule: ranks per criterion and cell, cell, tier and overall scores and ranks.

    Parameters
    ----------
    table : mapping
        ``{(tier, task): {controller: {criterion: value}}}`` with every criterion of
        ``weights`` (smaller is better; ``nan`` counts as ``inf``).  Every cell must hold the
        same controllers.
    weights : mapping
        Criterion -> weight >= 0 (not all 0).

    Returns
    -------
    dict
        ``cells``: ``{(tier, task): {controller: {"ranks": {criterion: rank}, "score": s}}}``;
        ``tiers``: ``{tier: {controller: {"score", "rank"}}}``; ``overall``:
        ``{controller: {"score", "rank"}}``; ``order``: controllers best first (overall score,
        then overall failure criterion mean, then name).
    """
    crit = [c for c in weights if weights[c] > 0]
    if not crit:
        raise ValueError("weights: at least one criterion needs a weight > 0")
    wsum = sum(weights[c] for c in crit)
    controllers = None
    cells: dict[tuple[str, str], dict[str, dict]] = {}
    for key, per in table.items():
        names = list(per)
        if controllers is None:
            controllers = names
        elif sorted(names) != sorted(controllers):
            raise ValueError(f"cell {key}: controllers {sorted(names)} differ from {sorted(controllers)}")
        ranks = {c: st.average_ranks([per[n][c] for n in controllers]) for c in crit}
        cells[key] = {n: {"ranks": {c: float(ranks[c][i]) for c in crit},
                          "score": sum(weights[c] * float(ranks[c][i]) for c in crit) / wsum}
                      for i, n in enumerate(controllers)}
    if controllers is None:
        raise ValueError("table: no cell")
    tiers: dict[str, dict[str, dict[str, float]]] = {}
    for tier in dict.fromkeys(k[0] for k in cells):
        keys = [k for k in cells if k[0] == tier]
        scores = [float(np.mean([cells[k][n]["score"] for k in keys])) for n in controllers]
        r = st.average_ranks(scores)
        tiers[tier] = {n: {"score": s, "rank": float(ri)} for n, s, ri in zip(controllers, scores, r)}
    overall_scores = [float(np.mean([tiers[t][n]["score"] for t in tiers])) for n in controllers]
    r = st.average_ranks(overall_scores)
    overall = {n: {"score": s, "rank": float(ri)} for n, s, ri in zip(controllers, overall_scores, r)}
    fail_mean = {n: float(np.mean([table[k][n].get("failure", 0.0) for k in table])) for n in controllers}
    order = sorted(controllers, key=lambda n: (overall[n]["score"], fail_mean[n], n))
    return {"cells": cells, "tiers": tiers, "overall": overall, "order": order}


def rank_bootstrap(df, weights: Mapping[str, float], *, seed: int, n_resamples: int = 200,
                   confidence: float = 0.95) -> dict[str, dict[str, float]]:
    """Uncertainty of the overall ranks: the scoring rule on seed-index resamples.

    Each resample draws the seed indices with replacement (one draw shared by every tier, task
    and controller, so the design stays paired), recomputes every cell's failure rate and
    metric medians, and applies :func:`score_table`.

    Parameters
    ----------
    df : pandas.DataFrame
        Runs with the derived metrics; every cell must hold the same seed indices.
    weights : mapping
        The scoring weights.
    seed : int
        Suite seed (generator ``SeedSequence([seed, crc32("rank-bootstrap")])``).
    n_resamples : int, optional
        Resamples.
    confidence : float, optional
        Level of the rank interval.

    Returns
    -------
    dict
        ``{controller: {"low", "high", "p_best", "mean"}}``: the interval of the overall rank
        (order statistics), the fraction of resamples where it ranks first (ties share it) and
        its mean rank.
    """
    seeds = np.sort(df["seed_index"].unique())
    n = seeds.size
    rng = _rng(seed, "rank-bootstrap")
    idx = rng.integers(0, n, size=(n_resamples, n))
    pos = {s: i for i, s in enumerate(seeds)}
    controllers = list(dict.fromkeys(df["controller"]))
    crit = [c for c in weights if weights[c] > 0]
    # per cell and controller: the criteria of every resample
    stats: dict[tuple[str, str], dict[str, dict[str, np.ndarray]]] = {}
    for (tier, task, ctrl), g in df.groupby(["tier", "task", "controller"], sort=False):
        order = np.argsort([pos[s] for s in g["seed_index"]])
        g = g.iloc[order]
        if len(g) != n:
            raise ValueError(f"cell {tier}/{task}/{ctrl}: {len(g)} runs, expected one per seed index ({n})")
        fail = (g["status"] != "ok").to_numpy(dtype=float)
        rec = {"failure": fail[idx].mean(axis=1)}
        for m in crit:
            if m != "failure":
                rec[m] = np.median(g[m].to_numpy(dtype=float)[idx], axis=1)
        stats.setdefault((tier, task), {})[ctrl] = rec
    ranks = np.empty((n_resamples, len(controllers)))
    for b in range(n_resamples):
        table = {k: {c: {q: float(v[q][b]) for q in crit} for c, v in per.items()} for k, per in stats.items()}
        res = score_table(table, {c: weights[c] for c in crit})
        ranks[b] = [res["overall"][c]["rank"] for c in controllers]
    alpha = (1.0 - confidence) / 2.0
    out = {}
    for j, c in enumerate(controllers):
        lo, hi = np.quantile(ranks[:, j], [alpha, 1.0 - alpha], method="inverted_cdf")
        out[c] = {"low": float(lo), "high": float(hi), "p_best": float(np.mean(ranks[:, j] <= 1.5)),
                  "mean": float(ranks[:, j].mean())}
    return out


def paired_comparisons(df, *, criteria: Sequence[str] = CRITERIA, controllers: Sequence[str] | None = None) -> list[dict]:
    """Every pair of controllers in every tier, on the same (task, seed index) pairs.

    For each metric: the Wilcoxon signed-rank test (p-value, rank-biserial correlation) and the
    sign test; for ``failure``: the exact sign test of the discordant pairs (McNemar's exact
    test).  Holm's adjustment is applied per (tier, criterion, test) over the controller pairs.

    Parameters
    ----------
    df : pandas.DataFrame
        Runs with the derived metrics.
    criteria : sequence of str, optional
        ``failure`` and/or metric names.
    controllers : sequence of str, optional
        Order of the controllers (pair ``(a, b)`` has ``a`` first); default: first appearance in ``df``.

    Returns
    -------
    list of dict
        ``tier``, ``a``, ``b``, ``criterion``, ``test`` and the fields of
        :class:`auvtrack.benchmark.statistics.PairedTest`, plus ``p_holm``.  Negative effects and
        ``n_less`` count for ``a`` being better (smaller).
    """
    out: list[dict] = []
    controllers = list(controllers) if controllers is not None else list(dict.fromkeys(df["controller"]))
    for tier, g in df.groupby("tier", sort=False):
        wide = {c: gc.set_index(["task", "seed_index"]).sort_index() for c, gc in g.groupby("controller", sort=False)}
        family: dict[tuple[str, str], list[dict]] = {}
        for a, b in itertools.combinations(controllers, 2):
            if a not in wide or b not in wide:
                continue
            A, B = wide[a].align(wide[b], join="inner", axis=0)
            for crit in criteria:
                if crit == "failure":
                    x = (A["status"] != "ok").to_numpy(dtype=float)
                    y = (B["status"] != "ok").to_numpy(dtype=float)
                    tests = [st.sign_test(x, y)]
                else:
                    x, y = A[crit].to_numpy(dtype=float), B[crit].to_numpy(dtype=float)
                    tests = [st.wilcoxon_test(x, y), st.sign_test(x, y)]
                for t in tests:
                    rec = {"tier": tier, "a": a, "b": b, "criterion": crit, **t.to_dict()}
                    family.setdefault((crit, t.test), []).append(rec)
                    out.append(rec)
        for recs in family.values():
            for rec, p in zip(recs, st.holm([r["p_value"] for r in recs])):
                rec["p_holm"] = float(p)
    return out

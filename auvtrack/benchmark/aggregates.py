"""Aggregates across tasks: IQM, performance profiles and probability of improvement (rliable-style).

The aggregate statistics of Agarwal, Schwarzer, Castro, Courville and Bellemare, "Deep
reinforcement learning at the edge of the statistical precipice", NeurIPS 2021 (the ``rliable``
library), on the benchmark's runs (``docs/benchmark.md``, "Aggregates across tasks"):

* :func:`iqm`, :func:`aggregate_median`, :func:`aggregate_mean`, :func:`optimality_gap`: the
  aggregates of a (runs, tasks) score matrix (their section 4.3, rliable's ``metrics``); the
  median and mean of task means take an optional ``cap`` (:func:`capped`), at which a failure
  counts instead of ``inf``;
* :func:`performance_profile`: the fraction of runs whose score is at most tau (their section
  4.2; Dolan & More 2002);
* :func:`probability_of_improvement`: P(X < Y) + P(X = Y)/2 per task, averaged over the tasks
  (their section 4.3, the Mann-Whitney U statistic over n m);
* :func:`stratified_draws` and :func:`bootstrap_replicates`: the stratified bootstrap (their
  section 4.1): within each stratum the seed indices are resampled with replacement, and **the
  same resampled indices serve every controller** (every controller flies the same seeds with
  common random numbers, so the design is paired);
* :func:`aggregate_estimates`, :func:`performance_profiles`, :func:`improvement_probabilities`:
  each statistic with its percentile-bootstrap interval, from a runs table or from arrays;
* :func:`normalise`: a run's error divided by a reference scale per cell (a reference
  controller's median, or a bound given per cell).

Conventions: **lower is better** (errors, normalised errors); ``nan`` and every metric of a run
whose ``status`` is not ``"ok"`` count as ``+inf`` (a failed run is worse than every completed
one), as in :func:`auvtrack.benchmark.leaderboard.derive_metrics`.  Interval bounds are order
statistics of the replicates (the inverse empirical CDF, NumPy's ``inverted_cdf``, as in
:func:`auvtrack.benchmark.statistics.bootstrap_median`, with the rank computed so that a level of
0.95 means 95 %), so infinite replicates are handled exactly; rliable interpolates linearly
(through ``arch``), which is undefined between two infinities.

Why written here rather than taken from rliable (1.2.0, its latest release, August 2024):
(1) rliable resamples every algorithm independently (``get_interval_estimates`` builds
one bootstrap per algorithm; the probability of improvement resamples X and Y independently),
which throws away the pairing of common random numbers; (2) its ``random_state`` argument has
no effect (``StratifiedBootstrap.update_indices`` draws from NumPy's global generator), so a
seeded ``numpy.random.Generator`` cannot drive it; (3) it pulls in ``arch`` (pinned ``< 8``,
with statsmodels), seaborn and absl-py, and a fresh install (arch 7.2.0 with pandas 3) fails at
import.  SciPy covers the pieces used here: ``scipy.stats.trim_mean`` (the IQM, as in rliable)
and ``scipy.stats.rankdata`` (the U statistic, vectorised over replicates); ``scipy.stats.
bootstrap`` can pair samples (``paired=True``) but has no strata, and interpolates its
quantiles.  ``tests/benchmark/test_aggregates.py`` checks every statistic against rliable's formulas on
hand-computed cases and against rliable's own numbers (``tests/data/rliable_reference.json``,
written by ``benchmarks/rliable_reference.py``).

References
----------
R. Agarwal, M. Schwarzer, P. S. Castro, A. Courville, M. G. Bellemare, "Deep reinforcement
learning at the edge of the statistical precipice", NeurIPS 34 (2021).  E. D. Dolan and J. J.
More, "Benchmarking optimization software with performance profiles", Math. Program. 91 (2002)
201-213.  H. B. Mann and D. R. Whitney, "On a test of whether one of two random variables is
stochastically larger than the other", Ann. Math. Stat. 18 (1947) 50-60.  B. Efron and R. J.
Tibshirani, An Introduction to the Bootstrap, Chapman & Hall, 1993.
"""
from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from typing import Any, Callable, Hashable, Mapping, Sequence

import numpy as np

from . import statistics as st

__all__ = ["AGGREGATES", "CAPPED", "iqm", "capped", "aggregate_median", "aggregate_mean", "optimality_gap",
           "performance_profile",
           "probability_of_improvement", "stratified_draws", "bootstrap_replicates", "Estimate", "Profile",
           "ScoreMatrices", "AggregateEstimates", "score_matrices", "reference_scales", "normalise",
           "aggregate_estimates", "performance_profiles", "improvement_probabilities"]

IQM_TRIM = 0.25
"""Fraction trimmed from each end for the interquartile mean (Agarwal et al. 2021, section 4.3)."""

_CHUNK_ELEMENTS = 2_000_000
"""Largest number of resampled scores held at once per array (replicates are computed in chunks)."""


# ---------------------------------------------------------------------------- input checks
def _scores(a: Any, name: str = "scores") -> np.ndarray:
    """Float copy of a score array with ``nan`` read as ``+inf``; ``-inf`` refused."""
    x = np.array(a, dtype=float)
    x[np.isnan(x)] = math.inf
    if np.any(x == -math.inf):
        raise ValueError(f"{name}: -inf is not a score (lower is better; a failure is +inf or nan)")
    return x


def _matrix(a: Any, name: str = "scores") -> np.ndarray:
    x = _scores(a, name)
    if x.ndim < 2 or x.shape[-1] < 1 or x.shape[-2] < 1:
        raise ValueError(f"{name}: must be shaped (runs, tasks) with at least one of each (got shape {x.shape})")
    return x


def _check_resamples(n_resamples: int) -> None:
    if int(n_resamples) != n_resamples or n_resamples < 1:
        raise ValueError(f"n_resamples: must be an integer >= 1 (got {n_resamples})")


def _check_level(confidence: float, n_resamples: int) -> None:
    if not 0.0 < confidence < 1.0:
        raise ValueError(f"confidence: must be in (0, 1) (got {confidence})")
    _check_resamples(n_resamples)


def _check_gamma(gamma: float) -> float:
    g = float(gamma)
    if not (math.isfinite(g) and g > 0.0):
        raise ValueError(f"gamma: must be finite and > 0 (got {gamma})")
    return g


def _check_taus(taus: Sequence[float]) -> np.ndarray:
    t = np.asarray(taus, dtype=float)
    if t.ndim != 1 or t.size == 0 or not np.all(np.isfinite(t)):
        raise ValueError("taus: must be a non-empty 1-D sequence of finite thresholds")
    return t


# ---------------------------------------------------------------------------- the statistics
def iqm(scores: Any) -> np.ndarray | float:
    """Interquartile mean over every run and task (Agarwal et al. 2021, section 4.3).

    ``scipy.stats.trim_mean(scores, 0.25)`` over the flattened (runs, tasks) matrix, as rliable's
    ``aggregate_iqm``: of the ``n = runs x tasks`` scores sorted ascending, ``k = floor(n / 4)``
    are cut from each end and the rest averaged.  A failed run (``inf``) lands in the top cut
    while at most ``k`` runs fail; with more the IQM is ``inf``.

    Parameters
    ----------
    scores : array_like
        Shape ``(..., runs, tasks)``; leading axes are independent batches (bootstrap
        replicates).  ``nan`` counts as ``+inf``.

    Returns
    -------
    float or numpy.ndarray
        The IQM (dimensionless for normalised scores), one per batch.
    """
    from scipy.stats import trim_mean

    x = _matrix(scores)
    flat = x.reshape(*x.shape[:-2], -1)
    out = trim_mean(flat, IQM_TRIM, axis=-1)
    return float(out) if np.ndim(out) == 0 else np.asarray(out, dtype=float)


def _check_cap(cap: Any) -> float | np.ndarray | None:
    if cap is None:
        return None
    c = np.array(cap, dtype=float)
    if c.ndim > 1 or c.size == 0 or not np.all(np.isfinite(c) & (c > 0.0)):
        raise ValueError(f"cap: must be finite and > 0 (one number, or one per task), or None (got {cap})")
    return float(c) if c.ndim == 0 else c


def capped(scores: Any, cap: Any) -> np.ndarray:
    """Scores with every value above the cap (a failure's ``inf`` too) set to the cap.

    The task means of :func:`aggregate_median` and :func:`aggregate_mean` use capped scores when
    a cap is given: a failed run then counts as the cap, a large finite score, instead of
    ``inf``, which would make every mean it enters ``inf`` and hide everything else about the
    controller.

    Parameters
    ----------
    scores : array_like
        Scores shaped ``(..., tasks)`` (lower is better); ``nan`` counts as ``+inf``.
    cap : float, sequence of float or None
        Finite and > 0 (in the scores' unit): one number, or one per task (the last axis), or
        None for no cap.

    Returns
    -------
    numpy.ndarray
        ``min(s, cap)``, element by element (the scores unchanged, ``nan`` as ``inf``, for None).
    """
    x = _scores(scores)
    c = _check_cap(cap)
    if c is None:
        return x
    if np.ndim(c) == 1 and c.shape[0] != x.shape[-1]:
        raise ValueError(f"cap: need one per task ({x.shape[-1]}), got {c.shape[0]}")
    return np.minimum(x, c)


def aggregate_median(scores: Any, cap: Any = None) -> np.ndarray | float:
    """Median over the tasks of the per-task mean score (rliable's ``aggregate_median``).

    Without a cap, one failed run makes its task's mean ``inf``, and the median is ``inf`` once
    more than half the tasks hold a failure (for an even number of tasks, once the upper middle
    one does).  With a cap, each score enters its task mean as ``min(s, cap)`` (:func:`capped`):
    a failure counts as the cap and the median is finite.

    Parameters
    ----------
    scores : array_like
        Shape ``(..., runs, tasks)``; ``nan`` counts as ``+inf``.
    cap : float, sequence of float or None, optional
        Finite and > 0, one number or one per task: the value of a failure and the largest value
        of a completed run (None: rliable's uncapped statistic).

    Returns
    -------
    float or numpy.ndarray
        The median of the task means, one per batch.
    """
    x = capped(_matrix(scores), cap)
    out = np.median(np.mean(x, axis=-2), axis=-1)
    return float(out) if np.ndim(out) == 0 else out


def aggregate_mean(scores: Any, cap: Any = None) -> np.ndarray | float:
    """Mean over the tasks of the per-task mean score (rliable's ``aggregate_mean``).

    Without a cap, one failed run anywhere makes it ``inf``.  With a cap, each score enters its
    task mean as ``min(s, cap)`` (:func:`capped`): a failure counts as the cap, so the mean is
    finite, and a failure rate f in a task adds at most f times that task's cap to its mean;
    the benchmark states the failure rate next to it.

    Parameters
    ----------
    scores : array_like
        Shape ``(..., runs, tasks)``; ``nan`` counts as ``+inf``.
    cap : float, sequence of float or None, optional
        Finite and > 0, one number or one per task: the value of a failure and the largest value
        of a completed run (None: rliable's uncapped statistic).

    Returns
    -------
    float or numpy.ndarray
        The mean of the task means, one per batch.
    """
    x = capped(_matrix(scores), cap)
    out = np.mean(np.mean(x, axis=-2), axis=-1)
    return float(out) if np.ndim(out) == 0 else out


def optimality_gap(scores: Any, gamma: float = 1.0) -> np.ndarray | float:
    """Optimality gap of errors: the mean of ``max(0, 1 - gamma / s)`` over every run and task.

    rliable's gap (Agarwal et al. 2021, section 4.3) is ``g - mean(min(x, g))`` for a score x
    where higher is better and a target g.  For an error s (lower is better) it is applied to
    the reciprocal score ``x = 1 / s`` with ``g = 1 / gamma`` and scaled by ``gamma``:
    ``gamma (1/gamma - mean(min(1/s, 1/gamma))) = mean(max(0, 1 - gamma / s))``.  A run at or
    below the target error ``gamma`` adds 0, a run at twice the target 1/2, a failed run
    (``inf``) 1: the gap lies in [0, 1] and is finite whatever fails.

    Parameters
    ----------
    scores : array_like
        Non-negative errors shaped ``(..., runs, tasks)``; ``nan`` counts as ``+inf``.
    gamma : float, optional
        Target error, finite and > 0 (1: the reference's median, for :func:`normalise`'d scores).

    Returns
    -------
    float or numpy.ndarray
        The gap in [0, 1], one per batch.
    """
    x = _matrix(scores)
    if np.any(x < 0.0):
        raise ValueError("scores: the optimality gap needs errors >= 0")
    g = _check_gamma(gamma)
    with np.errstate(divide="ignore", over="ignore"):
        per_run = np.maximum(0.0, 1.0 - g / x)
    out = np.mean(per_run, axis=(-2, -1))
    return float(out) if np.ndim(out) == 0 else out


def performance_profile(scores: Any, taus: Sequence[float]) -> np.ndarray:
    """Fraction of runs whose score is at most tau, for each tau (Agarwal et al. 2021, section 4.2).

    ``F(tau) = #{(run, task): s <= tau} / (runs x tasks)``: the empirical distribution function
    of the pooled scores (rliable's run-score distribution, ``1 - mean(s > tau)``; Dolan & More
    2002 with the error ratio in place of the solver's cost ratio).  A failed run (``inf``) is
    above every finite tau.

    Parameters
    ----------
    scores : array_like
        Shape ``(..., runs, tasks)``; ``nan`` counts as ``+inf``.
    taus : sequence of float
        Finite thresholds.

    Returns
    -------
    numpy.ndarray
        Shape ``(..., len(taus))``: fractions in [0, 1].
    """
    x = _matrix(scores)
    t = _check_taus(taus)
    flat = np.sort(x.reshape(-1, x.shape[-2] * x.shape[-1]), axis=1)
    counts = np.stack([np.searchsorted(row, t, side="right") for row in flat])
    return (counts / flat.shape[1]).reshape(*x.shape[:-2], t.size)


def probability_of_improvement(x: Any, y: Any) -> np.ndarray | float:
    """P(X < Y): the probability that a run of X has a smaller error than a run of Y on the same task.

    Per task m, ``P_m = (#{(i, j): x_im < y_jm} + #{x_im = y_jm} / 2) / (n_x n_y)``, the
    Mann-Whitney U statistic of Y over n_x n_y (Mann & Whitney 1947), computed from the average
    ranks of the pooled sample: ``U = R_y - n_y (n_y + 1) / 2``; the result is the mean of P_m over
    the tasks (Agarwal et al. 2021, section 4.3; rliable's ``probability_of_improvement`` on
    higher-is-better scores is this function on ``-x`` and ``-y``).  Lower is better: a value
    above 1/2 says X tends to do better.  Two failures (``inf``) are a tie; ``P(X<Y) + P(Y<X) = 1``.

    Parameters
    ----------
    x, y : array_like
        Scores shaped ``(..., runs_x, tasks)`` and ``(..., runs_y, tasks)`` (same batch axes and
        tasks); ``nan`` counts as ``+inf``.

    Returns
    -------
    float or numpy.ndarray
        The probability in [0, 1], one per batch.
    """
    from scipy.stats import rankdata

    a, b = _matrix(x, "x"), _matrix(y, "y")
    if a.shape[:-2] != b.shape[:-2] or a.shape[-1] != b.shape[-1]:
        raise ValueError(f"x, y: need the same tasks and batch axes (got shapes {a.shape} and {b.shape})")
    nx, ny = a.shape[-2], b.shape[-2]
    ranks = rankdata(np.concatenate([a, b], axis=-2), method="average", axis=-2)
    u = ranks[..., nx:, :].sum(axis=-2) - ny * (ny + 1) / 2.0
    out = np.mean(u / (nx * ny), axis=-1)
    return float(out) if np.ndim(out) == 0 else out


AGGREGATES: dict[str, Callable[..., Any]] = {
    "iqm": iqm,
    "median": aggregate_median,
    "mean": aggregate_mean,
    "optimality_gap": optimality_gap,
}
"""Aggregate name -> statistic of a ``(..., runs, tasks)`` matrix (lower is better for each)."""
CAPPED = ("median", "mean")
"""The aggregates that take a ``cap`` (the averages of task means, which one ``inf`` would make ``inf``)."""


# ---------------------------------------------------------------------------- the bootstrap
def _strata_ids(strata: Sequence[Hashable] | None, n_columns: int) -> np.ndarray:
    if strata is None:
        return np.arange(n_columns)
    labels = list(strata)
    if len(labels) != n_columns:
        raise ValueError(f"strata: need one label per column ({n_columns}), got {len(labels)}")
    first = {s: i for i, s in enumerate(dict.fromkeys(labels))}
    return np.array([first[s] for s in labels])


def stratified_draws(n_runs: int, strata: Sequence[Hashable] | int, n_resamples: int,
                     rng: np.random.Generator) -> np.ndarray:
    """Resampled run indices of a stratified bootstrap, one set per stratum (Agarwal et al. 2021, section 4.1).

    For each stratum in order of first appearance, ``rng.integers(0, n_runs, (n_resamples,
    n_runs))``: the seed indices drawn with replacement within that stratum, independently of
    the other strata.  Columns (cells) of one stratum share its draw, and every controller
    resampled with these draws shares them too (:func:`bootstrap_replicates`).

    Parameters
    ----------
    n_runs : int
        Runs (seed indices) per column, >= 1.
    strata : sequence of hashable, or int
        A stratum label per column (equal labels: one stratum), or the number of columns, each
        its own stratum (rliable's stratification by task).
    n_resamples : int
        Bootstrap replicates, >= 1.
    rng : numpy.random.Generator
        Seeded generator (same state, same draws).

    Returns
    -------
    numpy.ndarray
        Integer array ``(columns, n_resamples, n_runs)``: row indices of every replicate for
        each column.
    """
    if int(n_runs) != n_runs or n_runs < 1:
        raise ValueError(f"n_runs: must be an integer >= 1 (got {n_runs})")
    _check_resamples(n_resamples)
    ids = _strata_ids(None, strata) if isinstance(strata, (int, np.integer)) else _strata_ids(strata, len(strata))
    per_stratum = {s: rng.integers(0, n_runs, size=(int(n_resamples), int(n_runs))) for s in dict.fromkeys(ids.tolist())}
    return np.stack([per_stratum[s] for s in ids.tolist()])


def bootstrap_replicates(statistic: Callable[..., Any], arrays: Sequence[Any], draws: np.ndarray,
                         chunk: int | None = None) -> np.ndarray:
    """The statistic on every replicate, all arrays resampled with the same draws (paired).

    Replicate b of array A is ``A[draws[j, b, i], j]`` for run i and column j: runs are
    resampled within their column's stratum only, and the same indices apply to every array,
    so the pairing of the arrays' rows (the common seeds) is kept.

    Parameters
    ----------
    statistic : callable
        ``statistic(*resampled)`` with each resampled array shaped ``(batch, runs, columns)``,
        returning an array whose first axis is the batch.
    arrays : sequence of array_like
        Score matrices ``(runs, columns)`` of one shape; ``nan`` counts as ``+inf``.
    draws : numpy.ndarray
        ``(columns, n_resamples, runs)`` from :func:`stratified_draws`.
    chunk : int, optional
        Replicates per batch (default: about two million resampled scores per array).

    Returns
    -------
    numpy.ndarray
        ``(n_resamples, ...)``: the statistic of every replicate.
    """
    mats = [_matrix(a) for a in arrays]
    if not mats:
        raise ValueError("arrays: need at least one score matrix")
    shape = mats[0].shape
    if any(m.ndim != 2 or m.shape != shape for m in mats):
        raise ValueError(f"arrays: need 2-D score matrices of one shape (got {[m.shape for m in mats]})")
    d = np.asarray(draws)
    n_runs, n_cols = shape
    if d.ndim != 3 or d.shape[0] != n_cols or d.shape[2] != n_runs:
        raise ValueError(f"draws: need shape (columns={n_cols}, resamples, runs={n_runs}) (got {d.shape})")
    n_resamples = d.shape[1]
    step = int(chunk) if chunk else max(1, _CHUNK_ELEMENTS // (n_runs * n_cols))
    cols = np.arange(n_cols)
    parts = []
    for start in range(0, n_resamples, step):
        rows = np.transpose(d[:, start:start + step, :], (1, 2, 0))  # (batch, runs, columns)
        parts.append(np.asarray(statistic(*(m[rows, cols] for m in mats)), dtype=float))
    return np.concatenate(parts, axis=0)


@dataclass(frozen=True)
class Estimate:
    """A statistic with its percentile-bootstrap interval.

    Attributes
    ----------
    point : float
        The statistic on the data.
    low, high : float
        Interval bounds: order statistics of the replicates (``inf`` allowed).
    confidence : float
        Level of the interval.
    replicates : numpy.ndarray
        The statistic of every bootstrap replicate (same draws as the other estimates of the
        same call: their differences are paired).
    """

    point: float
    low: float
    high: float
    confidence: float
    replicates: np.ndarray = field(repr=False, compare=False)

    def to_dict(self) -> dict[str, float]:
        """``{"point", "low", "high"}``.

        Returns
        -------
        dict
            The estimate and its bounds.
        """
        return {"point": self.point, "low": self.low, "high": self.high}


def _quantiles(rep: np.ndarray, confidence: float) -> tuple[np.ndarray, np.ndarray]:
    """The alpha and 1 - alpha quantiles (alpha = (1 - confidence) / 2) of the replicates as order statistics.

    The order statistic of rank ``k = ceil(q B)`` (the inverse of the empirical CDF, NumPy's
    ``inverted_cdf``), with ``q B`` rounded to 9 decimals first: in binary, ``(1 - 0.95) / 2``
    is 0.025000000000000022, which would turn ``k = 50`` of B = 2000 into 51.
    """
    b = rep.shape[0]
    alpha = (1.0 - confidence) / 2.0
    ranks = [max(1, math.ceil(round(q * b, 9))) for q in (alpha, 1.0 - alpha)]
    srt = np.sort(rep, axis=0)
    return srt[ranks[0] - 1], srt[ranks[1] - 1]


def _estimate(point: float, rep: np.ndarray, confidence: float) -> Estimate:
    lo, hi = _quantiles(rep, confidence)
    return Estimate(float(point), float(lo), float(hi), confidence, rep)


def _difference(a: np.ndarray | float, b: np.ndarray | float) -> np.ndarray:
    """``a - b`` with two infinities a tie (0), as :mod:`auvtrack.benchmark.statistics` does."""
    x, y = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    with np.errstate(invalid="ignore"):
        d = x - y
    return np.where(np.isinf(x) & np.isinf(y) & (x == y), 0.0, d)


# ---------------------------------------------------------------------------- runs tables
@dataclass(frozen=True)
class ScoreMatrices:
    """Scores of every controller as (runs, cells) matrices on common seeds.

    Attributes
    ----------
    scores : dict of str to numpy.ndarray
        Controller -> ``(seeds, cells)`` matrix (``inf`` for failures).
    cells : tuple of tuple
        The cell (values of the cell columns, e.g. ``(task, tier)``) of each column.
    strata : tuple
        The stratum label of each column (cells of one stratum share their resampled seeds).
    seeds : numpy.ndarray
        The seed index of each row.
    """

    scores: dict[str, np.ndarray]
    cells: tuple[tuple, ...]
    strata: tuple
    seeds: np.ndarray


def _key(value: Any) -> tuple:
    return value if isinstance(value, tuple) else (value,)


def _failed_as_inf(runs, score: str) -> np.ndarray:
    if score not in runs.columns:
        raise ValueError(f"score: no column {score!r} in the runs table")
    vals = runs[score].to_numpy(dtype=float, copy=True)
    if "status" in runs.columns:
        vals[(runs["status"] != "ok").to_numpy()] = math.inf
    vals[np.isnan(vals)] = math.inf
    return vals


def score_matrices(runs, score: str, *, cells: Sequence[str] = ("task", "tier"), strata: Sequence[str] = ("task",),
                   controllers: Sequence[str] | None = None) -> ScoreMatrices:
    """One ``(seeds, cells)`` score matrix per controller from a runs table.

    Parameters
    ----------
    runs : pandas.DataFrame
        One row per run with ``controller``, ``seed_index``, ``status``, the ``cells`` columns
        and the score column.  A run whose status is not ``"ok"`` and a ``nan`` score count as
        ``+inf``.
    score : str
        Score column (lower is better), e.g. a :func:`normalise`'d error.
    cells : sequence of str, optional
        Columns whose values make a matrix column (a *cell*): ``("task",)`` or ``("task", "tier")``.
    strata : sequence of str, optional
        Columns, among ``cells``, whose values make a stratum.  The default ``("task",)`` resamples
        the seeds of each task once for all its tiers: in the suite, seed index i of a task has
        the same scenario seed and start offsets in every tier, so its runs in different tiers
        are one correlated observation.  ``strata = cells`` resamples each cell independently.
    controllers : sequence of str, optional
        Controllers and their order (default: all, in order of first appearance).

    Returns
    -------
    ScoreMatrices
        The matrices: rows ordered by seed index, columns by cell, sorted (so that the numbers
        do not depend on the order of the table's rows).
    """
    import pandas as pd

    cells, strata = list(cells), list(strata)
    missing = [c for c in ["controller", "seed_index", *cells] if c not in runs.columns]
    if missing:
        raise ValueError(f"runs: missing columns {missing}")
    if not cells or not set(strata) <= set(cells):
        raise ValueError(f"strata: must be columns among cells {cells} (got {strata})")
    vals = _failed_as_inf(runs, score)
    names = list(controllers) if controllers is not None else list(dict.fromkeys(runs["controller"]))
    if not names:
        raise ValueError("runs: no controller")
    if runs.duplicated(["controller", "seed_index", *cells]).any():
        raise ValueError("runs: more than one run per controller, cell and seed index")
    cell_keys = sorted(set(runs[cells].itertuples(index=False, name=None)), key=lambda k: tuple(map(str, k)))
    seeds = np.sort(runs["seed_index"].unique())
    full = pd.MultiIndex.from_tuples([(s, *k) for s in seeds for k in cell_keys])
    out: dict[str, np.ndarray] = {}
    for name in names:
        mine = (runs["controller"] == name).to_numpy()
        if not mine.any():
            raise ValueError(f"controllers: {name!r} has no run in the table")
        index = pd.MultiIndex.from_frame(runs.loc[mine, ["seed_index", *cells]])
        mat = pd.Series(vals[mine], index=index).reindex(full).to_numpy().reshape(seeds.size, len(cell_keys))
        holes = np.isnan(mat).any(axis=0)
        if holes.any():
            raise ValueError(f"runs: controller {name!r} in cell {cell_keys[int(np.argmax(holes))]} does not have "
                             f"one run per seed index ({seeds.size}): the paired design needs the same seeds everywhere")
        out[name] = mat
    pos = [cells.index(s) for s in strata]
    labels = tuple(tuple(k[i] for i in pos) for k in (_key(c) for c in cell_keys))
    return ScoreMatrices(out, tuple(_key(c) for c in cell_keys), labels, seeds)


def _as_matrices(data, score: str | None, cells: Sequence[str], strata) -> ScoreMatrices:
    if isinstance(data, ScoreMatrices):
        return data
    if hasattr(data, "columns"):  # a pandas DataFrame of runs
        if score is None:
            raise ValueError("score: name the score column of the runs table")
        return score_matrices(data, score, cells=cells, strata=("task",) if strata is None else strata)
    if score is not None:
        raise ValueError("score: only for a runs table (arrays are the scores)")
    mats = {str(k): _matrix(v, f"scores[{k!r}]") for k, v in dict(data).items()}
    if not mats:
        raise ValueError("scores: need at least one controller")
    shapes = sorted({m.shape for m in mats.values()})
    if len(shapes) != 1 or len(shapes[0]) != 2:
        raise ValueError(f"scores: need (runs, tasks) arrays of one shape for the paired design (got {shapes})")
    n_runs, n_cols = shapes[0]
    labels = tuple(range(n_cols)) if strata is None else tuple(strata)
    _strata_ids(labels, n_cols)
    return ScoreMatrices(mats, tuple((j,) for j in range(n_cols)), labels, np.arange(n_runs))


def _draws(sm: ScoreMatrices, n_resamples: int, rng: np.random.Generator) -> np.ndarray:
    n_runs = next(iter(sm.scores.values())).shape[0]
    return stratified_draws(n_runs, list(sm.strata), n_resamples, rng)


# ---------------------------------------------------------------------------- normalisation
def reference_scales(runs, score: str, controller: str, *, cells: Sequence[str] = ("task", "tier")) -> dict[tuple, float]:
    """The reference controller's median score per cell (failures as ``inf``), the normalisation's divisor.

    Parameters
    ----------
    runs : pandas.DataFrame
        Runs with ``controller``, ``status``, the ``cells`` columns and the score column.
    score : str
        Score column.
    controller : str
        The reference controller (e.g. the LOS autopilot).
    cells : sequence of str, optional
        Columns that make a cell.

    Returns
    -------
    dict
        ``{cell tuple: median}``; every median is finite and > 0.

    Raises
    ------
    ValueError
        The reference has no run in a cell, or its median there is 0, ``inf`` (it fails in at
        least half the runs) or undefined.
    """
    cells = list(cells)
    missing = [c for c in ["controller", *cells] if c not in runs.columns]
    if missing:
        raise ValueError(f"runs: missing columns {missing}")
    vals = _failed_as_inf(runs, score)
    is_ref = (runs["controller"] == controller).to_numpy()
    out: dict[tuple, float] = {}
    for key, idx in runs.groupby(cells, sort=False).indices.items():
        k = _key(key)
        mine = idx[is_ref[idx]]
        if mine.size == 0:
            raise ValueError(f"reference: controller {controller!r} has no run in cell {k}")
        m = st.median(vals[mine])
        if not (math.isfinite(m) and m > 0.0):
            raise ValueError(f"reference: median {score} of {controller!r} in cell {k} is {m}; "
                             f"a scale must be finite and > 0")
        out[k] = m
    return out


def normalise(runs, score: str, reference: str | Mapping[Any, float], *,
              cells: Sequence[str] = ("task", "tier")):
    """Normalised score ``s / s_ref(cell)`` of every run (lower is better; 1 = the reference).

    Each run's error is divided by its cell's scale: the median of a reference controller on
    the same cell (:func:`reference_scales`) or a given bound per cell (e.g. a feasibility
    bound).  The ratio is dimensionless, so that cells of different difficulty pool in one
    aggregate (Agarwal et al. 2021 normalise by reference scores in the same way).  A failed
    run (``status`` not ``"ok"``, or a ``nan`` score) gets ``+inf``: it stays worse than every
    completed run, lands in the IQM's top cut while at most a quarter of the pooled runs fail,
    and counts as above every tau in a performance profile.  The reference's own runs are
    normalised too (their median is 1 per cell).

    Parameters
    ----------
    runs : pandas.DataFrame
        Runs with ``status``, the ``cells`` columns, the score column and, for a reference
        controller, ``controller``.
    score : str
        Score column (e.g. ``rmse``).
    reference : str or mapping
        A controller name, or ``{cell: scale}`` with a finite scale > 0 for every cell (a cell
        is a tuple of the ``cells`` values; a plain value when there is one cell column).
    cells : sequence of str, optional
        Columns that make a cell.

    Returns
    -------
    pandas.Series
        The normalised scores, aligned with ``runs``, named ``<score>_norm``.
    """
    import pandas as pd

    cells = list(cells)
    if isinstance(reference, str):
        scales = reference_scales(runs, score, reference, cells=cells)
    else:
        scales = {}
        for k, v in dict(reference).items():
            s = float(v)
            if not (math.isfinite(s) and s > 0.0):
                raise ValueError(f"reference: scale of cell {_key(k)} must be finite and > 0 (got {v})")
            scales[_key(k)] = s
    missing = [c for c in cells if c not in runs.columns]
    if missing:
        raise ValueError(f"runs: missing columns {missing}")
    keys = list(runs[cells].itertuples(index=False, name=None))
    absent = sorted({k for k in keys if k not in scales}, key=str)
    if absent:
        raise ValueError(f"reference: no scale for cells {absent}")
    vals = _failed_as_inf(runs, score)
    return pd.Series(vals / np.array([scales[k] for k in keys]), index=runs.index, name=f"{score}_norm")


# ---------------------------------------------------------------------------- estimates
@dataclass(frozen=True)
class AggregateEstimates:
    """Aggregates of every controller with stratified-bootstrap intervals, from one set of draws.

    Attributes
    ----------
    estimates : dict
        ``{aggregate: {controller: Estimate}}``.
    confidence : float
        Level of the intervals.
    """

    estimates: dict[str, dict[str, Estimate]]
    confidence: float

    def difference(self, aggregate: str, a: str, b: str) -> Estimate:
        """The paired difference ``aggregate(a) - aggregate(b)`` with its interval.

        Both controllers' replicates come from the same resampled seeds, so the difference of
        replicates is a replicate of the difference.  Two infinite values differ by 0.

        Parameters
        ----------
        aggregate : str
            An aggregate of :attr:`estimates`.
        a, b : str
            Controllers.

        Returns
        -------
        Estimate
            Negative values: ``a`` has the smaller (better) aggregate.
        """
        if aggregate not in self.estimates:
            raise ValueError(f"aggregate: one of {sorted(self.estimates)} (got {aggregate!r})")
        per = self.estimates[aggregate]
        for c in (a, b):
            if c not in per:
                raise ValueError(f"controller: one of {sorted(per)} (got {c!r})")
        ea, eb = per[a], per[b]
        return _estimate(float(_difference(ea.point, eb.point)), _difference(ea.replicates, eb.replicates),
                         self.confidence)

    def to_dict(self) -> dict[str, dict[str, dict[str, float]]]:
        """``{aggregate: {controller: {"point", "low", "high"}}}``.

        Returns
        -------
        dict
            Plain numbers (``inf`` allowed).
        """
        return {a: {c: e.to_dict() for c, e in per.items()} for a, per in self.estimates.items()}


def aggregate_estimates(data, rng: np.random.Generator, *, score: str | None = None,
                        cells: Sequence[str] = ("task", "tier"), strata: Sequence | None = None,
                        aggregates: Sequence[str] = tuple(AGGREGATES), gamma: float = 1.0,
                        cap: Any = None, n_resamples: int = 2000,
                        confidence: float = 0.95) -> AggregateEstimates:
    """IQM, median, mean and optimality gap of every controller with stratified-bootstrap intervals.

    One set of stratified draws (:func:`stratified_draws`) resamples every controller: the
    intervals are percentile intervals (order statistics) of the replicates, and
    :meth:`AggregateEstimates.difference` gives paired differences.

    Parameters
    ----------
    data : pandas.DataFrame or mapping of str to array_like
        A runs table (with ``score``) or ``{controller: (runs, tasks) array}``, every array on
        the same seeds (row i: seed i).
    rng : numpy.random.Generator
        Seeded generator (same state, same numbers).
    score : str, optional
        Score column of a runs table (lower is better, e.g. a :func:`normalise`'d error).
    cells : sequence of str, optional
        Cell columns of a runs table (:func:`score_matrices`).
    strata : sequence, optional
        Runs table: stratum columns among ``cells`` (default ``("task",)``).  Arrays: a stratum
        label per column (default: each column its own stratum, as rliable).
    aggregates : sequence of str, optional
        Names among :data:`AGGREGATES`.
    gamma : float, optional
        Target error of the optimality gap.
    cap : float, sequence of float or None, optional
        Cap of the median and mean of task means (:data:`CAPPED`, :func:`capped`), one number or
        one per column: a failure counts as the cap there; None (default): rliable's uncapped
        statistics.
    n_resamples : int, optional
        Bootstrap replicates.
    confidence : float, optional
        Level in (0, 1).

    Returns
    -------
    AggregateEstimates
        Estimates per aggregate and controller.
    """
    _check_level(confidence, n_resamples)
    bad = [a for a in aggregates if a not in AGGREGATES]
    if bad or not aggregates:
        raise ValueError(f"aggregates: names among {list(AGGREGATES)} (got {list(aggregates)})")
    g, c = _check_gamma(gamma), _check_cap(cap)
    sm = _as_matrices(data, score, cells, strata)
    draws = _draws(sm, n_resamples, rng)
    stats = {a: (lambda s, f=AGGREGATES[a]: f(s, g)) if a == "optimality_gap" else
             (lambda s, f=AGGREGATES[a]: f(s, c)) if a in CAPPED else AGGREGATES[a] for a in aggregates}
    out: dict[str, dict[str, Estimate]] = {a: {} for a in aggregates}
    for name, mat in sm.scores.items():
        for a, f in stats.items():
            out[a][name] = _estimate(f(mat), bootstrap_replicates(f, [mat], draws), confidence)
    return AggregateEstimates(out, confidence)


@dataclass(frozen=True)
class Profile:
    """A performance profile with its pointwise stratified-bootstrap band.

    Attributes
    ----------
    taus : numpy.ndarray
        Thresholds.
    fraction : numpy.ndarray
        Fraction of runs with a score at most tau.
    low, high : numpy.ndarray
        Pointwise percentile-bootstrap bounds.
    confidence : float
        Level of the band.
    """

    taus: np.ndarray
    fraction: np.ndarray
    low: np.ndarray
    high: np.ndarray
    confidence: float

    def to_dict(self) -> dict[str, list[float]]:
        """``{"taus", "fraction", "low", "high"}`` as lists.

        Returns
        -------
        dict
            Plain lists.
        """
        return {k: [float(v) for v in getattr(self, k)] for k in ("taus", "fraction", "low", "high")}


def performance_profiles(data, taus: Sequence[float], rng: np.random.Generator, *, score: str | None = None,
                         cells: Sequence[str] = ("task", "tier"), strata: Sequence | None = None,
                         n_resamples: int = 2000, confidence: float = 0.95) -> dict[str, Profile]:
    """Performance profile of every controller with a stratified-bootstrap band.

    Parameters
    ----------
    data : pandas.DataFrame or mapping of str to array_like
        A runs table (with ``score``) or ``{controller: (runs, tasks) array}`` on common seeds.
    taus : sequence of float
        Finite thresholds (normalised errors).
    rng : numpy.random.Generator
        Seeded generator.
    score : str, optional
        Score column of a runs table.
    cells : sequence of str, optional
        Cell columns of a runs table.
    strata : sequence, optional
        As in :func:`aggregate_estimates`.
    n_resamples : int, optional
        Bootstrap replicates.
    confidence : float, optional
        Level in (0, 1).

    Returns
    -------
    dict of str to Profile
        One profile per controller (:func:`performance_profile`), failures above every tau.
    """
    _check_level(confidence, n_resamples)
    t = _check_taus(taus)
    sm = _as_matrices(data, score, cells, strata)
    draws = _draws(sm, n_resamples, rng)
    out = {}
    for name, mat in sm.scores.items():
        rep = bootstrap_replicates(lambda s: performance_profile(s, t), [mat], draws)
        lo, hi = _quantiles(rep, confidence)
        out[name] = Profile(t, performance_profile(mat, t), lo, hi, confidence)
    return out


def improvement_probabilities(data, rng: np.random.Generator, *, score: str | None = None,
                              cells: Sequence[str] = ("task", "tier"), strata: Sequence | None = None,
                              pairs: Sequence[tuple[str, str]] | None = None, n_resamples: int = 2000,
                              confidence: float = 0.95) -> dict[tuple[str, str], Estimate]:
    """P(X < Y) for pairs of controllers, with paired stratified-bootstrap intervals.

    :func:`probability_of_improvement` of X over Y (lower error is better), per cell and
    averaged over the cells; both controllers are resampled with the same seed indices.

    P counts every pair (i, j) of runs, of which the N matched pairs (same seed) weigh 1/N.  A
    paired resample repeats a seed in X and Y together, so on average the matched pairs weigh
    ``(2 - 1/N) / N``: the replicates are centred on ``P + (D - P) / N``, D the matched-seed rate
    ``mean_k([x_k < y_k] + [x_k = y_k] / 2)`` (exact; ``tests/benchmark/test_aggregates.py``).  With the
    suite's 100 seeds the shift is at most 0.01; with ``--quick``'s 3 seeds it can move the
    interval off the point estimate.

    Parameters
    ----------
    data : pandas.DataFrame or mapping of str to array_like
        A runs table (with ``score``) or ``{controller: (runs, tasks) array}`` on common seeds.
    rng : numpy.random.Generator
        Seeded generator.
    score : str, optional
        Score column of a runs table.
    cells : sequence of str, optional
        Cell columns of a runs table (the "tasks" over which P is averaged).
    strata : sequence, optional
        As in :func:`aggregate_estimates`.
    pairs : sequence of (str, str), optional
        Ordered pairs (X, Y); default: every ordered pair of distinct controllers.
    n_resamples : int, optional
        Bootstrap replicates.
    confidence : float, optional
        Level in (0, 1).

    Returns
    -------
    dict
        ``{(X, Y): Estimate}`` of P(X < Y).
    """
    _check_level(confidence, n_resamples)
    sm = _as_matrices(data, score, cells, strata)
    names = list(sm.scores)
    wanted = list(itertools.permutations(names, 2)) if pairs is None else [tuple(p) for p in pairs]
    for x, y in wanted:
        for c in (x, y):
            if c not in sm.scores:
                raise ValueError(f"pairs: controller {c!r} not among {names}")
        if x == y:
            raise ValueError(f"pairs: ({x!r}, {y!r}) compares a controller with itself")
    draws = _draws(sm, n_resamples, rng)
    cache: dict[tuple[str, str], tuple[float, np.ndarray]] = {}
    out = {}
    for x, y in wanted:
        if (y, x) in cache:  # P(X<Y) = 1 - P(Y<X), replicate by replicate
            p, rep = cache[(y, x)]
            p, rep = 1.0 - p, 1.0 - rep
        else:
            p = probability_of_improvement(sm.scores[x], sm.scores[y])
            rep = bootstrap_replicates(probability_of_improvement, [sm.scores[x], sm.scores[y]], draws)
        cache[(x, y)] = (p, rep)
        out[(x, y)] = _estimate(p, rep, confidence)
    return out

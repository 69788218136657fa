"""Statistics of the benchmark (``auvtrack compare``): intervals, paired tests, ranks.

Pure functions of their arguments (a bootstrap takes its generator): no I/O, no global state.
SciPy does the work where it has it:

* failure rates: the Wilson score interval (Wilson 1927; ``scipy.stats.binomtest(...).
  proportion_ci(method="wilson")``);
* medians: the percentile bootstrap (Efron & Tibshirani 1993, ch. 13) with a seeded generator,
  written here because SciPy's ``bootstrap`` interpolates its quantiles, which is undefined when
  a sample holds ``inf`` (a failed run, a settling time that never settled); here every
  quantile is an order statistic, so ``inf`` is simply the largest value;
* paired comparisons: the Wilcoxon signed-rank test (``scipy.stats.wilcoxon``) with the
  matched-pairs rank-biserial correlation as effect size (Kerby 2014), and the sign test
  (``scipy.stats.binomtest``) with the difference of win proportions;
* Holm's step-down adjustment of a family of p-values (Holm 1979);
* average ranks with ties (``scipy.stats.rankdata``).

Conventions: ``nan`` in a metric sample means "no value" and is treated as ``+inf`` by the
callers of this module (a failed run is worse than any completed one); the functions here take
``inf`` as an ordinary, largest value.

References
----------
E. B. Wilson, "Probable inference, the law of succession, and statistical inference", JASA 22
(1927) 209-212.  R. G. Newcombe, "Two-sided confidence intervals for the single proportion:
comparison of seven methods", Stat. Med. 17 (1998) 857-872.  B. Efron and R. J. Tibshirani, An
Introduction to the Bootstrap, Chapman & Hall, 1993.  D. S. Kerby, "The simple difference
formula: an approach to teaching nonparametric correlation", Compr. Psychol. 3 (2014).
S. Holm, "A simple sequentially rejective multiple test procedure", Scand. J. Stat. 6 (1979)
65-70.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np

__all__ = ["wilson_interval", "wilson_halfwidth_max", "median", "bootstrap_median", "MedianEstimate", "PairedTest", "wilcoxon_test",
           "sign_test", "rank_biserial", "holm", "average_ranks", "rank_preserving_differences"]


def wilson_interval(k: int, n: int, confidence: float = 0.95) -> tuple[float, float]:
    """Wilson score interval of a binomial proportion ``k / n``.

    Parameters
    ----------
    k : int
        Successes (here: failed runs), ``0 <= k <= n``.
    n : int
        Trials, ``n >= 1``.
    confidence : float, optional
        Confidence level in (0, 1).

    Returns
    -------
    (float, float)
        Lower and upper bound in [0, 1]:
        ``(p + z^2/2n -+ z sqrt(p(1-p)/n + z^2/4n^2)) / (1 + z^2/n)``, ``p = k/n``,
        ``z`` the ``(1 + confidence)/2`` normal quantile.

    Raises
    ------
    ValueError
        ``n < 1``, ``k`` outside [0, n] or ``confidence`` outside (0, 1).
    """
    from scipy.stats import binomtest

    if n < 1 or not 0 <= k <= n:
        raise ValueError(f"wilson_interval: need 0 <= k <= n and n >= 1 (got k={k}, n={n})")
    if not 0.0 < confidence < 1.0:
        raise ValueError(f"confidence: must be in (0, 1) (got {confidence})")
    ci = binomtest(int(k), int(n)).proportion_ci(confidence_level=confidence, method="wilson")
    return float(ci.low), float(ci.high)


def wilson_halfwidth_max(n: int, confidence: float = 0.95) -> float:
    """Largest half-width ``(high - low) / 2`` of the Wilson interval over every count ``k`` of ``n`` trials.

    Parameters
    ----------
    n : int
        Trials, >= 1.
    confidence : float, optional
        Level.

    Returns
    -------
    float
        The worst case (reached near ``k = n / 2``): how many runs a failure-rate interval of a
        given width needs, whatever the rate turns out to be.
    """
    return max((hi - lo) / 2.0 for lo, hi in (wilson_interval(k, n, confidence) for k in range(n // 2 + 1)))


def _clean(x: Sequence[float]) -> np.ndarray:
    a = np.asarray(x, dtype=float).ravel()
    return np.where(np.isnan(a), np.inf, a)


def median(x: Sequence[float]) -> float:
    """Sample median with ``nan`` read as ``+inf`` (the mean of the two middle values for even sizes).

    Parameters
    ----------
    x : sequence of float
        Sample, at least one value; ``inf`` allowed.

    Returns
    -------
    float
        The median (``inf`` when the middle is ``inf``).
    """
    a = _clean(x)
    if a.size == 0:
        raise ValueError("median: empty sample")
    return float(np.median(a))


@dataclass(frozen=True)
class MedianEstimate:
    """A median with its percentile-bootstrap interval.

    Attributes
    ----------
    median : float
        The sample median (``nan`` read as ``inf``).
    low, high : float
        Bounds of the bootstrap interval (order statistics of the bootstrap distribution).
    n : int
        Sample size.
    confidence : float
        Level of the interval.
    """

    median: float
    low: float
    high: float
    n: int
    confidence: float

    def to_dict(self) -> dict:
        """``{"median", "low", "high", "n"}``."""
        return {"median": self.median, "low": self.low, "high": self.high, "n": self.n}


def bootstrap_median(x: Sequence[float], rng: np.random.Generator, *, confidence: float = 0.95,
                     n_resamples: int = 2000) -> MedianEstimate:
    """Median and percentile-bootstrap interval (Efron & Tibshirani 1993, ch. 13).

    ``n_resamples`` resamples of size n are drawn with replacement by ``rng.integers(0, n,
    (n_resamples, n))``; the interval is the ``(1 - confidence)/2`` and ``(1 + confidence)/2``
    quantiles of their medians, taken as order statistics (NumPy's ``inverted_cdf``), so that
    ``inf`` values are handled exactly.

    Parameters
    ----------
    x : sequence of float
        Sample, at least one value; ``nan`` counts as ``+inf``.
    rng : numpy.random.Generator
        Seeded generator (the result is a function of the sample and the generator state).
    confidence : float, optional
        Level in (0, 1).
    n_resamples : int, optional
        Bootstrap resamples, >= 1.

    Returns
    -------
    MedianEstimate
        The median, the interval's bounds, the sample size and the level.
    """
    a = _clean(x)
    n = a.size
    if n == 0:
        raise ValueError("bootstrap_median: empty sample")
    if not 0.0 < confidence < 1.0:
        raise ValueError(f"confidence: must be in (0, 1) (got {confidence})")
    if n_resamples < 1:
        raise ValueError(f"n_resamples: must be >= 1 (got {n_resamples})")
    med = float(np.median(a))
    if np.all(a == a[0]):  # degenerate: every resample has the same median
        return MedianEstimate(med, med, med, n, confidence)
    idx = rng.integers(0, n, size=(n_resamples, n))
    boot = np.median(a[idx], axis=1)
    alpha = (1.0 - confidence) / 2.0
    lo, hi = np.quantile(boot, [alpha, 1.0 - alpha], method="inverted_cdf")
    return MedianEstimate(med, float(lo), float(hi), n, confidence)


def rank_preserving_differences(a: Sequence[float], b: Sequence[float]) -> np.ndarray:
    """Paired differences ``a - b`` with infinities replaced so that the signed ranks are unchanged.

    ``nan`` counts as ``+inf``.  Both infinite: 0 (a tie).  One infinite: ``+-(1 + 2 max|d|)``
    over the finite differences, larger in magnitude than any finite difference, so that the
    Wilcoxon statistic (a function of the signs and the ranks of ``|d|``) is exactly that of the
    order "an infinite value is worse than any finite one".

    Parameters
    ----------
    a, b : sequence of float
        Paired samples of the same length.

    Returns
    -------
    numpy.ndarray
        Finite differences.
    """
    x, y = _clean(a), _clean(b)
    if x.shape != y.shape:
        raise ValueError(f"paired samples differ in length ({x.size} and {y.size})")
    d = np.zeros_like(x)
    fin = np.isfinite(x) & np.isfinite(y)
    d[fin] = x[fin] - y[fin]
    big = 1.0 + 2.0 * (float(np.max(np.abs(d[fin]))) if fin.any() else 0.0)
    d[np.isinf(x) & np.isfinite(y)] = big
    d[np.isfinite(x) & np.isinf(y)] = -big
    return d


def rank_biserial(d: Sequence[float]) -> float:
    """Matched-pairs rank-biserial correlation of paired differences (Kerby 2014).

    ``r = (R+ - R-) / (R+ + R-)`` with ``R+-`` the sums of the ranks of ``|d|`` (average ranks
    for ties) of the positive and negative differences; zero differences are dropped.  ``r`` is
    in [-1, 1]: +1 when every non-zero difference is positive.

    Parameters
    ----------
    d : sequence of float
        Finite paired differences.

    Returns
    -------
    float
        ``r``, or ``nan`` when every difference is zero.
    """
    from scipy.stats import rankdata

    x = np.asarray(d, dtype=float)
    x = x[x != 0.0]
    if x.size == 0:
        return math.nan
    r = rankdata(np.abs(x))
    rp, rm = float(r[x > 0].sum()), float(r[x < 0].sum())
    return (rp - rm) / (rp + rm)


@dataclass(frozen=True)
class PairedTest:
    """Result of a paired comparison of A against B (negative differences: A smaller).

    Attributes
    ----------
    test : str
        ``"wilcoxon"`` or ``"sign"``.
    n : int
        Pairs compared.
    n_less, n_greater, n_ties : int
        Pairs with A < B, A > B and A = B.
    statistic : float
        The test statistic (Wilcoxon: SciPy's, ``min(R+, R-)``; sign: ``n_less``).
    p_value : float
        Two-sided p-value (``nan`` when every pair is tied).
    effect : float
        Wilcoxon: the rank-biserial correlation of ``a - b`` (negative: A smaller);
        sign: ``(n_greater - n_less) / (n_less + n_greater)`` (same sign convention).
    median_difference : float
        Median of ``a - b`` over the pairs (``inf`` arithmetic as in the samples).
    """

    test: str
    n: int
    n_less: int
    n_greater: int
    n_ties: int
    statistic: float
    p_value: float
    effect: float
    median_difference: float

    def to_dict(self) -> dict:
        """Every field as a plain dict."""
        return dict(self.__dict__)


def _counts(d: np.ndarray) -> tuple[int, int, int]:
    return int((d < 0).sum()), int((d > 0).sum()), int((d == 0).sum())


def _median_difference(a: np.ndarray, b: np.ndarray) -> float:
    x, y = _clean(a), _clean(b)
    with np.errstate(invalid="ignore"):
        diff = x - y
    diff = np.where(np.isinf(x) & np.isinf(y), 0.0, diff)
    return float(np.median(diff)) if diff.size else math.nan


def wilcoxon_test(a: Sequence[float], b: Sequence[float]) -> PairedTest:
    """Two-sided Wilcoxon signed-rank test of paired samples (SciPy, ``zero_method="wilcox"``).

    Infinite values (and ``nan``) are ordered above every finite value through
    :func:`rank_preserving_differences`; zero differences are dropped, as in Wilcoxon's original
    procedure.  The p-value is SciPy's exact null distribution for up to 50 pairs without ties
    or zeros, and its normal approximation with the tie correction otherwise (SciPy's
    ``"auto"`` would enumerate all 2**n sign patterns for small samples with ties: exact, but
    seconds per test).

    Parameters
    ----------
    a, b : sequence of float
        Paired samples (same length): the same seeds run by controllers A and B.

    Returns
    -------
    PairedTest
        With the rank-biserial correlation as effect size.
    """
    from scipy.stats import wilcoxon

    d = rank_preserving_differences(a, b)
    less, greater, ties = _counts(d)
    med = _median_difference(np.asarray(a, float), np.asarray(b, float))
    if less + greater == 0:
        return PairedTest("wilcoxon", d.size, less, greater, ties, math.nan, math.nan, math.nan, med)
    nz = d[d != 0.0]
    exact = nz.size <= 50 and ties == 0 and np.unique(np.abs(nz)).size == nz.size
    res = wilcoxon(d, zero_method="wilcox", alternative="two-sided", method="exact" if exact else "asymptotic")
    return PairedTest("wilcoxon", d.size, less, greater, ties, float(res.statistic), float(res.pvalue),
                      rank_biserial(d), med)


def sign_test(a: Sequence[float], b: Sequence[float]) -> PairedTest:
    """Two-sided exact sign test of paired samples (``scipy.stats.binomtest``, p = 1/2, ties dropped).

    Parameters
    ----------
    a, b : sequence of float
        Paired samples (same length); ``nan`` counts as ``+inf``, two infinities are a tie.

    Returns
    -------
    PairedTest
        ``statistic`` = pairs with A < B; ``effect`` = (A > B minus A < B) / untied pairs.
    """
    from scipy.stats import binomtest

    d = rank_preserving_differences(a, b)
    less, greater, ties = _counts(d)
    med = _median_difference(np.asarray(a, float), np.asarray(b, float))
    m = less + greater
    if m == 0:
        return PairedTest("sign", d.size, less, greater, ties, float(less), math.nan, math.nan, med)
    p = binomtest(less, m, 0.5, alternative="two-sided").pvalue
    return PairedTest("sign", d.size, less, greater, ties, float(less), float(p), (greater - less) / m, med)


def holm(p_values: Sequence[float]) -> np.ndarray:
    """Holm's step-down adjusted p-values (family-wise error control; Holm 1979).

    With the m p-values sorted ascending, ``p~(i) = max_{j <= i} min(1, (m - j + 1) p(j))``;
    ``nan`` entries are left out of the family and stay ``nan``.

    Parameters
    ----------
    p_values : sequence of float
        The family of p-values.

    Returns
    -------
    numpy.ndarray
        Adjusted p-values in the input order.
    """
    p = np.asarray(p_values, dtype=float)
    out = np.full(p.shape, math.nan)
    ok = np.flatnonzero(~np.isnan(p))
    m = ok.size
    if m == 0:
        return out
    order = ok[np.argsort(p[ok], kind="stable")]
    running = 0.0
    for i, idx in enumerate(order):
        running = max(running, min(1.0, (m - i) * p[idx]))
        out[idx] = running
    return out


def average_ranks(values: Sequence[float]) -> np.ndarray:
    """Ranks 1..n, smallest value first, ties sharing their average rank; ``nan`` counts as ``+inf``.

    Parameters
    ----------
    values : sequence of float
        One value per competitor (``inf`` allowed: equal infinities tie).

    Returns
    -------
    numpy.ndarray
        Float ranks (``scipy.stats.rankdata(method="average")``).
    """
    from scipy.stats import rankdata

    return rankdata(_clean(values), method="average").astype(float)

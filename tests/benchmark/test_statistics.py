"""The benchmark's statistics against closed forms, published values, SciPy and their coverage.

Coverage tests compare a Monte Carlo coverage with the interval's *exact* coverage, computed
independently (a sum of binomial probabilities), with a tolerance of three binomial standard
deviations of the Monte Carlo estimate: sqrt(c (1 - c) / M) for M repetitions.  The exact
coverage itself is then compared with the nominal level.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, strategies as hs
from scipy import stats

from auvtrack.benchmark import statistics as st

Z95 = stats.norm.ppf(0.975)


def wilson_closed_form(k: int, n: int, z: float = Z95) -> tuple[float, float]:
    p = k / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return centre - half, centre + half


@given(hs.integers(1, 5000).flatmap(lambda n: hs.tuples(hs.integers(0, n), hs.just(n))))
def test_wilson_matches_the_closed_form(kn):
    k, n = kn
    lo, hi = st.wilson_interval(k, n)
    elo, ehi = wilson_closed_form(k, n)
    assert lo == pytest.approx(max(0.0, elo), abs=1e-12) and hi == pytest.approx(min(1.0, ehi), abs=1e-12)
    assert 0.0 <= lo <= k / n <= hi <= 1.0


@pytest.mark.parametrize("k, n, lo, hi", [  # Newcombe (1998), Table II, method 3 (Wilson score)
    (81, 263, 0.2553, 0.3662), (15, 148, 0.0624, 0.1605), (0, 20, 0.0, 0.1611), (1, 29, 0.0061, 0.1718)])
def test_wilson_reproduces_newcombe_1998(k, n, lo, hi):
    got = st.wilson_interval(k, n)
    assert got[0] == pytest.approx(lo, abs=5e-5) and got[1] == pytest.approx(hi, abs=5e-5)


def test_wilson_refuses_bad_counts():
    for k, n in ((-1, 10), (11, 10), (0, 0)):
        with pytest.raises(ValueError, match="wilson_interval"):
            st.wilson_interval(k, n)


@pytest.mark.parametrize("n, p", [(100, 0.05), (100, 0.3), (400, 0.5), (50, 0.1)])
def test_wilson_coverage_on_synthetic_binomials(n, p):
    ks = np.arange(n + 1)
    covers = np.array([lo <= p <= hi for lo, hi in (st.wilson_interval(int(k), n) for k in ks)])
    exact = float(stats.binom.pmf(ks, n, p)[covers].sum())  # the interval's exact coverage at (n, p)
    M = 4000
    draws = np.random.default_rng(1234).binomial(n, p, size=M)
    mc = float(covers[draws].mean())
    assert abs(mc - exact) <= 3 * math.sqrt(exact * (1 - exact) / M)
    # Brown, Cai & DasGupta (2001): Wilson's coverage stays close to nominal for n p (1 - p) >= 4
    assert abs(exact - 0.95) <= 0.025


def _exact_bootstrap_median_interval(x: np.ndarray, confidence: float) -> tuple[float, float]:
    """The B -> infinity percentile interval of the median of an odd-sized sample of distinct values.

    The resampled median is the order statistic x(j) with P(median* <= x(j)) = P(Bin(n, j/n) >= m + 1).
    """
    n = x.size
    m = n // 2
    xs = np.sort(x)
    cdf = np.array([stats.binom.sf(m, n, j / n) for j in range(1, n + 1)])
    a = (1 - confidence) / 2
    return float(xs[np.argmax(cdf >= a)]), float(xs[np.argmax(cdf >= 1 - a)]), cdf


def test_bootstrap_median_equals_the_exact_bootstrap_interval():
    rng = np.random.default_rng(7)
    x = rng.lognormal(size=41)
    lo, hi, cdf = _exact_bootstrap_median_interval(x, 0.95)
    B = 20000
    # the Monte Carlo bootstrap can only miss the exact order statistic if the CDF is within a few
    # standard errors of the level at a neighbouring point: check that it is not, then require equality
    se = math.sqrt(0.025 * 0.975 / B)
    assert np.min(np.abs(cdf - 0.025)) > 5 * se and np.min(np.abs(cdf - 0.975)) > 5 * se
    est = st.bootstrap_median(x, np.random.default_rng(99), n_resamples=B)
    assert est.median == float(np.median(x))
    assert (est.low, est.high) == (lo, hi)


def test_bootstrap_median_coverage_on_synthetic_data():
    n, M, B = 41, 300, 4000
    true_median = 1.0  # lognormal(0, 1)
    gen = np.random.default_rng(2024)
    hits = 0
    for r in range(M):
        x = gen.lognormal(size=n)
        est = st.bootstrap_median(x, np.random.default_rng(r), n_resamples=B)
        hits += est.low <= true_median <= est.high
    # the B -> infinity interval is [x(l), x(u)] for fixed l, u (they depend on n only), so its exact
    # coverage is P(l <= K <= u - 1) with K = #{x_i < median} ~ Bin(n, 1/2)
    m = n // 2
    cdf = np.array([stats.binom.sf(m, n, j / n) for j in range(1, n + 1)])
    l_, u_ = int(np.argmax(cdf >= 0.025)) + 1, int(np.argmax(cdf >= 0.975)) + 1
    exact = float(stats.binom.cdf(u_ - 1, n, 0.5) - stats.binom.cdf(l_ - 1, n, 0.5))
    mc = hits / M
    assert abs(mc - exact) <= 3 * math.sqrt(exact * (1 - exact) / M)
    assert abs(exact - 0.95) <= 0.03


def test_bootstrap_median_handles_infinities_and_is_seeded():
    x = np.array([0.1, 0.3, np.inf, 0.2, np.nan, 0.5, np.inf])  # nan counts as inf
    a = st.bootstrap_median(x, np.random.default_rng(5), n_resamples=500)
    b = st.bootstrap_median(x, np.random.default_rng(5), n_resamples=500)
    assert a == b
    assert a.median == 0.5 and a.high == math.inf and a.low <= 0.5
    all_inf = st.bootstrap_median([np.inf] * 4, np.random.default_rng(0))
    assert (all_inf.median, all_inf.low, all_inf.high) == (math.inf, math.inf, math.inf)
    const = st.bootstrap_median([2.0] * 5, np.random.default_rng(0))
    assert (const.low, const.high) == (2.0, 2.0)


def test_rank_biserial_hand_example():
    # |d| ranks 1..5; R+ = 1 + 3 + 4 = 8, R- = 2 + 5 = 7: r = (8 - 7) / 15
    assert st.rank_biserial([1.0, -2.0, 3.0, 4.0, -5.0]) == pytest.approx(1 / 15, abs=1e-15)
    assert st.rank_biserial([0.0, 2.0, 1.0]) == 1.0
    assert math.isnan(st.rank_biserial([0.0, 0.0]))


@pytest.mark.parametrize("n", [12, 30, 80])
def test_wilcoxon_matches_scipy(n):
    rng = np.random.default_rng(n)
    a, b = rng.normal(size=n), rng.normal(0.3, 1.0, size=n)
    res = st.wilcoxon_test(a, b)
    method = "exact" if n <= 50 else "asymptotic"
    ref = stats.wilcoxon(a - b, method=method)
    assert res.p_value == pytest.approx(ref.pvalue, rel=1e-12)
    d = a - b
    r = stats.rankdata(np.abs(d))
    rp, rm = r[d > 0].sum(), r[d < 0].sum()
    assert res.statistic == pytest.approx(min(rp, rm), rel=1e-12) == pytest.approx(ref.statistic, rel=1e-12)
    assert res.effect == pytest.approx((rp - rm) / (rp + rm), rel=1e-12)
    assert (res.n_less, res.n_greater, res.n_ties) == (int((d < 0).sum()), int((d > 0).sum()), 0)


def test_wilcoxon_orders_infinities_above_every_finite_value():
    rng = np.random.default_rng(3)
    a, b = rng.normal(size=60), rng.normal(size=60)
    a[:5] = np.inf  # A failed on five seeds
    b[3:8] = np.nan  # B failed on five seeds (two shared with A: ties)
    res = st.wilcoxon_test(a, b)
    # inf - finite = +inf for every such pair (tied at the top), inf - inf a tie (0): the same test on
    # explicit finite differences, with a magnitude larger than any finite difference for the infinite ones
    fa, fb = np.isinf(a), np.isnan(b)
    d = np.where(fa & fb, 0.0, np.where(fa, 1e9, np.where(fb, -1e9, a - b)))
    ref = stats.wilcoxon(d, zero_method="wilcox", method="asymptotic")
    assert res.p_value == pytest.approx(ref.pvalue, rel=1e-12)
    assert res.n_ties == 2 and res.n == 60


def test_sign_test_matches_binomtest():
    a = np.array([1.0, 2.0, 3.0, 4.0, 5.0, 6.0, np.inf, 1.0])
    b = np.array([2.0, 3.0, 1.0, 5.0, 6.0, 7.0, 1.0, 1.0])
    res = st.sign_test(a, b)
    assert (res.n_less, res.n_greater, res.n_ties) == (5, 2, 1)
    assert res.p_value == pytest.approx(stats.binomtest(5, 7, 0.5).pvalue, rel=1e-14)
    assert res.effect == pytest.approx((2 - 5) / 7)


def test_holm_hand_example():
    got = st.holm([0.01, 0.04, 0.03, 0.005, math.nan])
    # sorted: 0.005 x 4 = 0.02, 0.01 x 3 = 0.03, 0.03 x 2 = 0.06, 0.04 x 1 -> max(0.06, 0.04)
    np.testing.assert_allclose(got[:4], [0.03, 0.06, 0.06, 0.02], rtol=1e-14)
    assert math.isnan(got[4])
    assert st.holm([0.6, 0.9]).tolist() == [1.0, 1.0]


def test_average_ranks_ties_and_infinities():
    assert st.average_ranks([0.2, np.inf, 0.1, np.nan, 0.2]).tolist() == [2.5, 4.5, 1.0, 4.5, 2.5]


@pytest.mark.parametrize("n", [1, 7, 100, 400])
def test_wilson_halfwidth_max_is_the_worst_count(n):
    widths = [(hi - lo) / 2 for lo, hi in (wilson_closed_form(k, n) for k in range(n + 1))]
    assert st.wilson_halfwidth_max(n) == pytest.approx(max(widths), rel=1e-12)
    # the worst case is the middle count, and it shrinks like 1 / sqrt(n)
    assert max(widths) == pytest.approx(widths[n // 2], rel=1e-12)

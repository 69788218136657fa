"""Aggregates across tasks against hand-computed cases, brute force, SciPy and rliable's own numbers.

rliable is not installed here: its numbers are in ``tests/data/rliable_reference.json``, written by
``benchmarks/rliable_reference.py`` in a throw-away environment.  rliable counts higher scores as
better; the conversions to errors (lower is better) are those of the module docstring of
:mod:`auvtrack.benchmark.aggregates`: IQM, median and mean unchanged, P(X < Y) = rliable's P(-X > -Y),
profile = 1 - rliable's ``mean(e > tau)``, optimality gap = gamma x rliable's gap of 1/e at 1/gamma.
"""
from __future__ import annotations

import io
import itertools
import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, strategies as hs
from hypothesis.extra import numpy as hnp
from scipy import stats

from auvtrack.benchmark import aggregates as ag
from auvtrack.benchmark import aggregate_plots as ap

INF = math.inf
REF = json.loads((Path(__file__).resolve().parents[1] / "data" / "rliable_reference.json").read_text())


def _arr(rows) -> np.ndarray:
    return np.array([[INF if v is None else v for v in r] for r in rows], dtype=float)


# -------------------------------------------------------------------- hand-computed cases
def test_iqm_by_hand():
    x = np.array([[1.0, 5.0], [2.0, 6.0], [3.0, 7.0], [4.0, 8.0]])
    assert ag.iqm(x) == 4.5                                   # n = 8, cut 2 each end: mean(3, 4, 5, 6)
    x[0, 1] = INF                                             # 1 2 3 4 6 7 8 inf -> mean(3, 4, 6, 7)
    assert ag.iqm(x) == 5.0
    x[1, 1] = x[2, 1] = INF                                   # 3 failures > floor(8 / 4): inf in the middle
    assert ag.iqm(x) == INF
    assert ag.iqm([[1.0], [np.nan], [2.0], [3.0]]) == 2.5     # nan is a failure; n = 4: mean(2, 3)


def test_median_mean_and_gap_by_hand():
    x = np.array([[1.0, 2.0, 10.0], [3.0, 4.0, 20.0]])      # task means 2, 3, 15
    assert ag.aggregate_median(x) == 3.0 and ag.aggregate_mean(x) == pytest.approx(20.0 / 3.0, rel=1e-15)
    x[0, 2] = INF                                             # task means 2, 3, inf
    assert ag.aggregate_median(x) == 3.0 and ag.aggregate_mean(x) == INF
    e = np.array([[0.5, 2.0], [INF, 1.0]])                    # max(0, 1 - 1/e) = 0, 1/2, 1, 0
    assert ag.optimality_gap(e) == 0.375
    assert ag.optimality_gap(e, gamma=2.0) == 0.25            # max(0, 1 - 2/e) = 0, 0, 1, 0
    assert ag.optimality_gap([[0.0]]) == 0.0                  # a perfect run adds nothing


def test_capped_median_and_mean_by_hand():
    """A failed run counts as the cap in its task's mean, a completed run above the cap as the cap."""
    x = np.array([[0.5, 2.0, 1.0],
                  [1.0, INF, 3.0],                            # a failed run
                  [1.5, 30.0, 2.0]])                          # a completed run above the cap
    assert ag.aggregate_mean(x) == INF and ag.aggregate_median(x) == 2.0  # rliable's, uncapped
    # capped at 10: task means (0.5 + 1 + 1.5) / 3 = 1, (2 + 10 + 10) / 3 = 22/3, (1 + 3 + 2) / 3 = 2
    assert ag.aggregate_mean(x, cap=10.0) == pytest.approx((1.0 + 22.0 / 3.0 + 2.0) / 3.0, rel=1e-15)
    assert ag.aggregate_median(x, cap=10.0) == 2.0
    assert ag.aggregate_mean(x, cap=0.5) == 0.5               # every score at or above the cap
    assert ag.aggregate_mean([[np.nan]], cap=4.0) == 4.0      # nan is a failure
    assert ag.capped(x, None)[1, 1] == INF and ag.capped(x, 10.0).max() == 10.0
    # one cap per task: 4, 10, 2 -> task means (0.5 + 1 + 1.5) / 3 = 1, 22/3, (1 + 2 + 2) / 3 = 5/3
    assert ag.aggregate_mean(x, cap=[4.0, 10.0, 2.0]) == pytest.approx((1.0 + 22.0 / 3.0 + 5.0 / 3.0) / 3.0, rel=1e-15)
    assert ag.aggregate_median(x, cap=[4.0, 10.0, 2.0]) == pytest.approx(5.0 / 3.0, rel=1e-15)
    for bad in (0.0, -1.0, INF, np.nan, [1.0, 0.0, 1.0], [[1.0]]):
        with pytest.raises(ValueError, match="cap: must be finite and > 0"):
            ag.aggregate_mean(x, cap=bad)
    with pytest.raises(ValueError, match=r"cap: need one per task \(3\), got 2"):
        ag.aggregate_mean(x, cap=[1.0, 2.0])


def test_capped_estimates_cap_the_means_only():
    """``aggregate_estimates(cap=...)`` caps the median and mean; the IQM and the gap are unchanged."""
    x = {"a": np.array([[0.5, 2.0], [1.0, INF], [1.5, 3.0], [0.7, 2.5]])}
    plain = ag.aggregate_estimates(x, np.random.default_rng(5), n_resamples=200)
    cap = ag.aggregate_estimates(x, np.random.default_rng(5), n_resamples=200, cap=10.0)
    assert plain.estimates["mean"]["a"].point == INF
    assert cap.estimates["mean"]["a"].point == pytest.approx((3.7 / 4 + 17.5 / 4) / 2, rel=1e-15)
    assert np.all(np.isfinite(cap.estimates["mean"]["a"].replicates))
    assert np.all(cap.estimates["mean"]["a"].replicates <= 10.0)
    for a in ("iqm", "optimality_gap"):
        assert cap.estimates[a]["a"].to_dict() == plain.estimates[a]["a"].to_dict()


def test_probability_of_improvement_by_hand():
    # pairs (x, y): 1<2, 1<3, 2=2 (1/2), 2<3 -> 3.5 / 4
    assert ag.probability_of_improvement([[1.0], [2.0]], [[2.0], [3.0]]) == 0.875
    # failures: inf = inf is a tie, 1 < inf twice -> (1/2 + 1/2 + 1 + 1) / 4
    assert ag.probability_of_improvement([[INF], [1.0]], [[INF], [INF]]) == 0.75
    # two tasks: 1 and 0, averaged; runs of X and Y may differ in number
    assert ag.probability_of_improvement([[1.0, 5.0]], [[2.0, 3.0], [4.0, 4.0]]) == 0.5


def test_performance_profile_by_hand():
    s = np.array([[0.5, 2.0], [1.0, INF]])
    assert ag.performance_profile(s, [0.0, 0.5, 1.0, 1.5, 10.0, 1e300]).tolist() == [0.0, 0.25, 0.5, 0.5, 0.75, 0.75]


# -------------------------------------------------------------------- properties
scores_st = hnp.arrays(float, hnp.array_shapes(min_dims=2, max_dims=2, min_side=1, max_side=7),
                       elements=hs.one_of(hs.sampled_from([0.0, 0.5, 1.0, 2.0, INF]),
                                          hs.floats(0.0, 1e3, allow_nan=False)))


@given(scores_st)
def test_iqm_is_the_mean_of_the_middle_order_statistics(s):
    v = np.sort(s.ravel())
    k = v.size // 4                                           # scipy's trim_mean: floor(0.25 n) cut per end
    got = ag.iqm(s)
    assert (got == INF) == (int(np.isinf(v).sum()) > k)
    if math.isfinite(got):
        assert got == pytest.approx(float(np.mean(v[k:v.size - k])), rel=1e-12, abs=1e-300)


@given(scores_st, hs.data())
def test_probability_of_improvement_counts_pairs(x, data):
    y = data.draw(hnp.arrays(float, (data.draw(hs.integers(1, 6)), x.shape[1]),
                             elements=hs.sampled_from([0.0, 0.5, 1.0, 2.0, 3.0, INF])))
    brute = np.mean([np.mean((x[:, m, None] < y[None, :, m]) + 0.5 * (x[:, m, None] == y[None, :, m]))
                     for m in range(x.shape[1])])
    p, q = ag.probability_of_improvement(x, y), ag.probability_of_improvement(y, x)
    assert p == pytest.approx(brute, abs=1e-12) and p + q == pytest.approx(1.0, abs=1e-12)
    fin = np.isfinite(x).all() and np.isfinite(y).all()
    if fin:  # SciPy's U statistic of Y over X (ties 1/2), per task
        u = np.mean([stats.mannwhitneyu(y[:, m], x[:, m]).statistic / (x.shape[0] * y.shape[0])
                     for m in range(x.shape[1])])
        assert p == pytest.approx(u, abs=1e-12)


@given(scores_st, hnp.arrays(float, hs.integers(1, 8), elements=hs.floats(0.0, 10.0)))
def test_profile_is_the_pooled_empirical_distribution(s, taus):
    prof = ag.performance_profile(s, taus)
    brute = [(s <= t).mean() for t in taus]                   # inf <= t is never true
    assert prof.tolist() == pytest.approx(brute, abs=1e-15)
    order = np.argsort(taus)
    assert np.all(np.diff(prof[order]) >= 0)


@given(scores_st, hs.floats(0.01, 100.0))
def test_optimality_gap_is_bounded_and_counts_failures_as_one(s, gamma):
    g = ag.optimality_gap(s, gamma)
    assert 0.0 <= g <= 1.0
    assert g >= np.isinf(s).mean() - 1e-15                    # each failure adds 1 / n


def test_statistics_take_batches():
    rng = np.random.default_rng(0)
    batch = rng.lognormal(size=(3, 6, 4))
    for f in (ag.iqm, ag.aggregate_median, ag.aggregate_mean, ag.optimality_gap):
        assert np.array_equal(f(batch), [f(b) for b in batch])
    assert np.array_equal(ag.probability_of_improvement(batch, batch[::-1]),
                          [ag.probability_of_improvement(a, b) for a, b in zip(batch, batch[::-1])])
    taus = [0.5, 1.0, 2.0]
    assert np.array_equal(ag.performance_profile(batch, taus), [ag.performance_profile(b, taus) for b in batch])


# -------------------------------------------------------------------- rliable's numbers
@pytest.mark.parametrize("case", ["clean", "failing"])
def test_point_estimates_equal_rliable(case):
    data = {c: _arr(v) for c, v in REF[case].items()}
    pts = REF["points"][case]
    for c, e in data.items():
        for name, f in (("iqm", ag.iqm), ("median", ag.aggregate_median), ("mean", ag.aggregate_mean)):
            want = INF if pts[name][c] is None else pts[name][c]
            assert f(e) == pytest.approx(want, rel=1e-12), (name, c)
        for g, want in pts["optimality_gap"][c].items():
            assert ag.optimality_gap(e, float(g)) == pytest.approx(float(g) * want, rel=1e-12)
        assert (1.0 - ag.performance_profile(e, REF["taus"])).tolist() == pytest.approx(pts["profile"][c], abs=1e-15)
    for pair, want in pts["poi"].items():
        x, y = pair.split(",")
        assert ag.probability_of_improvement(data[x], data[y]) == pytest.approx(want, abs=1e-12)


def _legacy_draws(seed: int, runs: int, tasks: int, reps: int, samples: int = 1) -> list[np.ndarray]:
    """rliable's resampled indices: numpy.random.RandomState(seed).choice per replicate and sample."""
    rs = np.random.RandomState(seed)
    out = [np.empty((tasks, reps, runs), dtype=int) for _ in range(samples)]
    for b in range(reps):
        for d in out:
            d[:, b, :] = rs.choice(runs, (runs, tasks), replace=True).T
    return out


def test_bootstrap_replicates_reproduce_rliable_intervals():
    """With rliable's resampled indices, our replicates give rliable's intervals (its linear percentiles)."""
    data = {c: _arr(v) for c, v in REF["clean"].items()}
    n, m, reps = REF["runs"], REF["tasks"], REF["reps"]
    q = [2.5, 97.5]
    funcs = {"iqm": ag.iqm, "median": ag.aggregate_median, "mean": ag.aggregate_mean, "optimality_gap": ag.optimality_gap}
    for key, rec in REF["intervals"]["aggregates"].items():
        name, c = key.split("/")
        (draws,) = _legacy_draws(rec["seed"], n, m, reps)
        rep = ag.bootstrap_replicates(funcs[name], [data[c]], draws)
        assert np.percentile(rep, q).tolist() == pytest.approx(rec["ci"], rel=1e-12), key
    for c, rec in REF["intervals"]["profile"].items():
        (draws,) = _legacy_draws(rec["seed"], n, m, reps)
        rep = 1.0 - ag.bootstrap_replicates(lambda s: ag.performance_profile(s, REF["taus"]), [data[c]], draws)
        lo, hi = np.percentile(rep, q, axis=0)
        assert lo.tolist() == pytest.approx(rec["low"], abs=1e-12) and hi.tolist() == pytest.approx(rec["high"], abs=1e-12)
    cols = np.arange(m)
    for pair, rec in REF["intervals"]["poi"].items():
        # rliable resamples X and Y independently (not paired): two index sets per replicate
        x, y = pair.split(",")
        dx, dy = _legacy_draws(rec["seed"], n, m, reps, samples=2)
        rx = data[x][np.transpose(dx, (1, 2, 0)), cols]
        ry = data[y][np.transpose(dy, (1, 2, 0)), cols]
        rep = ag.probability_of_improvement(rx, ry)
        assert np.percentile(rep, q).tolist() == pytest.approx(rec["ci"], abs=1e-12), pair


# -------------------------------------------------------------------- the stratified bootstrap
def test_draws_are_shared_within_a_stratum_and_independent_across():
    d = ag.stratified_draws(7, ["a", "b", "a", "c"], 50, np.random.default_rng(1))
    assert d.shape == (4, 50, 7) and d.min() >= 0 and d.max() <= 6
    assert np.array_equal(d[0], d[2]) and not np.array_equal(d[0], d[1]) and not np.array_equal(d[1], d[3])
    e = ag.stratified_draws(7, 4, 50, np.random.default_rng(1))          # each column its own stratum
    assert np.array_equal(e[0], d[0]) and np.array_equal(e[1], d[1]) and not np.array_equal(e[2], e[0])


def test_replicates_are_the_statistic_of_the_resampled_matrix():
    rng = np.random.default_rng(2)
    a = rng.lognormal(size=(6, 3))
    d = ag.stratified_draws(6, 3, 40, np.random.default_rng(3))
    rep = ag.bootstrap_replicates(ag.iqm, [a], d)
    manual = [ag.iqm(np.column_stack([a[d[j, b], j] for j in range(3)])) for b in range(40)]
    assert np.array_equal(rep, manual)
    assert np.array_equal(ag.bootstrap_replicates(ag.iqm, [a], d, chunk=1), rep)   # chunking changes nothing


def test_resampling_never_mixes_strata():
    # a constant per task: an unstratified bootstrap would move every task mean; a stratified one cannot
    s = np.tile([1.0, 2.0, 7.0], (10, 1))
    res = ag.aggregate_estimates({"k": s}, np.random.default_rng(0), n_resamples=200)
    for a in ("iqm", "median", "mean"):
        e = res.estimates[a]["k"]
        assert np.all(e.replicates == e.point) and e.low == e.high == e.point


def test_same_generator_state_same_numbers():
    rng = np.random.default_rng(9)
    data = {"a": rng.lognormal(size=(15, 4)), "b": rng.lognormal(size=(15, 4))}
    runs = [ag.aggregate_estimates(data, np.random.default_rng(5), n_resamples=300) for _ in range(2)]
    assert runs[0].to_dict() == runs[1].to_dict()
    other = ag.aggregate_estimates(data, np.random.default_rng(6), n_resamples=300)
    assert other.to_dict() != runs[0].to_dict()
    p1 = ag.improvement_probabilities(data, np.random.default_rng(5), n_resamples=300)
    p2 = ag.improvement_probabilities(data, np.random.default_rng(5), n_resamples=300)
    assert {k: v.to_dict() for k, v in p1.items()} == {k: v.to_dict() for k, v in p2.items()}


def test_pairing_is_kept_across_controllers():
    """Identical scores per seed: every replicate of every difference is 0 and P(X<Y) is 1/2."""
    rng = np.random.default_rng(4)
    s = rng.lognormal(size=(20, 5))
    s[3, 1] = s[11, 4] = INF
    data = {"x": s, "y": s.copy(), "z": 1.5 * s}
    res = ag.aggregate_estimates(data, np.random.default_rng(0), n_resamples=500)
    for a in ag.AGGREGATES:
        d = res.difference(a, "x", "y")
        assert np.all(d.replicates == 0.0) and d.point == d.low == d.high == 0.0
    # a common scale: z is worse in every replicate
    assert np.all(res.difference("iqm", "x", "z").replicates < 0.0)
    poi = ag.improvement_probabilities(data, np.random.default_rng(0), n_resamples=500)
    assert np.all(poi[("x", "y")].replicates == 0.5) and np.all(poi[("y", "x")].replicates == 0.5)
    prof = ag.performance_profiles(data, [0.5, 1.0, 2.0], np.random.default_rng(0), n_resamples=500)
    assert np.array_equal(prof["x"].low, prof["y"].low) and np.array_equal(prof["x"].high, prof["y"].high)
    # the same check fails for independent resampling (rliable's): the test can tell the two apart
    dx, dy = (ag.stratified_draws(20, 5, 500, np.random.default_rng(k)) for k in (1, 2))
    unpaired = ag.bootstrap_replicates(ag.iqm, [s], dx) - ag.bootstrap_replicates(ag.iqm, [s], dy)
    assert np.count_nonzero(unpaired) > 400


def test_paired_resampling_weights_matched_seeds_in_p_by_one_over_n():
    """Exact mean over all N^N resamples of N = 3 seeds: E[P*] = P + (D - P) / N.

    P counts every pair (i, j) of runs; a paired resample repeats seed k in X and in Y together, so
    the matched pairs (k, k) weigh E[c_k^2] = 2 - 1/N instead of 1 (c_k: multinomial counts).  D is
    the matched-seed rate mean_k([x_k < y_k] + [x_k = y_k] / 2).
    """
    x, y = np.array([[1.0], [4.0], [6.0]]), np.array([[2.0], [3.0], [7.0]])
    p = ag.probability_of_improvement(x, y)
    assert p == 5.0 / 9.0                                    # 1<2, 1<3, 1<7, 4<7, 6<7
    d = 2.0 / 3.0                                            # 1<2, not 4<3, 6<7
    draws = np.array(list(itertools.product(range(3), repeat=3))).T[None].transpose(0, 2, 1)
    assert draws.shape == (1, 27, 3)
    rep = ag.bootstrap_replicates(ag.probability_of_improvement, [x, y], draws)
    assert rep.mean() == pytest.approx(p + (d - p) / 3.0, rel=1e-14)


def test_reversed_pairs_are_complements():
    rng = np.random.default_rng(8)
    data = {"a": rng.lognormal(size=(12, 3)), "b": rng.lognormal(0.3, size=(12, 3))}
    poi = ag.improvement_probabilities(data, np.random.default_rng(1), n_resamples=200)
    direct = ag.bootstrap_replicates(ag.probability_of_improvement, [data["b"], data["a"]],
                                     ag.stratified_draws(12, 3, 200, np.random.default_rng(1)))
    assert poi[("b", "a")].replicates == pytest.approx(direct, abs=1e-12)
    assert poi[("a", "b")].point + poi[("b", "a")].point == pytest.approx(1.0, abs=1e-12)


def test_interval_is_the_order_statistic_of_the_replicates():
    rng = np.random.default_rng(12)
    data = {"a": rng.lognormal(size=(30, 4))}
    e = ag.aggregate_estimates(data, np.random.default_rng(2), n_resamples=400, aggregates=["iqm"]).estimates["iqm"]["a"]
    r = np.sort(e.replicates)
    assert e.low == r[math.ceil(0.025 * 400) - 1] and e.high == r[math.ceil(0.975 * 400) - 1]
    assert e.low <= e.point <= e.high


# -------------------------------------------------------------------- runs tables and normalisation
def _runs(seed: int = 0, n: int = 8) -> pd.DataFrame:
    rng = np.random.default_rng(seed)
    rows = []
    for c, scale in (("ref", 1.0), ("good", 0.6), ("bad", 1.8)):
        for task, tscale in (("helix", 1.0), ("circle", 3.0)):
            for tier in ("ideal", "ocean"):
                for s in range(n):
                    rows.append({"controller": c, "task": task, "tier": tier, "seed_index": s, "status": "ok",
                                 "rmse": scale * tscale * (1.0 + 0.3 * rng.random())})
    df = pd.DataFrame(rows)
    df.loc[(df.controller == "bad") & (df.seed_index == 2), "status"] = "failed"   # metric left finite
    return df


def test_score_matrices_from_a_runs_table():
    df = _runs()
    sm = ag.score_matrices(df, "rmse")
    assert sm.cells == (("circle", "ideal"), ("circle", "ocean"), ("helix", "ideal"), ("helix", "ocean"))
    assert sm.strata == (("circle",), ("circle",), ("helix",), ("helix",)) and sm.seeds.tolist() == list(range(8))
    want = df[(df.controller == "good") & (df.task == "circle") & (df.tier == "ocean")].sort_values("seed_index")
    assert sm.scores["good"][:, 1].tolist() == want["rmse"].tolist()
    assert np.all(np.isinf(sm.scores["bad"][2])) and np.isfinite(sm.scores["bad"][[0, 1, 3]]).all()
    shuffled = ag.score_matrices(df.sample(frac=1.0, random_state=1), "rmse", controllers=list(sm.scores))
    assert all(np.array_equal(shuffled.scores[c], sm.scores[c]) for c in sm.scores)   # row order is irrelevant


def test_runs_table_and_arrays_give_the_same_estimates():
    df = _runs()
    sm = ag.score_matrices(df, "rmse")
    a = ag.aggregate_estimates(df, np.random.default_rng(3), score="rmse", n_resamples=200)
    b = ag.aggregate_estimates(sm.scores, np.random.default_rng(3), strata=sm.strata, n_resamples=200)
    assert a.to_dict() == b.to_dict()


def test_tiers_of_a_task_share_their_resampled_seeds():
    df = _runs()
    df.loc[df.tier == "ocean", "rmse"] = df.loc[df.tier == "ideal", "rmse"].to_numpy() + 1.0
    sm = ag.score_matrices(df, "rmse")
    draws = ag.stratified_draws(8, list(sm.strata), 300, np.random.default_rng(0))
    assert sm.cells[2:] == (("helix", "ideal"), ("helix", "ocean"))
    gap = ag.bootstrap_replicates(lambda s: s[..., 3].mean(axis=-1) - s[..., 2].mean(axis=-1), [sm.scores["ref"]], draws)
    assert gap == pytest.approx(np.ones(300), abs=1e-12)       # the same seeds in both tiers, every replicate
    by_cell = ag.score_matrices(df, "rmse", strata=("task", "tier"))
    assert len(set(by_cell.strata)) == 4
    draws = ag.stratified_draws(8, list(by_cell.strata), 300, np.random.default_rng(0))
    gap = ag.bootstrap_replicates(lambda s: s[..., 3].mean(axis=-1) - s[..., 2].mean(axis=-1), [sm.scores["ref"]], draws)
    assert np.ptp(gap) > 0.01                                  # resampled per cell, the tiers' seeds part


def test_runs_table_refuses_unpaired_designs():
    df = _runs()
    with pytest.raises(ValueError, match="'good' in cell \\('circle', 'ideal'\\)"):
        ag.score_matrices(df.drop(df[(df.controller == "good") & (df.task == "circle") & (df.seed_index == 5)].index[:1]),
                          "rmse")
    with pytest.raises(ValueError, match="more than one run"):
        ag.score_matrices(pd.concat([df, df.iloc[:1]]), "rmse")
    with pytest.raises(ValueError, match="score: no column 'itae'"):
        ag.score_matrices(df, "itae")
    with pytest.raises(ValueError, match="strata"):
        ag.score_matrices(df, "rmse", cells=("task",), strata=("tier",))


def test_normalise_by_the_reference_median():
    df = _runs()
    norm = ag.normalise(df, "rmse", "ref")
    assert norm.name == "rmse_norm" and norm.index.equals(df.index)
    for (task, tier), g in df.groupby(["task", "tier"]):
        ref = g[g.controller == "ref"]["rmse"]
        assert norm[g.index].tolist() == pytest.approx((g["rmse"] / np.median(ref)).where(g.status == "ok", INF).tolist())
        assert np.median(norm[ref.index]) == pytest.approx(1.0, rel=1e-15)
    assert np.all(np.isinf(norm[df.status != "ok"]))
    scaled = df.assign(rmse=df["rmse"] * 37.0)                   # dimensionless: units cancel
    assert ag.normalise(scaled, "rmse", "ref").tolist() == pytest.approx(norm.tolist(), rel=1e-14)


def test_normalise_by_given_bounds():
    df = _runs()
    bounds = {("helix", "ideal"): 2.0, ("helix", "ocean"): 2.0, ("circle", "ideal"): 4.0, ("circle", "ocean"): 4.0}
    norm = ag.normalise(df, "rmse", bounds)
    helix = (df.task == "helix") & (df.status == "ok")
    assert norm[helix].tolist() == (df.loc[helix, "rmse"] / 2.0).tolist()
    by_task = ag.normalise(df, "rmse", {"helix": 2.0, "circle": 4.0}, cells=("task",))
    assert by_task.equals(norm)
    with pytest.raises(ValueError, match="no scale for cells"):
        ag.normalise(df, "rmse", {("helix", "ideal"): 1.0})
    with pytest.raises(ValueError, match="finite and > 0"):
        ag.normalise(df, "rmse", {**bounds, ("helix", "ideal"): 0.0})


def test_normalise_refuses_a_reference_without_a_scale():
    df = _runs()
    with pytest.raises(ValueError, match="'los' has no run in cell"):
        ag.normalise(df, "rmse", "los")
    df.loc[(df.controller == "ref") & (df.task == "helix") & (df.tier == "ideal") & (df.seed_index < 5), "status"] = "failed"
    with pytest.raises(ValueError, match=r"median rmse of 'ref' in cell \('helix', 'ideal'\) is inf"):
        ag.normalise(df, "rmse", "ref")


def test_failures_in_the_iqm_of_normalised_scores():
    df = _runs(n=8)
    df["rmse_norm"] = ag.normalise(df, "rmse", "ref")
    sm = ag.score_matrices(df, "rmse_norm")
    # bad fails 4 of its 32 runs: fewer than floor(32 / 4) = 8, so its IQM stays finite
    assert np.isinf(sm.scores["bad"]).sum() == 4 and math.isfinite(ag.iqm(sm.scores["bad"]))
    df.loc[(df.controller == "bad") & (df.seed_index < 3), "status"] = "failed"   # 12 of 32 > 8
    assert ag.iqm(ag.score_matrices(df, "rmse_norm").scores["bad"]) == INF


# -------------------------------------------------------------------- bad input
@pytest.mark.parametrize("call, field", [
    (lambda: ag.aggregate_estimates({"a": np.ones((3, 2))}, np.random.default_rng(0), n_resamples=0), "n_resamples"),
    (lambda: ag.aggregate_estimates({"a": np.ones((3, 2))}, np.random.default_rng(0), confidence=1.0), "confidence"),
    (lambda: ag.aggregate_estimates({"a": np.ones((3, 2))}, np.random.default_rng(0), gamma=0.0), "gamma"),
    (lambda: ag.aggregate_estimates({"a": np.ones((3, 2))}, np.random.default_rng(0), aggregates=["max"]), "aggregates"),
    (lambda: ag.aggregate_estimates({"a": np.ones((3, 2)), "b": np.ones((4, 2))}, np.random.default_rng(0)), "scores"),
    (lambda: ag.aggregate_estimates({"a": np.ones((3, 2))}, np.random.default_rng(0), strata=[0]), "strata"),
    (lambda: ag.aggregate_estimates({"a": np.ones((3, 2))}, np.random.default_rng(0), score="rmse"), "score"),
    (lambda: ag.aggregate_estimates(_runs(), np.random.default_rng(0)), "score"),
    (lambda: ag.performance_profile(np.ones((3, 2)), [1.0, INF]), "taus"),
    (lambda: ag.iqm(np.array([[1.0, -INF]])), "scores"),
    (lambda: ag.iqm(np.ones(3)), "scores"),
    (lambda: ag.optimality_gap(np.array([[-1.0]])), "scores"),
    (lambda: ag.probability_of_improvement(np.ones((3, 2)), np.ones((3, 3))), "x, y"),
    (lambda: ag.improvement_probabilities({"a": np.ones((3, 2))}, np.random.default_rng(0), pairs=[("a", "a")]), "pairs"),
    (lambda: ag.improvement_probabilities({"a": np.ones((3, 2))}, np.random.default_rng(0), pairs=[("a", "q")]), "pairs"),
    (lambda: ag.stratified_draws(0, 2, 10, np.random.default_rng(0)), "n_runs"),
])
def test_bad_input_is_one_line_naming_the_field(call, field):
    with pytest.raises(ValueError) as exc:
        call()
    msg = str(exc.value)
    assert msg.startswith(f"{field}:") and "\n" not in msg


# -------------------------------------------------------------------- figures
def _png(fig) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=50)
    return buf.getvalue()


def test_figures_draw_every_controller_and_pair():
    rng = np.random.default_rng(0)
    s = rng.lognormal(size=(10, 3))
    bad = s * 2.0
    bad[:4] = INF                                                # 12 of 30 failures: an infinite IQM
    data = {"a": s, "b": 1.2 * s, "c": bad}
    est = ag.aggregate_estimates(data, np.random.default_rng(1), n_resamples=100)
    fig = ap.figure_aggregate_intervals(est)
    assert len(fig.axes) == 4 and [t.get_text() for t in fig.axes[0].get_yticklabels()] == ["a", "b", "c"]
    assert any(t.get_text() == "inf" for t in fig.axes[0].texts)            # the infinite IQM is marked
    prof = ag.performance_profiles(data, np.linspace(0.0, 6.0, 25), np.random.default_rng(1), n_resamples=100)
    fig = ap.figure_performance_profiles(prof)
    assert [t.get_text() for t in fig.axes[0].get_legend().get_texts()] == ["a", "b", "c"]
    poi = ag.improvement_probabilities(data, np.random.default_rng(1), n_resamples=100)
    fig = ap.figure_improvement_probabilities(poi)
    assert [t.get_text() for t in fig.axes[0].get_yticklabels()] == ["a < b", "a < c", "b < c"]
    for f in (ap.figure_aggregate_intervals(est), ap.figure_performance_profiles(prof, log_x=False),
              ap.figure_improvement_probabilities(poi, pairs=[("c", "a")])):
        assert _png(f).startswith(b"\x89PNG")
    with pytest.raises(ValueError, match="pairs"):
        ap.figure_improvement_probabilities(poi, pairs=[("a", "z")])


# -------------------------------------------------------------------- docstrings
def _documented():
    import inspect

    for mod in (ag, ap):
        for name in mod.__all__:
            obj = getattr(mod, name)
            if inspect.isfunction(obj):
                yield f"{mod.__name__}.{name}"
            elif inspect.isclass(obj):
                yield from (f"{mod.__name__}.{name}.{m}" for m, f in vars(obj).items()
                            if inspect.isfunction(f) and not m.startswith("_"))


@pytest.mark.parametrize("path", list(_documented()))
def test_public_functions_are_fully_documented(path):
    from numpydoc.validate import validate

    rules = {"GL08", "SS01", "SS03", "SS06", "PR01", "PR02", "PR03", "RT01", "RT03"}   # tests/docs/test_docstrings.py
    assert [f"{c}: {m}" for c, m in validate(path)["errors"] if c in rules] == []

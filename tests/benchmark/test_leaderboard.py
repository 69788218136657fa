"""The benchmark's scoring rule on a hand-made table, per-run metrics, cells, rank intervals, pairs."""
from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from auvtrack.metrics import METRIC_NAMES
from auvtrack.benchmark import leaderboard as lb
from auvtrack.benchmark.suite import METRICS

INF = math.inf
W = {"failure": 2.0, "rmse": 1.0}
# {(tier, task): {controller: {criterion: value}}}; expected scores worked out by hand below
TABLE = {
    ("t1", "k1"): {"A": {"failure": 0.0, "rmse": 0.1}, "B": {"failure": 0.0, "rmse": 0.2},
                   "C": {"failure": 0.5, "rmse": INF}},
    ("t1", "k2"): {"A": {"failure": 0.1, "rmse": 0.3}, "B": {"failure": 0.0, "rmse": 0.3},
                   "C": {"failure": 0.0, "rmse": 0.1}},
    ("t2", "k1"): {"A": {"failure": 0.0, "rmse": 0.1}, "B": {"failure": 0.0, "rmse": 0.1},
                   "C": {"failure": 0.0, "rmse": 0.2}},
    ("t2", "k2"): {"A": {"failure": 0.0, "rmse": 0.05}, "B": {"failure": 0.0, "rmse": 0.2},
                   "C": {"failure": 0.0, "rmse": 0.1}},
}


def test_scoring_rule_on_a_hand_made_table():
    res = lb.score_table(TABLE, W)
    cells = res["cells"]
    # (t1, k1): failure ranks A 1.5, B 1.5, C 3; rmse ranks 1, 2, 3; score = (2 f + r) / 3
    assert cells[("t1", "k1")]["A"]["ranks"] == {"failure": 1.5, "rmse": 1.0}
    assert [cells[("t1", "k1")][c]["score"] for c in "ABC"] == pytest.approx([4 / 3, 5 / 3, 3.0])
    # (t1, k2): failure 3, 1.5, 1.5; rmse 2.5, 2.5, 1
    assert [cells[("t1", "k2")][c]["score"] for c in "ABC"] == pytest.approx([8.5 / 3, 5.5 / 3, 4 / 3])
    assert [cells[("t2", "k1")][c]["score"] for c in "ABC"] == pytest.approx([5.5 / 3, 5.5 / 3, 7 / 3])
    assert [cells[("t2", "k2")][c]["score"] for c in "ABC"] == pytest.approx([5 / 3, 7 / 3, 2.0])
    t1, t2 = res["tiers"]["t1"], res["tiers"]["t2"]
    assert [t1[c]["score"] for c in "ABC"] == pytest.approx([12.5 / 6, 10.5 / 6, 13 / 6])
    assert [t1[c]["rank"] for c in "ABC"] == [2.0, 1.0, 3.0]
    assert [t2[c]["score"] for c in "ABC"] == pytest.approx([10.5 / 6, 12.5 / 6, 13 / 6])
    assert [t2[c]["rank"] for c in "ABC"] == [1.0, 2.0, 3.0]
    ov = res["overall"]
    assert [ov[c]["score"] for c in "ABC"] == pytest.approx([23 / 12, 23 / 12, 13 / 6])
    assert [ov[c]["rank"] for c in "ABC"] == [1.5, 1.5, 3.0]
    # A and B tie on the score: the lower mean failure rate (B: 0, A: 0.025) comes first
    assert res["order"] == ["B", "A", "C"]


def test_a_controller_that_always_fails_is_ranked_last_not_dropped():
    table = {k: {**v, "D": {"failure": 1.0, "rmse": INF}} for k, v in TABLE.items()}
    res = lb.score_table(table, W)
    assert res["order"][-1] == "D" and len(res["order"]) == 4
    # last on every criterion, except the rmse of (t1, k1), where C is infinite too (tie: 3.5)
    assert res["overall"]["D"]["rank"] == 4.0
    assert res["overall"]["D"]["score"] == pytest.approx(((2 * 4 + 3.5) / 3 + 4 + 4 + 4) / 4)
    assert all(res["tiers"][t]["D"]["rank"] == 4.0 for t in ("t1", "t2"))
    # the others keep their order among themselves
    assert res["order"][:3] == ["B", "A", "C"]


def test_scoring_rule_refuses_cells_with_different_controllers():
    bad = dict(TABLE)
    bad[("t2", "k2")] = {"A": {"failure": 0.0, "rmse": 0.1}}
    with pytest.raises(ValueError, match="differ"):
        lb.score_table(bad, W)
    with pytest.raises(ValueError, match="weight"):
        lb.score_table(TABLE, {"failure": 0.0})


def _runs(values: dict[str, list[float]], fail: dict[str, list[bool]] | None = None, tiers=("t1",), tasks=("k1", "k2")):
    """A runs table: one row per (tier, task, seed, controller) with every metric = the given value."""
    rows = []
    for tier in tiers:
        for task in tasks:
            for c, vals in values.items():
                for i, v in enumerate(vals):
                    failed = (fail or {}).get(c, [False] * len(vals))[i]
                    row = {"tier": tier, "task": task, "controller": c, "seed_index": i,
                           "status": "failed" if failed else "ok", "cause": "pitch_limit" if failed else ""}
                    row.update({m: v for m in METRICS})
                    rows.append(row)
    return pd.DataFrame(rows)


def test_derive_metrics_combines_axes_and_marks_failures_infinite():
    base = {m: 0.0 for m in METRIC_NAMES}
    ok = dict(base, rmse_x=3.0, rmse_y=4.0, rmse_z=12.0, itae_x=1.0, itae_y=2.0, itae_z=3.0, max_abs_x=0.5,
              max_abs_y=0.7, max_abs_z=0.1, settle_5cm_x=1.0, settle_5cm_y=INF, settle_5cm_z=2.0,
              energy_tau_u=1.0, energy_tau_q=2.0, energy_tau_r=4.0, tv_tau_u=0.5, tv_tau_q=0.25, tv_tau_r=0.25,
              status="ok")
    df = lb.derive_metrics(pd.DataFrame([ok, dict(ok, status="failed")]), "5cm")
    r = df.iloc[0]
    assert (r.rmse, r.itae, r.max_error, r.settling, r.energy, r.tv) == (13.0, 6.0, 0.7, INF, 7.0, 1.0)
    assert all(df.iloc[1][m] == INF for m in METRICS)


def test_cell_statistics_failure_interval_and_median_with_failures():
    df = _runs({"A": [0.1, 0.2, 0.3, 0.4, 0.5], "B": [1.0, 2.0, 3.0, 4.0, 5.0]},
               {"A": [False, False, False, True, True]})
    df.loc[df["status"] == "failed", METRICS] = INF
    cells = lb.cell_statistics(df, seed=1, n_resamples=300)
    a = next(c for c in cells if c["controller"] == "A" and c["task"] == "k1")
    assert (a["n"], a["failures"], a["failure_rate"], a["causes"]) == (5, 2, 0.4, {"pitch_limit": 2})
    assert a["rmse"]["median"] == 0.3 and a["rmse"]["median_ok"] == 0.2
    assert a["failure_ci"][0] < 0.4 < a["failure_ci"][1]
    assert cells == lb.cell_statistics(df, seed=1, n_resamples=300)  # seeded


def test_rank_bootstrap_of_a_dominant_controller_and_determinism():
    rng = np.random.default_rng(0)
    df = _runs({"A": list(rng.random(20) * 0.1), "B": list(1 + rng.random(20))})
    weights = {c: 1.0 for c in ("failure",) + METRICS}
    r = lb.rank_bootstrap(df, weights, seed=3, n_resamples=60)
    assert r["A"] == {"low": 1.0, "high": 1.0, "p_best": 1.0, "mean": 1.0}
    assert r["B"]["low"] == r["B"]["high"] == 2.0
    assert r == lb.rank_bootstrap(df, weights, seed=3, n_resamples=60)


def test_paired_comparisons_pair_the_same_seeds_and_adjust_per_tier():
    df = _runs({"A": [0.1, 0.2, 0.3, 0.4, 0.5, 0.6], "B": [0.2, 0.3, 0.4, 0.5, 0.6, 0.7],
                "C": [0.3, 0.1, 0.5, 0.2, 0.7, 0.4]}, {"C": [True, False, False, False, False, False]})
    df.loc[df["status"] == "failed", METRICS] = INF
    pairs = lb.paired_comparisons(df.sample(frac=1.0, random_state=1), controllers="ABC")  # row order must not matter
    ab = next(p for p in pairs if (p["a"], p["b"], p["criterion"], p["test"]) == ("A", "B", "rmse", "sign"))
    assert (ab["n"], ab["n_less"], ab["n_greater"]) == (12, 12, 0)
    fail = next(p for p in pairs if (p["a"], p["b"], p["criterion"]) == ("A", "C", "failure"))
    assert (fail["n_less"], fail["n_greater"], fail["n_ties"]) == (2, 0, 10)
    family = [p for p in pairs if p["criterion"] == "rmse" and p["test"] == "wilcoxon"]
    assert len(family) == 3 and all(p["p_holm"] >= p["p_value"] for p in family)

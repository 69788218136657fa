"""Robustness Monte Carlo: sampling distributions, determinism, summaries, the --quick path."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from auvtrack.scenario import load_scenario
from auvtrack.studies import robustness as rb
from auvtrack.studies.registry import all_studies


def test_draws_lie_in_their_ranges_and_are_seeded():
    a = rb.draw_samples(500, 7)
    assert a == rb.draw_samples(500, 7)
    assert a != rb.draw_samples(500, 8)
    for s in a:
        for f in (s.M, s.D, s.C):
            assert -0.3 <= f <= 0.3
        assert 0 <= s.amplitude <= 2 and 0 <= s.phase < 2 * math.pi
        for x, x0, h in zip(s.eta0, rb.ETA0, rb.OFFSET):
            assert abs(x - x0) <= h
        assert s.eta0[3] == 0.0
    # a prefix of a larger draw is not required, but n = 1 must give a valid sample
    assert len(rb.draw_samples(1, 0)) == 1
    with pytest.raises(ValueError, match="n: must be >= 1"):
        rb.draw_samples(0, 0)


def test_draws_are_uniform_ks_and_moments():
    s = rb.draw_samples(3000, 123)
    for name in ("M", "D", "C"):
        x = np.array([getattr(v, name) for v in s])
        assert stats.kstest(x, "uniform", args=(-0.3, 0.6)).pvalue > 1e-3
        assert abs(x.mean()) < 4 * 0.6 / math.sqrt(12 * len(x))
        assert x.var() == pytest.approx(0.6 ** 2 / 12, rel=0.1)
    amp = np.array([v.amplitude for v in s])
    assert stats.kstest(amp, "uniform", args=(0.0, 2.0)).pvalue > 1e-3
    # the three model errors are drawn independently
    m = np.array([[v.M, v.D, v.C] for v in s])
    assert np.all(np.abs(np.corrcoef(m.T)[np.triu_indices(3, 1)]) < 0.1)


def test_sample_scenario_applies_the_draw():
    s = rb.draw_samples(1, 3)[0]
    sc = load_scenario(rb.sample_scenario(s, "remus100", "ftsmc", None, 2.0, 0.002))
    assert sc.vehicle.preset == "remus100"
    assert (sc.uncertainty.M, sc.uncertainty.D, sc.uncertainty.C) == (s.M, s.D, s.C)
    assert sc.initial.eta == s.eta0 and sc.seed == s.index
    assert sc.disturbance[0]["amplitude"] == s.amplitude


def test_summarise_counts_causes_and_quantiles():
    ok = [{"status": "ok", "cause": None, **{q: float(i) for q, _ in rb.QUANTITIES}} for i in range(1, 21)]
    ok[-1]["settle_1cm"] = math.inf
    bad = [{"status": "failed", "cause": c, **{q: 0.0 for q, _ in rb.QUANTITIES}}
           for c in ("pitch_limit", "pitch_limit", "controller")]
    s = rb.summarise(ok + bad)
    assert s["n"] == 23 and s["failed"] == 3 and s["failure_rate"] == pytest.approx(3 / 23)
    assert s["causes"] == {"pitch_limit": 2, "controller": 1}
    assert s["rmse"]["median"] == 10.0 and s["rmse"]["p95"] == 19.0
    assert s["settle_1cm"]["n_inf"] == 1 and s["settle_1cm"]["p95"] == 19.0


def test_quick_study_end_to_end(tmp_path):
    assert "robustness" in all_studies()
    report = rb.run(tmp_path, quick=True)
    text = report.read_text()
    assert "## Vehicle `paper`" in text and "## Vehicle `remus100`" in text
    import pandas as pd
    df = pd.read_csv(tmp_path / "runs.csv")
    n_ctrl = df["controller"].nunique()
    assert len(df) == rb.QUICK.n * len(rb.QUICK.vehicles) * n_ctrl
    # common random numbers: every controller sees the same draws
    assert df.groupby("index")["M"].nunique().max() == 1
    # reproducible
    report2 = rb.run(tmp_path / "again", quick=True)
    df2 = pd.read_csv(tmp_path / "again" / "runs.csv")
    pd.testing.assert_frame_equal(df, df2)
    assert report2.exists()

"""The per-run score: hand-computed cases, failure first, the cap, and the suite's [run_score] table."""
from __future__ import annotations

import math
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from auvtrack.benchmark.scoring import failure_floor, run_score
from auvtrack.benchmark.suite import SuiteError, load_suite
from test_suite_validation import TINY

W, S = {"rmse": 2.0, "energy": 1.0, "tv": 0.0}, {"rmse": 0.5, "energy": 100.0}


def test_hand_computed_scores():
    ok = {"status": "ok", "rmse": 0.25, "energy": 300.0, "tv": 1e9, "t_stop": 10.0}
    assert run_score(ok, W, S, cap=10.0, duration=10.0) == pytest.approx((2 * 0.5 + 1 * 3.0) / 3)
    capped = dict(ok, rmse=50.0)  # 100 scales, capped at 10
    assert run_score(capped, W, S, cap=10.0, duration=10.0) == pytest.approx((2 * 10.0 + 3.0) / 3)
    nan = dict(ok, energy=math.nan)
    assert run_score(nan, W, S, cap=10.0, duration=10.0) == pytest.approx((2 * 0.5 + 10.0) / 3)
    assert run_score({"status": "failed", "t_stop": 2.5}, W, S, cap=10.0, duration=10.0) == pytest.approx(11.75)
    assert run_score({"status": "failed", "t_stop": 0.0}, W, S, cap=10.0, duration=10.0) == pytest.approx(12.0)


@given(st.floats(0, 1e12), st.floats(0, 1e12), st.floats(0, 100), st.floats(0.1, 100), st.floats(0.01, 1e3))
def test_every_failure_scores_worse_than_every_completed_run(rmse, energy, t_stop, duration, cap):
    ok = run_score({"status": "ok", "rmse": rmse, "energy": energy, "tv": 0.0}, W, S, cap=cap, duration=duration)
    bad = run_score({"status": "failed", "t_stop": min(t_stop, duration)}, W, S, cap=cap, duration=duration)
    assert 0.0 <= ok <= cap < failure_floor(cap) <= bad <= cap + 2.0


@given(st.integers(0, 5000), st.integers(0, 5000))
def test_a_later_failure_scores_better(k1, k2):
    t1, t2 = k1 / 100, k2 / 100  # stop times on a 10 ms grid
    a = run_score({"status": "failed", "t_stop": t1}, W, S, cap=10.0, duration=50.0)
    b = run_score({"status": "failed", "t_stop": t2}, W, S, cap=10.0, duration=50.0)
    assert (a < b) == (t1 > t2) and (a == b) == (t1 == t2)


def test_a_weighted_criterion_needs_a_scale():
    with pytest.raises(ValueError, match=r"scales\.tv: missing"):
        run_score({"status": "ok", "rmse": 1.0, "tv": 1.0}, {"rmse": 1.0, "tv": 1.0}, {"rmse": 1.0},
                  cap=10.0, duration=1.0)


@pytest.mark.parametrize("table, expect", [
    ("[run_score.weights]\nrmse = 1.0\n", r"run_score\.scales\.rmse: missing"),
    ("[run_score.weights]\nwobble = 1.0\n", r"run_score\.weights\.wobble: not a criterion"),
    ("[run_score.weights]\nrmse = 1.0\n[run_score.scales]\nrmse = 0.0\n", r"run_score\.scales\.rmse"),
    ("[run_score]\ncap = -1.0\n", r"run_score\.cap"),
])
def test_a_bad_run_score_table_is_one_line(tmp_path, table, expect):
    import re
    path = tmp_path / "bad.toml"
    path.write_text(TINY + table)
    with pytest.raises(SuiteError) as info:
        load_suite(path, check=False)
    assert "\n" not in str(info.value) and re.search(expect, str(info.value)), str(info.value)


def test_the_suite_scores_with_its_table_and_its_task_duration(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text(TINY + "[run_score.weights]\nxtrack_rmse = 1.0\n[run_score.scales]\nxtrack_rmse = 0.5\n")
    suite = load_suite(path, check=False)
    assert suite.run_score({"status": "ok", "xtrack_rmse": 0.25}, "helix") == pytest.approx(0.5)
    assert suite.run_score({"status": "failed", "t_stop": 1.5}, "helix") == pytest.approx(11.5)  # T = 3 s
    path.write_text(TINY)
    with pytest.raises(SuiteError, match=r"run_score\.weights: no criterion"):
        load_suite(path, check=False).run_score({"status": "ok"}, "helix")


def test_the_shipped_v1_scores_runs():
    suite = load_suite("auv-track-v1", check=False)
    assert suite.run_score({"status": "ok", "rmse": 0.5, "max_error": 2.0, "energy": 24000.0, "tv": 300.0},
                           "helix") == pytest.approx(1.0)

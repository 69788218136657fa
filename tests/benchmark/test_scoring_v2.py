"""The v2 leaderboard rule (engine metrics as criteria) and the aggregates across tasks of a comparison."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from auvtrack.benchmark import aggregates as ag
from auvtrack.benchmark import leaderboard as lb
from auvtrack.benchmark.across_tasks import REFERENCE, aggregate_analysis, normalisation
from auvtrack.benchmark.compare import analyse
from auvtrack.benchmark.suite import CRITERIA, METRICS, SuiteError, load_suite
from auvtrack.metrics import METRIC_NAMES
from test_suite_validation import TINY

INF = math.inf
PATH_FIRST = """
[scoring]
failure = 3.0
xtrack_rmse = 2.0
vtrack_rmse = 1.0
rmse = 0.5
itae = 0.0
max_error = 0.0
settling = 0.0
energy = 0.5
tv = 0.5
[run_score.weights]
xtrack_rmse = 1.0
[run_score.scales]
xtrack_rmse = 0.5
"""


def _suite(tmp_path: Path, extra: str = PATH_FIRST):
    path = tmp_path / "tiny.toml"
    path.write_text(TINY + extra)
    return load_suite(path, check=False)


# ------------------------------------------------------------------ the rule
def test_v2_scores_path_following_first_and_keeps_the_virtual_point_and_actuator_use():
    sc = load_suite("auv-track-v2", check=False).file.scoring
    w = sc.weights()
    assert sc.primary() == "xtrack_rmse" and max(w, key=w.get) == "failure"
    metric_w = {c: w[c] for c in sc.metrics()}
    assert w["failure"] == pytest.approx(sum(metric_w.values()) / 2)  # failure: a third of the score, as in v1
    path = w["xtrack_rmse"] + w["vtrack_rmse"]
    assert path == pytest.approx(sum(metric_w.values()) / 2)  # path following: half the metrics' weight
    for c in ("along_rmse", "rmse", "energy", "tv", "act_rate_q", "act_rate_r", "t_act_limit_q", "t_act_limit_r"):
        assert 0 < w[c] < w["xtrack_rmse"], c
    assert set(sc.metrics()) <= set(METRICS) | set(METRIC_NAMES)


def test_v1_rule_is_unchanged():
    sc = load_suite("auv-track-v1", check=False).file.scoring
    assert sc.criteria() == CRITERIA and sc.metrics() == METRICS and sc.primary() == "rmse"
    assert sc.weights() == {"failure": 3.0} | {m: 1.0 for m in METRICS}
    assert list(sc.weights()) == list(CRITERIA)  # v1's order: the scores' floating-point sums are unchanged


@pytest.mark.parametrize("line, expect", [
    ("wobble = 1.0", r"scoring\.wobble: not a criterion"),
    ("xtrack_rmse = -1.0", r"scoring\.xtrack_rmse: must be a finite number >= 0"),
    ("xtrack_rmse = true", r"scoring\.xtrack_rmse: must be a finite number >= 0"),
    ("xtrack_rmse = 1e300", r"scoring\.xtrack_rmse: must be 0 or in \[1e-06, 1e\+06\]"),
])
def test_bad_engine_criteria_are_refused_with_one_line(tmp_path, line, expect):
    path = tmp_path / "bad.toml"
    path.write_text(TINY + "[scoring]\n" + line + "\n")
    with pytest.raises(SuiteError, match=expect) as err:
        load_suite(path, check=False)
    assert "\n" not in str(err.value)


def test_engine_criteria_are_ranked_like_v1_s_on_a_hand_made_table():
    """A beats B on the cross-track error (weight 2) and loses on energy (weight 1): (2*1 + 1*2)/3 vs (2*2 + 1)/3."""
    table = {("t", "k"): {"A": {"xtrack_rmse": 0.1, "energy": 9.0}, "B": {"xtrack_rmse": 0.3, "energy": 1.0}}}
    res = lb.score_table(table, {"xtrack_rmse": 2.0, "energy": 1.0})
    assert res["cells"][("t", "k")]["A"]["score"] == pytest.approx(4 / 3)
    assert res["cells"][("t", "k")]["B"]["score"] == pytest.approx(5 / 3)
    assert res["order"] == ["A", "B"]


def test_derive_metrics_marks_the_scored_engine_metrics_of_failed_runs_infinite():
    base = {m: 0.5 for m in METRIC_NAMES}
    df = lb.derive_metrics(pd.DataFrame([dict(base, status="ok"), dict(base, status="failed"),
                                         dict(base, status="ok", xtrack_rmse=math.nan)]), "5cm",
                           ("failure", "xtrack_rmse"))
    assert df["xtrack_rmse"].tolist() == [0.5, INF, INF]
    assert df["vtrack_rmse"].tolist() == [0.5, 0.5, 0.5]  # not a criterion: as the engine gave it


def _runs(rng: np.random.Generator, seeds: int = 8, fail: tuple = ()) -> pd.DataFrame:
    """LOS errors e > 0 per run; A = e / 2 and B = 3 e on the same seeds (the paired design)."""
    rows = []
    for task in ("helix", "line"):
        for tier in ("calm", "model"):
            e = rng.uniform(0.2, 1.0, seeds)
            for ctrl, k in ((REFERENCE, 1.0), ("A", 0.5), ("B", 3.0)):
                for i in range(seeds):
                    bad = (ctrl, task, tier, i) in fail
                    row = {m: 0.0 for m in METRIC_NAMES}
                    row.update(tier=tier, task=task, controller=ctrl, seed_index=i, status="failed" if bad else "ok",
                               cause="pitch_limit" if bad else "", xtrack_rmse=k * e[i], rmse_x=k * e[i])
                    rows.append(row)
    return pd.DataFrame(rows)


# ------------------------------------------------------------------ aggregates across tasks
def test_normalisation_by_the_los_autopilot_then_the_run_score_scale(tmp_path):
    df = lb.derive_metrics(_runs(np.random.default_rng(0)), "5cm", ("xtrack_rmse",))
    scales, rule = normalisation(df, "xtrack_rmse", [REFERENCE, "A"], 0.5)
    los = df[df["controller"] == REFERENCE]
    assert scales[("helix", "calm")] == np.median(los.loc[(los.task == "helix") & (los.tier == "calm"), "xtrack_rmse"])
    assert REFERENCE in rule
    scales, rule = normalisation(df, "xtrack_rmse", ["A", "B"], 0.5)  # no LOS: the scale, every cell
    assert set(scales.values()) == {0.5} and len(scales) == 4 and "scale 0.5" in rule
    assert normalisation(df, "xtrack_rmse", ["A", "B"], None)[0] is None


def test_aggregates_are_paired_and_hand_checkable(tmp_path):
    """A = LOS / 2 run by run: every aggregate of A is half LOS's, replicate by replicate (one set of draws);
    P(A < B) = 1 with the interval [1, 1], P(A < LOS) the Mann-Whitney rate by brute force; B = 3 LOS: its profile is 0 below tau = 3 * min(LOS)."""
    suite = _suite(tmp_path)
    df = lb.derive_metrics(_runs(np.random.default_rng(1)), "5cm", suite.file.scoring.criteria())
    agg = aggregate_analysis(df, suite, [REFERENCE, "A", "B"])
    assert agg["score"] == "xtrack_rmse" and REFERENCE in agg["normalisation"]
    est = agg["estimates"]
    for a in ("iqm", "median", "mean"):
        for k in ("point", "low", "high"):
            assert est[a]["A"][k] == pytest.approx(est[a][REFERENCE][k] / 2, rel=1e-12), (a, k)
            assert est[a]["B"][k] == pytest.approx(est[a][REFERENCE][k] * 3, rel=1e-12), (a, k)
    norm = ag.normalise(df, "xtrack_rmse", REFERENCE).to_numpy()
    los = norm[(df["controller"] == REFERENCE).to_numpy()]
    assert est["iqm"][REFERENCE]["point"] == pytest.approx(ag.iqm(los.reshape(-1, 1)))
    poi = {(r["x"], r["y"]): r for r in agg["improvement"]}
    assert (poi[("A", "B")]["point"], poi[("A", "B")]["low"], poi[("A", "B")]["high"]) == (1, 1, 1)
    assert poi[("B", "A")]["point"] == 0.0 and len(poi) == 6
    brute = np.mean([np.mean(g.loc[g.controller == "A", "xtrack_rmse"].to_numpy()[:, None]
                             < g.loc[g.controller == REFERENCE, "xtrack_rmse"].to_numpy()[None, :])
                     for _, g in df.groupby(["task", "tier"])])  # no ties: (1/K) sum_c #{a_i < l_j} / N^2
    assert poi[("A", REFERENCE)]["point"] == pytest.approx(brute)
    assert poi[(REFERENCE, "A")]["point"] == pytest.approx(1 - brute)
    prof = agg["profiles"]["B"]
    taus = np.array(prof["taus"])
    below = taus < 3 * los.min()
    assert np.all(np.array(prof["fraction"])[below] == 0.0)
    assert agg == aggregate_analysis(df, suite, [REFERENCE, "A", "B"])  # seeded


def test_failures_are_infinite_and_a_unusable_reference_falls_back_to_the_scale(tmp_path):
    """The LOS autopilot fails 5 of 8 runs of one cell (median inf): every cell is divided by the scale."""
    suite = _suite(tmp_path)
    fail = {(REFERENCE, "line", "calm", i) for i in range(5)}
    df = lb.derive_metrics(_runs(np.random.default_rng(2), fail=fail), "5cm", suite.file.scoring.criteria())
    agg = aggregate_analysis(df, suite, [REFERENCE, "A", "B"])
    assert set(agg["scales"].values()) == {0.5} and "cannot serve" in agg["normalisation"]
    # the median and mean of task means count a failure as where the run score saturates: cap x scale
    # = 10 x 0.5 = 5 of xtrack_rmse, normalised by the cell's divisor (here the scale 0.5): 10
    assert suite.file.run_score.cap == 10.0 and set(agg["cap"].values()) == {10.0}
    assert "`xtrack_rmse` = 5 m" in agg["cap_rule"]
    los = df[df["controller"] == REFERENCE]
    r = np.where(los["status"] == "ok", los["xtrack_rmse"] / 0.5, INF)
    cell_means = pd.Series(np.minimum(r, 10.0)).groupby([los["task"].to_numpy(), los["tier"].to_numpy()]).mean()
    assert cell_means[("line", "calm")] > 5 * 10.0 / 8  # the five failures, at 10 each
    assert agg["estimates"]["mean"][REFERENCE]["point"] == pytest.approx(cell_means.mean(), rel=1e-12)
    assert agg["estimates"]["median"][REFERENCE]["point"] == pytest.approx(cell_means.median(), rel=1e-12)
    assert agg["failure_rate"] == {REFERENCE: 5 / 32, "A": 0.0, "B": 0.0}
    assert math.isfinite(agg["estimates"]["iqm"][REFERENCE]["point"])  # 5 of 32 runs: below a quarter
    assert max(agg["profiles"][REFERENCE]["fraction"]) <= 1 - 5 / 32


def test_analyse_ranks_and_tests_the_weighted_criteria_only(tmp_path):
    suite = _suite(tmp_path)
    df = lb.derive_metrics(_runs(np.random.default_rng(3)), "5cm", suite.file.scoring.criteria())
    res = analyse(df, suite)
    assert res["metrics"] == ["xtrack_rmse", "vtrack_rmse", "rmse", "energy", "tv"]
    assert {p["criterion"] for p in res["paired"]} == {"failure", *res["metrics"]}
    assert "itae" not in res["cells"][0] and res["cells"][0]["xtrack_rmse"]["median"] > 0
    assert res["scores"]["order"][0] == "A"  # the smallest cross-track error, equal elsewhere
    assert res["aggregates"]["estimates"]["iqm"]["A"]["point"] < res["aggregates"]["estimates"]["iqm"]["B"]["point"]


def test_the_weights_in_the_docs_are_the_suite_s():
    """docs/benchmark.md's table of v2's leaderboard weights is the shipped [scoring] table."""
    import re

    text = (Path(__file__).resolve().parents[2] / "docs" / "benchmark.md").read_text()
    table = text[text.index("| criterion | weight | what |"):].split("\n\n")[0]
    doc: dict[str, float] = {}
    for names, weight in re.findall(r"^\s*\| ((?:`\w+`(?:, )?)+) \| ([\d.]+)", table, flags=re.M):
        doc.update({n: float(weight) for n in re.findall(r"`(\w+)`", names)})
    assert doc == load_suite("auv-track-v2", check=False).file.scoring.weights()


# ------------------------------------------------------------------ the report's competitor and failure tables
def test_tuning_and_gain_tables_read_the_presets_provenance():
    from auvtrack.benchmark.report_competitors import TUNING_COLUMNS, gain_rows, tuning_rows
    from auvtrack.benchmark.suite import resolve_controllers
    from auvtrack.control import CONTROLLERS
    from auvtrack.control.gain_presets import get_gain_preset

    entries = resolve_controllers(["pid", "sta"], None, "{kind}_remus100_auv-track-v1")
    rows = {r[0]: r for r in tuning_rows(entries)}
    assert all(len(r) == len(TUNING_COLUMNS) for r in rows.values())
    prov = get_gain_preset("pid_remus100_auv-track-v1").provenance
    assert rows["pid"][2] == prov["tool"] and str(prov["budget_runs"]) in rows["pid"][4]
    assert rows["sta"][1:3] == ["package defaults", "not tuned"]  # no such preset for sta
    gains = gain_rows(entries)
    preset = get_gain_preset("pid_remus100_auv-track-v1").gains
    published = CONTROLLERS["pid"].params.model_validate({"kind": "pid"})
    assert {r[1] for r in gains} == {k for k, v in preset.items() if getattr(published, k) != v}
    assert all(r[0] == "pid" for r in gains)


def test_a_tuned_plugin_shows_its_tuning_and_untuned_competitors_are_named(tmp_path):
    """A plug-in entering ``compare --tune`` with tuned params takes its row from that tuning's provenance
    (not "not tuned", budget 0); ``not_tuned_on`` names every competitor not tuned on the suite compared."""
    import json

    from auvtrack.benchmark.report_competitors import not_tuned_on, tuning_rows
    from auvtrack.benchmark.suite import ControllerEntry, resolve_controllers

    entries = resolve_controllers(["pid", "sta"], None, "{kind}_remus100_auv-track-v1")
    prov = {"tool": "auvtrack tune", "suite": "auv-track-v1 v1", "split": "training", "budget_trials": 8,
            "runs_per_trial": 20, "budget_runs": 160, "train_score": 0.5, "validation_score": 0.6,
            "study_runs": 150, "wall_s": 12.0}
    tuned = ControllerEntry("mine", {"kind": "plugin", "module": "mine.py", "params": {"kp": 2.0}}, "tuned", "d")
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "results.json").write_text(json.dumps({"provenance": prov}))
    untuned = ControllerEntry("raw", {"kind": "plugin", "module": "raw.py"}, "defaults", "e")
    rows = {r[0]: r for r in tuning_rows([*entries, tuned, untuned], tmp_path)}
    assert rows["mine"][2:5] == ["auvtrack tune", "auv-track-v1 v1, training split", "8 trials x 20 runs = 160 runs"]
    assert rows["mine"][6] == "0.5 / 0.6" and "150 runs flown" in rows["mine"][5]
    assert rows["raw"][1:3] == ["plug-in Params defaults", "not tuned"]
    assert tuning_rows([tuned], None)[0][1:3] == ["plug-in Params defaults", "not tuned"]  # no tuning folder
    listed = list(rows.values())
    assert not_tuned_on(listed, "auv-track-v1 v1") == ["sta", "raw"]
    assert not_tuned_on(listed, "auv-track-v2 v1") == ["pid", "sta", "mine", "raw"]
    assert not_tuned_on(listed, "auv-track-v1 v2") == ["pid", "sta", "mine", "raw"]  # another version


def test_why_it_failed_counts_add_up_and_unknown_causes_show():
    from auvtrack.benchmark.report_competitors import failure_cause_rows

    df = pd.DataFrame({"tier": ["a"] * 5 + ["b"] * 2, "controller": ["x", "x", "x", "y", "y", "x", "x"],
                       "status": ["failed", "failed", "ok", "failed", "ok", "ok", "ok"],
                       "cause": ["pitch_limit", "", "", "divergence", "", "", ""]})
    head, rows = failure_cause_rows(lb.pooled_failures(df, ("tier", "controller")))
    assert head == ["tier", "controller", "failed", "divergence", "pitch_limit", "unknown"]
    assert rows == [["a", "x", "2/3", 0, 1, 1], ["a", "y", "1/2", 1, 0, 0]]  # tier b: no failure, no row


def test_a_v2_like_comparison_end_to_end(tmp_path):
    """A tiny suite with v2's kind of [scoring]: the report ranks path following, carries the aggregates
    across tasks, the tuning table and the failure causes; runs.parquet marks failed runs' criteria inf."""
    import json

    from auvtrack.benchmark.compare import compare

    suite = _suite(tmp_path)
    res = compare(suite, controllers=["pid", REFERENCE], quick=True, out=tmp_path / "out", progress=False, workers=1)
    assert res.complete
    doc = json.loads((tmp_path / "out" / "results.json").read_text())
    assert doc["criteria"] == ["failure", "xtrack_rmse", "vtrack_rmse", "rmse", "energy", "tv"]
    assert set(doc["metrics"]) == {"xtrack_rmse", "vtrack_rmse", "rmse", "energy", "tv"}
    agg = doc["aggregates"]
    assert agg["score"] == "xtrack_rmse" and agg["estimates"] is not None
    assert set(agg["estimates"]["iqm"]) == {"pid", REFERENCE}
    assert {(r["x"], r["y"]) for r in agg["improvement"]} == {("pid", REFERENCE), (REFERENCE, "pid")}
    runs = pd.read_parquet(tmp_path / "out" / "runs.parquet")
    assert np.all(np.isinf(runs.loc[runs["status"] != "ok", "xtrack_rmse"]))
    assert (runs["cause"][runs["status"] != "ok"] != "").all()  # every failure has a cause
    md = (tmp_path / "out" / "report.md").read_text()
    for text in ("## Aggregates across tasks", "objective (train / validation)", "xtrack_rmse (m) median [95 % bootstrap]",
                 "failure rate, all runs [Wilson 95 %]", "mean of task means (capped) [95 %]",
                 "median of task means (capped) [95 %]", "a failed run counts as `xtrack_rmse` = 5 m"):
        assert text in md, text
    scales = agg["scales"]  # the LOS autopilot's medians: a failure counts as 5 m over each
    assert agg["cap"] == pytest.approx({k: 5.0 / v for k, v in scales.items()}, rel=1e-15)
    assert set(agg["failure_rate"]) == {"pid", REFERENCE}
    assert all(math.isfinite(agg["estimates"][a][c]["point"]) for a in ("median", "mean") for c in ("pid", REFERENCE))
    assert set(doc["not_tuned_on_suite"]) == {"pid", REFERENCE}  # the tiny suite has no preset tuned on it
    assert "**Not tuned on this suite** (2 of 2)" in md and len(doc["tuning"]) == 2
    assert ("Why it failed" in md) == bool((runs["status"] != "ok").any())
    html = (tmp_path / "out" / "report.html").read_text()
    assert "data:image/png;base64," in html and "<img src=\"figures/" not in html  # self-contained
    from tools.findings import block_compare_v2

    doc["_provenance"] = {"command": "auvtrack compare --suite tiny", "stored": "now"}
    block = block_compare_v2(doc)
    assert "IQM of normalised `xtrack_rmse`" in block and "| `pid` |" in block and f"| `{REFERENCE}` |" in block
    assert f"{int((runs['status'] != 'ok').sum())} runs failed, 0 of them without a recorded cause" in block
    assert "no run on the calm truth tiers" in block  # the tiny suite has no truth tier

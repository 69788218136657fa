"""The auv-track-v2 blocks of ``tools.findings``: registration, storage and rendering.

The block is rendered from a small real result, ``tests/data/compare-v2-quick.json``: the
``results.json`` of ``auvtrack compare --suite auv-track-v2 --quick --controllers los_autopilot,pid,ppc``
(the quick variant: few seeds, short runs; the simd back end), re-written compact
(``json.dumps(..., separators=(",", ":"))``), nothing else changed.
The acceptance check is exercised both ways on edited copies of it.
"""
from __future__ import annotations

import copy
import json
from pathlib import Path

import pytest

from tools import findings

SMALL = Path(__file__).resolve().parents[1] / "data" / "compare-v2-quick.json"


@pytest.fixture
def small() -> dict:
    data = json.loads(SMALL.read_text())
    data["_provenance"] = {"command": findings.SOURCES["compare-v2"], "stored": "then", "source_hash": "x" * 16}
    return data


def _calm(cv: dict, kind: str) -> list[dict]:
    return [c for c in cv["cells"] if c["tier"] in findings.CALM_TRUTHS and c["controller"] == kind]


def test_compare_v2_is_a_registered_source_with_its_blocks():
    assert "auv-track-v2" in findings.SOURCES["compare-v2"]
    table = findings.blocks()
    assert table["compare-v2"][0] == "findings" and table["readme-benchmark"][0] == "readme"


def test_store_then_render_from_a_result(small, tmp_path, monkeypatch):
    """``store compare-v2 PATH`` writes strict JSON with the registered command; the block reads it back."""
    src = tmp_path / "results.json"
    src.write_text(SMALL.read_text())
    monkeypatch.setattr(findings, "RESULTS", tmp_path / "results")
    assert findings.main(["store", "compare-v2", str(src)]) == 0
    stored = findings.load("compare-v2")
    assert stored["_provenance"]["command"] == findings.SOURCES["compare-v2"]
    assert stored["leaderboard"] == small["leaderboard"]
    assert findings.block_compare_v2(stored).splitlines()[2:] == findings.block_compare_v2(small).splitlines()[2:]


def test_store_refuses_an_unknown_name_in_one_line(tmp_path, capsys):
    assert findings.main(["store", "compare-v3", str(tmp_path / "x.json")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "compare-v2" in err


def test_leaderboard_rows_follow_the_result(small):
    text = findings.block_compare_v2(small)
    rows = [ln for ln in text.splitlines() if ln.startswith("| ") and "`" in ln.split("|")[2]]
    assert [r.split("|")[2].strip().strip("`") for r in rows] == [r["controller"] for r in small["leaderboard"]]
    for row, lb in zip(rows, small["leaderboard"]):
        assert f"{lb['score']:.2f}" in row
    fails = sum(r["failures"] for r in small["pooled"])
    assert f"{fails} runs failed" in text
    assert f"{small['timing']['runs']} runs" in text and small["suite"]["name"] in text
    # a changed score changes the block
    bumped = copy.deepcopy(small)
    bumped["leaderboard"][0]["score"] += 0.5
    assert findings.block_compare_v2(bumped) != text


def test_every_failure_has_a_cause_in_the_small_result(small):
    """The block counts failures without a cause; the quick result has failures (the PPC's) and none unknown."""
    text = findings.block_compare_v2(small)
    assert sum(r["failures"] for r in small["pooled"]) > 0
    assert ", 0 of them without a recorded cause" in text


def _set_calm(cv: dict, failures: int, xtrack: float) -> dict:
    out = copy.deepcopy(cv)
    for kind in findings.BASELINES:
        for c in _calm(out, kind):
            c["failures"], c["xtrack_rmse"]["median"] = failures, xtrack
    return out


def test_calm_truth_acceptance_check_reads_the_cells(small):
    good = _set_calm(small, 0, 0.25)
    text = findings.block_compare_v2(good)
    assert text.count("does not hold") == 0 and text.count("holds") == len(findings.BASELINES)
    # one cell above the bound: that baseline's verdict flips, the other's stays
    wide = copy.deepcopy(good)
    _calm(wide, "pid")[-1]["xtrack_rmse"]["median"] = findings.XTRACK_TARGET + 0.01
    lines = {ln.split("`")[1]: ln for ln in findings.block_compare_v2(wide).splitlines() if ln.startswith("* `")}
    assert "does not hold" in lines["pid"] and "does not hold" not in lines["los_autopilot"]
    assert f"{findings.XTRACK_TARGET + 0.01:.3g}" in lines["pid"]
    # one failed run: the verdict flips even with small errors
    failed = copy.deepcopy(good)
    _calm(failed, "los_autopilot")[0]["failures"] = 1
    lines = {ln.split("`")[1]: ln for ln in findings.block_compare_v2(failed).splitlines() if ln.startswith("* `")}
    assert "does not hold" in lines["los_autopilot"] and "1 of" in lines["los_autopilot"]


def test_a_missing_baseline_is_named_not_passed(small):
    cut = copy.deepcopy(small)
    cut["cells"] = [c for c in cut["cells"] if c["controller"] != "pid"]
    text = findings.block_compare_v2(cut)
    assert "`pid`: no run on the calm truth tiers" in text


def test_readme_line_points_at_the_findings_section(small):
    text = findings.block_readme_compare_v2(small)
    pos = [text.index(f"`{r['controller']}`") for r in small["leaderboard"]]
    assert pos == sorted(pos)
    assert "docs/findings.md" in text and "§8" in text and "lower is better" in text


def test_the_stored_result_is_the_current_full_suite_with_every_builtin():
    """docs/results/compare-v2.json is the default (not --quick) run of the shipped suite as it is now,
    with every built-in tracking controller: a changed suite leaves no stale leaderboard behind."""
    from auvtrack.benchmark.suite import load_suite, tracking_kinds

    cv = findings.load("compare-v2")
    now = json.loads(json.dumps(load_suite("auv-track-v2", check=False).settings()))
    assert cv["suite"]["quick"] is False and cv["suite"]["file"] == now["file"]
    assert cv["suite"]["seeds"] == now["seeds"] and cv["suite"]["durations"] == now["durations"]
    assert sorted(c["label"] for c in cv["controllers"]) == sorted(tracking_kinds())
    assert cv["timing"]["runs"] == len(tracking_kinds()) * len(now["durations"]) * len(now["file"]["tiers"]) * now["seeds"]


def test_untuned_competitors_are_named_from_the_result(small):
    assert small["not_tuned_on_suite"] == ["los_autopilot", "pid", "ppc"]  # {kind}_tuned: Section 4's presets
    assert "**Not tuned on this suite** (3 of 3): `los_autopilot`, `pid`, `ppc`" in findings.block_compare_v2(small)
    tuned = dict(small, not_tuned_on_suite=[])
    assert "Every competitor's gains were tuned by `auvtrack tune` on auv-track-v2 v1" in findings.block_compare_v2(tuned)
    old = {k: v for k, v in small.items() if k != "not_tuned_on_suite"}
    assert "not recorded in this result" in findings.block_compare_v2(old)


def _uncaused(cv: dict) -> list[str]:
    """Every (tier, controller) of the report's *Why it failed* table whose failures lack a named cause,
    and every cell whose causes do not add up to its failures."""
    from auvtrack.benchmark.report_competitors import failure_cause_rows

    head, rows = failure_cause_rows(cv["pooled_tier"])
    causes = head[3:]
    out = [f"{r[0]}/{r[1]}: unknown" for r in rows if "unknown" in causes and r[3 + causes.index("unknown")]]
    failing = {(r["tier"], r["controller"]): r["failures"] for r in cv["pooled_tier"] if r["failures"]}
    shown = {(r[0], r[1]): sum(r[3:]) for r in rows}
    out += [f"{t}/{c}: {k} failed, {shown.get((t, c), 0)} with a cause in the table" for (t, c), k in failing.items()
            if shown.get((t, c)) != k]
    out += [f"{c['tier']}/{c['task']}/{c['controller']}: causes {c['causes']} for {c['failures']} failures"
            for c in cv["cells"] if sum(c["causes"].values()) != c["failures"] or "unknown" in c["causes"]]
    return out


def test_every_failure_of_every_tier_of_the_stored_result_has_a_cause_in_the_report():
    """The acceptance's second clause on docs/results/compare-v2.json: the report's *Why it failed* table
    (built from the stored ``pooled_tier``) names a cause for every failed run of every tier, and every
    cell's causes add up to its failures."""
    cv = findings.load("compare-v2")
    assert sum(r["failures"] for r in cv["pooled_tier"]) > 0  # there are failures to explain
    assert sum(r["failures"] for r in cv["pooled_tier"]) == sum(r["failures"] for r in cv["pooled"])
    assert _uncaused(cv) == []


def test_the_cause_check_finds_a_failure_without_a_cause(small):
    assert _uncaused(small) == []
    broken = copy.deepcopy(small)
    row = next(r for r in broken["pooled_tier"] if r["failures"])
    cause = next(iter(row["causes"]))
    row["causes"]["unknown"] = 1
    row["causes"][cause] -= 1
    assert [p for p in _uncaused(broken) if p.endswith("unknown")] == [f"{row['tier']}/{row['controller']}: unknown"]
    cell = next(c for c in broken["cells"] if c["failures"])
    cell["failures"] += 1
    assert any(p.startswith(f"{cell['tier']}/{cell['task']}/{cell['controller']}") for p in _uncaused(broken))

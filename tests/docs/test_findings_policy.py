"""The shipped policy's comparison in docs/gym.md: registration, compact storage, rendering and its link to the policy file.

The block is rendered from ``docs/results/compare-v2-policy.json`` (the ``results.json`` of
``auvtrack compare --suite auv-track-v2 --controllers pid,los_autopilot,policy --backend simd``,
stored by ``python -m tools.findings store compare-v2-policy``) and the shipped policy's header.
"""
from __future__ import annotations

import copy
import json

import pytest

from tools import findings


@pytest.fixture(scope="module")
def stored() -> dict:
    return findings.load("compare-v2-policy")


def _render(cv: dict) -> str:
    return findings.block_policy_compare(cv, findings._policy_header(), findings.shipped_policy_digest())


def test_policy_comparison_is_a_registered_source_with_its_block_in_gym_md():
    assert "--controllers pid,los_autopilot,policy" in findings.SOURCES["compare-v2-policy"]
    assert "auv-track-v2" in findings.SOURCES["compare-v2-policy"]
    assert findings.blocks()["policy-compare"][0] == "gym"
    assert findings.DOCS["gym"].name == "gym.md"


def test_the_stored_result_is_the_full_suite_flown_with_the_shipped_policy(stored):
    """Not --quick, the shipped suite as it is now, the three competitors, and the policy file shipped now."""
    from auvtrack.benchmark.suite import load_suite

    now = json.loads(json.dumps(load_suite("auv-track-v2", check=False).settings()))
    assert stored["suite"]["quick"] is False and stored["suite"]["file"] == now["file"]
    assert stored["suite"]["seeds"] == now["seeds"] and stored["suite"]["durations"] == now["durations"]
    assert [c["label"] for c in stored["controllers"]] == ["pid", "los_autopilot", "policy"]
    assert stored["timing"]["runs"] == 3 * len(now["durations"]) * len(now["file"]["tiers"]) * now["seeds"]
    assert stored["timing"]["batch_backend"] == "simd"
    policy = next(c for c in stored["controllers"] if c["label"] == "policy")
    assert policy["digest"] == findings.shipped_policy_digest()  # a re-trained policy makes this result stale
    assert set(stored) == set(findings.KEEP["compare-v2-policy"]) | {"_provenance"}  # compact: no paired tests


def test_store_keeps_the_listed_keys_only(stored, tmp_path, monkeypatch):
    src = tmp_path / "results.json"
    src.write_text(json.dumps({**{k: v for k, v in stored.items() if k != "_provenance"}, "paired": {"big": [1] * 10}}))
    monkeypatch.setattr(findings, "RESULTS", tmp_path / "results")
    assert findings.main(["store", "compare-v2-policy", str(src)]) == 0
    again = findings.load("compare-v2-policy")
    assert "paired" not in again and again["cells"] == stored["cells"]
    assert again["_provenance"]["command"] == findings.SOURCES["compare-v2-policy"]


def test_rows_follow_the_result(stored):
    """One row per tier and controller with its tier score, pooled failure rate and cell medians; unseen tiers marked."""
    text = _render(stored)
    rows = [ln.split("|")[1:-1] for ln in text.splitlines() if ln.startswith("| ") and "`" in ln.split("|")[3]]
    tiers = [t for t in stored["suite"]["file"]["tiers"] if t not in stored["suite"]["skipped_tiers"]]
    assert len(rows) == len(tiers) * len(stored["controllers"])
    lb = {r["controller"]: r for r in stored["leaderboard"]}
    pooled = {(r["tier"], r["controller"]): r for r in stored["pooled_tier"]}
    cells = {(c["tier"], c["task"], c["controller"]): c for c in stored["cells"]}
    trained = findings._policy_header()["provenance"]["tier"]
    for tier, seen, ctrl, score, fail, med in rows:
        tier, ctrl = tier.strip(), ctrl.strip().strip("`")
        assert score.strip().startswith(f"{lb[ctrl]['tiers'][tier]['score']:.2f} (")
        assert fail.strip().startswith(f"{100 * pooled[(tier, ctrl)]['failure_rate']:.1f} %")
        want = [findings._median_text(cells[(tier, task, ctrl)], "xtrack_rmse") for task in stored["suite"]["durations"]]
        assert [m.strip() for m in med.split(" / ")] == want
        assert seen.strip() == ("" if ctrl != "policy" else "yes" if tier == trained else "no")
    bumped = copy.deepcopy(stored)
    bumped["pooled_tier"][0]["failure_rate"] += 0.5
    assert _render(bumped) != text


def test_a_comparison_of_another_policy_file_is_refused(stored):
    with pytest.raises(ValueError, match="compare-v2-policy"):
        findings.block_policy_compare(stored, findings._policy_header(), "0" * 64)


def test_the_block_states_the_conditions(stored):
    text = _render(stored)
    pv = findings._policy_header()["provenance"]
    assert f"version {stored['suite']['version']}" in text and f"{stored['suite']['seeds']} evaluation seeds" in text
    assert f"back end {stored['timing']['batch_backend']}" in text
    assert f"{pv['config']['duration']:g} s on the {pv['tier']} tier" in text and pv["command"] in text


def test_the_verdict_line_reads_the_result(stored):
    """The policy's summary: tiers where it ranks last, its failures, the spans of the cell medians."""
    text = _render(stored)
    tiers = [t for t in stored["suite"]["file"]["tiers"] if t not in stored["suite"]["skipped_tiers"]]
    pol = next(r for r in stored["leaderboard"] if r["controller"] == "policy")
    last = sum(pol["tiers"][t]["rank"] == len(stored["controllers"]) for t in tiers)
    fails = sum(r["failures"] for r in stored["pooled_tier"] if r["controller"] == "policy")
    assert f"ranks last of {len(stored['controllers'])} in {last} of {len(tiers)} tiers; {fails} of its" in text
    worse = copy.deepcopy(stored)
    next(r for r in worse["pooled_tier"] if r["controller"] == "policy")["failures"] += 3
    assert f"{fails + 3} of its" in _render(worse)

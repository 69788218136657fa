"""docs/findings.md and the README's reproduction section quote only the stored study results.

* Every generated section equals what ``tools.findings`` renders from ``docs/results/``.
* Outside the generated sections findings.md contains no number except references (ERRATA n,
  Section n, eq. (n), §n, issue n, REMUS 100, ...): a number typed by hand fails the test.
* The stored results were produced by the current study definitions (the default settings and
  the default conditions), so a changed default cannot leave stale numbers behind.
"""
from __future__ import annotations

import json
import re
from dataclasses import asdict

import pytest

from auvtrack.studies import ablation, fixed_time, model_gap, robustness
from tools import findings

ALLOWED = [
    r"REMUS 100", r"ERRATA \d+", r"issue \d+", r"§\d+", r"Section \d+", r"Sec\. \d+(\.\d+)?",
    r"Figures? \d+(–\d+)?", r"Theorem \d+", r"Lemma \d+", r"\(\d+\)", r"^#+ \d+\.",
    r"(auv-track|compare)-v\d+",  # the names of a suite and of its stored result
]


def _outside_blocks(text: str) -> str:
    return findings.BLOCK_RE.sub(lambda m: "", text)


def test_every_generated_block_matches_the_stored_results():
    for key, path in findings.DOCS.items():
        text = path.read_text()
        names = [m.group("name") for m in findings.BLOCK_RE.finditer(text)]
        want = [n for n, (doc, _) in findings.blocks().items() if doc == key]
        assert sorted(names) == sorted(want), key  # every block present, once
        assert findings.render_text(text, key) == text, f"{path.name}: stale; run python -m tools.findings render"


def test_findings_has_no_number_outside_the_generated_sections():
    text = _outside_blocks(findings.DOCS["findings"].read_text())
    for line in text.splitlines():
        rest = line
        for pat in ALLOWED:
            rest = re.sub(pat, "", rest)
        assert not re.search(r"\d", rest), f"number typed by hand in docs/findings.md: {line!r}"


def test_the_number_check_catches_a_hand_typed_number():
    """The check above is not vacuous: a typed number outside a block is found."""
    text = "Prose with ERRATA 14 and §3 only.\nThe pulse survives 930 N.\n"
    bad = []
    for line in text.splitlines():
        rest = line
        for pat in ALLOWED:
            rest = re.sub(pat, "", rest)
        if re.search(r"\d", rest):
            bad.append(line)
    assert bad == ["The pulse survives 930 N."]


def test_a_changed_result_makes_the_block_stale(monkeypatch):
    real = findings.load

    def tampered(name):
        data = real(name)
        if name == "reproduce":
            data["full_window"]["FXTNTSMC"]["settle_1cm_x"] *= 1.5
        return data

    monkeypatch.setattr(findings, "load", tampered)
    text = findings.DOCS["findings"].read_text()
    assert findings.render_text(text, "findings") != text


def _jsonish(obj):
    return json.loads(json.dumps(obj))


def test_stored_results_come_from_the_current_study_definitions():
    ab = findings.load("ablation")
    assert ab["settings"] == _jsonish({**asdict(ablation.AblationSettings()), "horizon": ablation.AblationSettings().horizon})
    s40 = findings.load("ablation-surge40")
    want = ablation.settings_for(pulse="1,0,0,0.25,0.25", pulse_start=40.0)
    assert s40["settings"] == _jsonish({**asdict(want), "horizon": want.horizon})
    ft = findings.load("fixed-time")
    assert ft["settings"] == _jsonish(asdict(fixed_time.FixedTimeSettings()))
    assert ft["estimator"] == findings.DEFAULT_EST
    rb = findings.load("robustness")
    # workers only say how many threads ran the batch (every back end gives bit-identical results)
    stored, now = dict(rb["config"]), _jsonish(asdict(robustness.FULL))
    stored.pop("workers"), now.pop("workers")
    assert stored == now and rb["quick"] is False
    rl = findings.load("realism")
    assert rl["duration_s"] == 40.0
    rp = findings.load("reproduce")
    from auvtrack.scenario import load_scenario, paper_scenario_path
    from auvtrack.studies.reproduce import FORMS, conditions

    sc = load_scenario(paper_scenario_path())
    assert sc.estimator.kind == findings.DEFAULT_EST
    cond = conditions(sc, notes=("rho_bar_y(0) widened",))
    assert rp["conditions"] == cond
    assert [f["name"] for f in rp["forms"]] == [f[0] for f in FORMS]
    assert rp["steady_window"]["window"] == [50.0, 100.0]  # the full run, not --quick
    mg = findings.load("model-gap")
    assert mg["quick"] is False and mg["duration_s"] == 150.0
    assert sorted((r["controller"], r["truth"], r["reference"], r["current"], r["gains"]) for r in mg["rows"]) == \
        sorted(model_gap.jobs(False))
    assert mg["references"] == _jsonish(model_gap.REFERENCES) and mg["current"] == _jsonish(model_gap.CURRENT)
    for name in findings.SOURCES:
        assert findings.load(name)["_provenance"]["command"] == findings.SOURCES[name]


@pytest.mark.parametrize("name", sorted(findings.SOURCES))
def test_stored_results_are_strict_json(name):
    text = (findings.RESULTS / f"{name}.json").read_text()
    assert "NaN" not in text and "Infinity" not in text
    json.loads(text)


def test_the_prose_of_findings_md_holds_on_the_stored_results():
    """The sentences outside the generated sections read the data; each reading is checked here."""
    from auvtrack.studies.ablation import compare, config_label

    ab = findings.load("ablation")
    assert findings._direction_matters(ab)  # "the verdict differs between" directions
    est = findings.DEFAULT_EST
    for cond in ab["settings"]["conditions"]:
        none = findings._scan(ab, config_label("none", est), cond, "sway")
        for env in ("rigid", "reactive", "proactive"):
            r = findings._scan(ab, config_label(env, est), cond, "sway")
            assert compare(none, r) == 1  # sideways: no envelope survives more than any envelope
            assert r["first_failure"] < none["survives_up_to"] and not r["monotone"]  # a shared pitch window
            assert r["cause"] == "pitch_limit"
        for d, _ in ab["settings"]["directions"]:  # proactive vs rigid: helps or ties, never worse
            assert compare(findings._scan(ab, config_label("proactive", est), cond, d),
                           findings._scan(ab, config_label("rigid", est), cond, d)) >= 0
    none = findings._scan(ab, config_label("none", est), "continuous", "surge+moments")
    for env in ("rigid", "reactive", "proactive"):  # surge + moments: the envelopes survive larger pulses
        r = findings._scan(ab, config_label(env, est), "continuous", "surge+moments")
        assert compare(r, none) == 1 and r["survives_up_to"] > 2 * none["first_failure"]  # "several times"
    rp = findings.load("reproduce")
    forms = {f["name"]: f for f in rp["forms"]}
    acc = {n: findings._verdicts(f["verdicts"])["higher accuracy"] for n, f in forms.items()}
    assert acc["corrected"] == "supported" and acc["printed_law34"] == "not supported"  # (34) changes it
    assert acc["printed_surface28"] == acc["corrected"]
    assert forms["omega"]["full_window"] == forms["corrected"]["full_window"]  # coincide in Section 4
    for f in forms.values():  # "far below a millimetre in steady state, whichever form"
        if f["status"] == "ok":
            assert max(f["steady_window"][f"rmse_{a}"] for a in "xyz") < 1e-4
    ft = findings.load("fixed-time")
    assert ft["verdict"]["verdict"] == "not demonstrated" and findings._ft_facts(ft)["flat_by_estimator"]
    rl = findings.load("realism")
    for veh in ("paper", "remus100"):
        mine = [r for r in rl["rows"] if r["vehicle"] == veh]
        fx = [r for r in mine if r["controller"] == "fxtntsmc" and r["status"] != "ok"]
        fts = [r for r in mine if r["controller"] == "ftsmc" and r["status"] != "ok"]
        assert len(fts) < len(fx)  # the FTSMC is the more robust in a digital loop
        assert sum(r["cause"] == "envelope_violation" for r in fx) > len(fx) / 2  # "mostly envelope violations"
        for lv in {r["level"] for r in mine if r["factor"] == "current"}:  # better against currents
            a = next(r for r in mine if r["factor"] == "current" and r["level"] == lv and r["controller"] == "fxtntsmc")
            b = next(r for r in mine if r["factor"] == "current" and r["level"] == lv and r["controller"] == "ftsmc")
            assert a["status"] == "ok" and (b["status"] != "ok" or a["rmse"] < b["rmse"])


def test_the_model_gap_and_remus_prose_holds_on_the_stored_results():
    """§6 and §7 of findings.md: each sentence outside the generated blocks, read on the data."""
    mg = findings.load("model-gap")
    rows = mg["rows"]

    def mine(kind, truths=("prestero", "fossen"), current=None, gains="published"):
        return [r for r in rows if r["controller"] == kind and r["truth"] in truths and r["status"] != "infeasible"
                and (current is None or r["current"] is current) and r["gains"] == gains]

    # "calm; every task with the current, and Prestero's waypoint path, are ... not flown"
    infeasible = {(t["truth"], t["reference"], t["current"]) for t in mg["tasks"] if t["verdict"] == "infeasible"}
    assert infeasible == {(t, r, True) for t in ("prestero", "fossen") for r in model_gap.REFERENCES} | \
        {("prestero", "waypoints", False)}
    assert {t["verdict"] for t in mg["tasks"] if t["truth"] == "prestero" and not t["current"]} - {"infeasible"} \
        == {"marginal"}  # "marginal on Prestero's truth"
    for gains in ("published", "designed"):
        own = mine("fxtntsmc", ("5dof",), gains=gains)
        assert all(r["status"] == "ok" for r in own) and max(r["rmse_late"] for r in own) < 1e-3
    for r in mine("fxtntsmc"):  # published: fails every truth run, early
        assert r["status"] != "ok" and r["fail_time"] < 15.0
        assert r["cause"] in ("state_limit", "nonfinite")
    comp_f = mine("fxtntsmc", ("fossen",), gains="designed")
    assert all(r["status"] == "ok" for r in comp_f) and 0.1 < min(r["rmse_late"] for r in comp_f) \
        and max(r["rmse_late"] for r in comp_f) < 1.0 and max(r["xtrack_rmse_late"] for r in comp_f) < 1.0
    comp_p = mine("fxtntsmc", ("prestero",), gains="designed")
    assert comp_p and all(r["status"] != "ok" and r["cause"] == "envelope_violation" for r in comp_p)
    assert min(r["fail_time"] for r in comp_p) > max(r["fail_time"] for r in mine("fxtntsmc", ("prestero",)))
    for gains in ("published", "designed"):
        assert all(r["status"] == "ok" for r in mine("ftsmc", gains=gains))
        assert max(r["rmse_late"] for r in mine("ftsmc", ("prestero",), gains=gains)) < 0.2
        assert max(r["rmse_late"] for r in mine("ftsmc", ("fossen",), gains=gains)) < 0.75
    half = mg["duration_s"] / 2
    for kind in ("pid", "backstepping", "sta"):
        for gains in ("published", "designed"):
            assert all(r["status"] == "ok" for r in mine(kind, gains=gains))
        pub = mine(kind)
        for truth in ("prestero", "fossen"):  # as published: metres on either truth
            assert max(r["rmse_late"] for r in pub if r["truth"] == truth) > 10.0
        assert sum(max(r[f"t_sat_tau_{j}"] for j in "uqr") > half / 2 for r in pub) > len(pub) / 2
        des = mine(kind, gains="designed")
        assert max(r["rmse_late"] for r in des) < 0.5 and max(r["xtrack_rmse_late"] for r in des) < 0.5
    for gains in ("published", "designed"):
        assert all(r["status"] != "ok" and r["cause"] == "envelope_violation" for r in mine("ppc", gains=gains))
        ppc_own = mine("ppc", ("5dof",), gains=gains)
        assert [r["current"] for r in ppc_own if r["status"] != "ok"] == [True] * (len(ppc_own) // 2)
    los = mine("los_autopilot", ("prestero", "fossen"), gains="designed")
    assert los and all(r["status"] == "ok" for r in los) and max(r["xtrack_rmse_late"] for r in los) < 0.05
    assert all(0.8 * model_gap.ELL < r["rmse_late"] < 1.2 * model_gap.ELL for r in los)  # about ell behind
    calm_f = [r["rmse_late"] for r in mine("ftsmc", ("fossen",), False)]
    calm_p = [r["rmse_late"] for r in mine("ftsmc", ("prestero",), False)]
    assert min(calm_f) > 2 * max(calm_p)  # the truths disagree with each other
    # §6: the reduction's damping at the operating speed is smaller than at the trial speed
    from auvtrack.vehicle.presets import get_preset
    from auvtrack.vehicle.reduction import reduce_prestero
    from auvtrack.scenario import load_scenario, paper_scenario_path

    u0 = load_scenario(paper_scenario_path(), ["vehicle.preset=remus100"]).vehicle.u0
    trial = get_preset("remus100").u0
    assert u0 < trial and all(a < b for a, b in zip(reduce_prestero(u0)["d"], reduce_prestero(trial)["d"]))
    per = findings.load("robustness")["summary"]["remus100"]
    assert per and all(s["failed"] >= 1 for s in per.values())  # every controller fails some run on it


def test_findings_md_does_not_link_the_merged_draft():
    """The issue-11 draft was merged into findings.md §6 and §7 and deleted; no document links it."""
    assert not (findings.ROOT / "docs" / "findings_model_gap.md").exists()
    for path in [findings.ROOT / "README.md", *sorted((findings.ROOT / "docs").glob("*.md"))]:
        assert "findings_model_gap" not in path.read_text(), path.name


def test_performance_block_verdicts_follow_the_record():
    """README's performance verdicts are computed from the bench record, not typed: changing a
    number across its target flips the verdict."""
    import copy
    import json

    from tools import findings

    rec = json.loads(findings.BENCH.read_text())
    text = findings.block_performance(rec)
    assert f"{rec['cold']['seconds']:.1f} s" in text
    slow = copy.deepcopy(rec)
    for r in slow["single"]:
        if r["controller"] == "fxtntsmc":
            r["cpu_us_per_step"] = 2.5
    fast = copy.deepcopy(rec)
    fast["cold"]["seconds"], fast["cold_warmup"]["seconds"] = 10.0, 60.0
    assert "FXTNTSMC ≤ 2.0 | not met" in findings.block_performance(slow)
    assert "≤ 20 s on a quiet machine | met at that load" in findings.block_performance(fast)
    assert "≤ 90 s | met at that load" in findings.block_performance(fast)

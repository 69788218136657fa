"""The ablation study: bisection bracket logic on synthetic survival functions, the configuration
grid, and the ``--quick`` path end to end."""
from __future__ import annotations

import json
import math

import pytest

from auvtrack.studies import ablation
from auvtrack.studies.ablation import compare, configurations, find_threshold


def _step(threshold: float, cause: str = "pitch_limit"):
    calls = []

    def survives(a: float):
        calls.append(a)
        return (a <= threshold, None if a <= threshold else cause, None if a <= threshold else 1.0)

    return survives, calls


@pytest.mark.parametrize("threshold", [1.0, 1.7, 37.3, 999.0, 4321.0])
@pytest.mark.parametrize("rtol", [0.01, 0.2])
def test_bisection_finds_the_threshold_to_tolerance(threshold, rtol):
    survives, calls = _step(threshold)
    th = find_threshold(survives, 1.0, 1e4, growth=3.0, rtol=rtol)
    assert th.kind == "bracketed"
    assert th.survived <= threshold < th.failed
    assert th.failed / th.survived - 1 <= rtol
    assert th.cause == "pitch_limit" and th.fail_time == 1.0
    assert [p.amplitude for p in th.probes] == calls
    # every probe is consistent with the step, and the bracket is made of probes
    assert all(p.survived == (p.amplitude <= threshold) for p in th.probes)
    assert th.survived in calls and th.failed in calls
    # bracketing is geometric then bisection: logarithmic number of evaluations
    assert len(calls) <= math.log(1e4) / math.log(3) + 2 + math.log2(math.log(3) / math.log1p(rtol)) + 2


def test_bisection_reports_survival_up_to_the_cap():
    survives, calls = _step(math.inf)
    th = find_threshold(survives, 2.0, 500.0, growth=4.0, rtol=0.05)
    assert th.kind == "survives_cap" and th.failed is None and th.cause is None
    assert th.survived == 500.0 and calls[-1] == 500.0 and max(calls) == 500.0


def test_bisection_reports_failure_at_the_smallest_amplitude():
    survives, calls = _step(0.5, cause="envelope_violation")
    th = find_threshold(survives, 1.0, 1e4)
    assert th.kind == "fails_min" and th.survived == 0.0 and th.failed == 1.0
    assert th.cause == "envelope_violation" and calls == [1.0]


def test_bisection_on_a_non_monotone_survival_returns_a_true_transition():
    # survives on [1, 10] and [30, 100]: whatever transition is found must be a real one
    def survives(a):
        ok = a <= 10 or 30 <= a <= 100
        return ok, None if ok else "nonfinite", None

    th = find_threshold(survives, 1.0, 1e3, growth=3.0, rtol=0.01)
    assert th.kind == "bracketed"
    assert survives(th.survived)[0] and not survives(th.failed)[0]
    assert th.failed / th.survived - 1 <= 0.01


@pytest.mark.parametrize("kw", [dict(a_min=0.0, a_max=1.0), dict(a_min=2.0, a_max=1.0),
                                dict(a_min=1.0, a_max=math.inf), dict(a_min=1.0, a_max=2.0, growth=1.0),
                                dict(a_min=1.0, a_max=2.0, rtol=0.0)])
def test_bisection_rejects_bad_arguments(kw):
    with pytest.raises(ValueError):
        find_threshold(lambda a: (True, None, None), **kw)


def test_compare_uses_disjoint_brackets():
    a = {"survived": 100.0, "failed": 110.0}
    b = {"survived": 50.0, "failed": 55.0}
    c = {"survived": 105.0, "failed": 115.0}
    cap = {"survived": 1e4, "failed": None}
    assert compare(a, b) == 1 and compare(b, a) == -1
    assert compare(a, c) == 0 and compare(c, a) == 0
    assert compare(cap, a) == 1 and compare(cap, cap) == 0


def test_configuration_grid_is_4x3_plus_one_ftsmc():
    cfgs = configurations()
    assert len(cfgs) == 13 and len({c.label for c in cfgs}) == 13
    fts = [c for c in cfgs if "controller.kind=ftsmc" in c.overrides]
    assert len(fts) == 1 and not any("envelope" in o or "estimator" in o for o in fts[0].overrides)
    fx = [c for c in cfgs if "controller.kind=fxtntsmc" in c.overrides]
    assert {(o[1], o[2]) for o in (c.overrides for c in fx)} == {
        (f"envelope.kind={e}", f"estimator.kind={s}")
        for e in ablation.ENVELOPE_KINDS for s in ablation.ESTIMATOR_KINDS}


def test_pulse_is_added_to_section4():
    cfg = configurations()[-1]
    st = ablation.Settings()
    sc = ablation._scenario(cfg, "sampled", 30.0, (0, 5.0, 0, 0, 0), st)
    kinds = [d["kind"] for d in sc.disturbance]
    assert kinds == ["paper", "pulse"]
    assert sc.disturbance[1]["start"] == st.pulse_start and list(sc.disturbance[1]["force"]) == [0, 5.0, 0, 0, 0]
    assert sc.sim.control_rate == 500 and sc.sim.duration == 30.0 and st.pulse_start > 15.0  # after T = 15 s


@pytest.fixture(scope="module")
def quick_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("ablation")
    report = ablation.run(out, quick=True)
    return out, report


def test_quick_ablation_end_to_end(quick_run):
    out, report = quick_run
    assert report == out / "report.md" and report.exists()
    text = report.read_text()
    assert "Largest surviving pulse amplitude" in text and "figures/thresholds.png" in text
    assert (out / "figures" / "thresholds.png").exists()
    data = json.loads((out / "results.json").read_text())
    st = ablation.Settings.quick()
    assert len(data["thresholds"]) == len(st.configs) * len(st.directions) * len(st.conditions)
    assert len(data["nominal"]) == len(st.configs)
    for r in data["thresholds"]:
        assert r["kind"] in ("bracketed", "survives_cap", "fails_min")
        probes = r["probes"]
        assert probes and all(st.a_min <= p["amplitude"] <= st.a_max for p in probes)
        assert all((p["cause"] is None) == p["survived"] for p in probes)
        if r["kind"] != "survives_cap":
            assert r["cause"] in ("envelope_violation", "pitch_limit", "nonfinite", "state_limit", "nonfinite_input")
            assert r["failed"] > r["survived"] and r["fail_time"] >= st.pulse_start
        if r["kind"] == "bracketed":
            assert r["failed"] / r["survived"] - 1 <= st.rtol
    for r in data["nominal"]:  # Section 4 itself completes for these configurations
        assert r["status"] == "ok" and r["cause"] is None and 0 < r["settle_1cm"] < st.nominal_duration
    for r in data["reference"]:
        assert r["status"] in ("ok", "failed")
        if r["status"] == "ok":
            assert 0 <= r["max_abs_e"] < 1.0 and r["max_abs_tau"] > 0

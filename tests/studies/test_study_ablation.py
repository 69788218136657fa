"""The ablation study: the survival scan on synthetic survival functions (monotone and not), the
configuration grid, the ``--pulse`` / ``--pulse-start`` options and ``--quick`` end to end."""
from __future__ import annotations

import json
import math

import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from auvtrack.cli import main
from auvtrack.studies import ablation
from auvtrack.studies.ablation import (Probe, amplitude_grid, compare, config_label, configurations, scan_survival,
                                       summarize)


def _windows(*wins: tuple[float, float], cause: str = "pitch_limit"):
    """Survival function that survives exactly on the closed intervals ``wins``."""
    calls = []

    def survives(a: float):
        calls.append(a)
        ok = any(lo <= a <= hi for lo, hi in wins)
        return ok, None if ok else cause, None if ok else 1.0

    return survives, calls


@pytest.mark.parametrize("threshold", [1.7, 37.3, 999.0, 4321.0])
@pytest.mark.parametrize("rtol", [0.01, 0.2])
def test_scan_of_a_step_brackets_the_threshold_to_tolerance(threshold, rtol):
    survives, calls = _windows((0.0, threshold))
    sv = scan_survival(survives, 1.0, 1e4, per_decade=6, rtol=rtol)
    assert sv.kind == "bracketed" and sv.monotone
    assert sv.survives_up_to <= threshold < sv.first_failure
    assert sv.first_failure / sv.survives_up_to - 1 <= rtol
    assert sv.cause == "pitch_limit" and sv.fail_time == 1.0
    assert [p.amplitude for p in sv.probes] == calls
    assert all(p.survived == (p.amplitude <= threshold) for p in sv.probes)
    assert sv.intervals == [{"lo": 1.0, "hi": sv.survives_up_to, "failed_below": None,
                             "failed_above": sv.first_failure}]
    # the grid, then one bisection of one transition: logarithmic in the grid cell / tolerance
    n_grid = len(amplitude_grid(1.0, 1e4, 6))
    assert len(calls) <= n_grid + math.ceil(math.log2(math.log(10 ** (1 / 6)) / math.log1p(rtol))) + 1


def test_scan_finds_the_first_failure_below_a_second_survival_window():
    """The audit's case: fails near 930 N, survives again on [1100, 1400], fails above 1430 N.

    Bracketing by x3 from 1 N (1, 3, ..., 729, 2187) would skip the first failure; the grid does not.
    """
    survives, _ = _windows((0.0, 930.0), (1100.0, 1430.0))
    sv = scan_survival(survives, 1.0, 1e4, per_decade=12, rtol=0.02)
    assert sv.kind == "bracketed" and not sv.monotone
    assert sv.survives_up_to <= 930.0 < sv.first_failure <= 930.0 * 1.02
    assert len(sv.intervals) == 2
    lo, hi = sv.intervals
    assert lo["lo"] == 1.0 and lo["failed_below"] is None and lo["failed_above"] == sv.first_failure
    assert 1100.0 <= hi["lo"] <= 1100.0 * 1.02 and hi["failed_below"] < 1100.0
    assert 1430.0 / 1.02 <= hi["hi"] <= 1430.0 < hi["failed_above"]
    assert sv.largest_survived == hi["hi"]


def test_scan_reports_survival_up_to_the_cap_and_failure_at_the_smallest_amplitude():
    survives, calls = _windows((0.0, math.inf))
    sv = scan_survival(survives, 2.0, 500.0, per_decade=4, rtol=0.05)
    assert sv.kind == "survives_cap" and sv.first_failure is None and sv.cause is None and sv.monotone
    assert sv.survives_up_to == 500.0 and max(calls) == 500.0 and min(calls) == 2.0
    assert sv.intervals == [{"lo": 2.0, "hi": 500.0, "failed_below": None, "failed_above": None}]
    survives, _ = _windows((0.0, 0.5), cause="envelope_violation")
    sv = scan_survival(survives, 1.0, 1e4, per_decade=2)
    assert sv.kind == "fails_min" and sv.survives_up_to is None and sv.first_failure == 1.0
    assert sv.cause == "envelope_violation" and sv.intervals == [] and sv.largest_survived is None


def test_a_failure_below_a_survival_window_from_the_smallest_amplitude():
    survives, _ = _windows((50.0, 200.0))
    sv = scan_survival(survives, 1.0, 1e3, per_decade=10, rtol=0.01)
    assert sv.kind == "fails_min" and not sv.monotone and sv.survives_up_to is None
    (iv,) = sv.intervals
    assert 50.0 <= iv["lo"] <= 50.5 and 198.0 <= iv["hi"] <= 200.0
    assert iv["failed_below"] < 50.0 and iv["failed_above"] > 200.0


@settings(max_examples=60, deadline=None)
@given(edges=st.lists(st.floats(0.05, 3.95), min_size=1, max_size=6, unique=True),
       first_ok=st.booleans(), per_decade=st.integers(3, 12))
def test_every_transition_farther_apart_than_two_grid_steps_is_found(edges, first_ok, per_decade):
    """Survival alternates at the log10-amplitudes ``edges``: when neighbouring edges are more than
    two grid steps apart, the scan finds each one within the tolerance."""
    step = 1.0 / per_decade
    edges = sorted(edges)
    assume(all(b - a > 2 * step for a, b in zip(edges[:-1], edges[1:])) and step <= edges[0] and edges[-1] <= 4 - step)
    cuts = [10.0 ** e for e in edges]

    def survives(a: float):
        k = sum(a > c for c in cuts)
        ok = (k % 2 == 0) == first_ok
        return ok, None if ok else "nonfinite", None

    sv = scan_survival(survives, 1.0, 1e4, per_decade=per_decade, rtol=0.01)
    ordered = sorted(sv.probes, key=lambda p: p.amplitude)
    found = [(p.amplitude, q.amplitude) for p, q in zip(ordered[:-1], ordered[1:]) if p.survived != q.survived]
    assert len(found) == len(cuts)
    for (lo, hi), c in zip(found, cuts):
        assert lo <= c < hi and hi / lo - 1 <= 0.01
    assert len(sv.intervals) == sum(1 for i in range(len(cuts) + 1) if (i % 2 == 0) == first_ok)


def test_summarize_is_order_independent():
    ps = [Probe(5.0, True), Probe(1.0, True), Probe(9.0, False, "pitch_limit", 2.0), Probe(20.0, True),
          Probe(7.0, False, "nonfinite", 3.0)]
    a, b = summarize(ps), summarize(list(reversed(ps)))
    assert (a.first_failure, a.cause, a.survives_up_to, a.intervals, a.monotone) == (
        b.first_failure, b.cause, b.survives_up_to, b.intervals, b.monotone)
    assert a.first_failure == 7.0 and a.cause == "nonfinite" and a.survives_up_to == 5.0 and not a.monotone
    assert a.intervals[1] == {"lo": 20.0, "hi": 20.0, "failed_below": 9.0, "failed_above": None}


@pytest.mark.parametrize("kw", [dict(a_min=0.0, a_max=1.0), dict(a_min=2.0, a_max=1.0),
                                dict(a_min=1.0, a_max=math.inf), dict(a_min=1.0, a_max=2.0, per_decade=0),
                                dict(a_min=1.0, a_max=2.0, rtol=0.0)])
def test_scan_rejects_bad_arguments(kw):
    with pytest.raises(ValueError):
        scan_survival(lambda a: (True, None, None), **kw)


def test_amplitude_grid_is_geometric_with_exact_ends():
    g = amplitude_grid(1.0, 1e4, 12)
    assert g[0] == 1.0 and g[-1] == 1e4 and len(g) == 49
    ratios = [b / a for a, b in zip(g[:-1], g[1:])]
    assert max(ratios) == pytest.approx(min(ratios)) == pytest.approx(10 ** (1 / 12))


def test_compare_uses_the_first_transition():
    a = {"survives_up_to": 100.0, "first_failure": 110.0}
    b = {"survives_up_to": 50.0, "first_failure": 55.0}
    c = {"survives_up_to": 105.0, "first_failure": 115.0}
    cap = {"survives_up_to": 1e4, "first_failure": None}
    dead = {"survives_up_to": None, "first_failure": 1.0}
    assert compare(a, b) == 1 and compare(b, a) == -1
    assert compare(a, c) == 0 and compare(c, a) == 0
    assert compare(cap, a) == 1 and compare(cap, cap) == 0
    assert compare(a, dead) == 1 and compare(dead, a) == -1 and compare(dead, dead) == 0


def test_configuration_grid():
    cfgs = configurations()
    labels = [c.label for c in cfgs]
    assert len(labels) == len(set(labels)) == 3 * 4 + 2 + 1
    fts = [c for c in cfgs if "controller.kind=ftsmc" in c.overrides]
    assert len(fts) == 1 and not any("envelope" in o or "estimator" in o for o in fts[0].overrides)
    for env in ablation.ENVELOPE_KINDS:
        for est in ablation.ESTIMATOR_KINDS:
            lab = config_label(env, est)
            cfg = next(c for c in cfgs if c.label == lab)
            assert f"envelope.kind={env}" in cfg.overrides
            # without an envelope the three adaptive laws are one law: the default runs for all
            want = est if (env != "none" or est == "none") else ablation.DEFAULT_ESTIMATOR
            assert f"estimator.kind={want}" in cfg.overrides


def test_pulse_is_added_to_section4():
    cfg = configurations()[-1]
    st_ = ablation.AblationSettings()
    sc = ablation._scenario(cfg, "sampled", 30.0, (0, 5.0, 0, 0, 0), st_)
    kinds = [d["kind"] for d in sc.disturbance]
    assert kinds == ["paper", "pulse"]
    assert sc.disturbance[1]["start"] == st_.pulse_start and list(sc.disturbance[1]["force"]) == [0, 5.0, 0, 0, 0]
    assert sc.sim.control_rate == 500 and sc.sim.duration == 30.0 and st_.pulse_start > 15.0  # after T = 15 s
    assert st_.horizon == st_.pulse_start + st_.pulse_duration + st_.recovery == 40.0


def test_pulse_options_set_one_direction_and_the_onset():
    st_ = ablation.settings_for(pulse="1,0,0,0.25,0.25", pulse_start=40.0)
    assert st_.directions == (("pulse [1, 0, 0, 0.25, 0.25]", (1.0, 0.0, 0.0, 0.25, 0.25)),)
    assert st_.pulse_start == 40.0 and st_.horizon == 60.0
    q = ablation.settings_for(quick=True, pulse="0,1,0,0,0")
    assert q.configs == ablation.AblationSettings.quick().configs and len(q.directions) == 1
    assert {c.split("/")[1] for c in q.configs} == {"none", "rigid", "proactive"}
    assert {c.split("/")[2] for c in q.configs} == {ablation.DEFAULT_ESTIMATOR}


@pytest.mark.parametrize("args, field", [
    (["--pulse", "1,0,0"], "--pulse"), (["--pulse", "1,0,0,x,0"], "--pulse"), (["--pulse", "0,0,0,0,0"], "--pulse"),
    (["--pulse", "1,0,0,nan,0"], "--pulse"), (["--pulse-start", "-1"], "--pulse-start"),
    (["--pulse-start", "inf"], "--pulse-start")])
def test_bad_pulse_options_are_one_line_exit_2(args, field, capsys, tmp_path):
    assert main(["study", "ablation", "--quick", "--out", str(tmp_path / "x"), *args]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("auvtrack: error:") and field in err
    assert not (tmp_path / "x").exists()  # refused before anything ran


def test_pulse_options_are_refused_by_other_studies(capsys, tmp_path):
    assert main(["study", "fixed-time", "--quick", "--out", str(tmp_path), "--pulse", "1,0,0,0,0"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--pulse" in err and "fixed-time" in err


@pytest.fixture(scope="module")
def quick_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("ablation")
    report = ablation.run(out, quick=True)
    return out, report


def test_quick_ablation_end_to_end(quick_run):
    out, report = quick_run
    assert report == out / "report.md" and report.exists()
    text = report.read_text()
    assert "Survival per configuration" in text and "figures/survival.png" in text and "### heave pulse" in text
    assert "## Findings" not in text and "## Observations of this quick run (3 configurations" in text
    assert (out / "figures" / "survival.png").exists()
    data = json.loads((out / "results.json").read_text())
    st_ = ablation.AblationSettings.quick()
    assert len(data["scans"]) == len(st_.configs) * len(st_.directions) * len(st_.conditions)
    assert len(data["nominal"]) == len(st_.configs)
    grid = amplitude_grid(st_.a_min, st_.a_max, st_.per_decade)
    for r in data["scans"]:
        assert r["kind"] in ("bracketed", "survives_cap", "fails_min")
        probes = r["probes"]
        assert [p["amplitude"] for p in probes[:len(grid)]] == grid  # the grid comes first
        assert all(st_.a_min <= p["amplitude"] <= st_.a_max for p in probes)
        assert all((p["cause"] is None) == p["survived"] for p in probes)
        # the record is the summary of its probes
        again = summarize([Probe(**p) for p in probes])
        assert (again.first_failure, again.survives_up_to, again.intervals, again.monotone) == (
            r["first_failure"], r["survives_up_to"], r["intervals"], r["monotone"])
        if r["kind"] != "survives_cap":
            assert r["cause"] in ("envelope_violation", "pitch_limit", "nonfinite", "state_limit", "nonfinite_input")
            assert r["fail_time"] >= st_.pulse_start
        if r["kind"] == "bracketed":
            assert r["first_failure"] / r["survives_up_to"] - 1 <= st_.rtol
    assert set(data["tally"]) == {d for d, _ in st_.directions}
    for r in data["nominal"]:  # Section 4 itself completes for these configurations
        assert r["status"] == "ok" and r["cause"] is None and 0 < r["settle_1cm"] < st_.nominal_duration
    for r in data["reference"]:
        assert r["status"] in ("ok", "failed")
        if r["status"] == "ok":
            assert 0 <= r["max_abs_e"] < 1.0 and r["max_abs_tau"] > 0

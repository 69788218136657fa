"""The fixed-time study: the initial-error grid, the start construction, and ``--quick`` end to end."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

from auvtrack.vehicle.kinematics import attitude, j3, virtual_point
from auvtrack.reference import build_reference
from auvtrack.studies import fixed_time
from auvtrack.studies.fixed_time import DIRECTIONS, FixedTimeSettings, initial_scenario, magnitude_grid


@pytest.mark.parametrize("st", [FixedTimeSettings(), FixedTimeSettings.quick()], ids=["default", "quick"])
def test_initial_error_grid_spans_three_decades_and_several_directions(st):
    mags = np.array(st.magnitudes)
    assert np.all(mags > 0) and np.all(np.diff(np.sort(mags)) > 0)
    assert math.log10(mags.max() / mags.min()) >= 3.0 - 1e-12
    assert len(st.directions) >= 2 and all(d in DIRECTIONS for d in st.directions)
    assert set(st.controllers) >= {"fxtntsmc", "ftsmc"}
    for d in DIRECTIONS.values():
        assert np.linalg.norm(d) == pytest.approx(1.0)


def test_default_grid_has_at_least_three_directions_and_both_starts():
    st = FixedTimeSettings()
    assert len(st.directions) >= 3 and set(st.starts) == {"matched", "rest"}


def test_magnitude_grid_is_log_spaced():
    g = magnitude_grid(1e-2, 1e1, 2)
    assert g[0] == pytest.approx(1e-2) and g[-1] == pytest.approx(1e1) and len(g) == 7
    assert np.allclose(np.diff(np.log10(g)), 0.5)
    with pytest.raises(ValueError):
        magnitude_grid(1.0, 0.1)


@pytest.mark.parametrize("start", ["matched", "rest"])
@pytest.mark.parametrize("e0", [(0.01, 0, 0), (-3.0, 2.0, 1.0)])
def test_start_puts_the_virtual_point_at_the_requested_error(start, e0):
    st = FixedTimeSettings(duration=10.0)
    sc = initial_scenario("fxtntsmc", e0, st, start)
    eta, nu = np.array(sc.initial.eta), np.array(sc.initial.nu)
    ell = sc.vehicle.l if sc.vehicle.l is not None else 1.0
    att = attitude(eta[3], eta[4])
    pd, vd, _ = build_reference(dict(sc.reference)).evaluate(0.0)
    np.testing.assert_allclose(np.array(virtual_point(tuple(eta), att, ell)) - pd, e0, rtol=0, atol=1e-12)
    assert sc.envelope.widen_start and sc.envelope.xi0 == st.xi0
    if start == "matched":  # e_dot(0) = J3 v1 + J4 - eta_d_dot = 0 with sway = heave = 0
        assert nu[1] == 0 and nu[2] == 0
        v1 = np.array([nu[0], nu[3], nu[4]])
        np.testing.assert_allclose(np.array(j3(att, ell)) @ v1, vd, rtol=0, atol=1e-12)
    else:
        assert np.all(nu == 0) and eta[3] == 0 and eta[4] == 0
    with pytest.raises(ValueError):
        initial_scenario("fxtntsmc", e0, st, "sideways")


@pytest.fixture(scope="module")
def quick_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("fixed_time")
    report = fixed_time.run(out, quick=True)
    return out, report


def test_quick_fixed_time_end_to_end(quick_run):
    out, report = quick_run
    st = FixedTimeSettings.quick()
    assert report.exists()
    text = report.read_text()
    assert "Theorem 1's bounds" in text and "widen_start" in text and "Start treatment" in text
    for s0 in st.starts:
        assert (out / "figures" / f"settling_vs_e0_{s0}.png").exists()
    data = json.loads((out / "results.json").read_text())
    runs = data["runs"]
    assert len(runs) == len(st.starts) * len(st.controllers) * len(st.directions) * len(st.magnitudes)
    # Theorem 1 is vacuous for the Section 4 gains over the quick horizon, and the report says so
    assert data["bounds"]["vacuous"] is True and "vacuous" in text
    assert data["bounds"]["T1"] > st.duration
    for r in runs:
        assert r["status"] in ("ok", "failed")
        if r["status"] == "ok":
            assert r["cause"] is None
            for th in ("settle_1cm", "settle_1mm"):
                assert r[th] is None or 0 <= r[th] <= st.duration  # None = not settled (inf)
        else:
            assert r["cause"] in ("pitch_limit", "envelope_violation", "nonfinite", "state_limit", "nonfinite_input")
            assert 0 < r["fail_time"] < st.duration
        if r["controller"] == "fxtntsmc":  # the start treatment is applied exactly when |e_i| > xi0 rho0_i
            rho0 = np.array(initial_scenario("fxtntsmc", (0.0, 0.0, 0.0), st).envelope.rho0)
            need = np.abs(r["e0_vec"]) > st.xi0 * rho0
            assert r["widened"] == bool(need.any())
            np.testing.assert_allclose(r["widening"], np.where(need, np.abs(r["e0_vec"]) / st.xi0 - rho0, 0.0),
                                       rtol=1e-12, atol=0)
    # small initial errors complete and settle to 1 cm for both controllers
    small = [r for r in runs if r["e0"] <= 0.1]
    assert small and all(r["status"] == "ok" and r["settle_1cm"] is not None for r in small)
    a = data["analysis"]["matched"]
    assert set(a) == set(st.controllers)
    assert all(sum(v["failures_by_cause"].values()) == v["runs"] - v["ok"] for v in a.values())
    # the verdict is computed from the stored numbers and says what was not shown
    vd = data["verdict"]
    assert vd["verdict"] in ("not demonstrated", "consistent with a fixed-time bound (not a proof)")
    assert vd["not_shown"] and "## Verdict" in text
    assert vd == fixed_time.verdict(data, st.starts[0])


def test_zero_weight_variant_starts_the_network_at_zero():
    from auvtrack.simulation.pipeline import prepare

    st = FixedTimeSettings(duration=1.0)
    p0 = prepare(initial_scenario("fxtntsmc-w0", (0.1, 0.0, 0.0), st))
    p1 = prepare(initial_scenario("fxtntsmc", (0.1, 0.0, 0.0), st))
    w0, w1 = np.array(p0.resolved["controller"]["rbf_weights0"]), np.array(p1.resolved["controller"]["rbf_weights0"])
    assert w0.shape == w1.shape and np.all(w0 == 0) and np.all(w1 > 0)
    assert p0.resolved["controller"]["rbf_centres"] == p1.resolved["controller"]["rbf_centres"]  # same network


def _rows(curve, kind="k"):
    return [{"controller": kind, "status": "ok", "e0": m, "settle_1cm": v} for m, v in curve]


def test_slopes_over_all_magnitudes_and_by_decade_are_least_squares_in_log_log():
    mags = list(magnitude_grid(1e-2, 1e1, 2))
    # t = 3 |e0|^0.5 below 0.1 m, constant above: slope 0.5 on the first decade, 0 on the last
    curve = [(m, 3 * min(m, 0.1) ** 0.5) for m in mags]
    rows = _rows(curve)
    dec = fixed_time._decade_slopes(rows, "settle_1cm", mags)
    assert [d["from"] for d in dec] == pytest.approx(mags[:len(dec)]) and dec[-1]["to"] == pytest.approx(10.0)
    assert dec[0]["slope"] == pytest.approx(0.5, abs=1e-12) and dec[-1]["slope"] == pytest.approx(0.0, abs=1e-12)
    x, y = np.log([c[0] for c in curve]), np.log([c[1] for c in curve])
    assert fixed_time._slope(rows, "settle_1cm", mags[0]) == pytest.approx(np.polyfit(x, y, 1)[0], rel=1e-12)


def test_monotonicity_reports_each_decrease_with_the_completed_directions():
    per_mag = {0.1: 5.0, 1.0: 4.0, 10.0: 6.0, 31.6: None}
    mono = fixed_time._monotone(per_mag, {0.1: 0, 1.0: 2, 10.0: 0, 31.6: 5}, 5)
    assert mono["nondecreasing"] is False
    assert mono["decreases"] == [{"from": 0.1, "to": 1.0, "settle_from": 5.0, "settle_to": 4.0,
                                  "completed_from": 5, "completed_to": 3, "directions": 5}]
    assert fixed_time._monotone({0.1: 1.0, 1.0: 1.0, 10.0: 2.0}, {0.1: 0, 1.0: 0, 10.0: 0}, 5)["nondecreasing"]

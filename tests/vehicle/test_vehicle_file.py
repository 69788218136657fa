"""A Fossen-type torpedo from a user's vehicle file: checks, paths, identity with the preset, reduction.

* Every field of the shipped ``remus100_fossen.toml`` is a field of the vehicle-file format with the
  same unit, and the file read by path packs and flies bit for bit as the preset.
* Bad files: one line naming the file and the field, for each kind of mistake (and, as a
  property, for any field set out of its range); ``auvtrack check`` and ``run`` refuse alike.
* Paths: relative to the scenario file's folder, or to the working directory for ``--set``.
* The reduced 5-DOF model: its masses, damping and restoring slope equal the truth's
  finite-difference linearisation at U0; the surge response matches; pitch and yaw differ by
  exactly the terms eq. (1)'s C0 adds (Munk moments, m11 for the rigid mass).
* ``remus600`` flies open loop: its top speed from a simulation from rest equals the surge
  balance and lies in the published range; it holds its depth.
"""
from __future__ import annotations

import math
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from auvtrack.vehicle.presets import get_preset, pack_vehicle
from auvtrack.plant.sixdof import fossen
from auvtrack.plant.sixdof.linearise import design_jacobian, step_response, truth_jacobian
from auvtrack.vehicle.truth_presets import load_preset6
from auvtrack.plant.sixdof.torpedo_reduction import reduce_torpedo
from auvtrack.plant.sixdof.truth import initial_state, integrate_open_loop, pack_truth, trim_rpm
from auvtrack.vehicle.vehicle_file import FIELDS, load_vehicle_file, shipped_dir
from auvtrack.scenario import ScenarioError, load_scenario

ROOT = Path(__file__).resolve().parents[1]
FOSSEN = shipped_dir() / "remus100_fossen.toml"
TEXT = FOSSEN.read_text()


def _write(tmp_path: Path, text: str, name: str = "my_auv.toml") -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


def _set(text: str, key: str, new_entry: str) -> str:
    """The file text with the entry ``key = {...}`` of the current section replaced (first match)."""
    out, n = re.subn(rf"^{re.escape(key)} = \{{.*\}}$", new_entry, text, count=1, flags=re.M)
    assert n == 1, key
    return out


# --- the format covers the preset, and the preset by path is the preset ------------------------

def test_every_field_of_the_fossen_preset_is_a_vehicle_file_field_with_its_unit():
    pr = load_preset6("remus100_fossen")
    for section, entries in pr.record.items():
        for key, e in entries.items():
            assert f"{section}.{key}" in FIELDS, f"{section}.{key}"
            assert FIELDS[f"{section}.{key}"].unit == e["unit"], f"{section}.{key}"


def test_fossen_file_by_path_packs_bit_identical_to_the_preset():
    for direct in (False, True):
        a = pack_truth("remus100_fossen", direct=direct)
        b = pack_truth(str(FOSSEN), direct=direct)
        assert a.tobytes() == b.tobytes()
    with_over = {"delta_rate_max": 0.5}
    assert pack_truth("remus100_fossen", with_over).tobytes() == pack_truth(str(FOSSEN), with_over).tobytes()


def test_fossen_file_by_path_flies_bit_identical_to_the_preset():
    import auvtrack

    base = {"name": "id", "disturbance": [], "sim": {"duration": 3.0, "dt": 0.005, "log_dt": 0.05},
            "plant": {"model": "6dof"}, "vehicle": {"preset": "remus100", "u0": 1.5},
            "initial": {"nu": [1.2, 0.0, 0.0, 0.0, 0.0]}, "reference": {"kind": "line", "velocity": [1.2, 0, 0]},
            "controller": {"kind": "open_loop_actuators", "rpm_trim": True, "delta_r": 0.1, "delta_s": -0.05,
                           "t_execute": 0.5}}
    a = auvtrack.simulate({**base, "plant": {"model": "6dof", "preset": "remus100_fossen"}}, warn=False)
    b = auvtrack.simulate({**base, "plant": {"model": "6dof", "preset": str(FOSSEN)}}, warn=False)
    assert a.status == b.status == "ok"
    assert set(a.channels) == set(b.channels)
    for k in a.channels:
        np.testing.assert_array_equal(a.channels[k], b.channels[k], err_msg=k)
    assert b.scenario["resolved"]["plant"]["file"]["path"] == str(FOSSEN)
    assert b.scenario["resolved"]["plant"]["coefficients"] == a.scenario["resolved"]["plant"]["coefficients"] | {
        "design": b.scenario["resolved"]["plant"]["coefficients"]["design"]}


# --- bad files -------------------------------------------------------------------------------------

BAD = [
    (lambda t: _set(t, "S_fin", 'S_fin = { value = -1, unit = "m^2", source = "x" }'),
     "my_auv.toml: fins.S_fin: must be > 0 m^2 (got -1)"),
    (lambda t: _set(t, "S_fin", 'S_fin = { value = 6.65, unit = "cm^2", source = "x" }'),
     "my_auv.toml: fins.S_fin.unit: must be 'm^2' (got 'cm^2')"),
    (lambda t: _set(t, "S_fin", 'S_fin = { value = inf, unit = "m^2", source = "x" }'),
     "my_auv.toml: fins.S_fin: must be a finite number (got inf)"),
    (lambda t: _set(t, "S_fin", 'S_fin = { value = "0.1", unit = "m^2", source = "x" }'),
     "my_auv.toml: fins.S_fin: must be a number in m^2 (got '0.1')"),
    (lambda t: _set(t, "S_fin", 'S_fin = { value = 0.1, unit = "m^2" }'),
     "my_auv.toml: fins.S_fin.source: required key is missing"),
    (lambda t: _set(t, "S_fin", 'S_fin = { value = 0.1, unit = "m^2", source = "x", units = "m" }'),
     "my_auv.toml: fins.S_fin.units: unknown key (allowed: value, unit, source, note)"),
    (lambda t: _set(t, "S_fin", ""), "my_auv.toml: fins.S_fin: required field is missing"),
    (lambda t: t + '\n[engine]\npower = { value = 1, unit = "W", source = "x" }\n', "my_auv.toml: engine: unknown key"),
    (lambda t: t.replace("[fins]\n", '[fins]\nS_rudder = { value = 1, unit = "m^2", source = "x" }\n'),
     "my_auv.toml: fins.S_rudder: unknown field"),
    (lambda t: _set(t, "r_g", 'r_g = { value = [0.0, 0.02], unit = "m", source = "x" }'),
     "my_auv.toml: hull.r_g: must be 3 numbers in m"),
    (lambda t: _set(t, "n_strips", 'n_strips = { value = 20.5, unit = "-", source = "x" }'),
     "my_auv.toml: hull.n_strips: must be a whole number (got 20.5)"),
    (lambda t: _set(t, "diam", 'diam = { value = 1.7, unit = "m", source = "x" }'),
     "my_auv.toml: hull.diam: must be < hull.L = 1.6 m"),
    (lambda t: _set(t, "r_g", 'r_g = { value = [0.0, 0.0, -0.02], unit = "m", source = "x" }'),
     "my_auv.toml: hull.r_g: the righting moment W z_g - B z_b must be > 0 N m"),
    (lambda t: _set(t, "x_fin", 'x_fin = { value = -2.0, unit = "m", source = "x" }'),
     "my_auv.toml: fins.x_fin: must be >= -hull.L = -1.6 m"),
    (lambda t: _set(t, "n_max", 'n_max = { value = 0.0, unit = "rpm", source = "x" }'),
     "my_auv.toml: actuators.n_max: must be in (0, 100000] rpm (got 0)"),
    (lambda t: "colour = 3\n" + t, "my_auv.toml: colour: unknown key"),
    (lambda t: t.replace("[hull]", "[hull"), "my_auv.toml: TOML syntax error"),
]


@pytest.mark.parametrize("edit, message", BAD)
def test_a_bad_file_is_one_line_naming_file_and_field(tmp_path, monkeypatch, edit, message):
    monkeypatch.chdir(tmp_path)
    _write(tmp_path, edit(TEXT))
    with pytest.raises(ValueError) as exc:
        load_vehicle_file("my_auv.toml")
    assert str(exc.value).startswith(message), str(exc.value)
    assert "\n" not in str(exc.value)
    with pytest.raises(ScenarioError) as exc2:  # the same through a scenario, with the scenario's path
        load_scenario({}, ["plant.model=6dof", "plant.preset=my_auv.toml"])
    assert f"plant.preset: {message}" in str(exc2.value)


SCALARS = [k for k, f in FIELDS.items() if f.size == 1 and not f.allow_inf]


def _with(text: str, key: str, value: float) -> str:
    """The file text with field ``key`` (section.name) set to ``value``, added if absent."""
    section, name = key.split(".")
    entry = f'{name} = {{ value = {value!r}, unit = "{FIELDS[key].unit}", source = "x" }}'
    if re.search(rf"^{re.escape(name)} = ", text, flags=re.M):
        return _set(text, name, entry)
    if f"[{section}]\n" in text:
        return text.replace(f"[{section}]\n", f"[{section}]\n{entry}\n")
    return text + f"\n[{section}]\n{entry}\n"


@settings(max_examples=40, deadline=None)
@given(key=st.sampled_from(SCALARS), below=st.booleans(), offset=st.floats(1e-3, 1e3))
def test_any_field_out_of_range_is_refused_naming_it(tmp_path_factory, key, below, offset):
    f = FIELDS[key]
    bound = f.lo if below else f.hi
    if not math.isfinite(bound):
        return
    p = _write(tmp_path_factory.mktemp("v"), _with(TEXT, key, bound - offset if below else bound + offset))
    with pytest.raises(ValueError, match=re.escape(f"my_auv.toml: {key}: must be ")):
        load_vehicle_file(p)


def test_defaults_of_the_optional_fields_are_recorded_with_their_source():
    pr = load_vehicle_file(FOSSEN)
    assert pr.values["design.l"] == FIELDS["design.l"].default
    assert pr.record["design"]["u0"]["source"].startswith("default:")
    assert "hull.mass" not in pr.values and "hull.buoyancy" not in pr.values


def test_mass_and_buoyancy_enter_the_rigid_body_and_the_restoring_force(tmp_path):
    text = TEXT.replace("[hull]\n", '[hull]\nmass = { value = 40.0, unit = "kg", source = "x" }\n'
                                     'buoyancy = { value = 400.0, unit = "N", source = "x" }\n')
    pr = load_vehicle_file(_write(tmp_path, text))
    dd, d0 = fossen.derived(pr), fossen.derived(load_preset6("remus100_fossen"))
    assert dd["m"] == 40.0 and dd["W"] == 40.0 * 9.81 and dd["B"] == 400.0
    keep = ~np.eye(6, dtype=bool) | (np.arange(6) != 3)[:, None]  # added mass of the displaced water ...
    np.testing.assert_allclose(dd["M_a"][keep], d0["M_a"][keep], rtol=1e-15)
    assert dd["M_a"][3, 3] == pytest.approx(0.3 * dd["Ix"])  # ... but roll: r44 times the vehicle's Ix
    assert dd["M_rb"][0, 0] == 40.0 and dd["gm"] == pytest.approx(40.0 * 9.81 * 0.02)


# --- paths -------------------------------------------------------------------------------------------

def test_paths_are_relative_to_the_scenario_file_or_the_working_directory(tmp_path, monkeypatch):
    (tmp_path / "auvs").mkdir()
    (tmp_path / "scen").mkdir()
    _write(tmp_path / "auvs", TEXT)
    scen = tmp_path / "scen" / "s.toml"
    scen.write_text('[plant]\nmodel = "6dof"\npreset = "../auvs/my_auv.toml"\n'
                    '[vehicle]\npreset = "../auvs/my_auv.toml"\n')
    monkeypatch.chdir(tmp_path / "scen")  # a different folder than the file's own would break a cwd rule
    other = tmp_path / "elsewhere"
    other.mkdir()
    monkeypatch.chdir(other)
    sc = load_scenario(scen)
    want = str((tmp_path / "auvs" / "my_auv.toml").resolve())
    assert sc.plant.preset == want and sc.vehicle.preset == want
    monkeypatch.chdir(tmp_path)
    sc2 = load_scenario(scen, ["plant.preset=auvs/my_auv.toml"])  # --set: relative to the working directory
    assert sc2.plant.preset == want
    assert load_scenario(sc2.to_dict()) == sc2  # the resolved scenario is location-free


def _cli(cwd, *args):
    import os
    return subprocess.run([sys.executable, "-m", "auvtrack.cli", *args], capture_output=True, text=True, cwd=cwd,
                          env={**os.environ, "PYTHONPATH": str(ROOT)})


def test_check_and_run_refuse_a_bad_file_alike(tmp_path):
    (tmp_path / "auvs").mkdir()
    _write(tmp_path / "auvs", _set(TEXT, "S_fin", 'S_fin = { value = -1, unit = "m^2", source = "x" }'))
    scen = tmp_path / "s.toml"
    scen.write_text('[plant]\nmodel = "6dof"\npreset = "auvs/my_auv.toml"\n')
    check = _cli(tmp_path, "check", "s.toml")
    run = _cli(tmp_path, "run", "s.toml", "--out", str(tmp_path / "out"))
    want = "auvtrack: error: s.toml: plant.preset: auvs/my_auv.toml: fins.S_fin: must be > 0 m^2 (got -1)"
    for r in (check, run):
        assert r.returncode == 2 and r.stderr.strip() == want, r.stderr
    assert not (tmp_path / "out").exists()


def test_vehicle_preset_from_a_file_is_the_reduction_at_the_reference_speed(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    _write(tmp_path, TEXT)
    sc = load_scenario({}, ["vehicle.preset=my_auv.toml"])
    red = reduce_torpedo(load_vehicle_file("my_auv.toml"), sc.vehicle.u0)
    assert sc.vehicle.u0 == pytest.approx(0.4123, abs=1e-4)  # the Section 4 helix's mean speed (remus100 alike)
    assert sc.vehicle.u0 == load_scenario({}, ["vehicle.preset=remus100"]).vehicle.u0
    assert sc.vehicle.m == red["m"] and sc.vehicle.d == red["d"] and sc.vehicle.wgml == red["wgml"]
    assert sc.vehicle.l == FIELDS["design.l"].default


# --- the reduced 5-DOF model against the truth's linearisation ------------------------------------

CASES = [("remus100_fossen", 1.5), ("remus100_fossen", 0.6), ("remus600", 1.54)]


@pytest.fixture(scope="module")
def linear():
    out = {}
    for name, u0 in CASES:
        pre = get_preset(name, u0=u0)
        vp = pack_vehicle(pre.m, pre.d, pre.wgml, pre.l)
        out[(name, u0)] = (truth_jacobian(name, u0, h=1e-8), design_jacobian(vp, u0, h=1e-8), pre)
    return out


@pytest.mark.parametrize("case", CASES)
def test_reduced_masses_damping_and_restoring_equal_the_truth_linearisation(linear, case):
    tj, dj, pre = linear[case]
    M = tj["M"]
    np.testing.assert_allclose(pre.m, (M[0, 0], M[1, 1], M[2, 2], M[4, 4], M[5, 5]), rtol=1e-12)
    K = tj["K"]
    diag_truth = np.array([K[0, 0], K[1, 1], K[2, 2], K[4, 4], K[5, 5]])
    np.testing.assert_allclose(-diag_truth, pre.d, rtol=1e-5, atol=2e-5)
    # the 5-DOF model's own slopes (finite differences of eq. 1) are its numbers
    np.testing.assert_allclose(-np.diag(pre.m) @ np.diag(dj["A"])[:5], pre.d, rtol=1e-6, atol=1e-7)
    theta_slope = (M @ tj["A"][:6, 7])[4]
    assert theta_slope == pytest.approx(-pre.wgml, rel=1e-6)
    assert pre.m[3] * dj["A"][3, 5] == pytest.approx(-pre.wgml, rel=1e-6)
    # input gains: tau reaches nu_dot through the mass matrix (M^-1; 5-DOF: its diagonal)
    np.testing.assert_allclose(tj["B"][[0, 4, 5], [0, 1, 2]], np.diag(np.linalg.inv(M))[[0, 4, 5]], rtol=1e-5)
    np.testing.assert_allclose(dj["B"][[0, 3, 4], [0, 1, 2]], 1.0 / np.array(pre.m)[[0, 3, 4]], rtol=1e-6)


@pytest.mark.parametrize("case", CASES)
def test_surge_response_to_a_small_thrust_step_matches_the_truth(linear, case):
    tj, dj, _ = linear[case]
    ts = np.linspace(0.0, 30.0, 301)
    amp = 0.01 * tj["tau_u0"]
    yt = step_response(tj["A"], tj["B"], 0, amp, ts)[:, 0]
    y5 = step_response(dj["A"], dj["B"], 0, amp, ts)[:, 0]
    assert np.abs(y5 - yt).max() <= 0.005 * np.abs(yt).max()  # stated tolerance: 0.5 % of the response


@pytest.mark.parametrize("case", CASES)
def test_pitch_and_yaw_differ_by_exactly_the_c0_terms_of_eq1(linear, case):
    """Off the diagonal the design model is eq. (1)'s structure: C0 built from the diagonal masses."""
    tj, dj, pre = linear[case]
    u0 = case[1]
    m11, m22, m33, m44, m55 = pre.m
    m_rb = fossen.derived(load_vehicle_file(shipped_dir() / f"{case[0]}.toml"))["m"]
    idx = [0, 1, 2, 4, 5]
    Kt = tj["K"][np.ix_(idx, idx)]
    K5 = np.diag(pre.m) @ dj["A"][:5, :5]
    expected_gap = np.zeros((5, 5))
    expected_gap[1, 4] = -(m11 - m_rb) * u0   # sway from r: -m11 U0 against the rigid body's -m U0
    expected_gap[2, 3] = (m11 - m_rb) * u0    # heave from q
    expected_gap[3, 2] = -(m11 - m33) * u0    # pitch from w: the Munk moment, absent from the truth
    expected_gap[4, 1] = -(m22 - m11) * u0    # yaw from v: the Munk moment
    gap = K5 - Kt
    scale = np.abs(K5).max()
    np.testing.assert_allclose(gap, expected_gap, atol=1e-5 * scale)


def test_design_model_of_fossens_remus_is_unstable_where_the_truth_is_stable(linear):
    tj, dj, _ = linear[("remus100_fossen", 1.5)]
    assert np.linalg.eigvals(tj["A"]).real.max() < 0.0
    assert np.linalg.eigvals(dj["A"]).real.max() > 0.5  # 1/s: the C0 Munk moments, unopposed


# --- remus600 ------------------------------------------------------------------------------------------

def test_remus600_flies_open_loop_at_a_published_speed_and_holds_depth():
    from auvtrack.plant.sixdof.layout import P_NMAX
    from tools.sea_trials import speed_at_rpm

    pp = pack_truth("remus600")
    n_max = float(pp[P_NMAX])
    out = integrate_open_loop("remus600", (0.0, 0.0, n_max), 90.0, 0.01, pp=pp, times=(60.0, 90.0))
    u60, u90 = out[60.0][6], out[90.0][6]
    assert abs(u90 - u60) < 1e-3  # terminal speed reached
    assert u90 == pytest.approx(speed_at_rpm("remus600", n_max), rel=2e-3)  # = the surge balance
    assert 1.54 <= u90 <= 5 * 1852 / 3600  # published: cruise 3 kn, top speed up to 5 kn
    # neutral and trimmed: once at speed it neither climbs nor dives (the start from rest pitches it
    # briefly through the CG offset)
    assert abs(out[90.0][2] - out[60.0][2]) < 1e-3 and abs(math.degrees(out[90.0][4])) < 0.01
    # cruise: the propeller trimmed for 3 kn keeps it there
    rpm = trim_rpm("remus600", pp, 1.54)
    x0 = initial_state(nu6=(1.54, 0, 0, 0, 0, 0), actuators=(0.0, 0.0, rpm))
    assert integrate_open_loop("remus600", (0.0, 0.0, rpm), 20.0, 0.01, x0=x0, pp=pp)["final"][6] == \
        pytest.approx(1.54, abs=1e-3)


def test_remus600_is_a_different_larger_vehicle():
    a, b = fossen.derived(load_vehicle_file(shipped_dir() / "remus600.toml")), fossen.derived(load_preset6("remus100_fossen"))
    assert a["m"] > 5 * b["m"] and a["M"][4, 4] > 20 * b["M"][4, 4]
    assert a["m"] > a["m_f"]  # heavier than its spheroid displaces, trimmed neutral
    assert a["B"] == a["W"]

"""A plant from outside the package (examples/plugin_plant.py: a 3-DOF horizontal-plane vehicle),
flown by a built-in controller: it reproduces the horizontal motion of the 5-DOF plant, its
contract is checked with one-line errors, and check and run refuse the same."""
from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

import auvtrack
from auvtrack.cli import EXIT_BAD_INPUT, main
from auvtrack.plant.registry import check_plant
from auvtrack.scenario import ScenarioError, load_scenario
from auvtrack.user_modules import load_module

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "plugin_plant.py"
BASE = {"vehicle": {"preset": "paper"}, "disturbance": [], "uncertainty": {"C": 0.0, "D": 0.0},
        "reference": {"kind": "circle", "radius": 20.0, "omega": 0.05, "depth": 5.0},
        "controller": {"kind": "pid"}, "sim": {"duration": 20.0, "dt": 0.01, "log_dt": 0.1},
        "initial": {"eta": [19.0, 0.0, 5.0, 0.0, 1.5707963], "nu": [1.0, 0.0, 0.0, 0.0, 0.0]}}


@pytest.fixture
def plant_file(tmp_path) -> Path:
    """The example copied to a folder outside the repository."""
    path = tmp_path / "elsewhere" / "my_plant.py"
    path.parent.mkdir()
    shutil.copy(EXAMPLE, path)
    return path


def test_a_3dof_plug_in_plant_flies_the_horizontal_motion_of_the_5dof_plant(plant_file):
    """Level flight at constant depth: the 5-DOF plant's horizontal equations are the plug-in's, so a
    PID run on each gives the same horizontal trajectory and input (to rounding)."""
    five = auvtrack.simulate(BASE)
    three = auvtrack.simulate({**BASE, "plant": {"model": "plugin", "module": str(plant_file)}})
    assert five.ok and three.ok
    assert three.scenario["plant"] == {"model": "plugin", "module": str(plant_file), "params": {}}
    for c in ("x", "y", "psi", "u", "v", "r", "tau_u", "tau_r"):
        scale = 1.0 + np.max(np.abs(five[c]))
        assert np.max(np.abs(five[c] - three[c])) <= 1e-9 * scale, c
    assert np.all(three["z"] == 5.0) and np.all(three["theta"] == 0.0)
    assert five.metrics["rmse_x"] < 0.2  # and it tracks


def test_the_plug_in_plant_limits_what_it_applies(plant_file):
    sc = {**BASE, "plant": {"model": "plugin", "module": str(plant_file), "params": {"tau_max": [5.0, 1.0]}}}
    res = auvtrack.simulate(sc)
    assert np.max(np.abs(res["tau_u"])) <= 5.0 and np.max(np.abs(res["tau_r"])) <= 1.0
    assert res.metrics["t_sat_tau_u"] > 0


def test_plug_in_plant_params_and_commands_are_checked_at_load(plant_file):
    with pytest.raises(ScenarioError, match=r"plant\.params\.tau_max.*Section of"):
        load_scenario({**BASE, "plant": {"model": "plugin", "module": str(plant_file), "params": {"tau_max": 3}}})
    with pytest.raises(ScenarioError, match=r"controller\.kind: open_loop_actuators commands the actuators; "
                                            r"plant\.model 'plugin' accepts tau"):
        load_scenario({**BASE, "controller": {"kind": "open_loop_actuators"},
                       "plant": {"model": "plugin", "module": str(plant_file)}})


BROKEN = {
    "no_setup": ("def setup(", "def not_setup(", r"does not define setup"),
    "not_compiled": ("@njit_noalloc\ndef rhs(", "def rhs(", r"rhs must be compiled"),
    "clashing_channel": ('LOG_NAMES = ()', 'LOG_NAMES = ("x",)', r"LOG_NAMES: channel name 'x' is taken"),
    "repeated_state": ('STATE = ("x", "y", "z", "psi", "u", "v", "r")', 'STATE = ("x", "x", "z", "psi", "u", "v", "r")',
                       r"STATE repeats a name"),
    "actuators_only": ('ACCEPTS = ("tau",)', 'ACCEPTS = ("actuators",)', r"ACCEPTS must be"),
}


@pytest.mark.parametrize("case", sorted(BROKEN))
def test_a_broken_plant_is_refused_in_one_line_naming_the_file(tmp_path, case):
    old, new, expected = BROKEN[case]
    text = EXAMPLE.read_text()
    assert old in text
    path = tmp_path / f"{case}.py"
    path.write_text(text.replace(old, new))
    with pytest.raises(ValueError, match=expected) as err:
        check_plant(load_module(str(path)))
    assert str(path) in str(err.value) and "\n" not in str(err.value)
    # the command line refuses it the same way in check and run
    scenario = tmp_path / "s.toml"
    scenario.write_text(f'[plant]\nmodel = "plugin"\nmodule = "{case}.py"\n')
    assert main(["check", str(scenario)]) == EXIT_BAD_INPUT
    assert main(["run", str(scenario), "--out", str(tmp_path / "run")]) == EXIT_BAD_INPUT
    assert not (tmp_path / "run").exists()


def test_a_plant_with_a_typing_error_is_refused_in_one_line_naming_its_file_and_line(tmp_path, capsys):
    """The plug-in's functions are compiled alone at set-up: check and run name the user's line, not the kernel."""
    text = EXAMPLE.read_text()
    assert "    dx[2] = 0.0\n" in text
    path = tmp_path / "typo_plant.py"
    path.write_text(text.replace("    dx[2] = 0.0\n", "    dx[2] = object()\n"))
    line = path.read_text().splitlines().index("    dx[2] = object()") + 1
    scenario = tmp_path / "s.toml"
    scenario.write_text('[plant]\nmodel = "plugin"\nmodule = "typo_plant.py"\n')
    for args in (["check", str(scenario)], ["run", str(scenario), "--out", str(tmp_path / "run")]):
        assert main(args) == EXIT_BAD_INPUT
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1 and "Traceback" not in err, err
        assert f"plant.module: {path}: cannot compile: {path}:{line}: Untyped global name 'object'" in err, err
    assert not (tmp_path / "run").exists()


def test_compile_error_line_reads_a_highlighted_report(tmp_path):
    """Numba's colour scheme wraps the report in ANSI codes; the line keeps the user's location and the cause."""
    from auvtrack.jit.errors import compile_error_line

    user = tmp_path / "p.py"
    report = ("\x1b[1m\x1b[1mFailed in nopython mode pipeline (step: nopython frontend)\n"
              "\x1b[1m\x1b[1mUntyped global name 'object':\x1b[0m \x1b[1mCannot determine Numba type\x1b[0m\n"
              f'\x1b[1m\nFile "{user}", line 7:\x1b[0m\n')
    assert compile_error_line(report, "k") == (f"k: cannot compile: {user}:7: Untyped global name 'object': "
                                               "Cannot determine Numba type")


def _faulty_plant(tmp_path, after: float) -> Path:
    """The example with an out-of-bounds write in rhs once t > after."""
    text = EXAMPLE.read_text()
    body = "    dx[6] = (cmd[2] - c * (m22 - m11) * u * v - pp[PARAMS.d55] * r) / pp[PARAMS.m55]\n"
    assert text.count(body) == 1
    path = tmp_path / "oob_plant.py"
    path.write_text(text.replace(body, body + f"    if t > {after!r}:\n        dx[100000] = 1.0\n"))
    return path


def test_check_and_run_refuse_a_plant_writing_out_of_bounds_naming_its_line(tmp_path, capsys):
    """The probe runs a plug-in plant's compiled functions bounds-checked: the index error of rhs at
    t > 0.5 s is named with its file, line and time in one line, by check and run alike (nothing
    written), and simulate raises PlantFault; the same plant faulting after the probe's horizon passes."""
    from auvtrack.simulation.probe import PROBE_S, PlantFault

    path = _faulty_plant(tmp_path, 0.5)
    line = path.read_text().splitlines().index("        dx[100000] = 1.0") + 1
    scenario = tmp_path / "s.toml"
    scenario.write_text('[plant]\nmodel = "plugin"\nmodule = "oob_plant.py"\n[controller]\nkind = "pid"\n'
                        '[sim]\nduration = 3.0\ndt = 0.01\n')
    lines = []
    for args in (["check", str(scenario)], ["run", str(scenario), "--out", str(tmp_path / "run")]):
        assert main(args) == EXIT_BAD_INPUT
        err = [ln for ln in capsys.readouterr().err.splitlines() if not ln.startswith("compiling kernels")]
        assert len(err) == 1 and "Traceback" not in err[0], err
        lines.append(err[0])
    assert lines[0] == lines[1] and not (tmp_path / "run").exists()
    assert f"plant.module: {path}:{line}: rhs raised IndexError: index 100000 is out of bounds" in lines[0], lines[0]
    assert "in the step from t = 0.5" in lines[0] and "bounds-checked probe run of the first 2 s" in lines[0]
    with pytest.raises(PlantFault, match=rf"oob_plant.py:{line}: rhs raised IndexError"):
        auvtrack.simulate(str(scenario))
    (tmp_path / "late").mkdir()
    _faulty_plant(tmp_path / "late", PROBE_S + 0.5)
    scenario.write_text(scenario.read_text().replace("oob_plant.py", "late/oob_plant.py"))
    assert main(["check", str(scenario)]) == 0  # the documented limit: after the probe's horizon it is not seen

"""Plug-in controllers (``controller.kind = "plugin"``): the shipped example run from outside the
repository, its law's identity, bad plug-ins refused with one line naming the file and the
missing piece, a plug-in copy of a built-in law bit-identical to it, batches and sweeps."""
from __future__ import annotations

import json
import re
import shutil
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy.linalg import expm

from auvtrack.cli import EXIT_BAD_INPUT, main
from auvtrack.control.tracking import error_state
from auvtrack.vehicle.kinematics import attitude
from auvtrack.reference import build_reference
from auvtrack.batch.runner import run_batch
from auvtrack.perf.bench import plugin_copy
from auvtrack.scenario import ScenarioError, load_scenario, paper_scenario_path
from auvtrack.simulation.pipeline import prepare, run_prepared

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "plugin_controller.py"
IDEAL = ["uncertainty.C=0", "uncertainty.D=0", "disturbance=[]"]


def _scenario(folder: Path, module: str, params: str = "", extra: str = "") -> Path:
    """A Section 4 scenario file in ``folder`` whose controller is the plug-in ``module``."""
    path = folder / "scenario.toml"
    path.write_text(f'name = "plugin-test"\n{extra}\n[controller]\nkind = "plugin"\nmodule = "{module}"\n'
                    + (f"params = {{ {params} }}\n" if params else ""))
    return path


def _quiet_run(source, overrides=()):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return run_prepared(prepare(load_scenario(source, overrides)))


@pytest.fixture(scope="module")
def outside(tmp_path_factory):
    """A folder outside the repository holding a copy of the example (one kernel for the module)."""
    work = tmp_path_factory.mktemp("elsewhere")
    shutil.copy(EXAMPLE, work / "my_pd.py")
    return work


def test_the_example_runs_from_a_folder_outside_the_repository(outside, tmp_path, monkeypatch):
    """The example next to a scenario in a temporary folder, run there with the CLI."""
    sc = _scenario(outside, "my_pd.py")
    monkeypatch.chdir(tmp_path)  # neither the repository nor the plug-in's folder
    assert main(["run", str(sc), "--out", str(tmp_path / "out")]) == 0
    df = pd.read_csv(tmp_path / "out" / "trajectory.csv")
    late = df["t"] >= 80.0
    assert df["t"].iloc[-1] == pytest.approx(100.0)
    for a in "xyz":  # Section 4 (disturbance, 10 % C and D error) tracked to < 1 cm
        assert df[f"e{a}"][late].abs().max() < 0.01
    assert {"a_x", "a_y", "a_z"} <= set(df.columns)
    run = json.loads((tmp_path / "out" / "run.json").read_text())
    assert run["scenario"]["controller"] == {"kind": "plugin", "module": str((outside / "my_pd.py").resolve()),
                                             "params": {"kp": 9.0, "kd": 6.0}}
    assert main(["check", str(sc)]) == 0


def test_the_example_obeys_its_pd_law_on_the_nominal_plant(outside):
    """e'' + kd e' + kp e = 0 on the disturbance-free nominal plant: the logged e is the exact solution."""
    res = _quiet_run(_scenario(outside, "my_pd.py", "kp = 2.0, kd = 1.5"), IDEAL + ["sim.duration=15"])
    assert res.ok
    A = np.array([[0.0, 1.0], [-2.0, -1.5]])
    eta = tuple(res[c][0] for c in ("x", "y", "z", "theta", "psi"))
    nu = tuple(res[c][0] for c in ("u", "v", "w", "q", "r"))
    refm0 = np.vstack(build_reference({"kind": "helix"}).evaluate(0.0))
    vp = prepare(load_scenario({})).vp_nom
    e0, ed0, _ = (np.array(v) for v in error_state(eta, attitude(eta[3], eta[4]), nu, refm0, vp))
    for i, a in enumerate("xyz"):
        want = np.array([expm(A * t) @ np.array([e0[i], ed0[i]]) for t in res.t])[:, 0]
        np.testing.assert_allclose(res[f"e{a}"], want, rtol=0, atol=1e-8)


def test_params_are_validated_by_the_plugins_own_model(tmp_path, capsys):
    sc = _scenario(tmp_path, str(EXAMPLE), "kp = -1.0")
    for command in ("check", "run"):
        assert main([command, str(sc), "--out", str(tmp_path / "r")] if command == "run" else [command, str(sc)]) \
            == EXIT_BAD_INPUT
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1 and "controller.params.kp" in err and str(EXAMPLE) in err, err
    with pytest.raises(ScenarioError, match=r"controller\.params\.kq: Extra inputs"):
        load_scenario(_scenario(tmp_path, str(EXAMPLE), "kq = 1.0"))
    with pytest.raises(ScenarioError, match=r"controller\.params\.kp: must be a real number"):
        load_scenario(_scenario(tmp_path, str(EXAMPLE), 'kp = "9"'))


GOOD_SETUP = """
def setup(params, ctx):
    return CompiledController(cp=np.zeros(2), xc0=np.zeros(0), aux_names=AUX_NAMES)
"""
GOOD_LAW = """
@njit
def control(t, y, xc, args, out):
    out.u[0] = 0.0
    return 0
"""
HEAD = """import numpy as np
from auvtrack.control.plugin import CompiledController, ControllerParamsBase, njit
AUX_NAMES = ()
class Params(ControllerParamsBase):
    pass
"""


@pytest.mark.parametrize("name, source, expected", [
    ("import_error", "x = 1 / 0\n" + HEAD + GOOD_LAW + GOOD_SETUP,
     r"controller\.module: cannot import .*import_error\.py: ZeroDivisionError: division by zero"),
    ("no_setup", HEAD + GOOD_LAW, r"controller\.module: .*no_setup\.py does not define setup"),
    ("no_law_no_params", "AUX_NAMES = ()\n" + GOOD_SETUP,
     r"controller\.module: .*no_law_no_params\.py does not define Params, control"),
    ("tuple_setup", HEAD + GOOD_LAW + "\ndef setup(params, ctx):\n    return np.zeros(2), np.zeros(0)\n",
     r"controller\.module: .*tuple_setup\.py: setup must return a CompiledController \(got tuple\)"),
    ("matrix_cp", HEAD + GOOD_LAW + GOOD_SETUP.replace("np.zeros(2)", "np.zeros((2, 2))"),
     r"controller\.module: .*matrix_cp\.py: setup's cp must be a 1-D array of real numbers \(got shape \(2, 2\)"),
    ("aux_mismatch", HEAD + GOOD_LAW + GOOD_SETUP.replace("aux_names=AUX_NAMES", "aux_names=('a',)"),
     r"controller\.module: .*aux_mismatch\.py: setup's aux_names \('a',\) differ from AUX_NAMES \(\)"),
    ("tuple_status", HEAD + GOOD_LAW.replace("return 0", "return 0, 1") + GOOD_SETUP,
     r"controller\.module: .*tuple_status\.py: control must return an int status \(got tuple"),
    ("float_status", HEAD + GOOD_LAW.replace("return 0", "return 0.5") + GOOD_SETUP,
     r"controller\.module: .*float_status\.py: control must return an int status \(got float"),
    ("not_compiled", HEAD + GOOD_LAW.replace("out.u[0] = 0.0", "out.u[0] = object()") + GOOD_SETUP,
     r"controller\.module: .*not_compiled\.py: cannot compile: /.*not_compiled\.py:9: Untyped global name 'object'"),
    ("missing_file", None, r"controller\.module: no such file .*missing_file\.py"),
])
def test_a_broken_plugin_is_one_line_naming_the_file_and_the_missing_piece(tmp_path, capsys, name, source,
                                                                            expected):
    if source is not None:
        (tmp_path / f"{name}.py").write_text(source)
    sc = _scenario(tmp_path, f"{name}.py")
    for command in ("check", "run"):
        args = [command, str(sc)] + (["--out", str(tmp_path / "r")] if command == "run" else [])
        assert main(args) == EXIT_BAD_INPUT
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1 and "Traceback" not in err, err
        assert re.search(expected, err), err
    assert not (tmp_path / "r").exists()


def test_a_plugin_copy_of_a_builtin_law_is_bit_identical_to_it(tmp_path):
    path = plugin_copy("ftsmc", tmp_path)  # the module with absolute imports, as a file
    built = _quiet_run(paper_scenario_path(), ["controller={kind=\"ftsmc\", k1=0.07}", "sim.duration=20"])
    plug = _quiet_run(paper_scenario_path(), [f"controller={{kind=\"plugin\", module=\"{path}\", "
                                              "params={k1=0.07}}", "sim.duration=20"])
    assert built.ok and plug.ok
    for name in ("x", "y", "z", "theta", "psi", "u", "tau_u", "tau_q", "tau_r", "sliding_x", "sliding_y", "sliding_z"):
        np.testing.assert_array_equal(plug[name], built[name], err_msg=name)
    assert plug.metrics == built.metrics


def test_a_plugin_given_by_module_name_with_its_own_status(tmp_path, monkeypatch):
    """A dotted module on sys.path; its STATUS names the failure it returns."""
    (tmp_path / "my_stopper.py").write_text(HEAD + GOOD_SETUP + """
STATUS = {11: "my stop: t > 0.5 s"}
@njit
def control(t, y, xc, args, out):
    out.u[0] = 0.0
    out.u[1] = 0.0
    out.u[2] = 0.0
    return 11 if t > 0.5 else 0
""")
    monkeypatch.syspath_prepend(str(tmp_path))
    res = _quiet_run(paper_scenario_path(), ["controller={kind=\"plugin\", module=\"my_stopper\"}", "sim.duration=2"])
    assert not res.ok and res.failure["cause"] == "controller"
    assert res.failure["detail"] == "my stop: t > 0.5 s"
    assert res.failure["time"] == pytest.approx(0.5, abs=1.5e-3)  # the step in which the law first said so


def test_batches_and_sweep_chunks_accept_a_plugin(outside):
    from auvtrack.batch.sweep_spec import load_study
    from auvtrack.batch.sweep_worker import run_chunk

    sc = _scenario(outside, "my_pd.py", extra="[sim]\nduration = 5.0")
    single = _quiet_run(sc)
    batch = run_batch([prepare(load_scenario(sc)), prepare(load_scenario(sc, ["controller.params.kp=4"]))])
    assert batch[0].metrics == single.metrics and batch[1].metrics != single.metrics
    (outside / "study.toml").write_text('name = "plug"\nscenario = "scenario.toml"\nseed = 1\nsamples = 2\n'
                                         'chunk_size = 4\n[grid]\n"controller.params.kp" = [4.0, 9.0]\n')
    table = run_chunk(load_study(outside / "study.toml"), 0).to_pandas()
    assert len(table) == 4 and (table["status"] == "ok").all()


def test_a_path_given_outside_a_file_is_relative_to_the_current_folder(outside, monkeypatch):
    monkeypatch.chdir(outside)
    sc = load_scenario(paper_scenario_path(), ["controller={kind=\"plugin\", module=\"my_pd.py\"}"])
    assert sc.controller.module == str((outside / "my_pd.py").resolve())
    assert load_scenario(sc.to_dict()) == sc  # the resolved scenario names the file absolutely


HOSTILE = 'we\\Nird """ dir'  # a backslash sequence and a triple quote: legal in a file name


@pytest.mark.parametrize("change, expected", [
    (None, None),  # runs: nothing the user named reaches generated code unescaped
    (("\nSTATUS = None\n",), r"controller\.module: .*status_none\.py: STATUS must map codes 10 \.\. 2\*\*31 - 1 to "
                             r"messages \(got None\)"),
    (("    out.aux[0], out.aux[1], out.aux[2] = a\n", "    out.aux[0], out.aux[1], out.aux[2] = a\n    z = a[5]\n"),
     r"controller\.module: .*typing_error\.py: cannot compile: .*typing_error\.py:(?P<line>\d+): tuple index out of "
     r"range"),
], ids=["runs", "status_none", "typing_error"])
def test_a_plugin_in_a_folder_with_a_hostile_name(tmp_path, capsys, change, expected):
    """Loaded by module spec, named by repr in generated code: such a folder runs the law (check and run)
    or refuses it in one line naming the file and, for a compile error, the line of the cause."""
    folder = tmp_path / HOSTILE
    folder.mkdir()
    name = "law.py" if change is None else ("status_none.py" if len(change) == 1 else "typing_error.py")
    text = EXAMPLE.read_text()
    if change is not None:
        text = text + change[0] if len(change) == 1 else text.replace(*change)
    (folder / name).write_text(text)
    sc = _scenario(folder, name, extra="[sim]\nduration = 1.0")
    if expected is None:
        assert main(["check", str(sc)]) == 0
        assert main(["run", str(sc), "--out", str(tmp_path / "run")]) == 0
        assert (tmp_path / "run" / "trajectory.csv").is_file()
        return
    for args in (["check", str(sc)], ["run", str(sc), "--out", str(tmp_path / "run")]):
        assert main(args) == EXIT_BAD_INPUT
        err = [ln for ln in capsys.readouterr().err.splitlines() if not ln.startswith("compiling kernels")]
        assert len(err) == 1 and "Traceback" not in err[0], err
        m = re.search(expected, err[0])
        assert m, err[0]
        if "line" in m.groupdict():
            assert text.splitlines()[int(m["line"]) - 1].strip() == "z = a[5]"
    assert not (tmp_path / "run").exists()

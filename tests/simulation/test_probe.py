"""The bounds-checked probe run of a plug-in law: a law that writes out of bounds after t = 0 is
refused by ``check`` and ``run`` alike (one line naming its file, line and the index error), by
``simulate`` with a ``ValueError``, and nothing is written; a correct law passes untouched."""
from __future__ import annotations

import numpy as np
import pytest

import auvtrack
from auvtrack.cli import EXIT_BAD_INPUT, main
from auvtrack.control.contract import evaluate
from auvtrack.control.plugin import STATUS_RAISED, bounds_checked
from auvtrack.engine.kernels import KernelKey, kernel_source
from auvtrack.jit import njit
from auvtrack.simulation.probe import PROBE_S, LawFault

HEAD = """import numpy as np
from auvtrack.control.plugin import CompiledController, ControllerParamsBase, njit
AUX_NAMES = ()
class Params(ControllerParamsBase):
    after: float = 0.5

def setup(params, ctx):
    return CompiledController(cp=np.array([params.after]), xc0=np.zeros(0), aux_names=AUX_NAMES)

@njit
def control(t, y, xc, args, out):
    out.u[0] = -10.0 * y.eta[2]
"""
OOB_LINE = 14  # the line of the out-of-bounds write below
OUT_OF_BOUNDS = HEAD + """    if t > args.cp[0]:
        out.u[100000] = 1.0
    return 0
"""


def _scenario(folder, body: str, duration: float = 3.0, after: float = 0.5):
    (folder / "law.py").write_text(body)
    path = folder / "sc.toml"
    path.write_text(f'name = "probe"\n[sim]\nduration = {duration}\n[controller]\nkind = "plugin"\nmodule = "law.py"\n'
                    f'params = {{ after = {after} }}\n')
    return path


def _error_line(capsys) -> str:
    err = [ln for ln in capsys.readouterr().err.splitlines() if not ln.startswith("compiling kernels")]
    assert len(err) == 1 and err[0].startswith("auvtrack: error: ") and "Traceback" not in err[0], err
    return err[0]


def test_check_and_run_refuse_a_law_writing_out_of_bounds_after_t0(tmp_path, capsys):
    sc = _scenario(tmp_path, OUT_OF_BOUNDS)
    assert OUT_OF_BOUNDS.splitlines()[OOB_LINE - 1].strip() == "out.u[100000] = 1.0"
    assert main(["check", str(sc)]) == EXIT_BAD_INPUT
    line = _error_line(capsys)
    assert f"law.py:{OOB_LINE}: control raised IndexError: index 100000 is out of bounds" in line
    assert "in the step from t = 0.5 s" in line and "controller.module" in line
    out = tmp_path / "out"
    assert main(["run", str(sc), "--out", str(out)]) == EXIT_BAD_INPUT
    assert _error_line(capsys) == line  # check refuses exactly what run refuses
    assert not out.exists()  # refused before anything is written
    with pytest.raises(LawFault, match=rf"law.py:{OOB_LINE}: control raised IndexError"):
        auvtrack.simulate(str(sc))


def test_a_fault_after_the_probe_horizon_is_not_seen_and_a_correct_law_passes(tmp_path, capsys):
    """The probe runs the first PROBE_S seconds only (its documented limit): the same law writing
    out of bounds from t > PROBE_S + 1 is not refused by check; the correct part of the law passes."""
    sc = _scenario(tmp_path, OUT_OF_BOUNDS, duration=PROBE_S + 2.0, after=PROBE_S + 1.0)
    assert main(["check", str(sc)]) == 0
    assert "auvtrack: error" not in capsys.readouterr().err


def test_bounds_checked_returns_the_laws_status_or_the_raised_status():
    """The guarded law returns the law's own status and outputs when it runs within bounds."""

    @njit
    def law(t, y, xc, args, out):
        out.u[0] = t
        if t > 1.0:
            out.u[int(t) * 1000] = 1.0
        return 7 if t > 0.5 else 0

    guarded = bounds_checked(law)
    assert bounds_checked(law) is guarded  # made once
    ref, z5 = np.zeros((3, 3)), (0.0,) * 5
    status, u, _, _ = evaluate(guarded, 0.25, z5, z5, np.zeros(0), ref, np.zeros(1), np.zeros(40), n_aux=0)
    assert status == 0 and u[0] == 0.25
    assert evaluate(guarded, 0.75, z5, z5, np.zeros(0), ref, np.zeros(1), np.zeros(40), n_aux=0)[0] == 7
    assert evaluate(guarded, 2.0, z5, z5, np.zeros(0), ref, np.zeros(1), np.zeros(40), n_aux=0)[0] == STATUS_RAISED


def test_the_checked_kernel_only_rebinds_the_law():
    """A checked key is another kernel (its own name and cache) whose source differs only by the binding."""
    key = KernelKey("auvtrack.control.pid", "auvtrack.plant.five_dof", "pid on 5dof")
    checked = KernelKey(key.law, key.plant, key.label, checked=True)
    assert checked.name == key.name + "__checked"
    plain, other = kernel_source(key).splitlines(), kernel_source(checked).splitlines()
    extra = [ln for ln in other if ln not in plain]
    assert extra == ["law = llvm_inline(load_module('auvtrack.control.pid').control)",
                     "from auvtrack.control.plugin import bounds_checked  # noqa: E402",
                     "law = bounds_checked(law)"]


ENDLESS = HEAD + """    if t > args.cp[0]:
        while True:
            out.u[0] += 1.0
    return 0
"""
DRIVER = """
import sys
import auvtrack.simulation.probe as probe
from auvtrack.cli import main
probe.PROBE_WALL_S = 3.0
sys.exit(main([sys.argv[1], sys.argv[2]] + sys.argv[3:]))
"""


@pytest.mark.parametrize("command", ["check", "run"])
def test_a_law_that_never_returns_is_refused_after_the_probes_wall_time(tmp_path, command):
    """An endless loop at t > 0.5 s: check and run refuse it in one line (exit 2, nothing written)
    once the probe's wall-time bound has passed, and the process ends although the law still runs."""
    import subprocess
    import sys
    import time

    sc = _scenario(tmp_path, ENDLESS)
    out = tmp_path / "out"
    t0 = time.monotonic()
    p = subprocess.run([sys.executable, "-c", DRIVER, command, str(sc)] + (["--out", str(out)] if command == "run"
                                                                             else []),
                       capture_output=True, text=True, timeout=600)
    assert p.returncode == EXIT_BAD_INPUT, p.stderr
    err = [ln for ln in p.stderr.splitlines() if not ln.startswith("compiling kernels")]
    assert len(err) == 1 and "control did not return within 3 s of wall time" in err[0] and "law.py" in err[0]
    assert not out.exists() and time.monotonic() - t0 < 300


def test_a_first_call_that_spends_the_wall_time_loading_the_kernel_is_run_again(tmp_path, monkeypatch):
    """A kernel not yet loaded in this process loads (or compiles) in the probe's first call, holding
    the GIL, so that call can use up the wall time before the law runs: the probe runs once more
    instead of letting the law go unprobed."""
    import time
    from types import SimpleNamespace

    from auvtrack.engine import kernels
    from auvtrack.scenario import load_scenario
    from auvtrack.simulation import pipeline, probe as probe_module

    prep = pipeline.prepare(load_scenario(str(_scenario(tmp_path, OUT_OF_BOUNDS))))
    monkeypatch.setattr(probe_module, "PROBE_WALL_S", 0.5)
    real_kernel, real_call, calls = kernels.kernel, pipeline.call_kernel, []

    class NotLoaded:  # what the probe finds before its first call: no signature loaded yet
        signatures = ()

    def first_call_loads(p, out):
        calls.append(p.key)
        if len(calls) == 1:
            time.sleep(1.0)  # past the wall time, as a kernel compiling in the thread
            return 0, 0, 0.0  # and then the loop saw the stop request at its first step
        return real_call(p, out)

    seen = SimpleNamespace(warmup=kernels.warmup, kernel=lambda key: NotLoaded if not calls else real_kernel(key))
    monkeypatch.setattr(probe_module, "kernels", seen)
    monkeypatch.setattr(pipeline, "call_kernel", first_call_loads)
    with pytest.raises(LawFault, match=rf"law.py:{OOB_LINE}: control raised IndexError"):
        probe_module.probe(prep)
    assert len(calls) == 2


def test_a_call_stopped_before_its_first_step_is_made_again_even_with_the_kernel_loaded(tmp_path, monkeypatch):
    """A kernel already loaded can still spend the wall time before its first step (a new
    specialisation compiling, a starved thread): the probe judges by the steps taken, not by
    whether the kernel was loaded, and calls it again instead of returning without a verdict
    (after which an endless law would hang the real run)."""
    import time

    from auvtrack.engine import kernels
    from auvtrack.scenario import load_scenario
    from auvtrack.simulation import pipeline, probe as probe_module

    prep = pipeline.prepare(load_scenario(str(_scenario(tmp_path, OUT_OF_BOUNDS))))
    key = KernelKey(prep.key.law, prep.key.plant, prep.key.label, checked=True)
    kernels.warmup([key])
    assert kernels.kernel(key).signatures  # loaded: the case the loaded-kernel check let through
    monkeypatch.setattr(probe_module, "PROBE_WALL_S", 0.5)
    real_call, calls = pipeline.call_kernel, []

    def first_call_stalls(p, out):
        calls.append(p.key)
        if len(calls) == 1:
            time.sleep(1.0)
            return 0, 0, 0.0  # stopped at its first step: no step taken
        return real_call(p, out)

    monkeypatch.setattr(pipeline, "call_kernel", first_call_stalls)
    with pytest.raises(LawFault, match=rf"law.py:{OOB_LINE}: control raised IndexError"):
        probe_module.probe(prep)
    assert len(calls) == 2

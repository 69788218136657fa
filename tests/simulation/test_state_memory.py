"""The memory limit counts what the plant and the controller keep in state: a plug-in whose
state is larger than ``limits.max_memory_mb`` allows is refused after its set-up, before the
engine copies it, by ``check`` and ``run`` alike, with one line naming the controller."""
from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from auvtrack.cli import EXIT_BAD_INPUT, main
from auvtrack.scenario import ScenarioError, load_scenario
from auvtrack.scenario.plan import FLOAT, STATE_COPIES, check_state_memory, plan_run
from auvtrack.simulation.pipeline import prepare

SOURCE = """import numpy as np
from auvtrack.control.plugin import CompiledController, ControllerParamsBase, njit
AUX_NAMES = ()
class Params(ControllerParamsBase):
    n: int = 0
@njit
def control(t, y, xc, args, out):
    out.u[0] = 0.0
    return 0
def setup(params, ctx):
    return CompiledController(cp=np.zeros(2), xc0=np.zeros(params.n), aux_names=AUX_NAMES)
"""
N = 300_000  # 2.3 MiB of state, 18 MiB with the engine's copies


def _scenario(folder, n: int, limit_mb: int):
    (folder / "big_state.py").write_text(SOURCE)
    path = folder / "scenario.toml"
    path.write_text(f'name = "state"\n[sim]\nduration = 0.1\n[limits]\nmax_memory_mb = {limit_mb}\n'
                    f'[controller]\nkind = "plugin"\nmodule = "big_state.py"\nparams = {{ n = {n} }}\n')
    return path


def test_check_and_run_refuse_a_controller_state_over_the_memory_limit(tmp_path, capsys):
    sc = _scenario(tmp_path, N, 10)
    for command in ("check", "run"):
        args = [command, str(sc)] + (["--out", str(tmp_path / "r")] if command == "run" else [])
        assert main(args) == EXIT_BAD_INPUT
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1 and "Traceback" not in err, err
        assert "controller: the run's arrays need" in err and "limits.max_memory_mb = 10" in err, err
        assert f"{N + 2} floats" in err, err
    assert not (tmp_path / "r").exists()


def test_the_state_bound_is_the_estimate(tmp_path):
    """Refused one MiB below the estimate with the states, accepted at its ceiling."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sc = load_scenario(_scenario(tmp_path, N, 1024))
        prep = prepare(sc)
    plan = plan_run(sc, len(prep.channels))
    floats = {"plant": prep.plant.x0.size + prep.plant.pp.size, "controller": N + 2}
    need = plan.memory_bytes + STATE_COPIES * FLOAT * sum(floats.values())
    assert check_state_memory(sc, plan, floats) == need - plan.memory_bytes
    ceiling = math.ceil(need / 2 ** 20)
    check_state_memory(load_scenario(_scenario(tmp_path, N, ceiling)), plan, floats)
    with pytest.raises(ScenarioError, match=r"^controller: .*limits\.max_memory_mb") as info:
        check_state_memory(load_scenario(_scenario(tmp_path, N, ceiling - 1)), plan, floats)
    assert info.value.path == "controller"


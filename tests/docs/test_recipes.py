"""The recipes of docs/architecture.md: each addition is one file plus one line, and then it works.

In a copy of the package, a controller, a plant, an environment component, a study and a
benchmark suite are each added exactly as the recipe says (the new file, and at most one new line
in a registry); a fresh interpreter then flies the new controller in the new disturbance on the
5-DOF plant and on the new plant, finds the study and loads the suite.
"""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

import auvtrack

PACKAGE = Path(auvtrack.__file__).resolve().parent
EXAMPLES = PACKAGE.parent / "examples"

CONTROLLER = '''
"""PD on the virtual-point error with feed-forward: a controller added by the recipe."""
from typing import Literal

import numpy as np

from ..jit import njit
from ..packing import packed_layout
from .registry import CompiledController, ControllerParams, tunable
from .tracking import error_state_forces, input_for_accel_forces

NAME = "recipe_pd"
AUX_NAMES = ()
GAINS = packed_layout("RecipePD", kp=1, kd=1)


class Params(ControllerParams):
    """Gains."""

    kind: Literal["recipe_pd"] = "recipe_pd"
    kp: float = tunable(1.0, 0.01, 10.0, log=True, gt=0)
    kd: float = tunable(2.0, 0.1, 10.0, log=True, gt=0)


@njit
def control(t, y, xc, args, out):
    """PD law."""
    e, ed, f, g = error_state_forces(y.eta, y.att, y.nu, args.ref, args.vp)
    kp, kd = args.cp[GAINS.kp], args.cp[GAINS.kd]
    a = (-kp * e[0] - kd * ed[0], -kp * e[1] - kd * ed[1], -kp * e[2] - kd * ed[2])
    out.u[0], out.u[1], out.u[2] = input_for_accel_forces(y.att, args.vp, f, a, g)
    return 0


def setup(params, ctx):
    """Pack the gains."""
    return CompiledController(cp=GAINS.pack(kp=params.kp, kd=params.kd), xc0=np.zeros(0))
'''

COMPONENT = '''
"""A constant body-frame force: an environment component added by the recipe."""
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from ..jit import njit_noalloc
from .layout import ROW_SIZE


@dataclass(frozen=True, kw_only=True)
class ConstantForce:
    """A constant force [F_u, F_v, F_w, M_q, M_r] (N, N m)."""

    KIND: ClassVar[str] = "constant"
    CODE: ClassVar[float] = 41.0
    EFFECT: ClassVar[str] = "force"
    TIME_ONLY: ClassVar[bool] = True
    TERM: ClassVar[str] = "add_constant"

    force: tuple = (0.0, 0.0, 0.0, 0.0, 0.0)

    def describe(self) -> dict:
        """Its description."""
        return {"kind": "constant", "force": list(self.force)}

    def pack_row(self) -> np.ndarray:
        """Its packed row."""
        row = np.zeros(ROW_SIZE)
        row[0] = self.CODE
        row[1:6] = self.force
        return row


@njit_noalloc
def add_constant(rows, k, t, out):
    """Add the force of row k."""
    for i in range(5):
        out[i] += rows[k, 1 + i]
'''

STUDY = '''
"""A study added by the recipe."""
from pathlib import Path

from .registry import StudySpec


def run(out: Path, *, quick: bool = False, progress: bool = False) -> Path:
    """Write an empty report."""
    out.mkdir(parents=True, exist_ok=True)
    (out / "report.md").write_text("# recipe")
    return out / "report.md"


STUDY = StudySpec("recipe-study", run, "a study added by the recipe")
'''

CHECK = textwrap.dedent('''
    import json, sys
    import numpy as np
    import auvtrack
    from auvtrack.benchmark.suite import load_suite
    from auvtrack.studies.registry import all_studies

    base = {"vehicle": {"preset": "paper"}, "uncertainty": {"C": 0.0, "D": 0.0},
            "reference": {"kind": "circle", "radius": 20.0, "omega": 0.05, "depth": 5.0},
            "sim": {"duration": 5.0, "dt": 0.01, "log_dt": 0.1},
            "initial": {"eta": [19.0, 0.0, 5.0, 0.0, 1.5707963], "nu": [1.0, 0.0, 0.0, 0.0, 0.0]},
            "controller": {"kind": "recipe_pd", "kp": 2.0}}
    new_plant = auvtrack.simulate({**base, "disturbance": [], "plant": {"model": "horizontal3"}})
    calm = auvtrack.simulate({**base, "disturbance": []})
    pushed = auvtrack.simulate({**base, "disturbance": [{"kind": "constant", "force": [0, 50, 0, 0, 0]}]})
    print(json.dumps({"new_plant": new_plant.status, "calm": calm.status, "pushed": pushed.status,
                      "moved": float(np.max(np.abs(pushed["y"] - calm["y"]))),
                      "studies": sorted(all_studies()), "suite": load_suite("recipe-suite", check=False).name}))
''')


@pytest.mark.slow
def test_each_recipe_is_one_file_plus_one_line(tmp_path):
    pkg = tmp_path / "auvtrack"
    shutil.copytree(PACKAGE, pkg, ignore=shutil.ignore_patterns("__pycache__"))

    def add_line(path: Path, after: str, line: str) -> None:
        """The recipe's one line, right after an existing one."""
        text = path.read_text()
        assert text.count(after) == 1, (path, after)
        path.write_text(text.replace(after, after + line, 1))

    # a controller: its module, one line in BUILTIN
    (pkg / "control" / "recipe_pd.py").write_text(CONTROLLER)
    add_line(pkg / "control" / "__init__.py", '    "open_loop_actuators",\n', '    "recipe_pd",\n')
    # a plant: its module (the 3-DOF example made a built-in), one line in BUILTIN
    plant = (EXAMPLES / "plugin_plant.py").read_text()
    plant = plant.replace("from auvtrack.plant.plugin import CompiledPlant, PlantSection, njit_noalloc",
                          "from typing import Literal\n\nfrom .plugin import CompiledPlant, PlantSection, njit_noalloc")
    plant = plant.replace("from auvtrack.packing import", "from ..packing import").replace(
        "from auvtrack.vehicle.params import", "from ..vehicle.params import")
    plant = plant.replace('class Section(PlantSection):\n    """The ``params`` table of ``[plant]``."""\n',
                          'class Section(PlantSection):\n    """The ``[plant]`` section."""\n\n'
                          '    model: Literal["horizontal3"] = "horizontal3"')
    (pkg / "plant" / "horizontal3.py").write_text(plant)
    add_line(pkg / "plant" / "__init__.py", '    "sixdof",\n', '    "horizontal3",\n')
    # an environment component: its module, one line in COMPONENTS
    (pkg / "environment" / "constant.py").write_text(COMPONENT)
    add_line(pkg / "environment" / "registry.py", '    "current:GaussMarkovCurrent",\n', '    "constant:ConstantForce",\n')
    # a study: its module only
    (pkg / "studies" / "recipe_study.py").write_text(STUDY)
    # a suite: its data file only
    suites = pkg / "data" / "benchmarks"
    (suites / "recipe-suite.toml").write_text(
        (suites / "auv-track-v1.toml").read_text().replace('name = "auv-track-v1"', 'name = "recipe-suite"'))

    env = {**os.environ, "PYTHONPATH": str(tmp_path), "AUVTRACK_CACHE_DIR": str(tmp_path / "cache")}
    p = subprocess.run([sys.executable, "-c", CHECK], env=env, cwd=tmp_path, capture_output=True, text=True,
                       timeout=1800)
    assert p.returncode == 0, p.stderr[-3000:]
    out = json.loads(p.stdout.strip().splitlines()[-1])
    assert out["new_plant"] == "ok" and out["calm"] == "ok" and out["pushed"] == "ok"
    assert out["moved"] > 1e-3  # the new component pushes the vehicle sideways
    assert "recipe-study" in out["studies"] and out["suite"] == "recipe-suite"

"""Kernels per (controller, plant): generated from the engine, keyed by every source, bit-identical to engine v1."""
import hashlib
import json
import os
import platform
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

import auvtrack
from auvtrack import jit as _jit
from auvtrack.jit import vecmath as _vecmath
from auvtrack.control import CONTROLLERS
from auvtrack.plant import PLANTS
from auvtrack.scenario import load_scenario
from auvtrack.engine import loop as engine
from auvtrack.engine import kernels
from auvtrack.user_modules import load_module
from auvtrack.simulation.pipeline import prepare, run_prepared

DATA = Path(__file__).resolve().parents[1] / "data"


def test_every_kernel_part_is_copied_verbatim_under_its_decorator():
    """The generated module is the engine's loop: each @kernel_part body appears unchanged."""
    import inspect

    key = kernels.KernelKey(CONTROLLERS["ftsmc"].module, PLANTS["5dof"].module, "ftsmc on 5dof")
    src = kernels.kernel_source(key)
    assert set(engine.KERNEL_PARTS) >= {"run", "stage", "state_cause", "log_row", "run_many"}
    for name, decorator in engine.KERNEL_PARTS.items():
        body = "\n".join(inspect.getsource(getattr(engine, name)).splitlines()[1:])
        assert f"@{decorator}\n{body}" in src
    assert "law = llvm_inline(load_module('auvtrack.control.ftsmc').control)" in src
    assert "plant = with_sizes(load_module('auvtrack.plant.five_dof'))" in src


def test_each_pair_has_its_own_kernel_and_module():
    a = kernels.KernelKey("auvtrack.control.ftsmc", "auvtrack.plant.five_dof")
    b = kernels.KernelKey("auvtrack.control.fxtntsmc", "auvtrack.plant.five_dof")
    assert a.name != b.name
    assert kernels.kernel_module(a) is not kernels.kernel_module(b)
    law = kernels.kernel_module(a).law  # the law's code, compiled once for LLVM to inline (_jit.llvm_inline)
    assert law.py_func.__code__ is load_module("auvtrack.control.ftsmc").control.py_func.__code__
    assert law.targetoptions["forceinline"] and "inline" not in law.targetoptions


def test_a_plugin_kernel_is_named_by_the_file_content(tmp_path):
    f = tmp_path / "my_law.py"
    f.write_text("x = 1\n")
    k1 = kernels.KernelKey(str(f), "auvtrack.plant.five_dof").name
    f.write_text("x = 2\n")
    k2 = kernels.KernelKey(str(f), "auvtrack.plant.five_dof").name
    assert k1 != k2 and k1.startswith("k_plugin_my_law_")


def test_law_module_imports_a_file_once_per_content(tmp_path):
    f = tmp_path / "law_file.py"
    f.write_text("VALUE = 3\n")
    m1 = load_module(str(f))
    assert m1.VALUE == 3 and load_module(str(f)) is m1
    f.write_text("VALUE = 4\n")
    assert load_module(str(f)).VALUE == 4
    with pytest.raises(ImportError, match="no such file"):
        load_module(str(tmp_path / "absent.py"))


def test_editing_a_compiled_source_selects_a_fresh_cache_and_only_then(tmp_path):
    """The cache folder is named by a hash of the compiled sources (Numba keys only by the caller's file):
    an edit of a callee of every kernel selects a new folder, an edit of the command line does not."""
    pkg = tmp_path / "auvtrack"
    shutil.copytree(Path(auvtrack.__file__).parent, pkg, ignore=shutil.ignore_patterns("__pycache__"))
    code = "import auvtrack.jit as j; print(j.cache_dir())"
    env = {**os.environ, "PYTHONPATH": str(tmp_path), "AUVTRACK_CACHE_DIR": str(tmp_path / "cache")}

    def folder():
        return subprocess.run([sys.executable, "-c", code], env=env, cwd=tmp_path, capture_output=True, text=True,
                              check=True).stdout.strip()

    before = folder()
    cli = pkg / "cli" / "run.py"  # no compiled code
    cli.write_text(cli.read_text() + "\n# edited\n")
    assert folder() == before
    dyn = pkg / "vehicle" / "dynamics.py"  # a callee of every kernel, not the file of any kernel
    dyn.write_text(dyn.read_text() + "\n# edited\n")
    after = folder()
    assert before != after and Path(after).parent == Path(before).parent


def _cpu_vendor() -> str:
    try:
        return next(line.split(":", 1)[1].strip() for line in Path("/proc/cpuinfo").read_text().splitlines()
                    if line.startswith("vendor_id"))
    except (OSError, StopIteration):
        return ""


def _digests():
    """The record for this back end (and, for a libmvec back end, this CPU vendor), or None."""
    doc = json.loads((DATA / "engine_v1_digests.json").read_text())
    for key in (f"{_vecmath.BACKEND}/{_cpu_vendor()}", _vecmath.BACKEND):
        rec = doc.get(key)
        if rec is not None and rec.get("vendor", _cpu_vendor()) == _cpu_vendor():
            return rec
    return None


ENGINE_V1 = _digests()


@pytest.mark.skipif(ENGINE_V1 is None or ENGINE_V1["glibc"] != platform.libc_ver()[1],
                    reason="engine-v1 digests were recorded for another vector-math back end, CPU vendor or glibc")
@pytest.mark.parametrize("case", sorted((ENGINE_V1 or {"cases": {}})["cases"]))
def test_5dof_trajectories_are_bit_identical_to_engine_v1(case):
    """Trajectories (every channel up to chi, as float64 bytes) equal those of the engine before plants
    became pluggable (commit 2bbb533, tests/data/engine_v1_digests.json).

    Run as engine v1 ran them: with its default estimator law (`omega`; the default is now
    `effective`, which differs only where the risk monitor is in its band) and without the
    channel added since (`gain_ratio_*`)."""
    rec = ENGINE_V1["cases"][case]
    res = run_prepared(prepare(load_scenario({}, ["estimator.kind=omega", *rec["overrides"]])))
    assert res.status == rec["status"]
    names = [c for c in res.names if not c.startswith("gain_ratio_")]
    last = max(i for i, c in enumerate(names) if c.startswith("chi_"))
    data = np.ascontiguousarray(np.column_stack([res[c] for c in names[:last + 1]]))
    assert hashlib.sha256(data.tobytes()).hexdigest() == rec["data_sha256"]


def test_compile_notice_on_an_empty_cache(tmp_path):
    """A run that has to compile says so first, with an estimate; a second run compiles nothing."""
    env = {**os.environ, "AUVTRACK_CACHE_DIR": str(tmp_path / "cache")}
    code = textwrap.dedent("""
        import auvtrack
        r = auvtrack.simulate({"controller": {"kind": "open_loop"}}, ["sim.duration=0.01"])
        print(r.status)
    """)
    first = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=900)
    assert first.returncode == 0, first.stderr
    assert "compiling kernels (first run only, about" in first.stderr and "open_loop on 5dof" in first.stderr
    second = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=900)
    assert second.returncode == 0 and "compiling" not in second.stderr
    markers = list((tmp_path / "cache").glob("*/kernels/*.compiled.json"))
    assert len(markers) == 1 and json.loads(markers[0].read_text())["seconds"] > 0

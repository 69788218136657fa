"""Kernels per (controller, plant): generated from the engine's loop, compiled on demand, cached on disk.

A kernel is the RK4 loop of :mod:`auvtrack.engine.loop` with one controller's compiled
law bound to the name ``law`` and one plant module bound to ``plant``.  :func:`kernel` writes a
small module for the pair into the kernel cache folder (a verbatim copy of the engine's
``@kernel_part`` functions under the decorators the engine names), imports it and returns its
``run``.  Numba compiles it the first time it runs and caches it on disk next to it, so

* only the pairs a run needs are ever compiled (a new controller or plant costs nothing until
  used), and each pair gets its own specialised loop: the law is inlined, with no run-time
  dispatch;
* the folder is named by a hash of every package source (:func:`auvtrack.jit.cache_dir`); a
  plug-in's kernel is also named by a hash of the plug-in file, so editing either selects fresh
  kernels (a plug-in's own imports of other files are not hashed: see ``docs/plugins.md``);
* :func:`warmup` compiles several pairs in parallel, one process each, and reports progress; a
  run that has to compile says so first ("compiling kernels (first run only, about N s)").

A controller's law is named by ``law``: an importable module name (``auvtrack.control.ftsmc``)
or the path of a ``.py`` file (a plug-in), whose module defines ``control``.
"""
from __future__ import annotations

import importlib
import importlib.util
import inspect
import json
import os
import subprocess
import sys
import tempfile
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Iterable, Sequence

import numpy as np

from .. import jit as _jit
from ..jit.errors import CompileError, compile_error_line
from ..user_modules import file_digest
from ..user_modules import identifier as _ident
from . import loop as engine

__all__ = ["KernelKey", "kernel", "is_compiled", "warmup", "kernel_source", "compile_estimate", "usable_cores"]

COMPILE_ESTIMATE_S = 20.0  # shown before the first compile of a kernel when nothing was measured yet


@dataclass(frozen=True)
class KernelKey:
    """One kernel: a controller law and a plant, each a module name or a ``.py`` path.

    Attributes
    ----------
    law : str
        ``"auvtrack.control.fxtntsmc"``, ``"my_package.my_law"`` or ``"/abs/path/my_controller.py"``.
    plant : str
        ``"auvtrack.plant.five_dof"`` or a plug-in plant's module name or ``.py`` path.
    label : str
        Human name for messages, e.g. ``"fxtntsmc on 5dof"``.
    checked : bool
        The law compiled with bounds checking, an exception it raises turned into a status
        (:func:`auvtrack.control.plugin.bounds_checked`), and a plant that is not built in
        bounds-checked too (:func:`auvtrack.plant.checked.bounds_checked_plant`): the kernel of a
        plug-in's probe run.
    """

    law: str
    plant: str
    label: str = ""
    checked: bool = False

    @property
    def is_file(self) -> bool:
        """True when the law is a plug-in file."""
        return self.law.endswith(".py")

    @property
    def name(self) -> str:
        """Identifier of the generated module (also its file name)."""
        return f"k_{_part_name(self.law)}__{_part_name(self.plant)}" + ("__checked" if self.checked else "")


def _part_name(spec: str) -> str:
    """A law's or plant's part of a kernel name: its module's last name, or for a plug-in its name and content hash."""
    if spec.endswith(".py"):
        path = Path(spec).resolve()
        return f"plugin_{_ident(path.stem)}_{file_digest(path)}"
    if spec.startswith("auvtrack."):
        return _ident(spec.rsplit(".", 1)[-1])
    found = importlib.util.find_spec(spec)  # a plug-in given by module name: its full name and the hash of its file
    origin = Path(found.origin) if found is not None and found.origin else None
    return f"plugin_{_ident(spec)}_{file_digest(origin) if origin and origin.is_file() else '0'}"


def _comment(text: str) -> str:
    """One comment line naming what a user chose (a file name, a label), whatever characters it holds."""
    return "# " + repr(text)[1:-1]


def kernel_source(key: KernelKey) -> str:
    """Python source of the generated kernel module of ``key``.

    Parameters
    ----------
    key : KernelKey
        The pair.

    Returns
    -------
    str
        A module binding ``law`` and ``plant`` followed by a copy of every ``@kernel_part`` of
        :mod:`auvtrack.engine.loop` under its decorator.
    """
    parts = []
    for name, decorator in engine.KERNEL_PARTS.items():
        src = inspect.getsource(getattr(engine, name))
        lines = src.splitlines()
        assert lines[0].startswith("@kernel_part("), f"engine.{name}: the marker must be the only decorator"
        parts.append(f"@{decorator}\n" + "\n".join(lines[1:]) + "\n")
    bind = "llvm_inline(load_module({key.law!r}).control)  # one compilation, inlined by LLVM where called"
    if key.checked:  # a plug-in's probe run: index errors and exceptions become a status
        bind = ("llvm_inline(load_module({key.law!r}).control)\n"
                "from auvtrack.control.plugin import bounds_checked  # noqa: E402\n"
                "law = bounds_checked(law)")
    head = f'''"""Kernel of one (controller law, plant) pair: generated by auvtrack.engine.kernels; do not edit.

The loop is a copy of auvtrack/engine/loop.py's kernel parts with ``law`` and ``plant`` bound below.
"""
{_comment(key.label or key.name)}
from auvtrack.jit import llvm_inline, njit, njit_noalloc  # noqa: F401
from auvtrack.engine.loop import *  # noqa: F401,F403
from auvtrack.plant.contract import with_sizes
from auvtrack.user_modules import load_module

plant = with_sizes(load_module({key.plant!r}))
law = {bind.format(key=key)}
'''
    if key.checked and not key.plant.startswith("auvtrack."):  # a plug-in plant's functions, bounds-checked too
        head += ("from auvtrack.plant.checked import bounds_checked_plant  # noqa: E402\n"
                 "plant = bounds_checked_plant(plant)\n")
    tail = "\n\nlog_row.lane_stub = True  # the SIMD batch kernels keep no trajectory (metrics only)\n"
    return head + "\n\n" + "\n\n".join(parts) + tail


def lanes_source(key: KernelKey) -> str:
    """Python source of the SIMD batch module of ``key``: the lane form of its kernel's ``run``.

    Parameters
    ----------
    key : KernelKey
        The pair.

    Returns
    -------
    str
        A module importing the pair's kernel module, binding ``run__lanes`` to the lane form of its
        ``run`` (:func:`auvtrack.engine.lanes.lane_version`), followed by a copy of every
        ``@kernel_part(..., lanes=True)`` of :mod:`auvtrack.engine.loop`.
    """
    parts = []
    for name, decorator in engine.LANE_PARTS.items():
        src = inspect.getsource(getattr(engine, name))
        lines = src.splitlines()
        assert lines[0].startswith("@kernel_part("), f"engine.{name}: the marker must be the only decorator"
        parts.append(f"@{decorator}\n" + "\n".join(lines[1:]) + "\n")
    head = f'''"""SIMD batch kernel of one (controller law, plant) pair: generated by auvtrack.engine.kernels; do not edit.

``run__lanes`` is the lane form of the kernel's ``run`` (auvtrack.engine.lanes); the loop below
is a copy of auvtrack/engine/loop.py's lane parts.
"""
{_comment(key.label or key.name)}
from auvtrack.jit import njit, njit_noalloc  # noqa: F401
from auvtrack.jit.lane_values import as_lanes, first_lanes, get_lane  # noqa: F401
from auvtrack.engine.loop import *  # noqa: F401,F403
from auvtrack.engine.kernels import KernelKey, kernel_module
from auvtrack.engine.lanes import lane_version

run__lanes = lane_version(kernel_module(KernelKey({key.law!r}, {key.plant!r}, {key.label!r})).run)
'''
    return head + "\n\n" + "\n\n".join(parts)


def lanes_module(key: KernelKey):
    """The generated SIMD batch module of ``key`` (its ``run_lanes``), imported on first use.

    Parameters
    ----------
    key : KernelKey
        The pair.

    Returns
    -------
    module
        The module; raises :class:`auvtrack.engine.lanes.NotLaneable` when the pair's law or
        plant uses a construct the lane rewrite does not handle.
    """
    return generated_module(key.name + "__lanes", lambda: lanes_source(key))


def generated_module(name: str, source: Callable[[], str]):
    """Write a generated module into the kernel cache folder (unless it holds it) and import it once.

    Parameters
    ----------
    name : str
        Module name inside the cache folder (``auvtrack_kernels.<name>``).
    source : callable
        Returns the module's source; called only when the module is not imported yet.

    Returns
    -------
    module
        The imported module (removed from ``sys.modules`` again if its import fails).
    """
    modname = f"auvtrack_kernels.{name}"
    with _LOCK:
        if modname in sys.modules:
            return sys.modules[modname]
        path = _folder() / f"{name}.py"
        _write_if_changed(path, source())
        spec = importlib.util.spec_from_file_location(modname, path)
        module = importlib.util.module_from_spec(spec)
        sys.modules[modname] = module
        try:
            spec.loader.exec_module(module)
        except BaseException:
            del sys.modules[modname]
            raise
        return module


def _folder() -> Path:
    folder = _jit.cache_dir() / "kernels"
    folder.mkdir(parents=True, exist_ok=True)
    return folder


def _write_if_changed(path: Path, text: str) -> None:
    """Write ``text`` atomically unless the file already holds it (keeps its time stamp for Numba)."""
    if path.is_file() and path.read_text() == text:
        return
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.stem}-", suffix=".tmp")
    with os.fdopen(fd, "w") as f:
        f.write(text)
    os.replace(tmp, path)


_LOADED: dict[str, Callable] = {}
_LOCK = threading.RLock()


def _marker(key: KernelKey, lanes: bool = False) -> Path:
    return _folder() / f"{key.name}.{'lanes' if lanes else 'compiled'}.json"


def is_compiled(key: KernelKey, lanes: bool = False) -> bool:
    """True when the kernel of ``key`` is compiled in this process or cached on disk.

    Parameters
    ----------
    key : KernelKey
        The pair.
    lanes : bool, optional
        Ask about its SIMD batch kernel (:func:`compile_lanes`) instead.

    Returns
    -------
    bool
        Whether running it (or its first SIMD batch) needs no compilation.
    """
    if lanes:
        return _marker(key, lanes=True).is_file()
    loaded = _LOADED.get(key.name)
    if loaded is not None and loaded.signatures:
        return True
    return _marker(key).is_file()


def _module(key: KernelKey):
    name = key.name
    path = _folder() / f"{name}.py"
    _write_if_changed(path, kernel_source(key))
    modname = f"auvtrack_kernels.{name}"
    if modname in sys.modules:
        return sys.modules[modname]
    spec = importlib.util.spec_from_file_location(modname, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[modname] = module
    spec.loader.exec_module(module)
    return module


def kernel_module(key: KernelKey):
    """The generated module of ``key`` (its ``run`` and ``run_many``), imported on first use.

    Parameters
    ----------
    key : KernelKey
        The pair.

    Returns
    -------
    module
        The generated kernel module.
    """
    kernel(key)
    return sys.modules[f"auvtrack_kernels.{key.name}"]


def kernel(key: KernelKey) -> Callable:
    """The compiled ``run`` of a (law, plant) pair (generated and imported on first use).

    Parameters
    ----------
    key : KernelKey
        The pair.

    Returns
    -------
    callable
        ``run(plant_bundle, controller_bundle, environment, ref_p, settings, outputs)``; it
        compiles on its first call unless cached on disk.
    """
    with _LOCK:
        fn = _LOADED.get(key.name)
        if fn is None:
            fn = _module(key).run
            _LOADED[key.name] = fn
        return fn


def mark_compiled(key: KernelKey, seconds: float) -> None:
    """Record that ``key`` is compiled and cached, and how long it took (for the next estimate)."""
    _write_if_changed(_marker(key), json.dumps({"kernel": key.name, "seconds": round(seconds, 2)}))


def compile_estimate(lanes: bool = False) -> float:
    """Seconds one kernel took to compile here the last times (median of the markers), or a default.

    Parameters
    ----------
    lanes : bool, optional
        The estimate for a SIMD batch kernel (:func:`compile_lanes`) instead.

    Returns
    -------
    float
        The estimate shown by the compile notice.
    """
    times = []
    root = _jit.cache_dir().parent
    for marker in root.glob(f"*/kernels/*.{'lanes' if lanes else 'compiled'}.json"):
        try:
            times.append(float(json.loads(marker.read_text())["seconds"]))
        except (OSError, ValueError, KeyError):
            continue
    if not times:
        return COMPILE_ESTIMATE_S
    times.sort()
    return times[len(times) // 2]


def _compile_run(run) -> None:
    """Compile ``run`` for the argument types every prepared run has (:func:`engine.example_arguments`)."""
    import numba

    run.compile(tuple(numba.typeof(a) for a in engine.example_arguments()))


def example_lane_arguments() -> tuple:
    """Arguments of a lanes module's ``run_lanes`` with the types the SIMD back end passes, over no block.

    Each run's arrays stacked in blocks of :data:`~auvtrack.engine.loop.LANES` along a last
    axis (``auvtrack.batch.runner._LaneGroup``): C-contiguous float64, int64 for ``si``, ``info``,
    ``counts`` and ``cause``; ``b0 = b1 = 0``, so a call compiles (or loads) and runs nothing.
    """
    L = engine.LANES
    f3, f4, i3 = np.zeros((1, 1, L)), np.zeros((1, 1, 1, L)), np.zeros((1, 1, L), np.int64)
    ins = engine.Stacked(f3, f3, f3, f3, f3, f4, f4, f4, f3, i3, f3)
    outs = engine.StackedOutputs(f4, f3, f4, i3, np.zeros((1, L), np.int64), np.zeros((1, L)))
    return ins, outs, np.zeros(1, np.int64), 0, 0


def compile_lanes(key: KernelKey) -> bool:
    """Compile (or load) the SIMD batch kernel of ``key`` for the types the batch runner passes.

    Parameters
    ----------
    key : KernelKey
        The pair.

    Returns
    -------
    bool
        False when the pair has no lane form (the SIMD back end then runs it on threads).
    """
    from numba.core.errors import NumbaError

    from .lanes import NotLaneable

    t0 = time.perf_counter()
    try:
        lanes_module(key).run_lanes(*example_lane_arguments())
    except (NotLaneable, NumbaError):
        return False
    _write_if_changed(_marker(key, lanes=True), json.dumps({"kernel": key.name,
                                                           "seconds": round(time.perf_counter() - t0, 2)}))
    return True


def _compile_in_process(key: KernelKey, lanes: bool = False) -> float:
    from numba.core.errors import NumbaError

    t0 = time.perf_counter()
    if not is_compiled(key):
        try:
            _compile_run(kernel(key))
        except NumbaError as exc:
            raise CompileError(compile_error_line(str(exc), key.label or key.name), str(exc)) from None
        mark_compiled(key, time.perf_counter() - t0)
    if lanes and not is_compiled(key, lanes=True):
        compile_lanes(key)
    return time.perf_counter() - t0


def warmup(keys: Iterable[KernelKey], *, jobs: int | None = None,
           notice: Callable[[str], None] | None = None, progress: bool = False,
           lanes: bool = False) -> list[KernelKey]:
    """Compile the kernels of ``keys`` that are not cached yet, several at once, and load them.

    One missing kernel compiles in this process; several compile in ``jobs`` child processes (Numba
    holds the GIL while compiling), each compiling its share one after the other, and are then
    loaded from the disk cache.  The kernels of one law go to the same child, so that the law and
    the functions the kernels share (plant, reference, metrics) compile once per child.

    Parameters
    ----------
    keys : iterable of KernelKey
        The pairs needed.
    jobs : int, optional
        Processes compiling at once (default: usable cores).
    notice : callable, optional
        Receives the one-line "compiling kernels ..." notice (default: printed to stderr).
    progress : bool, optional
        Show a progress bar over the kernels being compiled.
    lanes : bool, optional
        Also compile each pair's SIMD batch kernel (:func:`compile_lanes`); otherwise it compiles
        on the first ``simd`` batch that needs it.

    Returns
    -------
    list of KernelKey
        The keys that were compiled now.
    """
    todo, per_key = [], []
    per, per_lanes = compile_estimate(), compile_estimate(lanes=True) if lanes else 0.0
    for k in dict.fromkeys(keys):  # each key once, in order
        cost = (0.0 if is_compiled(k) else per) + (per_lanes if lanes and not is_compiled(k, lanes=True) else 0.0)
        if cost:
            todo.append(k)
            per_key.append(cost)
    if not todo:
        return []
    jobs = jobs or usable_cores()
    waves = -(-len(todo) // max(1, jobs))
    say = notice or (lambda text: print(text, file=sys.stderr, flush=True))
    names = ", ".join(k.label or k.name for k in todo)
    what = "kernels and their SIMD batch forms" if lanes else "kernels"
    say(f"compiling {what} (first run only, about {max(per_key) * waves:.0f} s): {names}")
    bar = _bar(len(todo), progress)
    try:
        if len(todo) == 1 or jobs == 1:
            for k in todo:
                _compile_in_process(k, lanes)
                bar.update(1)
        else:
            shares = _shares(todo, jobs)
            children: list[subprocess.Popen] = []
            pool = ThreadPoolExecutor(max_workers=len(shares))
            try:
                for f in [pool.submit(_compile_in_child, share, bar, lanes, children) for share in shares]:
                    f.result()
            except BaseException:  # Ctrl-C, or a child failed: end the other children now, not when they finish
                for proc in children:
                    proc.kill()
                raise
            finally:
                pool.shutdown(wait=True)
            for k in todo:  # load the cached machine code into this process
                kernel(k)
    finally:
        bar.close()
    return todo


def _shares(keys: list[KernelKey], jobs: int) -> list[list[KernelKey]]:
    """Split ``keys`` over at most ``jobs`` children, the kernels of one law together, sizes balanced."""
    by_law: dict[str, list[KernelKey]] = {}
    for k in keys:
        by_law.setdefault(k.law, []).append(k)
    shares: list[list[KernelKey]] = [[] for _ in range(min(jobs, len(keys)))]
    for group in sorted(by_law.values(), key=len, reverse=True):
        if len(group) > -(-len(keys) // len(shares)):  # a law with more plants than a share: split it
            for k in group:
                min(shares, key=len).append(k)
        else:
            min(shares, key=len).extend(group)
    return [s for s in shares if s]


def _compile_in_child(keys: list[KernelKey], bar, lanes: bool = False, children: list | None = None) -> None:
    code = ("import sys, json; from auvtrack.engine.kernels import KernelKey, _child_compile; "
            "_child_compile([KernelKey(**k) for k in json.loads(sys.argv[1])], sys.argv[2] == '1')")
    arg = json.dumps([{"law": k.law, "plant": k.plant, "label": k.label, "checked": k.checked} for k in keys])
    with tempfile.TemporaryFile("w+") as errf, subprocess.Popen(
            [sys.executable, "-c", code, arg, "1" if lanes else "0"], stdout=subprocess.PIPE, stderr=errf,
            text=True) as proc:
        if children is not None:
            children.append(proc)
        for _ in proc.stdout:  # one line per kernel compiled
            bar.update(1)
        rc = proc.wait()
        errf.seek(0)
        err = errf.read()
    if rc != 0:
        names = ", ".join(k.label or k.name for k in keys)
        raise CompileError(compile_error_line(err, names), err.strip())


def _child_compile(keys: list[KernelKey], lanes: bool = False) -> None:
    for key in keys:
        _compile_in_process(key, lanes)
        print(key.name, flush=True)


def usable_cores() -> int:
    """The number of cores this process may use: the default count of workers and compile jobs everywhere.

    Returns
    -------
    int
        ``len(os.sched_getaffinity(0))`` (``os.cpu_count()`` where that does not exist), at least 1.
    """
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not Linux
        return max(1, os.cpu_count() or 1)


class _NoBar:
    def update(self, n: int) -> None:
        pass

    def close(self) -> None:
        pass


def _bar(total: int, progress: bool):
    if not progress:
        return _NoBar()
    from tqdm import tqdm

    return tqdm(total=total, desc="compiling", unit="kernel", leave=False)


def keys_for(pairs: Sequence[tuple[str, str, str]]) -> list[KernelKey]:
    """KernelKeys of (law, plant module, label) triples (helper for callers building many)."""
    return [KernelKey(law, plant, label) for law, plant, label in pairs]

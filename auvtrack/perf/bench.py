"""Benchmarks of the compiled closed loop (reported figures, never timed unit tests)."""
from __future__ import annotations

import os
import platform
import statistics
import time
from pathlib import Path


from .. import jit as _jit
from ..scenario import paper_scenario_path
from ..simulation.compiling import builtin_controllers

PAPER = paper_scenario_path()


def machine() -> dict:
    """Short description of this machine for benchmark records (CPU model, cores, load, versions, vector math)."""
    import numba

    from ..jit.vecmath import BACKEND

    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    try:
        load = [round(x, 2) for x in os.getloadavg()]
    except OSError:
        load = None
    return {"python": platform.python_version(), "cpu": cpu, "cores": os.cpu_count(), "system": platform.system(),
            "numba": numba.__version__, "load_avg_1_5_15": load, "vector_math": BACKEND}


def plugin_copy(kind: str, folder: Path) -> Path:
    """Write built-in controller ``kind``'s module as a stand-alone plug-in file (absolute imports).

    The same law through the plug-in path (``controller.kind = "plugin"``), for timing a plug-in
    against the built-in it copies.

    Parameters
    ----------
    kind : str
        A built-in controller.
    folder : pathlib.Path
        Where to write ``copy_of_<kind>.py``.

    Returns
    -------
    pathlib.Path
        The plug-in file.
    """
    import importlib
    import re

    from ..control import get

    module = importlib.import_module(get(kind).module)
    package = module.__name__ if Path(module.__file__).name == "__init__.py" else module.__name__.rsplit(".", 1)[0]

    def absolute(m: re.Match) -> str:  # a relative import, resolved against the module's package
        dots, rest = m.group(1), m.group(2)
        base = package.split(".")[: len(package.split(".")) - len(dots) + 1]
        return "from " + ".".join(base + ([rest] if rest else [])) + " import"

    src = re.sub(r"^from (\.+)([\w.]*) import", absolute, Path(module.__file__).read_text(), flags=re.M)
    path = Path(folder) / f"copy_of_{kind}.py"
    if not (path.is_file() and path.read_text() == src):  # unchanged: keep it (and its cached kernel)
        path.write_text(src)
    return path


def _overrides(kind: str) -> list[str]:
    """Scenario overrides of a bench row: a kind, or ``plugin:<file>`` for a plug-in."""
    if kind.startswith("plugin:"):
        return [f'controller={{kind="plugin", module="{kind[len("plugin:"):]}"}}']
    return [f"controller.kind={kind}"]


# the 6-DOF benchmark runs a straight line at 1 m/s from on track (remus100 design model),
# envelope off: a closed loop every controller completes on both truths (the Section 4 start from
# rest leaves the fins without authority and several controllers stop early; the model-gap study
# reports that).  Each preset is timed as its own row.
SIX_DOF_BENCH = {"vehicle": {"preset": "remus100"}, "disturbance": [], "envelope": {"kind": "none"},
                 "reference": {"kind": "line", "start": [1.0, 0.0, 5.0], "velocity": [1.0, 0.0, 0.0]},
                 "initial": {"eta": [0.0, 0.0, 5.0, 0.0, 0.0], "nu": [1.0, 0.0, 0.0, 0.0, 0.0]}}
PLANT_BENCH = {"5dof": ((PAPER, ()),),
               "6dof": tuple((SIX_DOF_BENCH, ("plant.model=6dof", f"plant.preset={p}"))
                             for p in ("remus100_prestero", "remus100_fossen"))}


def _prepared(kind: str, duration: float, source=PAPER, extra: tuple[str, ...] = ()):
    from ..scenario import load_scenario
    from ..simulation.pipeline import prepare

    return prepare(load_scenario(source, _overrides(kind) + [f"sim.duration={duration}", *extra]))


def bench_single(kind: str, *, repeat: int = 7, duration: float = 20.0) -> dict:
    """Median time per RK4 step of one closed-loop run of the Section 4 scenario.

    Reports the wall time (``us_per_step``) and the CPU time of the running thread
    (``cpu_us_per_step``), which is less disturbed by other processes on a shared machine.
    """
    return bench_singles((kind,), repeat=repeat, duration=duration)[0]


def bench_plant(kinds: tuple[str, ...], plant: str, *, repeat: int = 7, duration: float = 20.0,
                progress: bool = False) -> list[dict]:
    """:func:`bench_singles` on a plant model: ``"5dof"`` (Section 4) or ``"6dof"`` (each preset).

    Returns
    -------
    list of dict
        One row per (controller, preset), with ``plant`` (and ``preset`` for 6-DOF) added.
    """
    rows = []
    for source, extra in PLANT_BENCH[plant]:
        for r in bench_singles(kinds, repeat=repeat, duration=duration, source=source, extra=extra, progress=progress):
            rows.append({"plant": plant, **({"preset": extra[1].split("=", 1)[1]} if extra else {}), **r})
    return rows


def bench_singles(kinds: tuple[str, ...], *, repeat: int = 7, duration: float = 20.0, source=PAPER,
                  extra: tuple[str, ...] = (), progress: bool = False) -> list[dict]:
    """:func:`bench_single` for several controllers (``plugin:<file>`` for a plug-in), their repetitions interleaved.

    Round-robin timing: on a shared machine whose speed drifts for seconds at a time, a slow
    spell then lands on every controller alike instead of on one, so the ratios stay meaningful.
    The kernels missing from the cache compile first, in parallel (``progress``: with a bar).
    """
    from ..simulation.compiling import ensure_compiled
    from ..simulation.pipeline import run_prepared

    preps = {k: _prepared(k, duration, source, extra) for k in kinds}
    ensure_compiled(list(preps.values()), progress=progress)
    status = {k: run_prepared(p).status for k, p in preps.items()}  # compile or load from cache
    wall: dict[str, list[float]] = {k: [] for k in kinds}
    cpu: dict[str, list[float]] = {k: [] for k in kinds}
    for _ in range(repeat):
        for k, prep in preps.items():
            t0, c0 = time.perf_counter(), time.process_time()
            run_prepared(prep)
            cpu[k].append(time.process_time() - c0)
            wall[k].append(time.perf_counter() - t0)
    rows = []
    for k, prep in preps.items():
        steps = int(prep.si[0])
        per = [1e6 * t / steps for t in wall[k]]
        rows.append({"controller": k, "us_per_step": round(statistics.median(per), 4),
                     "min_us_per_step": round(min(per), 4),
                     "cpu_us_per_step": round(statistics.median(1e6 * t / steps for t in cpu[k]), 4),
                     "steps": steps, "repeat": repeat, "status": status[k], "machine": machine()})
    return rows


def user_bench_folder() -> Path:
    """A new folder for one ``bench --all`` record, outside any source tree.

    ``$XDG_DATA_HOME/auvtrack/bench/<UTC time>`` (``~/.local/share`` when unset), numbered if
    two runs start in the same second.

    Returns
    -------
    pathlib.Path
        A path that does not exist yet.
    """
    import datetime

    root = Path(os.environ.get("XDG_DATA_HOME") or Path.home() / ".local" / "share") / "auvtrack" / "bench"
    stamp = datetime.datetime.now(datetime.timezone.utc).strftime("%Y%m%dT%H%M%SZ")
    path, n = root / stamp, 1
    while path.exists():
        n += 1
        path = root / f"{stamp}-{n}"
    return path


def bench_all(*, repeat: int = 7, out: Path | None = None, progress: bool = False) -> dict:
    """The full benchmark suite; writes ``results.json`` and ``results.md`` into ``out``.

    Time to the first result with an empty kernel cache (a cold ``auvtrack run`` and a cold
    ``auvtrack warmup``, each in a new process), single-run µs per RK4 step for every controller,
    batch runs/s (runs as long as the single runs, at dt = 1 ms) and efficiency per back end, and sweep throughput on 1
    and 2 Dask workers (see :mod:`auvtrack.perf.sweep_bench`).  ``out`` defaults to a new user folder
    (:func:`user_bench_folder`), so running the suite from a clone leaves the working tree
    unchanged; pass ``out=Path("benchmarks")`` to update the record kept in the repository.

    Parameters
    ----------
    repeat : int, optional
        Timed repetitions per row (the single runs use three times as many).
    out : pathlib.Path, optional
        Folder for the results.
    progress : bool, optional
        Print the name of each part as it starts.

    Returns
    -------
    dict
        The record written to ``results.json``, plus ``"out"``: the folder (not written).
    """
    from .sweep_bench import (RUN_SECONDS, bench_batch, bench_breakdown, bench_cold_start, bench_cold_warmup,
                              bench_sweep, write_results)

    say = print if progress else (lambda *a, **k: None)
    mach = machine()  # load average before our own runs
    say("cold start")
    cold = bench_cold_start()
    cold_warmup = bench_cold_warmup()
    say("single runs")
    folder = _jit.cache_dir() / "bench_plugins"  # a fixed place: the plug-in kernels stay cached
    folder.mkdir(parents=True, exist_ok=True)
    copies = tuple(f"plugin:{plugin_copy(k, folder)}" for k in ("ftsmc", "fxtntsmc"))  # the paper's laws as plug-ins
    single = bench_singles(builtin_controllers() + copies, repeat=3 * repeat, duration=RUN_SECONDS)
    for row in single:
        if row["controller"].startswith("plugin:"):
            row["controller"] = Path(row["controller"]).stem.replace("copy_of_", "") + " (plug-in copy)"
    say("breakdown")
    breakdown = bench_breakdown(repeat=repeat)
    say("batch")
    batch = bench_batch(repeat=repeat)
    say("sweep")
    sweep = bench_sweep(repeat=max(3, repeat // 2))
    doc = {"machine": mach, "repeat": repeat, "cold": cold, "cold_warmup": cold_warmup, "single": single,
           "breakdown": breakdown, "batch": batch, "sweep": sweep}
    out = Path(out) if out is not None else user_bench_folder()
    write_results(doc, out)
    return {**doc, "out": out}


__all__ = ["bench_single", "bench_singles", "bench_all", "user_bench_folder", "machine", "plugin_copy"]

"""Benchmarks of the compiled closed loop (reported figures, never timed unit tests)."""
from __future__ import annotations

import os
import platform
import statistics
import time
from pathlib import Path


PAPER = Path(__file__).resolve().parents[1] / "data" / "scenarios" / "paper.toml"


def paper_scenario_path() -> Path:
    """Path of the packaged Section 4 scenario."""
    return PAPER


def machine() -> dict:
    """Short description of this machine for benchmark records."""
    return {"python": platform.python_version(), "cpu": platform.processor() or platform.machine(),
            "cores": os.cpu_count(), "system": platform.system()}


def _prepared(kind: str, duration: float):
    from ..scenario import load_scenario
    from ..simulation.api import prepare

    return prepare(load_scenario(PAPER, [f"controller.kind={kind}", f"sim.duration={duration}"]))


def bench_single(kind: str, *, repeat: int = 7, duration: float = 20.0) -> dict:
    """Median wall time per RK4 step of one closed-loop run of the Section 4 scenario."""
    from ..simulation.api import run_prepared

    prep = _prepared(kind, duration)
    run_prepared(prep)  # compile or load from cache
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        res = run_prepared(prep)
        times.append(time.perf_counter() - t0)
    steps = int(prep.si[0])
    per = [1e6 * t / steps for t in times]
    return {"controller": kind, "us_per_step": round(statistics.median(per), 4),
            "min_us_per_step": round(min(per), 4), "steps": steps, "repeat": repeat,
            "status": res.status, "machine": machine()}


def warmup() -> dict:
    """Compile (or load from the on-disk cache) the kernels of every registered controller."""
    from ..control import CONTROLLERS

    out = {}
    for kind in CONTROLLERS:
        t0 = time.perf_counter()
        from ..simulation.api import run_prepared

        run_prepared(_prepared(kind, 0.01))
        out[kind] = round(time.perf_counter() - t0, 3)
    return {"warmup_s": out}


__all__ = ["bench_single", "warmup", "machine", "paper_scenario_path"]

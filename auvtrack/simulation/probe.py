"""The probe run of a plug-in law or plant: its first seconds with bounds checking on, before the run.

A plug-in's law that writes past an array's end (``out.u[100000] = ...``) corrupts memory in the
compiled loop without a message, and the process may die at exit with a segmentation fault.
:func:`probe` runs the first :data:`PROBE_S` seconds of the scenario with the law compiled with
bounds checking (:func:`auvtrack.control.plugin.bounds_checked`, kernel
``KernelKey(..., checked=True)``, cached like any kernel); when the law raises there, the run is
refused with one line naming the time and, found by calling the law once more as plain Python
at the state where it raised, the plug-in's file, line and the error.  ``auvtrack check`` and
``auvtrack run`` (and :func:`auvtrack.simulate`) both probe, so ``check`` refuses what ``run``
would.  A plug-in plant's compiled functions are bounds-checked in the same run
(:func:`auvtrack.plant.checked.bounds_checked_plant`): one that raises there is refused with
its file, line, function and error.  A fault that first happens later than the probe's horizon,
or inside a compiled helper the law or plant calls, is not seen.
"""
from __future__ import annotations

import dataclasses
import math
import traceback
from pathlib import Path

import numpy as np

from ..engine import kernels
from ..engine import loop as engine
from ..plant.contract import SF, with_sizes
from ..user_modules import first_line, load_module

__all__ = ["PROBE_S", "PROBE_MAX_STEPS", "PROBE_WALL_S", "PROBE_ATTEMPTS", "ProbeFault", "LawFault", "PlantFault", "probe"]

PROBE_S = 2.0
"""Simulated seconds of the probe run (fewer when the scenario is shorter)."""
PROBE_MAX_STEPS = 50_000
"""At most this many RK4 steps (a very small time step probes less than :data:`PROBE_S`)."""
PROBE_WALL_S = 60.0
"""Wall-clock seconds the probe run may take: a law still computing then (an endless loop) is refused;
a probe that stopped at the request (a slow law) ends without a verdict."""


PROBE_ATTEMPTS = 3
"""Calls of the probe's kernel at most: one stopped at the wall time before its first step (still
loading or compiling, the law not yet called) is made again."""


class ProbeFault(ValueError):
    """A plug-in raised in the probe run (bounds checking on): one line naming where."""


class LawFault(ProbeFault):
    """A plug-in's law raised in the probe run (or never returned there)."""


class PlantFault(ProbeFault):
    """A plug-in plant's compiled function raised in the probe run."""


def _plugin_law(prep) -> bool:
    return getattr(prep.scenario.controller, "kind", None) == "plugin"


def _plugin_plant(prep) -> bool:
    return not prep.key.plant.startswith("auvtrack.")


def probe(prep, *, notice=None) -> None:
    """Run the first seconds of ``prep`` with its plug-in law and plant bounds-checked; refuse one that raises.

    Parameters
    ----------
    prep : Prepared
        A prepared run (:func:`auvtrack.simulation.pipeline.prepare`); nothing is done unless its
        controller or its plant is a plug-in.
    notice : callable, optional
        Receives the "compiling kernels" notice of the probe's kernel (default: printed to stderr).

    Raises
    ------
    LawFault
        ``controller.module: <file>:<line>: control raised IndexError: ... at t = ... s (bounds-checked
        probe run)``.
    PlantFault
        ``plant.module: <file>:<line>: rhs raised IndexError: ... in the step from t = ... s (...)``.
    KeyboardInterrupt
        On Ctrl-C while the probe runs.
    """
    if not (_plugin_law(prep) or _plugin_plant(prep)):
        return
    from ..control.plugin import STATUS_RAISED
    from ..interrupt import run_in_thread
    from ..plant.checked import take_fault
    from .pipeline import call_kernel, outputs_for

    dt = float(prep.sf[SF.dt])
    steps = min(prep.n_steps, PROBE_MAX_STEPS, max(1, math.ceil(PROBE_S / dt)))
    si = prep.si.copy()
    si[engine.SI.n_steps] = steps
    key = dataclasses.replace(prep.key, checked=True, label=f"{prep.key.label} (bounds-checked probe)")
    short = dataclasses.replace(prep, key=key, settings=engine.Settings(si, prep.sf))
    kernels.warmup([key], notice=notice)
    out = outputs_for(short, rows=0)

    def stop() -> None:
        out.info[engine.INFO_STOP] = 1

    for _ in range(PROBE_ATTEMPTS):  # again when a call was stopped before its first step (it spent the
        take_fault()  # wall time loading or compiling the kernel); forget a fault of an earlier probe
        outcome = run_in_thread(lambda: call_kernel(short, out), stop, reraise=False, timeout=PROBE_WALL_S)
        stepped = int(out.info[engine.INFO_STEPS]) > 0
        if stepped or not outcome.timed_out or outcome.abandoned or outcome.interrupted:
            break
        out = outputs_for(short, rows=0)
    if outcome.interrupted:
        raise KeyboardInterrupt
    if outcome.abandoned:  # timed out and the law never came back to the loop
        raise LawFault(f"controller.module: {prep.key.law}: control did not return within {PROBE_WALL_S:g} s of "
                       f"wall time in the bounds-checked probe run of the first {steps * dt:.6g} s (an endless loop?)")
    if outcome.timed_out:
        return  # a slow law: stopped at the request, nothing wrong seen
    if isinstance(outcome.value, BaseException) or outcome.value is None:
        fault = take_fault()
        if fault is not None:  # a plug-in plant's function raised with bounds checking on
            t = int(out.info[engine.INFO_STEPS]) * dt
            raise PlantFault(f"plant.module: {fault} in the step from t = {t:.6g} s (bounds-checked probe run of "
                             f"the first {steps * dt:.6g} s)")
        return  # a plant that raised otherwise: the run reports it with its partial result
    cause, _, t = outcome.value
    if cause != engine.CAUSE_CONTROLLER or int(out.info[engine.INFO_STATUS]) != STATUS_RAISED:
        return  # ran, or stopped for a reason the run itself reports
    law = prep.key.law
    where = next((w for ts in (t, t + 0.5 * dt, t + dt) if (w := _python_fault(prep, ts, out.fail_state[1]))), None)
    raise LawFault(f"controller.module: {where or law + ': control raised an exception'} in the step from t = {t:.6g} s "
                   f"(bounds-checked probe run of the first {steps * dt:.6g} s)")


def _python_fault(prep, t: float, state: np.ndarray) -> str | None:
    """``file:line: Type: message`` of the law called as plain Python at (``t``, ``state``), or None if it does not raise.

    The loop records the state at the start of the step in which the law raised; the caller tries
    the times of the step's RK4 stages with it.
    """
    from ..control.contract import evaluate
    from ..reference import eval_reference

    law = prep.key.law
    mod = load_module(law)
    nxp = prep.plant.x0.size
    xp, xc = np.ascontiguousarray(state[:nxp]), np.ascontiguousarray(state[nxp:])
    plant = with_sizes(load_module(prep.key.plant))
    eta, nu = plant.pose(xp)
    refm = np.zeros((3, 3))
    eval_reference(prep.ref_p, t, refm)
    n_aux = int(prep.si[engine.SI.n_aux])
    try:
        lo, hi, applied = plant.feedback(xp, np.zeros(plant.N_CMD), prep.pp)
    except Exception:  # noqa: BLE001 - a plant without usable feedback here: the law still runs unlimited
        lo, hi, applied = (-np.inf,) * 3, (np.inf,) * 3, (0.0, 0.0, 0.0)
    try:
        evaluate(mod.control.py_func, t, eta, nu, xc, refm, prep.cp, prep.vp_nom, n_aux=n_aux, path=prep.ref_p,
                 lo=lo, hi=hi, applied=applied)
    except Exception as exc:  # noqa: BLE001 - what the user's law raised, named with its file and line
        frames = traceback.extract_tb(exc.__traceback__)
        own = [f for f in frames if _same_file(f.filename, mod)]
        where = f"{own[-1].filename}:{own[-1].lineno}" if own else law
        return f"{where}: control raised {first_line(exc)}"
    return None


def _same_file(filename: str, mod) -> bool:
    origin = getattr(mod, "__file__", None)
    try:
        return origin is not None and Path(filename).resolve() == Path(origin).resolve()
    except OSError:
        return False

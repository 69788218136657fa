"""Which kernels a piece of work needs, and compiling them before it starts.

A kernel is one (controller, plant module) pair of :mod:`auvtrack.engine.kernels`; these
functions name the pairs from the registries and hand them to the engine's compiler.
"""
from __future__ import annotations

import time
from typing import Sequence

from ..engine import kernels

__all__ = ["builtin_controllers", "builtin_pairs", "SIXDOF_ONLY", "kernel_keys", "compile_first", "ensure_compiled",
           "warmup"]


def builtin_controllers() -> tuple[str, ...]:
    """Kinds of the built-in controllers (``auvtrack.control.BUILTIN``; the plug-in loader is not one)."""
    from ..control import BUILTIN_NAMES

    # open_loop_actuators drives a 6-DOF plant's fins and propeller (issue 11): not on Section 4
    return tuple(n for n in BUILTIN_NAMES if n != "open_loop_actuators")


SIXDOF_ONLY: tuple[str, ...] = ("open_loop_actuators",)
"""Built-in controllers that only run on a 6-DOF plant (fin and propeller commands)."""


def builtin_pairs(controllers: tuple[str, ...] = (), plants: tuple[str, ...] = ()) -> list[tuple[str, str]]:
    """(controller, plant) pairs a run can use: every built-in controller on every plant it runs on.

    Parameters
    ----------
    controllers, plants : tuple of str, optional
        Registered names (default: every built-in controller, :data:`SIXDOF_ONLY` included, and every plant).

    Returns
    -------
    list of (str, str)
        The pairs, controllers in registry order; a :data:`SIXDOF_ONLY` controller only with ``"6dof"``.
    """
    from ..plant import PLANTS

    cs = controllers or builtin_controllers() + SIXDOF_ONLY
    return [(c, p) for c in cs for p in (plants or tuple(PLANTS)) if c not in SIXDOF_ONLY or p == "6dof"]


def ensure_compiled(preps: Sequence, *, progress: bool = False) -> None:
    """Compile (or load) the kernels that ``preps`` need, with the "compiling kernels" notice if any is new.

    Parameters
    ----------
    preps : sequence of Prepared
        Runs about to start.
    progress : bool, optional
        Show a progress bar over the kernels being compiled.
    """
    kernels.warmup([p.key for p in preps], progress=progress)


def kernel_keys(pairs: Sequence[tuple[str, str]]) -> list[kernels.KernelKey]:
    """The kernels of (controller kind, plant model) pairs: one per plant module.

    A plant with presets in their own modules (``"6dof"``) gives one kernel per preset.

    Parameters
    ----------
    pairs : sequence of (str, str)
        Registered controller kinds and plant models, e.g. ``[("fxtntsmc", "5dof")]``.

    Returns
    -------
    list of KernelKey
        In the order of ``pairs``.
    """
    from ..control import CONTROLLERS
    from ..plant import PLANTS

    return [kernels.KernelKey(CONTROLLERS[c].module, module, f"{c} on {label}")
            for c, p in pairs for label, module in PLANTS[p].kernel_modules.items()]


def compile_first(pairs: Sequence[tuple[str, str]], *, progress: bool = False) -> list[kernels.KernelKey]:
    """Compile (or load) the kernels a piece of work needs before it starts its own progress bars.

    Studies and ``reproduce`` call this first, so that a first run shows its "compiling kernels
    (first run only, about N s)" step, with its own progress bar, before the work's bar.

    Parameters
    ----------
    pairs : sequence of (str, str)
        (controller kind, plant model) pairs, see :func:`kernel_keys`.
    progress : bool, optional
        Show a progress bar over the kernels being compiled.

    Returns
    -------
    list of KernelKey
        The kernels compiled now (empty when every one was cached).
    """
    return kernels.warmup(kernel_keys(pairs), progress=progress)


def warmup(controllers: tuple[str, ...] = (), plants: tuple[str, ...] = (), *, progress: bool = False,
           simd: bool = False) -> dict:
    """Compile (or load from the on-disk cache) the kernel of every controller on every plant.

    Kernels that are not cached compile in parallel, one process per core
    (:func:`auvtrack.engine.kernels.warmup`); the ``prange`` batch form of a kernel compiles
    on its first use.

    Parameters
    ----------
    controllers, plants : tuple of str, optional
        Registered names (default: every built-in controller on every plant it runs on,
        :func:`builtin_pairs`; a 6-DOF plant's kernels one per preset module).
    progress : bool, optional
        Show a progress bar while compiling.
    simd : bool, optional
        Also compile each pair's SIMD batch kernel (``run_batch(..., backend="simd")``), which
        otherwise compiles on first use.

    Returns
    -------
    dict
        ``{"kernels": [...], "compiled": [...], "seconds": wall time}``.
    """
    keys = kernel_keys(builtin_pairs(controllers, plants))
    t0 = time.perf_counter()
    done = kernels.warmup(keys, progress=progress, lanes=simd)
    return {"kernels": [k.label for k in keys], "compiled": [k.label for k in done],
            "seconds": round(time.perf_counter() - t0, 2)}

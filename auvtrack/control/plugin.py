"""Plug-in controllers: ``controller.kind = "plugin"`` runs a controller module from outside the package.

A plug-in is a controller module like the built-ins (contract: :mod:`auvtrack.control.contract`,
``docs/plugins.md``): it defines ``AUX_NAMES``, ``Params`` (a pydantic model of its
``controller.params`` table), the compiled law ``control(t, y, xc, args, out) -> int`` and
``setup(params, ctx) -> CompiledController``; ``NAME`` (default ``"plugin"``), ``COMMANDS``,
``TRACKS``, ``PLANTS``, ``SECTIONS`` and ``STATUS`` are optional.  ``controller.module`` is a
``.py`` path (relative to the scenario file, or absolute) or a dotted module name.

Checks, each a one-line error naming the file and the missing or wrong piece: when the scenario
is loaded (so that ``auvtrack check`` refuses what ``auvtrack run`` would) the module imports and
follows the contract (:func:`~auvtrack.control.registry.check_controller`: a compiled law, channel
names that clash with nothing, ...) and ``params`` validates against its ``Params`` (every number
finite and real); at set-up, ``setup`` returns a ``CompiledController`` whose shapes are right,
and the law, compiled once more with bounds checking, runs at the initial state and returns an
int status.  The law is then compiled into its own kernel and cached like a built-in
(:mod:`auvtrack.engine.kernels`).  This module also re-exports what a plug-in needs, so that a
plug-in file imports from one place.
"""
from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import Any, Literal

import numpy as np
from pydantic import Field, ValidationError, ValidationInfo, field_validator

from ..jit import njit, njit_noalloc
from ..packing import packed_layout
from ..user_modules import first_line, resolve
from .contract import CONTROLLER_STATUS, WORK_SIZE, evaluate
from .registry import CompiledController, ControllerParams, ControllerSpec, SetupContext, check_controller, tunable
from .tracking import error_state, error_state_forces, input_for_accel, input_for_accel_forces, sig, sign

NAME = "plugin"


class PluginFailure(ValueError):
    """A plug-in's own code broke (raised anything but the contract's ``ValueError`` refusal).

    Parameters
    ----------
    module : str
        The plug-in's file or module.
    cause : str
        ``Type: first line`` of the exception it raised.
    """

    def __init__(self, module: str, cause: str) -> None:
        super().__init__(f"controller.module: {module}: setup fails: {cause}")
        self.module = module
        self.cause = cause


STATUS_RAISED = 9
"""Status of a law that raised (an index out of bounds under bounds checking) in a probe run
(:func:`bounds_checked`); a code of the shared range 1-9 that no law returns."""

__all__ = ["PluginFailure", "STATUS_RAISED", "bounds_checked", "Params", "setup", "load", "spec_of", "CompiledController", "ControllerParamsBase", "ControllerParams",
           "SetupContext", "njit", "njit_noalloc", "packed_layout", "tunable", "error_state", "error_state_forces",
           "input_for_accel", "input_for_accel_forces", "sig", "sign", "WORK_SIZE", "CONTROLLER_STATUS"]

ControllerParamsBase = ControllerParams  # the base of a plug-in's Params (frozen, unknown keys refused)


def load(law: str) -> tuple[Any, ControllerSpec]:
    """Import the plug-in ``law`` (absolute ``.py`` path or dotted name) and check it against the contract.

    Parameters
    ----------
    law : str
        The resolved ``controller.module``.

    Returns
    -------
    (module, ControllerSpec)
        The plug-in module and its checked record (its capabilities).

    Raises
    ------
    ValueError
        ``<file>: ...`` when it cannot be imported or breaks the contract.
    """
    from ..user_modules import load_module

    if law.endswith(".py") and not Path(law).is_file():
        raise ValueError(f"no such file {law}")
    try:
        mod = load_module(law)
    except Exception as exc:  # any error raised while importing the user's file
        raise ValueError(f"cannot import {law}: {first_line(exc)}") from None
    key = (mod, law)
    if key not in _SPECS:  # checked once per imported module (a set-up per episode reuses the record)
        _SPECS[key] = dataclasses.replace(check_controller(mod, plugin=True), module=law)
    return mod, _SPECS[key]


_SPECS: dict = {}
"""The checked record of each (imported plug-in module, ``controller.module``) (:func:`load`)."""


def spec_of(section: "Params") -> ControllerSpec:
    """The checked record of the plug-in a ``[controller]`` section names (its capabilities).

    Parameters
    ----------
    section : Params
        A validated plug-in section.

    Returns
    -------
    ControllerSpec
        The plug-in's record (its capabilities), its module the file or dotted name, set up through
        this loader (:func:`setup`: checks and a first call of the law).
    """
    return dataclasses.replace(load(section.module)[1], setup=setup, params=Params)


def _numbers(model, data: dict, law: str) -> None:
    """Refuse strings, booleans, complex and non-finite numbers where the plug-in's model expects numbers."""
    for name, value in data.items():
        field = model.model_fields.get(name)
        if field is None or field.annotation not in (float, int):
            continue
        if isinstance(value, (str, bool, complex)) or not isinstance(value, (int, float)):
            raise ValueError(f"{name}: must be a real number (got {value!r}); Params of {law}")
        if not math.isfinite(value):
            raise ValueError(f"{name}: must be finite (got {value!r}); Params of {law}")


class Params(ControllerParams):
    """``[controller]`` of a plug-in: the module holding the law and the table passed to it."""

    kind: Literal["plugin"] = "plugin"
    module: str = Field(..., min_length=1,
                        description="a .py file (relative to the scenario file, or absolute) or a dotted module name")
    params: dict[str, Any] = Field(default_factory=dict, validate_default=True,
                                   description="the plug-in's parameters, validated by its Params")

    @field_validator("module", mode="after")
    @classmethod
    def _module(cls, v: str) -> str:
        law = resolve(v)  # relative to the current folder here: a file's path is anchored when read
        load(law)
        return law

    @field_validator("params", mode="after")
    @classmethod
    def _params(cls, v: dict, info: ValidationInfo) -> dict:
        law = info.data.get("module")
        if law is None:  # the module failed: its error is the one reported
            return v
        mod, _ = load(law)
        _numbers(mod.Params, v, law)
        try:
            own = mod.Params.model_validate(v)
        except ValidationError as exc:
            err = exc.errors(include_url=False)[0]
            where = ".".join(str(x) for x in err["loc"])
            got = f" (got {err['input']!r})" if "input" in err and err["type"] != "missing" else ""
            raise ValueError(f"{where + ': ' if where else ''}{err['msg']}{got}; Params of {law}") from None
        dumped = own.model_dump()
        _numbers(mod.Params, dumped, law)  # the defaults too
        return dumped


def _check_compiled(cc: Any, spec: ControllerSpec, law: str) -> CompiledController:
    if not isinstance(cc, CompiledController):
        raise ValueError(f"controller.module: {law}: setup must return a CompiledController "
                         f"(got {type(cc).__name__})")
    arrays = {}
    for name in ("cp", "xc0"):
        a = np.asarray(getattr(cc, name))
        if a.ndim != 1 or not (np.issubdtype(a.dtype, np.floating) or np.issubdtype(a.dtype, np.integer)):
            raise ValueError(f"controller.module: {law}: setup's {name} must be a 1-D array of real numbers "
                             f"(got shape {a.shape}, dtype {a.dtype})")
        if not np.all(np.isfinite(a)):
            raise ValueError(f"controller.module: {law}: setup's {name} holds a non-finite number")
        arrays[name] = np.ascontiguousarray(a, dtype=np.float64)
    if tuple(cc.aux_names) != tuple(spec.aux_names):
        raise ValueError(f"controller.module: {law}: setup's aux_names {tuple(cc.aux_names)} differ from "
                         f"AUX_NAMES {tuple(spec.aux_names)}")
    return dataclasses.replace(cc, aux_names=tuple(cc.aux_names), **arrays)


_PROBED: dict = {}
"""A law's bounds-checked probe copy (:func:`_probe`), by the law's dispatcher."""


def _probe(mod, law: str, cc: CompiledController, ctx: SetupContext) -> None:
    """Run the law once at the initial state, compiled with bounds checking: an int status, no bad index."""
    from numba import njit as numba_njit

    from numba.core.errors import NumbaError

    from ..jit.errors import CompileError, compile_error_line

    from ..interrupt import run_in_thread

    checked = _PROBED.get(mod.control)
    if checked is None:  # compiled once per law and process: a set-up per episode does not recompile it
        checked = _PROBED[mod.control] = numba_njit(boundscheck=True, nogil=True)(mod.control.py_func)
    try:
        outcome = run_in_thread(lambda: evaluate(checked, 0.0, ctx.eta0, ctx.nu0, cc.xc0, ctx.refm0, cc.cp,
                                                 ctx.vp_nom, n_aux=len(cc.aux_names)))
    except NumbaError as exc:
        raise CompileError(f"controller.module: {compile_error_line(str(exc), law)}", str(exc)) from None
    except Exception as exc:
        raise ValueError(f"controller.module: {law}: control fails at the initial state: {first_line(exc)}") from None
    if outcome.interrupted:  # Ctrl-C while the law ran (an endless loop?): stop here
        raise KeyboardInterrupt
    status = outcome.value[0]
    if isinstance(status, (bool, np.bool_)) or not isinstance(status, (int, np.integer)):
        raise ValueError(f"controller.module: {law}: control must return an int status "
                         f"(got {type(status).__name__} {status!r})")


_CHECKED: dict = {}


def bounds_checked(law):
    """The law compiled with bounds checking, any exception it raises returned as :data:`STATUS_RAISED`.

    A law that writes past an array's end corrupts memory silently in the compiled loop (and may
    crash the process at exit); compiled with ``boundscheck=True`` the same write raises
    ``IndexError``, which the wrapper catches so that the loop stops with a controller status,
    recording the time and the state (the kernel of a probe run,
    ``KernelKey(..., checked=True)``).  Only the law's own body is checked, not the compiled
    helpers it calls.

    Parameters
    ----------
    law : numba dispatcher
        A controller module's compiled ``control``.

    Returns
    -------
    numba dispatcher
        ``guarded(t, y, xc, args, out) -> int``, made once per law and process.
    """
    import types as pytypes

    import numba

    got = _CHECKED.get(law)
    if got is not None:
        return got
    fn = law.py_func
    copy = pytypes.FunctionType(fn.__code__, fn.__globals__, fn.__name__, fn.__defaults__, fn.__closure__)
    copy.__qualname__ = fn.__qualname__ + "__bounds_checked"
    copy.__module__ = fn.__module__
    checked = numba.njit(boundscheck=True, error_model="numpy")(copy)
    raised = STATUS_RAISED

    @numba.njit(boundscheck=True, error_model="numpy")
    def guarded(t, y, xc, args, out):
        try:
            return checked(t, y, xc, args, out)
        except Exception:  # noqa: BLE001 - any exception of the law becomes a status the probe reports
            return raised

    _CHECKED[law] = guarded
    return guarded


def setup(params: Params, ctx: SetupContext) -> CompiledController:
    """Validate the plug-in's params, call its ``setup`` and check what it returns.

    Parameters
    ----------
    params : Params
        The scenario's ``[controller]``.
    ctx : SetupContext
        Passed on to the plug-in's ``setup``.

    Returns
    -------
    CompiledController
        The plug-in's, with ``law`` naming its file (or module) and its status messages.

    Raises
    ------
    ValueError
        One line naming the file and what is wrong (or the plug-in's own gain-condition error).
    """
    try:
        mod, spec = load(params.module)
    except ValueError as exc:
        raise ValueError(f"controller.module: {exc}") from None
    own = mod.Params.model_validate(params.params)
    try:
        made = mod.setup(own, ctx)
    except ValueError:
        raise  # the plug-in's own one-line refusal (a gain condition)
    except Exception as exc:
        raise PluginFailure(params.module, first_line(exc)) from None
    cc = _check_compiled(made, spec, params.module)
    _probe(mod, params.module, cc, ctx)
    resolved = {**cc.resolved, "plugin": {"module": params.module, "params": params.params}}
    return dataclasses.replace(cc, law=params.module, resolved=resolved, statuses={**cc.statuses, **spec.statuses})

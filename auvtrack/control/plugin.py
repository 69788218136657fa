"""Plug-in controllers: ``controller.kind = "plugin"`` runs a controller module from outside the package.

A plug-in is a controller module like the built-ins (contract: ``docs/plugins.md``): it defines
``AUX_NAMES``, ``Params`` (a pydantic model of its ``controller.params`` table), the compiled law
``control(t, eta, nu, att, xc, refm, vp, cp, tau, dxc, aux, work) -> int`` and
``setup(scenario, ctx) -> CompiledController`` (``scenario.controller`` is then its own validated
``Params``); ``STATUS`` is optional.  ``controller.module`` is a ``.py`` path (relative to the
scenario file, or absolute) or a dotted module name.

Checks, each a one-line error naming the file and the missing piece: when the scenario is loaded
(so that ``auvtrack check`` refuses what ``auvtrack run`` would) the module imports, defines the
contract's names, and ``params`` validates against its ``Params``; at set-up, ``setup`` returns a
``CompiledController`` whose shapes are right and ``control`` compiles and returns an int status
at the initial state.  The law is then compiled into its own kernel and cached like a built-in
(:mod:`auvtrack.engine.kernels`).  This module also re-exports what a plug-in needs, so that a
plug-in file imports from one place.
"""
from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any, Literal

import numpy as np
from pydantic import BaseModel, Field, ValidationError, ValidationInfo, field_validator

from ..engine.jit import njit, njit_noalloc
from .contract import CONTROLLER_STATUS, WORK_SIZE
from .registry import CompiledController, ControllerParams
from .tracking import error_state, error_state_forces, input_for_accel, input_for_accel_forces, sig, sign

NAME = "plugin"
AUX_NAMES: tuple[str, ...] = ()  # the plug-in's own, known once it is loaded
REQUIRED = ("AUX_NAMES", "Params", "control", "setup")
control = None  # the law is the plug-in's (CompiledController.law names it)

__all__ = ["Params", "setup", "load", "resolve", "anchor_module", "CompiledController", "ControllerParamsBase",
           "ControllerParams", "njit", "njit_noalloc", "error_state", "error_state_forces", "input_for_accel",
           "input_for_accel_forces", "sig", "sign", "WORK_SIZE", "CONTROLLER_STATUS"]

ControllerParamsBase = ControllerParams  # the base of a plug-in's Params (frozen, unknown keys refused)


def resolve(module: str, base_dir: str | Path | None = None) -> str:
    """The plug-in's law as the kernels name it: an absolute ``.py`` path or the dotted module name.

    Parameters
    ----------
    module : str
        ``controller.module``: a ``.py`` path or a dotted module name.
    base_dir : str or path, optional
        Folder of the scenario file, for a relative path (default: the current folder).

    Returns
    -------
    str
        The absolute path (``.py``) or ``module`` itself.
    """
    if not module.endswith(".py"):
        return module
    path = Path(module).expanduser()
    if not path.is_absolute():
        path = Path(base_dir or Path.cwd()) / path
    return str(path.resolve())


def anchor_module(data: dict, folder: str | Path) -> dict:
    """Make a relative ``controller.module`` ``.py`` path of a scenario file's data relative to ``folder``.

    Called by the loaders on what a scenario file holds, so that the path written in a file is
    relative to that file (paths given in a dict or by ``--set`` are relative to the current
    folder).

    Parameters
    ----------
    data : dict
        Parsed scenario (modified in place).
    folder : str or path
        The folder of the scenario file.

    Returns
    -------
    dict
        ``data``.
    """
    ctrl = data.get("controller") if isinstance(data, dict) else None
    module = ctrl.get("module") if isinstance(ctrl, dict) else None
    if isinstance(module, str) and module.endswith(".py"):
        ctrl["module"] = resolve(module, Path(folder).resolve())
    return data


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return f"{type(exc).__name__}: {text[0] if text else ''}".rstrip(": ")


def load(law: str):
    """Import the plug-in ``law`` (absolute ``.py`` path or dotted name) and check the contract's names.

    Parameters
    ----------
    law : str
        Output of :func:`resolve`.

    Returns
    -------
    module
        The plug-in module.

    Raises
    ------
    ValueError
        ``<file>: ...`` when it cannot be imported or lacks a name of the contract.
    """
    from ..engine.kernels import law_module

    if law.endswith(".py") and not Path(law).is_file():
        raise ValueError(f"no such file {law}")
    try:
        mod = law_module(law)
    except Exception as exc:  # any error raised while importing the user's file
        raise ValueError(f"cannot import {law}: {_first_line(exc)}") from None
    missing = [n for n in REQUIRED if not hasattr(mod, n)]
    if missing:
        raise ValueError(f"{law} does not define {', '.join(missing)} (a plug-in defines "
                         f"{', '.join(REQUIRED)}; see docs/plugins.md)")
    if not (isinstance(mod.Params, type) and issubclass(mod.Params, BaseModel)):
        raise ValueError(f"{law}: Params must be a pydantic model class (got {mod.Params!r})")
    names = mod.AUX_NAMES
    if not (isinstance(names, (tuple, list)) and all(isinstance(n, str) and n for n in names)):
        raise ValueError(f"{law}: AUX_NAMES must be a tuple of channel names (got {names!r})")
    return mod


def _strict_numbers(model, data: dict, law: str) -> None:
    """Refuse strings and booleans where the plug-in's model expects numbers (as for built-ins)."""
    for name, value in data.items():
        field = model.model_fields.get(name)
        if field is not None and field.annotation in (float, int) and isinstance(value, (str, bool)):
            raise ValueError(f"{name}: must be a number (got {value!r}); Params of {law}")


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
        mod = load(law)
        _strict_numbers(mod.Params, v, law)
        try:
            own = mod.Params.model_validate(v)
        except ValidationError as exc:
            err = exc.errors(include_url=False)[0]
            where = ".".join(str(x) for x in err["loc"])
            got = f" (got {err['input']!r})" if "input" in err and err["type"] != "missing" else ""
            raise ValueError(f"{where + ': ' if where else ''}{err['msg']}{got}; Params of {law}") from None
        return own.model_dump()


def _check_compiled(cc: Any, mod, law: str) -> CompiledController:
    if not isinstance(cc, CompiledController):
        raise ValueError(f"controller.module: {law}: setup must return a CompiledController "
                         f"(got {type(cc).__name__})")
    cp, xc0 = np.asarray(cc.cp), np.asarray(cc.xc0)
    for name, a in (("cp", cp), ("xc0", xc0)):
        if a.ndim != 1 or not np.issubdtype(a.dtype, np.number):
            raise ValueError(f"controller.module: {law}: setup's {name} must be a 1-D array of numbers "
                             f"(got shape {a.shape}, dtype {a.dtype})")
    if tuple(cc.aux_names) != tuple(mod.AUX_NAMES):
        raise ValueError(f"controller.module: {law}: setup's aux_names {tuple(cc.aux_names)} differ from "
                         f"AUX_NAMES {tuple(mod.AUX_NAMES)}")
    return dataclasses.replace(cc, cp=np.ascontiguousarray(cp, dtype=np.float64),
                               xc0=np.ascontiguousarray(xc0, dtype=np.float64), aux_names=tuple(cc.aux_names))


def _probe(mod, law: str, cc: CompiledController, scenario, ctx) -> None:
    """Call the compiled law once at the initial state: it must compile and return an int status."""
    from ..vehicle.kinematics import attitude

    eta, nu = tuple(float(x) for x in scenario.initial.eta), tuple(float(x) for x in scenario.initial.nu)
    tau, dxc, aux = np.zeros(3), np.zeros(cc.xc0.size), np.zeros(len(cc.aux_names))
    try:
        status = mod.control(0.0, eta, nu, attitude(eta[3], eta[4]), cc.xc0.copy(), np.ascontiguousarray(ctx.refm0),
                             np.ascontiguousarray(ctx.vp_nom), cc.cp, tau, dxc, aux, np.zeros(WORK_SIZE))
    except Exception as exc:
        raise ValueError(f"controller.module: {law}: control fails at the initial state: "
                         f"{_first_line(exc)}") from None
    if isinstance(status, (bool, np.bool_)) or not isinstance(status, (int, np.integer)):
        raise ValueError(f"controller.module: {law}: control must return an int status "
                         f"(got {type(status).__name__} {status!r})")


def setup(scenario, ctx) -> CompiledController:
    """Validate the plug-in's params, call its ``setup`` and check what it returns.

    Parameters
    ----------
    scenario : Scenario
        ``scenario.controller`` is this module's :class:`Params`.
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
    p: Params = scenario.controller
    try:
        mod = load(p.module)
    except ValueError as exc:
        raise ValueError(f"controller.module: {exc}") from None
    own = mod.Params.model_validate(p.params)
    cc = _check_compiled(mod.setup(scenario.model_copy(update={"controller": own}), ctx), mod, p.module)
    _probe(mod, p.module, cc, scenario, ctx)
    statuses = {int(k): str(v) for k, v in dict(getattr(mod, "STATUS", {})).items()}
    resolved = {**cc.resolved, "plugin": {"module": p.module, "params": p.params}}
    return dataclasses.replace(cc, law=p.module, resolved=resolved, statuses={**cc.statuses, **statuses})

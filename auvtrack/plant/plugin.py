"""Plug-in plants: ``plant.model = "plugin"`` runs a plant module from outside the package.

A plug-in plant is a plant module like the built-ins (contract: :mod:`auvtrack.plant.contract`,
``docs/plugins.md``): ``NAME``, ``STATE``, ``COMMAND``, ``LOG_NAMES``, ``ACCEPTS``, ``Section``
(a pydantic model of its ``plant.params`` table), ``setup(section, ctx) -> CompiledPlant`` and the
compiled functions.  ``plant.module`` is a ``.py`` path (relative to the scenario file, or
absolute) or a dotted module name.  It is checked (:func:`~auvtrack.plant.registry.check_plant`)
when the scenario is loaded, so that ``auvtrack check`` refuses what ``auvtrack run`` would; its
kernel is generated and cached like a built-in's.  This module also re-exports what a plug-in
plant needs, so that a plug-in file imports from one place.
"""
from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any, Literal

from pydantic import Field, ValidationError, field_validator, model_validator

from ..jit import njit, njit_noalloc
from .contract import CAUSE_PITCH, CAUSE_ROLL, SCRATCH_SIZE, SF
from .registry import CompiledPlant, PlantContext, PlantSection, PlantSpec, check_plant

NAME = "plugin"

__all__ = ["Section", "setup", "load", "spec_of", "compile_functions", "CompiledPlant", "PlantContext", "PlantSection", "njit",
           "njit_noalloc", "CAUSE_PITCH", "CAUSE_ROLL", "SCRATCH_SIZE", "SF"]


def load(module: str):
    """Import the plug-in plant ``module`` (absolute ``.py`` path or dotted name) and check it.

    Parameters
    ----------
    module : str
        The resolved ``plant.module``.

    Returns
    -------
    (module, PlantSpec)
        The module and its checked record.

    Raises
    ------
    ValueError
        ``<file>: ...`` when it cannot be imported or breaks the contract.
    """
    from ..user_modules import first_line
    from ..user_modules import load_module

    if module.endswith(".py") and not Path(module).is_file():
        raise ValueError(f"no such file {module}")
    try:
        mod = load_module(module)
    except Exception as exc:  # any error raised while importing the user's file
        raise ValueError(f"cannot import {module}: {first_line(exc)}") from None
    return mod, check_plant(mod)


class Section(PlantSection):
    """``[plant]`` of a plug-in: the module and the table its own ``Section`` validates."""

    model: Literal["plugin"] = "plugin"
    module: str = Field(..., min_length=1,
                        description="a .py file (relative to the scenario file, or absolute) or a dotted module name")
    params: dict[str, Any] = Field(default_factory=dict, description="the plug-in's keys, validated by its Section")

    @field_validator("module", mode="after")
    @classmethod
    def _module(cls, v: str) -> str:
        from ..user_modules import resolve

        law = resolve(v)
        load(law)
        return law

    @model_validator(mode="after")
    def _params(self) -> "Section":
        mod, _ = load(self.module)
        try:
            mod.Section.model_validate(self.params)
        except ValidationError as exc:
            err = exc.errors(include_url=False)[0]
            where = ".".join(str(x) for x in err["loc"])
            got = f" (got {err['input']!r})" if "input" in err and err["type"] != "missing" else ""
            raise ValueError(f"params.{where + ': ' if where else ''}{err['msg']}{got}; Section of {self.module}") from None
        return self


def spec_of(section: Section) -> PlantSpec:
    """The checked record of the plug-in a ``[plant]`` section names (its capabilities).

    Parameters
    ----------
    section : Section
        A validated plug-in section.

    Returns
    -------
    PlantSpec
        The plug-in's record, its module the file or dotted name.
    """
    _, spec = load(section.module)
    return dataclasses.replace(spec, module=section.module, setup=setup, section=Section)


def setup(section: Section, ctx: PlantContext) -> CompiledPlant:
    """Validate the plug-in's params, call its ``setup`` and check what it returns.

    Parameters
    ----------
    section : Section
        The scenario's ``[plant]``.
    ctx : PlantContext
        Passed on to the plug-in's ``setup``.

    Returns
    -------
    CompiledPlant
        The plug-in's, with ``module`` naming its file (or module).

    Raises
    ------
    ValueError
        One line naming the file and what is wrong.
    """
    import numpy as np

    mod, spec = load(section.module)
    own = mod.Section.model_validate(section.params)
    cp = mod.setup(own, ctx)
    if not isinstance(cp, CompiledPlant):
        raise ValueError(f"plant.module: {section.module}: setup must return a CompiledPlant (got {type(cp).__name__})")
    x0 = np.ascontiguousarray(cp.x0, dtype=np.float64)
    pp = np.ascontiguousarray(cp.pp, dtype=np.float64)
    if x0.shape != (len(spec.state),):
        raise ValueError(f"plant.module: {section.module}: setup's x0 has shape {x0.shape}, STATE has "
                         f"{len(spec.state)} names")
    if pp.ndim != 1:
        raise ValueError(f"plant.module: {section.module}: setup's pp must be a 1-D array (got shape {pp.shape})")
    compile_functions(mod, section.module, pp, x0, len(spec.command))
    return dataclasses.replace(cp, pp=pp, x0=x0, log_names=spec.log_names, module=section.module,
                               resolved={**cp.resolved, "plugin": {"module": section.module, "params": section.params}})


def compile_functions(mod, module: str, pp, x0, n_cmd: int) -> None:
    """Compile each of the plug-in's compiled functions alone, with the types the loop passes.

    A typing error then names the plug-in's file and line at set-up (``check`` and ``run`` alike),
    not the generated kernel that calls it.  Nothing runs: the functions are compiled only (and
    cached on disk like the kernel).

    Parameters
    ----------
    mod : module
        The plug-in plant.
    module : str
        Its ``plant.module`` (for the message).
    pp, x0 : numpy.ndarray
        What its ``setup`` returned.
    n_cmd : int
        The length of its command.

    Raises
    ------
    auvtrack.jit.errors.CompileError
        ``plant.module: <file>: cannot compile: <file>:<line>: <cause>``.
    """
    import numba
    from numba.core.errors import NumbaError

    from ..jit.errors import CompileError, compile_error_line
    from .contract import example_arguments

    for name, args in example_arguments(x0, pp, n_cmd).items():
        try:
            getattr(mod, name).compile(tuple(numba.typeof(a) for a in args))
        except NumbaError as exc:
            raise CompileError(f"plant.module: {compile_error_line(str(exc), module)}", str(exc)) from None

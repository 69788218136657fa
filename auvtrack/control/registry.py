"""Controller registry.

A controller is one module that defines

* a pydantic ``Params`` model for its ``[controller]`` scenario section (with ``kind``),
* a compiled ``control(...)`` function (the signature is documented in
  :mod:`auvtrack.control.dispatch`), and
* a ``setup(scenario, ctx)`` function returning a :class:`CompiledController`,

and registers itself here with a unique integer ``code``.  Adding a controller means one new
file, one ``register`` call (in :mod:`auvtrack.control`), one branch in
:mod:`auvtrack.control.dispatch` and one in :func:`auvtrack.simulation.engine.run_kernel`
(compiled code cannot look functions up at run time), plus its parameter model.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np
from pydantic import BaseModel


@dataclass(frozen=True)
class CompiledController:
    """Everything the compiled engine needs to run one controller.

    Attributes
    ----------
    code : int
        Dispatch code of the controller (see :mod:`auvtrack.control.dispatch`).
    cp : numpy.ndarray
        Packed float64 parameters.
    xc0 : numpy.ndarray
        Initial internal state (adaptive weights, envelope filters); may be empty.
    aux_names : tuple of str
        Names of the extra logged channels the controller writes (``rho_x``, ``S_x``, ...).
    notes : tuple of str
        Warnings to show the user (e.g. an initial envelope widening).
    resolved : dict
        Derived values worth recording in ``run.json``.
    """

    code: int
    cp: np.ndarray
    xc0: np.ndarray
    aux_names: tuple[str, ...] = ()
    notes: tuple[str, ...] = ()
    resolved: dict[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class ControllerSpec:
    """Registration record of one controller."""

    name: str
    code: int
    params: type[BaseModel]
    setup: Callable[..., CompiledController]
    summary: str = ""


CONTROLLERS: dict[str, ControllerSpec] = {}


def register(spec: ControllerSpec) -> ControllerSpec:
    """Add ``spec`` to :data:`CONTROLLERS`.

    Parameters
    ----------
    spec : ControllerSpec
        The registration record; its name and code must be unused.

    Returns
    -------
    ControllerSpec
        ``spec`` itself.

    Raises
    ------
    ValueError
        If the name or the code is already registered.
    """
    if spec.name in CONTROLLERS or any(s.code == spec.code for s in CONTROLLERS.values()):
        raise ValueError(f"controller {spec.name!r} (code {spec.code}) is already registered")
    CONTROLLERS[spec.name] = spec
    return spec


def get(name: str) -> ControllerSpec:
    """Return a registered controller.

    Parameters
    ----------
    name : str
        Controller kind, e.g. ``"fxtntsmc"``.

    Returns
    -------
    ControllerSpec
        Its registration record.

    Raises
    ------
    KeyError
        If ``name`` is not registered (the message names the choices).
    """
    try:
        return CONTROLLERS[name]
    except KeyError:
        raise KeyError(f"unknown controller {name!r}; choose one of {sorted(CONTROLLERS)}") from None

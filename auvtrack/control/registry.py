"""Controller registry.

A controller is one module (the contract is in :mod:`auvtrack.control.contract`) that defines

* ``NAME``, the scenario's ``controller.kind``, and ``AUX_NAMES``, its logged channels;
* ``Params``, the pydantic model of its ``[controller]`` section (``kind: Literal[NAME]``);
* the compiled law ``control(t, eta, nu, att, xc, refm, vp, cp, tau, dxc, aux, work) -> status``;
* ``setup(scenario, ctx) -> CompiledController``, which packs its gains and initial state and
  checks its gain conditions;
* optionally ``STATUS = {code: message}`` for its own failure codes.

Registering a built-in controller is one line in :mod:`auvtrack.control` (its module in the
``BUILTIN`` tuple).  The engine's kernel for a (controller, plant) pair is generated and compiled
on demand (:mod:`auvtrack.engine.kernels`), so no code elsewhere names a controller.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from types import ModuleType
from typing import Any, Callable

import numpy as np
from pydantic import BaseModel, ConfigDict

CONTRACT = ("NAME", "AUX_NAMES", "Params", "control", "setup")


class ControllerParams(BaseModel):
    """Base of every controller's ``Params``: frozen, unknown keys refused."""

    model_config = ConfigDict(extra="forbid", frozen=True)


@dataclass(frozen=True)
class CompiledController:
    """Everything the compiled engine needs to run one controller.

    Attributes
    ----------
    cp : numpy.ndarray
        Packed float64 parameters.
    xc0 : numpy.ndarray
        Initial internal state (adaptive weights, envelope filters, integrators); may be empty.
    aux_names : tuple of str
        Names of the extra logged channels the controller writes (``rho_x``, ``sliding_x``, ...).
    notes : tuple of str
        Warnings to show the user (e.g. an initial envelope widening).
    resolved : dict
        Derived values worth recording in ``run.json``.
    law : str
        Where the compiled ``control`` lives: an importable module name or a ``.py`` file path.
        Empty: the registered module's (plug-ins set it to their file).
    statuses : dict of int to str
        Messages of status codes beyond the registered module's ``STATUS`` (a plug-in's own).
    """

    cp: np.ndarray
    xc0: np.ndarray
    aux_names: tuple[str, ...] = ()
    notes: tuple[str, ...] = ()
    resolved: dict[str, Any] = field(default_factory=dict)
    law: str = ""
    statuses: dict[int, str] = field(default_factory=dict)


@dataclass(frozen=True)
class ControllerSpec:
    """Registration record of one controller.

    Attributes
    ----------
    name : str
        ``controller.kind``.
    module : str
        Importable name of the module holding the compiled ``control``.
    params : type
        Its pydantic ``Params`` model.
    setup : callable
        ``setup(scenario, ctx) -> CompiledController``.
    summary : str
        One line for listings (the module docstring's first line).
    statuses : dict of int to str
        Messages of the controller's own status codes.
    """

    name: str
    module: str
    params: type[BaseModel]
    setup: Callable[..., CompiledController]
    summary: str = ""
    statuses: dict[int, str] = field(default_factory=dict)

    @classmethod
    def from_module(cls, module: ModuleType) -> "ControllerSpec":
        """Build the record from a controller module.

        Parameters
        ----------
        module : module
            Defines every name of :data:`CONTRACT` (and optionally ``STATUS``).

        Returns
        -------
        ControllerSpec
            The record.

        Raises
        ------
        TypeError
            If a name of the contract is missing.
        """
        missing = [n for n in CONTRACT if not hasattr(module, n)]
        if missing:
            raise TypeError(f"controller module {module.__name__} lacks {', '.join(missing)}")
        doc = (module.__doc__ or "").strip()
        return cls(module.NAME, module.__name__, module.Params, module.setup,
                   doc.splitlines()[0] if doc else "", dict(getattr(module, "STATUS", {})))


CONTROLLERS: dict[str, ControllerSpec] = {}


def register(spec: ControllerSpec) -> ControllerSpec:
    """Add ``spec`` to :data:`CONTROLLERS`.

    Parameters
    ----------
    spec : ControllerSpec
        The registration record; its name must be unused.

    Returns
    -------
    ControllerSpec
        ``spec`` itself.

    Raises
    ------
    ValueError
        If the name is already registered.
    """
    if spec.name in CONTROLLERS:
        raise ValueError(f"controller {spec.name!r} is already registered")
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

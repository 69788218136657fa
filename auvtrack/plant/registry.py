"""Plant registry: the truth models the engine can integrate, each checked against the contract once.

A plant is one module following :mod:`auvtrack.plant.contract`.  Registering a built-in is one
line in :mod:`auvtrack.plant` (``register(module)``); :func:`check_plant` runs on every
registration and on every plug-in plant, and turns a module into a :class:`PlantSpec` whose
capabilities (what it accepts, its section) the rest of the package reads.  The engine's
kernel for a (controller, plant) pair is generated on demand (:mod:`auvtrack.engine.kernels`).
"""
from __future__ import annotations

import inspect
from dataclasses import dataclass, field
from types import ModuleType
from typing import Any, Callable

import numpy as np
from pydantic import BaseModel

from ..fields import Section

__all__ = ["PlantSection", "CompiledPlant", "PlantContext", "PlantSpec", "check_plant", "PLANTS", "register", "get"]

COMPILED = ("pose", "accel5", "allocate", "rhs", "applied", "feedback", "effort", "attitude_cause", "log_extra")
"""The compiled functions of a plant module (:mod:`auvtrack.plant.contract`)."""
REQUIRED = ("NAME", "STATE", "COMMAND", "LOG_NAMES", "ACCEPTS", "Section", "setup") + COMPILED
"""Every name a plant module defines (``check_scenario`` is optional)."""
KINDS = ("tau", "actuators")


class PlantSection(Section):
    """Base of every plant's ``[plant]`` section model (``model: Literal[NAME]`` and its own keys)."""


@dataclass(frozen=True)
class CompiledPlant:
    """What the engine needs of one plant for one run.

    Attributes
    ----------
    pp : numpy.ndarray
        Packed float64 parameters of the true plant (layout defined by the plant module).
    x0 : numpy.ndarray
        Initial plant state, ``len(STATE)`` of the module.
    log_names : tuple of str
        Names of the plant's extra logged channels (its ``LOG_NAMES``).
    notes : tuple of str
        Messages to show the user.
    resolved : dict
        JSON record of the plant actually simulated (numbers and their sources) for ``run.json``.
    module : str
        Where the compiled functions live (module name or ``.py`` path); empty: the registered
        module's (a plug-in plant names its file).
    """

    pp: np.ndarray
    x0: np.ndarray
    log_names: tuple[str, ...] = ()
    notes: tuple[str, ...] = ()
    resolved: dict[str, Any] = field(default_factory=dict)
    module: str = ""


@dataclass(frozen=True)
class PlantContext:
    """What a plant's ``setup`` may use besides its own section.

    Attributes
    ----------
    eta0, nu0 : tuple of 5 float
        Initial pose (x, y, z, theta, psi) (m, rad) and velocity (u, v, w, q, r) (m/s, rad/s).
    phi0, p0 : float
        Initial roll (rad) and roll rate (rad/s) (plants with roll).
    vp_true : numpy.ndarray
        The packed 5-DOF vehicle with the scenario's ``[uncertainty]`` applied (the 5-DOF truth).
    vehicle_record : dict
        The design vehicle's record (numbers and sources).
    design_preset : str
        Name of the controller's design vehicle preset.
    actuator : object
        The ``[actuator]`` section: limits of tau on the 5-DOF plant.
    commands : str
        What the controller commands: ``"tau"`` or ``"actuators"``.
    seed : int
        Scenario seed.
    """

    eta0: tuple
    nu0: tuple
    phi0: float = 0.0
    p0: float = 0.0
    vp_true: np.ndarray = field(default_factory=lambda: np.zeros(0))
    vehicle_record: dict = field(default_factory=dict)
    design_preset: str = ""
    actuator: Any = None
    commands: str = "tau"
    seed: int = 0


@dataclass(frozen=True)
class PlantSpec:
    """Registration record of one plant model.

    Attributes
    ----------
    name : str
        Value of the scenario key ``plant.model``.
    module : str
        Importable name of the module with the compiled contract functions.
    section : type
        Its ``[plant]`` section model.
    setup : callable
        ``setup(section, ctx) -> CompiledPlant``.
    summary : str
        One line for listings.
    accepts : tuple of str
        What controllers may command: ``"tau"`` and possibly ``"actuators"``.
    state, command, log_names : tuple of str
        Names of the state, actuator-command and extra logged components.
    check_scenario : callable or None
        ``check_scenario(scenario)``: refuses options of other sections that do not apply to
        this plant (one-line ``ValueError`` naming the field).
    """

    name: str
    module: str
    section: type[BaseModel]
    setup: Callable[..., CompiledPlant]
    summary: str = ""
    accepts: tuple[str, ...] = ("tau",)
    state: tuple[str, ...] = ()
    command: tuple[str, ...] = ()
    log_names: tuple[str, ...] = ()
    check_scenario: Callable[[Any], None] | None = None

    @classmethod
    def from_module(cls, module: ModuleType) -> "PlantSpec":
        """Build the record from a plant module (:func:`check_plant`).

        Parameters
        ----------
        module : module
            A module defining every name of :data:`REQUIRED`.

        Returns
        -------
        PlantSpec
            The record.

        Raises
        ------
        ValueError
            One line naming the module and the missing or wrong piece.
        """
        return check_plant(module)


def _names(where: str, what: str, names: Any, allow_empty: bool = False) -> tuple[str, ...]:
    if not (isinstance(names, tuple) and (names or allow_empty)
            and all(isinstance(n, str) and n.isidentifier() for n in names)):
        raise ValueError(f"{where}: {what} must be a {'' if allow_empty else 'non-empty '}tuple of identifiers "
                         f"(got {names!r})")
    if len(set(names)) != len(names):
        raise ValueError(f"{where}: {what} repeats a name (got {names!r})")
    return names


def check_plant(module: ModuleType) -> PlantSpec:
    """Check a plant module against the contract and return its registration record.

    Parameters
    ----------
    module : module
        A built-in plant module or a plug-in.

    Returns
    -------
    PlantSpec
        The record.

    Raises
    ------
    ValueError
        ``<file>: <what is missing or wrong>`` (see :mod:`auvtrack.plant.contract`).
    """
    from numba.core.dispatcher import Dispatcher

    from ..channels import BASE_CHANNELS, CHI_CHANNELS
    from ..control.registry import channel_problem

    where = getattr(module, "__file__", None) or module.__name__
    missing = [n for n in REQUIRED if not hasattr(module, n)]
    if missing:
        raise ValueError(f"{where} does not define {', '.join(missing)} (a plant defines "
                         f"{', '.join(REQUIRED)}; see docs/plugins.md)")
    if not (isinstance(module.NAME, str) and module.NAME):
        raise ValueError(f"{where}: NAME must be a non-empty string (got {module.NAME!r})")
    state = _names(where, "STATE", module.STATE)
    command = _names(where, "COMMAND", module.COMMAND)
    if len(command) < 3:
        raise ValueError(f"{where}: COMMAND needs at least 3 components (the controller's 3-vector is written "
                         f"there) (got {command!r})")
    problem = channel_problem(module.LOG_NAMES, BASE_CHANNELS + CHI_CHANNELS)
    if problem:
        raise ValueError(f"{where}: LOG_NAMES: {problem}")
    accepts = module.ACCEPTS
    if not (isinstance(accepts, tuple) and accepts and set(accepts) <= set(KINDS) and "tau" in accepts):
        raise ValueError(f"{where}: ACCEPTS must be ('tau',) or ('tau', 'actuators') (got {accepts!r})")
    for name in COMPILED:
        if not isinstance(getattr(module, name), Dispatcher):
            raise ValueError(f"{where}: {name} must be compiled (@njit_noalloc from auvtrack.plant.plugin); "
                             f"got {type(getattr(module, name)).__name__}")
    sec = module.Section
    if not (isinstance(sec, type) and issubclass(sec, BaseModel)):
        raise ValueError(f"{where}: Section must be a pydantic model class (got {sec!r})")
    if not callable(module.setup) or len(inspect.signature(module.setup).parameters) != 2:
        raise ValueError(f"{where}: setup must be a function setup(section, ctx)")
    from .contract import with_sizes

    with_sizes(module)
    for attr, size in (("NX", len(state)), ("N_CMD", len(command)), ("N_LOG", len(module.LOG_NAMES))):
        if getattr(module, attr, size) != size:
            raise ValueError(f"{where}: {attr} = {getattr(module, attr)!r} differs from the names it counts ({size})")
    check = getattr(module, "check_scenario", None)
    doc = (module.__doc__ or "").strip()
    return PlantSpec(module.NAME, module.__name__, sec, module.setup, doc.splitlines()[0] if doc else "",
                     tuple(accepts), state, command, tuple(module.LOG_NAMES), check)


PLANTS: dict[str, PlantSpec] = {}


def register(spec: PlantSpec | ModuleType) -> PlantSpec:
    """Add a plant to :data:`PLANTS`.

    Parameters
    ----------
    spec : PlantSpec or module
        The record, or a plant module (checked by :func:`check_plant`); its name must be unused.

    Returns
    -------
    PlantSpec
        The record.

    Raises
    ------
    ValueError
        If the name is already registered, or the module breaks the contract.
    """
    if isinstance(spec, ModuleType):
        spec = check_plant(spec)
        model = spec.section.model_fields.get("model")
        if model is None or model.default != spec.name:
            raise ValueError(f"{spec.module}: Section needs a field model = {spec.name!r} (the scenario's plant.model)")
    if spec.name in PLANTS:
        raise ValueError(f"plant {spec.name!r} is already registered")
    PLANTS[spec.name] = spec
    return spec


def get(name: str) -> PlantSpec:
    """Return a registered plant.

    Parameters
    ----------
    name : str
        A ``plant.model`` value, e.g. ``"5dof"``.

    Returns
    -------
    PlantSpec
        Its registration record.

    Raises
    ------
    KeyError
        If ``name`` is not registered (the message names the choices).
    """
    try:
        return PLANTS[name]
    except KeyError:
        raise KeyError(f"unknown plant {name!r}; choose one of {sorted(PLANTS)}") from None

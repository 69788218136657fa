"""Controller registry: the controllers a scenario can name, each checked against the contract once.

A controller is one module following :mod:`auvtrack.control.contract`.  Registering a built-in is
one line in :mod:`auvtrack.control` (its module in the ``BUILTIN`` tuple);
:func:`check_controller` runs on every registration and on every plug-in, and turns a module into
a :class:`ControllerSpec` whose capabilities (what it commands, whether it tracks, which plants
it runs on) the rest of the package reads instead of keeping lists of names.  The engine's
kernel for a (controller, plant) pair is generated and compiled on demand
(:mod:`auvtrack.engine.kernels`).
"""
from __future__ import annotations

import inspect
import math
from dataclasses import dataclass, field
from types import ModuleType
from typing import Any, Callable, Mapping

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from .contract import COMMAND_KINDS

__all__ = ["ControllerParams", "CompiledController", "PlantView", "SetupContext", "ControllerSpec", "check_controller",
           "channel_problem", "tunable", "CONTROLLERS", "register", "get"]

REQUIRED = ("NAME", "AUX_NAMES", "Params", "control", "setup")
"""Names every controller module defines (the rest of the contract is optional)."""
RESERVED_CHANNELS = ("status",)
"""Names a controller's channel cannot take besides the engine's own (they are run-folder columns)."""
MAX_CHANNEL_NAME = 63


class ControllerParams(BaseModel):
    """Base of every controller's ``Params``: frozen, unknown keys refused."""

    model_config = ConfigDict(extra="forbid", frozen=True)


def tunable(default: float | tuple[float, ...], low: float, high: float, *, log: bool = False,
            per_item: bool = False, **field_kwargs: Any) -> Any:
    """A gain field of a ``Params`` model with its search space for ``auvtrack tune``.

    Parameters
    ----------
    default : float or tuple of float
        The field's default (a tuple: a vector field, each item searched in [low, high]).
    low, high : float
        The range searched (inclusive), inside the field's own admissible range.
    log : bool, optional
        Search on a logarithmic scale (``low > 0``).
    per_item : bool, optional
        For a vector field: one searched value per item; by default one value shared by every
        item (:mod:`auvtrack.tuning.space`).
    **field_kwargs
        Passed to :func:`pydantic.Field` (``gt``, ``ge``, ``description``...).

    Returns
    -------
    pydantic.fields.FieldInfo
        The field, its search space in ``json_schema_extra["tune"]``.

    Raises
    ------
    ValueError
        ``low >= high``, a log scale with ``low <= 0``, or a default outside a finite range.
    """
    if not (math.isfinite(low) and math.isfinite(high) and low < high):
        raise ValueError(f"tunable: needs finite low < high (got {low}, {high})")
    if log and low <= 0:
        raise ValueError(f"tunable: a log scale needs low > 0 (got {low})")
    extra = dict(field_kwargs.pop("json_schema_extra", None) or {})
    extra["tune"] = {"low": float(low), "high": float(high), "log": bool(log), **({"per_item": True} if per_item else {})}
    return Field(default, json_schema_extra=extra, **field_kwargs)


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
class PlantView:
    """What a controller's ``setup`` may know of the plant it flies (its actuators, its start).

    Attributes
    ----------
    module : str
        Where the plant's compiled functions live (module name or ``.py`` path).
    state : tuple of str
        Names of the plant's state components.
    command : tuple of str
        Names of its actuator-command components.
    x0 : numpy.ndarray
        Its initial state.
    pp : numpy.ndarray
        Its packed parameters (as packed for this controller).
    """

    module: str = ""
    state: tuple[str, ...] = ()
    command: tuple[str, ...] = ()
    x0: np.ndarray = field(default_factory=lambda: np.zeros(0))
    pp: np.ndarray = field(default_factory=lambda: np.zeros(0))

    def _functions(self):
        from ..user_modules import load_module

        return load_module(self.module)

    def initial(self, name: str) -> float:
        """The initial value of state component ``name``."""
        return float(self.x0[self.state.index(name)])

    def feedback(self) -> tuple:
        """(lo, hi, applied) at the initial state, in the controller's command units (the plant's ``feedback``)."""
        return self._functions().feedback(np.ascontiguousarray(self.x0), np.zeros(len(self.command)), self.pp)

    def applied(self, **state: float) -> tuple:
        """(tau_u, tau_q, tau_r) produced at a state whose named components are given, the others 0."""
        x = np.zeros(len(self.state))
        for k, v in state.items():
            x[self.state.index(k)] = v
        return self._functions().applied(x, np.zeros(len(self.command)), self.pp)


@dataclass(frozen=True)
class SetupContext:
    """What a controller's ``setup`` may use besides its own section.

    Attributes
    ----------
    vp_nom : numpy.ndarray
        Packed nominal vehicle (:mod:`auvtrack.vehicle.params`).
    refm0 : numpy.ndarray
        Reference at t = 0, rows eta_d, eta_d_dot, eta_d_ddot.
    e0 : numpy.ndarray
        Initial virtual-point error eta1(0) - eta_d(0) (m).
    seed : int
        Scenario seed.
    eta0, nu0 : tuple of float
        Initial pose (x, y, z, theta, psi) and velocity (u, v, w, q, r) of the run.
    actuator : object
        The scenario's ``[actuator]`` section (``tau_max``, ``rate_max``) of the 5-DOF plant.
    plant : PlantView
        The plant flown: its actuators and start (for a controller that commands its actuators).
    commands : str
        What the law commands on this plant (its ``COMMANDS`` preference the plant accepts).
    sections : dict
        The other scenario sections the controller declared in ``SECTIONS``, by name.
    dt : float
        RK4 step (s).
    control_rate : float
        Controller sampling rate (Hz; 0 = continuous).
    """

    vp_nom: np.ndarray
    refm0: np.ndarray
    e0: np.ndarray
    seed: int
    eta0: tuple = (0.0,) * 5
    nu0: tuple = (0.0,) * 5
    actuator: Any = None
    plant: PlantView = field(default_factory=PlantView)
    commands: str = "tau"
    sections: Mapping[str, Any] = field(default_factory=dict)
    dt: float = 0.001
    control_rate: float = 0.0

    def section(self, name: str) -> Any:
        """One of the declared extra sections (``KeyError`` naming ``SECTIONS`` otherwise)."""
        try:
            return self.sections[name]
        except KeyError:
            raise KeyError(f"section {name!r} is not among the controller's SECTIONS") from None


@dataclass(frozen=True)
class ControllerSpec:
    """Registration record of one controller: where it lives and what it can do.

    Attributes
    ----------
    name : str
        ``controller.kind``.
    module : str
        Importable name (or ``.py`` path) of the module holding the compiled ``control``.
    params : type
        Its pydantic ``Params`` model.
    setup : callable
        ``setup(params, ctx) -> CompiledController``.
    summary : str
        One line for listings (the module docstring's first line).
    statuses : dict of int to str
        Messages of the controller's own status codes.
    commands : tuple of str
        What it can command, in order of preference: ``("tau",)``, ``("actuators",)`` or both
        (``("actuators", "tau")``: the actuators where the plant takes them, tau elsewhere).
    tracks : bool
        Whether it tracks the reference (comparisons and tracking studies take only these).
    plants : tuple of str or None
        The plant models it runs on (None: every plant that accepts its commands).
    sections : tuple of str
        Other scenario sections its ``setup`` reads.
    warnings : callable or None
        ``warnings(params) -> list[str]`` for ``auvtrack check``.
    aux_names : tuple of str
        Its logged channels.
    time_exponents : dict or None
        Gain -> its time dimension n (units s^-n; a callable gives it from the defaults) when the
        law's default gains can be designed for a vehicle (:mod:`auvtrack.control.design`).
    nominal_axis : callable or None
        ``nominal_axis(params, axis, e0) -> (f, x0)``: one axis of its nominal closed loop, for the design.
    """

    name: str
    module: str
    params: type[BaseModel]
    setup: Callable[..., CompiledController]
    summary: str = ""
    statuses: dict[int, str] = field(default_factory=dict)
    commands: tuple[str, ...] = ("tau",)
    tracks: bool = True
    plants: tuple[str, ...] | None = None
    sections: tuple[str, ...] = ()
    warnings: Callable[[Any], list[str]] | None = None
    aux_names: tuple[str, ...] = ()
    time_exponents: dict[str, Any] | None = None
    nominal_axis: Callable[..., Any] | None = None

    @property
    def has_saturation_forms(self) -> bool:
        """Whether its ``Params`` has a ``saturation`` field (published or compensated forms)."""
        return "saturation" in self.params.model_fields

    def runs_on(self, plant) -> bool:
        """Whether this controller can fly ``plant`` (a :class:`~auvtrack.plant.registry.PlantSpec`).

        Parameters
        ----------
        plant : PlantSpec
            A registered plant.

        Returns
        -------
        bool
            The plant accepts what the controller commands, and the controller allows the plant.
        """
        return self.command_on(plant) is not None and (self.plants is None or plant.name in self.plants)

    def command_on(self, plant) -> str | None:
        """What it commands on ``plant``: its first preference the plant accepts (None: none).

        Parameters
        ----------
        plant : PlantSpec
            A registered plant.

        Returns
        -------
        str or None
            ``"tau"`` or ``"actuators"``.
        """
        return next((c for c in self.commands if c in plant.accepts), None)

    @classmethod
    def from_module(cls, module: ModuleType) -> "ControllerSpec":
        """Build the record from a controller module (:func:`check_controller`).

        Parameters
        ----------
        module : module
            Defines every name of :data:`REQUIRED` and optionally the rest of the contract.

        Returns
        -------
        ControllerSpec
            The record.

        Raises
        ------
        ValueError
            One line naming the module and the missing or wrong piece.
        """
        return check_controller(module)


def channel_problem(names, taken) -> str:
    """Why a set of channel names cannot be logged next to ``taken`` (empty when it can).

    Parameters
    ----------
    names : sequence of str
        The new channels.
    taken : iterable of str
        Channels already in the log.

    Returns
    -------
    str
        The first problem: not a tuple of non-empty identifiers, too long, repeated, or clashing.
    """
    if not isinstance(names, (tuple, list)):
        return f"must be a tuple of channel names (got {type(names).__name__})"
    seen = set(taken) | set(RESERVED_CHANNELS)
    for n in names:
        if not isinstance(n, str) or not n.isidentifier():
            return f"channel names must be Python identifiers (got {n!r})"
        if len(n) > MAX_CHANNEL_NAME:
            return f"channel name {n[:20]!r}... is longer than {MAX_CHANNEL_NAME} characters"
        if n in seen:
            return f"channel name {n!r} is taken (a built-in channel or repeated)"
        seen.add(n)
    return ""


def _where(module: ModuleType) -> str:
    return getattr(module, "__file__", None) or module.__name__


def check_controller(module: ModuleType, *, plugin: bool = False) -> ControllerSpec:
    """Check a controller module against the contract and return its registration record.

    Parameters
    ----------
    module : module
        A built-in controller module or a plug-in.
    plugin : bool, optional
        A plug-in: ``NAME`` may be left out (``"plugin"``) and ``Params`` is its ``params`` table.

    Returns
    -------
    ControllerSpec
        The record, with the module's capabilities.

    Raises
    ------
    ValueError
        ``<file>: <what is missing or wrong>`` (see :mod:`auvtrack.control.contract`).
    """
    from numba.core.dispatcher import Dispatcher

    from ..channels import BASE_CHANNELS, CHI_CHANNELS

    where = _where(module)
    required = [n for n in REQUIRED if not (plugin and n == "NAME")]
    missing = [n for n in required if not hasattr(module, n)]
    if missing:
        raise ValueError(f"{where} does not define {', '.join(missing)} (a controller defines "
                         f"{', '.join(required)}; see docs/plugins.md)")
    name = getattr(module, "NAME", "plugin")
    if not (isinstance(name, str) and name.isidentifier()):
        raise ValueError(f"{where}: NAME must be an identifier string (got {name!r})")
    problem = channel_problem(module.AUX_NAMES, BASE_CHANNELS + CHI_CHANNELS)
    if problem:
        raise ValueError(f"{where}: AUX_NAMES: {problem}")
    if not (isinstance(module.Params, type) and issubclass(module.Params, BaseModel)):
        raise ValueError(f"{where}: Params must be a pydantic model class (got {module.Params!r})")
    if not plugin:
        kind = module.Params.model_fields.get("kind")
        if kind is None or kind.default != name:
            raise ValueError(f"{where}: Params needs a field kind = {name!r} (the scenario's controller.kind)")
    if not isinstance(module.control, Dispatcher):
        raise ValueError(f"{where}: control must be compiled (decorate it with @njit from auvtrack.control.plugin); "
                         f"got {type(module.control).__name__}")
    if not callable(module.setup) or len(inspect.signature(module.setup).parameters) != 2:
        raise ValueError(f"{where}: setup must be a function setup(params, ctx)")
    commands = getattr(module, "COMMANDS", "tau")
    commands = (commands,) if isinstance(commands, str) else commands
    if not (isinstance(commands, tuple) and commands and all(c in COMMAND_KINDS for c in commands)
            and len(set(commands)) == len(commands)):
        raise ValueError(f"{where}: COMMANDS must be one of {', '.join(COMMAND_KINDS)} or a tuple of them in order "
                         f"of preference (got {getattr(module, 'COMMANDS')!r})")
    tracks = getattr(module, "TRACKS", True)
    if not isinstance(tracks, bool):
        raise ValueError(f"{where}: TRACKS must be True or False (got {tracks!r})")
    plants = getattr(module, "PLANTS", None)
    if plants is not None and not (isinstance(plants, tuple) and all(isinstance(p, str) for p in plants)):
        raise ValueError(f"{where}: PLANTS must be a tuple of plant models or None (got {plants!r})")
    sections = getattr(module, "SECTIONS", ())
    if not (isinstance(sections, tuple) and all(isinstance(s, str) for s in sections)):
        raise ValueError(f"{where}: SECTIONS must be a tuple of section names (got {sections!r})")
    status = getattr(module, "STATUS", {})
    if not isinstance(status, Mapping) or not all(
            isinstance(k, int) and not isinstance(k, bool) and 10 <= k < 2 ** 31 and isinstance(v, str)
            for k, v in status.items()):
        raise ValueError(f"{where}: STATUS must map codes 10 .. 2**31 - 1 to messages (got {status!r})")
    warn = getattr(module, "warnings", None)
    if warn is not None and not callable(warn):
        raise ValueError(f"{where}: warnings must be a function warnings(params) -> list of str")
    exponents, nominal = _gain_design(module, where)
    doc = (module.__doc__ or "").strip()
    return ControllerSpec(name, module.__name__, module.Params, module.setup, doc.splitlines()[0] if doc else "",
                          {int(k): str(v) for k, v in status.items()}, commands, tracks, plants, sections, warn,
                          tuple(module.AUX_NAMES), exponents, nominal)


def _gain_design(module: ModuleType, where: str) -> tuple[dict | None, Callable | None]:
    """A module's gain-design declaration: ``TIME_EXPONENTS`` (gain -> number or callable) with ``nominal_axis``."""
    exponents = getattr(module, "TIME_EXPONENTS", None)
    nominal = getattr(module, "nominal_axis", None)
    if exponents is None and nominal is None:
        return None, None
    if exponents is None or not callable(nominal):
        raise ValueError(f"{where}: a law whose gains can be designed defines both TIME_EXPONENTS and "
                         f"nominal_axis(params, axis, e0) (docs/controllers.md, \"Gains designed for the vehicle\")")
    fields = module.Params.model_fields
    if not isinstance(exponents, Mapping) or not exponents:
        raise ValueError(f"{where}: TIME_EXPONENTS must map gain names to their time dimension (got {exponents!r})")
    for k, n in exponents.items():
        if k not in fields:
            raise ValueError(f"{where}: TIME_EXPONENTS.{k}: not a field of Params")
        if not (callable(n) or (isinstance(n, (int, float)) and not isinstance(n, bool) and math.isfinite(n))):
            raise ValueError(f"{where}: TIME_EXPONENTS.{k}: must be a finite number or a function of the "
                             f"defaults (got {n!r})")
    return dict(exponents), nominal


CONTROLLERS: dict[str, ControllerSpec] = {}


def register(spec: ControllerSpec | ModuleType) -> ControllerSpec:
    """Add a controller to :data:`CONTROLLERS`.

    Parameters
    ----------
    spec : ControllerSpec or module
        The registration record, or a controller module (checked by :func:`check_controller`);
        its name must be unused.

    Returns
    -------
    ControllerSpec
        The record.

    Raises
    ------
    ValueError
        If the name is already registered, or the module breaks the contract.
    """
    if isinstance(spec, ModuleType):
        spec = check_controller(spec)
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

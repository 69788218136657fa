"""Validated scenario model (pydantic v2): one frozen model per TOML section.

Every key has a default reproducing the paper's Section 4 (with the ERRATA corrections), so an
empty scenario *is* the paper scenario.  Every model forbids unknown keys.  Numbers are strict:
a quoted ``"0.1"`` is not a number and ``true`` is not 1.  See ``docs/scenarios.md`` for the
table of keys, units and ranges.
"""
from __future__ import annotations

import math
import typing
from typing import Annotated, Any, Literal, Mapping, Union

from pydantic import (BaseModel, ConfigDict, Field, field_validator,
                      model_validator)

from ..control import CONTROLLERS
from ..control import spec_for as controller_spec_for
from ..control import fxtntsmc
from ..control.gain_presets import available_gain_presets, get_gain_preset
from ..environment.current import MAX_SAMPLES as MAX_CURRENT_SAMPLES
from ..vehicle.presets import available, contributed, get_preset, is_reduced
from ..vehicle.reduction import U0_MAX, U0_MIN, default_u0
from ..plant import PLANTS, five_dof
from ..plant import spec_for as plant_spec_for
from ..fields import (Bool, Coefficient, Coefficient5, Fraction, Int, Mass5, NonNeg, NonNeg5, Num, Open01, Pos, Pos3,
                      PosOrInf3, Range2, Str, Vec5, inf_words)
from ..vehicle.vehicle_file import is_vehicle_ref, resolve_path
from ..reference import build_reference
from .components import check_disturbances, check_reference, jsonable
from .designed import designed_controller
from .errors import format_value
from .names import check_name

__all__ = [
    "CONTROLLER_MODELS", "ControllerParams", "Scenario", "SimSection", "VehicleSection",
    "UncertaintySection", "InitialSection", "EnvelopeSection", "EstimatorSection",
    "MetricsSection", "OutputSection", "ActuatorSection", "SensorSection", "LimitsSection", "PlantSection",
]

# Controllers selectable by ``[controller] kind``: the parameter model of every registered controller.
CONTROLLER_MODELS: tuple[type[BaseModel], ...] = tuple(spec.params for spec in CONTROLLERS.values())
ControllerParams = Annotated[Union[CONTROLLER_MODELS], Field(discriminator="kind")]  # type: ignore[valid-type]
DEFAULT_CONTROLLER = "fxtntsmc"
_CONTROLLER_BY_KIND = {m.model_fields["kind"].default: m for m in CONTROLLER_MODELS}

MULTIPLE_RTOL = 1e-9
# Beyond 2**53 steps the step times k*dt are no longer exact; the run plan refuses such a grid
# long before (limits.max_steps <= 2**53), so the grid rules below leave it to the plan's message.
MAX_EXACT_STEPS = 2 ** 53


def is_multiple(value: float, step: float) -> bool:
    """True when ``value`` is a positive integer multiple of ``step`` within 1e-9 relative."""
    q = value / step
    if not math.isfinite(q):
        return False
    n = round(q)
    return n >= 1 and abs(n * step - value) <= MULTIPLE_RTOL * value


def _steps_beyond_exact(value: float, step: float) -> bool:
    """True when ``value / step`` is too large to be a step count (the plan refuses it)."""
    q = value / step
    return not math.isfinite(q) or q > MAX_EXACT_STEPS


class _Section(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


def _broadcast3(value: Any) -> Any:
    """A scalar number becomes three equal numbers; anything else is left to validation."""
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return (value, value, value)
    return value


class SimSection(_Section):
    """``[sim]``: time grid, control sampling and divergence guards.

    The grid rules: ``dt <= duration``; ``duration``, ``log_dt`` and ``1/control_rate`` are
    integer multiples of ``dt``; ``log_dt`` divides ``duration`` (the log always ends with the
    final state, t = duration); ``1/control_rate <= duration``.  Step counts are bounded by the
    run plan (:mod:`auvtrack.scenario.plan`, ``[limits]``).
    """

    duration: Pos = Field(100.0, description="simulated time, s")
    dt: Annotated[Num, Field(gt=0, le=0.1)] = Field(0.001, description="RK4 step, s")
    log_dt: Pos = Field(0.01, description="logging interval, s (integer multiple of dt, divides duration)")
    control_rate: NonNeg = Field(0.0, description="Hz; 0 = continuous (every RK4 stage)")
    theta_limit: Annotated[Num, Field(gt=0, lt=90)] = Field(85.0, description="|pitch| stop, deg")
    phi_limit: Annotated[Num, Field(gt=0, le=180)] = Field(  # 6-DOF truth plants
        85.0, description="|roll| stop, deg (6-DOF plants; the 5-DOF plant has no roll)")
    state_limit: Pos = Field(1e6, description="abs bound on every state before divergence")
    integrator: Literal["rk4"] = "rk4"

    @model_validator(mode="after")
    def _grid(self) -> "SimSection":
        if self.dt > self.duration:
            raise ValueError(f"dt: must be <= duration = {self.duration:g} s (got {self.dt:g})")
        if _steps_beyond_exact(self.duration, self.dt):
            return self  # far too many steps: the run plan refuses it, naming limits.max_steps
        if not is_multiple(self.duration, self.dt):
            raise ValueError(f"duration: must be an integer multiple of dt = {self.dt:g} s (got {self.duration:g})")
        if self.log_dt < self.dt:
            raise ValueError(f"log_dt: must be >= dt = {self.dt:g} s (got {self.log_dt:g})")
        if self.log_dt > self.duration:
            raise ValueError(f"log_dt: must be <= duration = {self.duration:g} s, so that the log holds the "
                             f"final state (got {self.log_dt:g})")
        if not is_multiple(self.log_dt, self.dt):
            raise ValueError(f"log_dt: must be an integer multiple of dt = {self.dt:g} s (got {self.log_dt:g})")
        if self.n_steps % self.log_every != 0:
            raise ValueError(f"log_dt: must divide duration = {self.duration:g} s into whole logging intervals, "
                             f"so that the log ends with the final state (got {self.log_dt:g})")
        if self.control_rate > 0:
            period = 1.0 / self.control_rate
            if not math.isfinite(period) or period > self.duration:
                raise ValueError(f"control_rate: must be >= 1/duration = {1.0 / self.duration:g} Hz, at least "
                                 f"two control samples per run (got {self.control_rate:g} Hz)")
            if not is_multiple(period, self.dt):
                raise ValueError(f"control_rate: 1/control_rate must be an integer multiple of dt = {self.dt:g} s "
                                 f"(got {self.control_rate:g} Hz, period {period:g} s)")
        return self

    @property
    def n_steps(self) -> int:
        """Number of RK4 steps."""
        return round(self.duration / self.dt)

    @property
    def log_every(self) -> int:
        """Steps between two logged rows."""
        return round(self.log_dt / self.dt)

    @property
    def control_every(self) -> int:
        """Steps between two controller updates (0 = continuous)."""
        return 0 if self.control_rate == 0 else round(1.0 / self.control_rate / self.dt)


_VEHICLE_FIELDS = ("m", "d", "wgml", "l")


class VehicleSection(_Section):
    """``[vehicle]``: a preset and optional overrides of its numbers.

    After validation ``m``, ``d``, ``wgml`` and ``l`` always hold the *effective* numbers
    (preset values filled in where no override is given); :meth:`resolve` reports each
    number's source.
    """

    preset: Str = Field("paper", description="one of auvtrack.vehicle.presets.available(), a shipped Fossen-type "
                                             "torpedo (remus100_fossen, remus600) or a vehicle file (.toml)")
    m: Mass5 | None = Field(None, description="m11, m22, m33 (kg), m44, m55 (kg m^2)")
    d: Coefficient5 | None = Field(None, description="d11, d22, d33 (N s/m), d44, d55 (N m s/rad)")
    wgml: Coefficient | None = Field(None, description="rho g nabla GM_L, N m")
    l: Annotated[Num, Field(gt=0, le=10)] | None = Field(  # noqa: E741 - paper's symbol
        None, description="virtual-point offset ell, m (ell = 0 makes J3 singular)")
    u0: Annotated[Num, Field(ge=U0_MIN, le=U0_MAX)] | None = Field(
        None, description="linearisation speed of a reduced preset (remus100), m/s; default: the "
                          "mean speed of the scenario's reference")

    @model_validator(mode="before")
    @classmethod
    def _fill_from_preset(cls, data: Any) -> Any:
        if not isinstance(data, Mapping):
            return data  # pydantic reports "must be a table"
        name = data.get("preset", "paper")
        if not isinstance(name, str):
            raise ValueError(f"preset: must be a string (got {format_value(name)})")
        names = available()
        if is_vehicle_ref(name):  # a vehicle file: relative to the working directory (a scenario
            name = resolve_path(name)  # file's own paths are made relative to it by the loader)
        elif name not in names and name not in contributed():
            raise ValueError(f"preset: unknown preset (allowed: {', '.join((*names, *contributed()))} "
                             f"or a vehicle file .toml) (got {name!r})")
        u0 = data.get("u0")
        if u0 is not None and not is_reduced(name):
            raise ValueError(f"u0: only a reduced preset ({', '.join(n for n in names if is_reduced(n))}) "
                             f"has a linearisation speed; {name!r} has none (got {format_value(u0)})")
        try:
            pre = get_preset(name, u0=u0 if isinstance(u0, (int, float)) and U0_MIN <= u0 <= U0_MAX else None)
        except ValueError as exc:
            if str(exc).startswith("vehicle.u0:"):
                raise ValueError(str(exc).removeprefix("vehicle.")) from None
            raise ValueError(f"preset: {exc}") from None
        out = dict(data)
        out["preset"] = name
        for key in _VEHICLE_FIELDS:
            if out.get(key) is None:
                out[key] = getattr(pre, key)
        return out

    def resolve(self) -> dict[str, Any]:
        """Effective vehicle numbers with the unit and source of each.

        Returns
        -------
        dict
            ``preset``, ``description``, ``m``, ``d``, ``wgml``, ``l`` and ``sources``:
            per number ``{"unit", "source", "origin"}`` with ``origin`` ``"preset"`` or
            ``"scenario"`` (an override differing from the preset value).
        """
        pre = get_preset(self.preset, u0=self.u0)  # a reduced preset at u0
        out: dict[str, Any] = {"preset": pre.name, "description": pre.description}
        if pre.u0 is not None:
            out["u0"] = pre.u0
        sources: dict[str, dict[str, str]] = {}
        for key in _VEHICLE_FIELDS:
            value, preset_value = getattr(self, key), getattr(pre, key)
            from_preset = value == preset_value
            out[key] = list(value) if isinstance(value, tuple) else value
            sources[key] = {
                "unit": pre.sources[key]["unit"],
                "source": pre.sources[key]["source"] if from_preset
                else f"scenario override (preset {pre.name!r} has {format_value(preset_value)})",
                "origin": "preset" if from_preset else "scenario",
            }
        out["sources"] = sources
        return out


class UncertaintySection(_Section):
    """``[uncertainty]``: fractional errors of the TRUE plant w.r.t. the controller's nominal model."""

    C: Fraction = Field(0.1, description="Delta C / C0 (Section 4: 10 %)")
    D: Fraction = Field(0.1, description="Delta D / D0 (Section 4: 10 %)")
    M: Fraction = Field(0.0, description="Delta M / M")
    G: Fraction = Field(0.0, description="Delta wgml / wgml")


# bounds of the initial state, per item: (lo, hi, open interval?, unit)
ETA0_BOUNDS = ((-1e6, 1e6, False, "m"), (-1e6, 1e6, False, "m"), (-1e6, 1e6, False, "m"),
               (-math.pi / 2, math.pi / 2, True, "rad"), (-1e3, 1e3, False, "rad"))
NU0_BOUNDS = ((-100.0, 100.0, False, "m/s"),) * 3 + ((-10.0, 10.0, False, "rad/s"),) * 2


def _check_items(values: tuple[float, ...], bounds) -> tuple[float, ...]:
    for i, (x, (lo, hi, is_open, unit)) in enumerate(zip(values, bounds)):
        inside = lo < x < hi if is_open else lo <= x <= hi
        if not inside:
            a, b = ("(", ")") if is_open else ("[", "]")
            raise ValueError(f"{i}: must be in {a}{lo:g}, {hi:g}{b} {unit} (got {format_value(x)})")
    return values


class InitialSection(_Section):
    """``[initial]``: initial state eta(0) = [x, y, z, theta, psi], nu(0) = [u, v, w, q, r].

    Each item has a physically meaningful range (:data:`ETA0_BOUNDS`, :data:`NU0_BOUNDS`);
    ``|theta(0)|`` must also be below ``sim.theta_limit``.
    """

    eta: Vec5 = Field((0.0, 0.5, 0.0, 0.0, 0.0), description="m, m, m, rad, rad")
    nu: Vec5 = Field((0.0, 0.0, 0.0, 0.0, 0.0), description="m/s, m/s, m/s, rad/s, rad/s")
    # roll and roll rate of a 6-DOF truth plant (0 for the 5-DOF plant)
    phi: Annotated[Num, Field(gt=-math.pi / 2, lt=math.pi / 2)] = Field(0.0, description="roll, rad (6-DOF plants)")
    p: Annotated[Num, Field(ge=-10.0, le=10.0)] = Field(0.0, description="roll rate, rad/s (6-DOF plants)")

    @field_validator("eta")
    @classmethod
    def _eta(cls, eta: tuple[float, ...]) -> tuple[float, ...]:
        return _check_items(eta, ETA0_BOUNDS)

    @field_validator("nu")
    @classmethod
    def _nu(cls, nu: tuple[float, ...]) -> tuple[float, ...]:
        return _check_items(nu, NU0_BOUNDS)


class ActuatorSection(_Section):
    """``[actuator]``: input limits; ``inf`` = ideal actuator (the paper's assumption)."""

    tau_max: PosOrInf3 = Field((math.inf, math.inf, math.inf), description="|tau_u| (N), |tau_q|, |tau_r| (N m)")
    rate_max: PosOrInf3 = Field((math.inf, math.inf, math.inf),
                                description="slew rate, N/s, N m/s (needs sim.control_rate > 0)")

    @field_validator("tau_max", "rate_max", mode="before")
    @classmethod
    def _words(cls, v: Any) -> Any:
        return inf_words(_broadcast3(v))


class SensorSection(_Section):
    """``[sensor]``: white measurement noise seen by the controller (needs sim.control_rate > 0)."""

    sigma_eta: NonNeg5 = Field((0.0,) * 5, description="std of x, y, z (m), theta, psi (rad)")
    sigma_nu: NonNeg5 = Field((0.0,) * 5, description="std of u, v, w (m/s), q, r (rad/s)")


# Plants selectable by ``[plant] model``: the section model of every registered plant.
PLANT_MODELS: tuple[type[BaseModel], ...] = tuple(spec.section for spec in PLANTS.values())
PlantSection = Annotated[Union[PLANT_MODELS], Field(discriminator="model")]  # type: ignore[valid-type]


class EnvelopeSection(_Section):
    """``[envelope]``: prescribed-performance envelope of the fxtntsmc (eq. 20-25, ERRATA 7-10)."""

    kind: Literal["none", "rigid", "reactive", "proactive"] = "proactive"
    rho0: Pos3 = Field((5.0, 0.5, 0.2), description="initial baseline envelope, m")
    rho_inf: Pos3 = Field((0.005, 0.005, 0.005), description="steady-state envelope, m")
    T: Pos = Field(15.0, description="baseline settling time, s")
    delta: Pos = Field(2.0, description="risk-monitor gain of eq. (21)")
    epsilon: Pos = Field(0.1, description="transition width of gamma in eq. (22)")
    lambda1: Pos = Field(0.5, description="adjustment decay rate, 1/s")
    lambda2: Pos = Field(0.3, description="adjustment growth gain, m/s")
    lambda3: Pos = Field(0.1, description="tanh scale of eq. (25)")
    xi0: Open01 = Field(0.9, description="target |e/rho| at t = 0 after widening")
    widen_start: Bool = Field(True, description="widen the envelope at a start on/outside it")
    reactive_threshold: Open01 = Field(0.8, description="|xi| at which 'reactive' acts fully")
    baseline: Literal["corrected", "printed"] = "corrected"

    @field_validator("rho0", "rho_inf", mode="before")
    @classmethod
    def _broadcast(cls, v: Any) -> Any:
        return _broadcast3(v)

    @model_validator(mode="after")
    def _ordered(self) -> "EnvelopeSection":
        for i, (r0, ri) in enumerate(zip(self.rho0, self.rho_inf)):
            if not ri < r0:
                raise ValueError(f"rho_inf.{i}: must be < rho0.{i} = {r0:g} (got {ri:g})")
        return self


class EstimatorSection(_Section):
    """``[estimator]``: RBF network estimating the lumped disturbance (eq. 11-13, 33-34)."""

    kind: Literal["none", "printed", "omega", "effective"] = "effective"
    # the engine's upper limit (scratch size) is checked by auvtrack.control.fxtntsmc.setup
    neurons: Annotated[Int, Field(ge=1)] = 7
    width: Pos = Field(1.0, description="Gaussian width b")
    centre_range: Range2 = Field((-1.0, 1.0), description="centres drawn uniformly in [lo, hi]")
    weight_range: Range2 = Field((0.0, 1.0), description="initial weights uniform in [lo, hi]")

    @field_validator("centre_range")
    @classmethod
    def _centre(cls, v: tuple[float, float]) -> tuple[float, float]:
        if not v[0] < v[1]:
            raise ValueError(f"must satisfy lo < hi (got {format_value(v)})")
        return v

    @field_validator("weight_range")
    @classmethod
    def _weight(cls, v: tuple[float, float]) -> tuple[float, float]:
        if not v[0] <= v[1]:
            raise ValueError(f"must satisfy lo <= hi (got {format_value(v)})")
        return v


def _window(value: Any) -> tuple[float, float]:
    """Parse ``[t0]``, ``[t0, t1]`` with t1 a number, ``inf``, ``"inf"`` or null (= inf)."""
    if not isinstance(value, (list, tuple)):
        raise ValueError(f"must be an array [t0, t1] (got {format_value(value)})")
    if not 1 <= len(value) <= 2:
        raise ValueError(f"must have 1 or 2 items [t0, t1] (got {len(value)})")
    items = list(value) + [math.inf] * (2 - len(value))
    if items[1] is None or (isinstance(items[1], str) and items[1].strip().lower() in ("inf", "+inf")):
        items[1] = math.inf
    for i, x in enumerate(items):
        if isinstance(x, bool) or not isinstance(x, (int, float)) or math.isnan(x):
            raise ValueError(f"{i}: must be a number (got {format_value(x)})")
    t0, t1 = float(items[0]), float(items[1])
    if not (math.isfinite(t0) and t0 >= 0):
        raise ValueError(f"0: must be a finite number >= 0 (got {format_value(t0)})")
    if not t1 > t0:
        raise ValueError(f"1: must be > t0 = {t0:g} (got {format_value(t1)})")
    return t0, t1


class MetricsSection(_Section):
    """``[metrics]``: time window [t0, t1] (s) over which the metrics are computed; the path-following metrics on or off."""

    window: tuple[float, float] = Field((0.0, math.inf), description="s; t1 may be inf")
    path: Bool = Field(True, description="compute the path-following metrics (a projection on the path at "
                                         "every step); false: skip them (NaN), for speed")

    @field_validator("window", mode="before")
    @classmethod
    def _parse(cls, v: Any) -> tuple[float, float]:
        return _window(v)


class OutputSection(_Section):
    """``[output]``: optional extra outputs."""

    mat: Bool = Field(False, description="also write trajectory.mat")


class LimitsSection(_Section):
    """``[limits]``: the largest run the plan accepts (:mod:`auvtrack.scenario.plan`).

    The defaults keep a run to minutes and a couple of GiB; raise them deliberately, e.g.
    ``--set limits.max_steps=1_000_000_000``.  Each limit has a hard ceiling of its own.
    """

    max_steps: Annotated[Int, Field(ge=1, le=MAX_EXACT_STEPS)] = Field(
        100_000_000, description="RK4 steps (sim.duration / sim.dt)")
    max_log_rows: Annotated[Int, Field(ge=1, le=2 ** 40)] = Field(
        10_000_000, description="logged rows (sim.duration / sim.log_dt + 1)")
    max_table_rows: Annotated[Int, Field(ge=1, le=MAX_CURRENT_SAMPLES)] = Field(
        20_000_000, description="rows of one noise or current table")
    max_memory_mb: Annotated[Int, Field(ge=1, le=2 ** 30)] = Field(
        2048, description="estimated peak memory of the run's arrays, MiB")


def _check_numbers(model: type[BaseModel], data: dict) -> None:
    """Refuse strings/booleans/non-finite values where ``model`` expects numbers.

    The controller parameter models are lax (they would read ``"0.5"`` as 0.5); scenario
    files are held to the same strictness as the other sections.
    """
    for name, value in data.items():
        field = model.model_fields.get(name)
        if field is None or name == "kind":
            continue
        ann = field.annotation
        if typing.get_origin(ann) is tuple:
            if isinstance(value, (list, tuple)):
                for i, item in enumerate(value):
                    _check_number(f"{name}.{i}", item)
        elif ann in (float, int):
            _check_number(name, value)


def _check_number(path: str, value: Any) -> None:
    if isinstance(value, (str, bool)):
        raise ValueError(f"{path}: must be a number (got {format_value(value)})")
    if isinstance(value, float) and not math.isfinite(value):
        raise ValueError(f"{path}: must be a finite number (got {format_value(value)})")


def _with_u0(data: Mapping) -> Mapping:
    """``data`` with ``vehicle.u0`` of a reduced preset filled with the mean speed of the reference."""
    veh = data.get("vehicle", {})
    if not isinstance(veh, Mapping) or veh.get("u0") is not None:
        return data
    name = veh.get("preset", "paper")
    if not isinstance(name, str) or not is_reduced(name):
        return data
    try:  # an invalid reference or duration is reported by its own validator
        ref = build_reference(check_reference(data.get("reference", {"kind": "helix"})))
        sim = data.get("sim", {})
        duration = float(sim.get("duration", SimSection.model_fields["duration"].default))
    except (ValueError, TypeError, AttributeError):
        return data
    return {**data, "vehicle": {**veh, "u0": default_u0(ref, duration)}}


def _apply_gain_preset(v: dict) -> dict:
    """Expand ``[controller] preset`` into the preset's gains (explicit keys win).

    The ``preset`` key is consumed here: the validated (and resolved) scenario holds every
    gain explicitly.  ``kind`` defaults to the preset's kind.
    """
    if "preset" not in v:
        return v
    name = v.pop("preset")
    if not isinstance(name, str):
        raise ValueError(f"preset: must be a string (got {format_value(name)})")
    names = available_gain_presets()
    if name not in names:
        raise ValueError(f"preset: unknown gain preset (allowed: {', '.join(names) or 'none'}) (got {name!r})")
    pre = get_gain_preset(name)
    kind = v.get("kind", pre.kind)
    if kind != pre.kind:
        raise ValueError(f"preset: gain preset {name!r} is for kind {pre.kind!r} (got kind {format_value(kind)})")
    return {**pre.gains, **v, "kind": kind}


class Scenario(BaseModel):
    """A complete, validated simulation scenario (frozen).

    Build one with :func:`auvtrack.scenario.load_scenario`; ``Scenario()`` is the paper's
    Section 4.  :meth:`to_dict` gives the fully resolved, JSON-serialisable form, and
    ``load_scenario(s.to_dict()) == s``.

    Attributes
    ----------
    name, description : str
        Run name (folder ``runs/<name>``) and free text.
    seed : int
        Seed of every random stream.
    sim, vehicle, uncertainty, initial, envelope, estimator, metrics, output, actuator, sensor, limits : section models
        The TOML sections of the same names.
    reference : dict
        Resolved reference spec (``kind`` and every field of that kind).
    controller : pydantic model
        Controller parameters, selected by ``kind``.
    disturbance : list of dict
        Resolved disturbance specs (summed); empty for none.
    """

    model_config = ConfigDict(extra="forbid", frozen=True)

    name: Str = Field("paper", description="run name (folder runs/<name>)")
    description: Str = ""
    seed: Annotated[Int, Field(ge=0, le=2 ** 63 - 1)] = Field(0, description="seed of every random stream")
    sim: SimSection = Field(default_factory=SimSection)
    vehicle: VehicleSection = Field(default_factory=VehicleSection)
    uncertainty: UncertaintySection = Field(default_factory=UncertaintySection)
    reference: dict[str, Any] = Field(default_factory=lambda: {"kind": "helix"}, validate_default=True)
    initial: InitialSection = Field(default_factory=InitialSection)
    controller: ControllerParams = Field(default_factory=fxtntsmc.Params)
    envelope: EnvelopeSection = Field(default_factory=EnvelopeSection)
    estimator: EstimatorSection = Field(default_factory=EstimatorSection)
    disturbance: list[dict[str, Any]] = Field(default_factory=lambda: [{"kind": "paper"}],
                                              validate_default=True)
    metrics: MetricsSection = Field(default_factory=MetricsSection)
    output: OutputSection = Field(default_factory=OutputSection)
    actuator: ActuatorSection = Field(default_factory=ActuatorSection)
    sensor: SensorSection = Field(default_factory=SensorSection)
    limits: LimitsSection = Field(default_factory=LimitsSection)
    plant: PlantSection = Field(default_factory=five_dof.Section)

    @model_validator(mode="before")
    @classmethod
    def _reduction_speed(cls, data: Any) -> Any:
        """Fill ``vehicle.u0`` of a reduced preset with the mean speed of the reference; then the
        controller's gains designed for the vehicle (:mod:`auvtrack.scenario.designed`)."""
        if not isinstance(data, Mapping):
            return data
        return designed_controller(_with_u0(data), DEFAULT_CONTROLLER)

    @field_validator("name")
    @classmethod
    def _name(cls, v: str) -> str:
        return check_name(v)

    @field_validator("description")
    @classmethod
    def _text(cls, v: str) -> str:
        try:
            v.encode("utf-8")
        except UnicodeEncodeError:
            raise ValueError("must be valid Unicode text (it holds a lone surrogate)") from None
        return v

    @field_validator("reference", mode="before")
    @classmethod
    def _reference(cls, v: Any) -> dict:
        return check_reference(v)

    @field_validator("disturbance", mode="before")
    @classmethod
    def _disturbance(cls, v: Any) -> list:
        return check_disturbances(v)

    @field_validator("plant", mode="before")
    @classmethod
    def _plant(cls, v: Any) -> Any:
        if isinstance(v, Mapping) and "model" not in v:
            return {**v, "model": five_dof.NAME}
        return v

    @field_validator("controller", mode="before")
    @classmethod
    def _controller(cls, v: Any) -> Any:
        if isinstance(v, Mapping):
            v = _apply_gain_preset(dict(v))
            v.setdefault("kind", DEFAULT_CONTROLLER)
            if not isinstance(v["kind"], str):
                raise ValueError(f"kind: must be a string (got {format_value(v['kind'])})")
            model = _CONTROLLER_BY_KIND.get(v["kind"])
            if model is not None:
                _check_numbers(model, v)
        return v

    @model_validator(mode="after")
    def _plant_and_controller(self) -> "Scenario":
        """The controller can fly the plant (what it commands), and the plant's own cross-checks."""
        plant, ctrl = plant_spec_for(self.plant), controller_spec_for(self.controller)
        if not ctrl.runs_on(plant):
            which = ("commands " + " or ".join("the actuators" if c == "actuators" else c for c in ctrl.commands)
                     if ctrl.command_on(plant) is None else f"runs on plant.model in {list(ctrl.plants or ())}")
            raise ValueError(f"controller.kind: {self.controller.kind} {which}; plant.model {self.plant.model!r} "
                             f"accepts {' or '.join(plant.accepts)} (choose another plant.model or controller)")
        if plant.check_scenario is not None:
            plant.check_scenario(self)
        return self


    @model_validator(mode="after")
    def _start_inside_limits(self) -> "Scenario":
        """A start beyond the pitch or the roll limit would stop the run at t = 0."""
        theta, lim = self.initial.eta[3], self.sim.theta_limit
        if not abs(theta) < math.radians(lim):
            raise ValueError(f"initial.eta.3: abs(theta) must be < sim.theta_limit = {lim:g} deg "
                             f"= {math.radians(lim):.6g} rad (got {format_value(theta)})")
        phi, lim = self.initial.phi, self.sim.phi_limit
        if not abs(phi) < math.radians(lim):
            raise ValueError(f"initial.phi: abs(phi) must be < sim.phi_limit = {lim:g} deg "
                             f"= {math.radians(lim):.6g} rad (got {format_value(phi)})")
        return self

    @model_validator(mode="after")
    def _sampled_only(self) -> "Scenario":
        """Rate limits and sensor noise act between control samples: they need a control rate."""
        if self.sim.control_rate == 0:
            if any(math.isfinite(r) for r in self.actuator.rate_max):
                raise ValueError("actuator.rate_max: a finite rate limit needs sim.control_rate > 0 (it acts "
                                 f"between control samples) (got {format_value(self.actuator.rate_max)})")
            if any(s > 0 for s in (*self.sensor.sigma_eta, *self.sensor.sigma_nu)):
                raise ValueError("sensor: noise needs sim.control_rate > 0 (one draw per control sample) "
                                 f"(got sigma_eta {format_value(self.sensor.sigma_eta)}, "
                                 f"sigma_nu {format_value(self.sensor.sigma_nu)})")
        return self

    def to_dict(self) -> dict[str, Any]:
        """Fully resolved, JSON-serialisable scenario.

        Every default is filled, the vehicle numbers are the effective ones, tuples become
        lists and an infinite value (``metrics.window[1]``) is written as the string ``"inf"``.
        ``load_scenario(s.to_dict()) == s``.
        """
        out = jsonable(self.model_dump(mode="python"))
        if out["vehicle"].get("u0") is None:  # only a reduced preset has a u0
            out["vehicle"].pop("u0", None)
        out["plant"] = {k: v for k, v in out["plant"].items() if v is not None}  # unset overrides
        return out

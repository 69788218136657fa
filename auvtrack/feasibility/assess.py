"""Is a scenario's reference within its plant's reach?  Trim, surge and tightest turn against the limits.

:func:`assess` compares what the reference asks (:mod:`auvtrack.feasibility.demands`:
speed, depth rate and curvature through the water in the current's worst case) with the
steady states of the plant the scenario flies (:mod:`~auvtrack.feasibility.steady6` for a
6-DOF truth, :mod:`~auvtrack.feasibility.steady5` for the 5-DOF plant):

* **trim**: steady straight flight at each extreme water speed and depth rate of the reference
  (fins, pitch and roll against their limits);
* **surge**: the propeller speed (6-DOF) or tau_u (5-DOF) of that straight flight, highest at
  the top speed through the water;
* **turn**: per side, the demanded water-relative curvature against the tightest steady turn at
  that water speed and depth rate (:func:`~auvtrack.feasibility.steady.tightest_turn`); the
  capability is computed on a grid of water speeds and interpolated to find the most demanding
  point, which is then solved exactly.

Each check's *usage* is required / available (a radius: tightest / demanded); its status is
``"infeasible"`` above 1, ``"marginal"`` above :data:`MARGINAL_FRACTION` (80 % of a limit) and
``"feasible"`` otherwise; the verdict is the worst status.  Speeds through the water below
:data:`MIN_SPEED` are assessed at it (at rest the fins have no authority at all).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping, Sequence

import numpy as np

from .demands import CURRENT_SIGMAS, CurrentBound, WaterPoints, current_bound, reference_demands, water_points
from .steady import KAPPA_CAP, SteadyModel, tightest_turn

MARGINAL_FRACTION = 0.8   # a check using more than this fraction of its limit is "marginal"
MIN_SPEED = 0.05          # m/s: lowest speed through the water assessed
TURN_EPS = 1e-6           # 1/m: curvature below it is straight flight (radius 1000 km)
SPEED_GRID = 5            # water speeds at which the tightest turn is computed before interpolation
STATUSES = ("feasible", "marginal", "infeasible")
STEADY_MODELS = ("5dof", "6dof")
"""The plants whose steady states :func:`steady_model` solves."""


def status_of(usage: float, marginal: float = MARGINAL_FRACTION) -> str:
    """Status of a check from its usage (required / available).

    Parameters
    ----------
    usage : float
        Fraction of the limit used (NaN counts as infeasible).
    marginal : float
        Fraction above which a check is marginal.

    Returns
    -------
    str
        ``"infeasible"`` (usage > 1 or NaN), ``"marginal"`` (usage > marginal) or ``"feasible"``.
    """
    if not usage <= 1.0:
        return "infeasible"
    return "marginal" if usage > marginal else "feasible"


@dataclass(frozen=True)
class Check:
    """One requirement against one limit.

    Attributes
    ----------
    name : str
        What is checked (``"stern plane, straight"``, ``"turn to starboard"``).
    required, available : float
        The demand and the limit in ``unit`` (for a turn: the demanded and the tightest radius).
    unit : str
        ``"deg"``, ``"rpm"``, ``"N"``, ``"N m"`` or ``"m"``.
    usage : float
        required / available (a turn: available / required, the curvature ratio).
    limit : str
        The scenario key of the limit that binds (``"plant.delta_max"``), or what prevents a
        steady state.
    condition : str
        Where the demand is largest (speed through the water, depth rate, current).
    marginal : float
        Fraction above which the check is marginal.
    """

    name: str
    required: float
    available: float
    unit: str
    usage: float
    limit: str
    condition: str
    marginal: float = MARGINAL_FRACTION

    @property
    def status(self) -> str:
        """``"feasible"``, ``"marginal"`` or ``"infeasible"`` (:func:`status_of`)."""
        return status_of(self.usage, self.marginal)

    @property
    def margin(self) -> float:
        """Fraction of the limit left, 1 - usage (negative when infeasible)."""
        return 1.0 - self.usage

    def describe(self) -> str:
        """The check in one phrase: demand, limit, usage, the binding key and where."""
        use = "unbounded" if not math.isfinite(self.usage) else f"{self.usage:.0%}"
        if self.unit == "m" and math.isinf(self.available):
            head = f"radius {_num(self.required)} m demanded, no steady flight within the limits at this speed"
        elif self.unit == "m":
            head = f"radius {_num(self.required)} m demanded, tightest {_num(self.available)} m"
        elif math.isnan(self.required):
            head = "no steady state found"
        else:
            head = f"{_num(self.required)} of {_num(self.available)} {self.unit}"
        return f"{self.name}: {head} ({use}, {self.limit}) at {self.condition}"


def _num(x: float) -> str:
    """A number for reports: 3 significant digits, whole numbers from 1000 on, 0 below 5e-4."""
    if not math.isfinite(x):
        return "inf" if x > 0 else str(x)
    if abs(x) >= 1000.0:
        return f"{x:.0f}"
    return "0" if abs(x) < 5e-4 else f"{x:.3g}"


@dataclass(frozen=True)
class Feasibility:
    """The assessment of one scenario.

    Attributes
    ----------
    scenario : str
        Scenario name.
    plant : str
        The plant assessed.
    verdict : str
        ``"feasible"``, ``"marginal"`` or ``"infeasible"``: the worst check's status; ``"unassessed"``
        for a plant whose steady states are not modelled here (a plug-in plant).
    checks : tuple of Check
        Every check (trim, surge, turns).
    reference : str
        What the reference asks over ground.
    current : CurrentBound
        The current's worst case used.
    marginal : float
        Fraction above which a check is marginal.
    notes : tuple of str
        What was not checked, and why.
    """

    scenario: str
    plant: str
    verdict: str
    checks: tuple
    reference: str
    current: CurrentBound
    marginal: float = MARGINAL_FRACTION
    notes: tuple = ()

    def worst(self) -> Check | None:
        """The most demanding check: worst status, then a finite usage (a cause before its consequence), then usage.

        Returns
        -------
        Check or None
            None without checks.
        """
        def key(c):
            return STATUSES.index(c.status), math.isfinite(c.usage), c.usage if math.isfinite(c.usage) else 0.0
        return max(self.checks, key=key, default=None)

    def summary(self) -> str:
        """A few lines: verdict, what the reference asks, one line per check.

        Returns
        -------
        str
            The report (no trailing newline).
        """
        lines = [f"feasibility: {self.verdict} ({self.plant})",
                 f"  reference: {self.reference}; current worst case: {self.current.describe()}"]
        lines += [f"  {c.status:<10} {c.describe()}" for c in self.checks]
        lines += [f"  note: {n}" for n in self.notes]
        lines.append(f"  (marginal: more than {self.marginal:.0%} of a limit; steady states of the plant's own "
                     f"equations, docs/vehicles.md#feasibility)")
        return "\n".join(lines)

    @property
    def flyable(self) -> bool:
        """True when every check is inside its limit (feasible or marginal)."""
        return self.verdict in ("feasible", "marginal")

    def warning(self) -> str | None:
        """One line for a marginal or infeasible verdict (None when feasible or unassessed).

        Returns
        -------
        str or None
            The verdict and the most demanding check.
        """
        if self.verdict in ("feasible", "unassessed"):
            return None
        w = self.worst()
        tail = ("tracking errors on this task measure the vehicle, not the controller"
                if self.verdict == "infeasible" else "little margin is left for control")
        return f"feasibility: {self.verdict}: {w.describe()}; {tail} (auvtrack check for every check)"


def steady_model(sc) -> SteadyModel:
    """The steady-state model of a scenario's plant (true vehicle and limits).

    Parameters
    ----------
    sc : auvtrack.scenario.Scenario
        Validated scenario.

    Returns
    -------
    SteadyModel
        :class:`~auvtrack.feasibility.steady6.Steady6` for ``plant.model = "6dof"``,
        else :class:`~auvtrack.feasibility.steady5.Steady5` of the true 5-DOF vehicle.
    """
    if sc.plant.model == "6dof":
        from .steady6 import Steady6
        return Steady6(sc.plant.preset, sc.plant.actuator_overrides(), sc.sim.theta_limit, sc.sim.phi_limit)
    from ..vehicle.presets import vehicle_arrays
    from .steady5 import Steady5
    _, vp_true, _ = vehicle_arrays(sc)
    return Steady5(vp_true, sc.actuator.tau_max, sc.sim.theta_limit, sc.vehicle.preset)


def _flight(speed_h: float, depth_rate: float) -> tuple[float, float]:
    """(speed, depth rate) of a demand with the horizontal speed raised to :data:`MIN_SPEED`."""
    return math.hypot(max(speed_h, MIN_SPEED), depth_rate), depth_rate


def _where(speed: float, depth_rate: float) -> str:
    sign = "+" if depth_rate >= 0 else "-"
    return f"{_num(speed)} m/s through the water, depth rate {sign}{_num(abs(depth_rate))} m/s"


def trim_checks(model: SteadyModel, pts: WaterPoints, marginal: float = MARGINAL_FRACTION) -> list[Check]:
    """Straight-flight checks (fins or tau_q, pitch, roll) and the surge check at the extreme demands.

    Parameters
    ----------
    model : SteadyModel
        The plant.
    pts : WaterPoints
        Water-relative demands.
    marginal : float
        Fraction above which a check is marginal.

    Returns
    -------
    list of Check
        One check per limit of the model (the candidate with the highest usage), plus one per
        demand where no steady straight flight exists (pitch beyond its stop, or no root).
    """
    uh, zd = pts.speed_h, pts.depth_rate
    idx = {int(f(x)) for x in (uh, zd, uh + zd, uh - zd) for f in (np.argmin, np.argmax)}
    cases = sorted({_flight(float(uh[i]), float(zd[i])) for i in idx})
    sin_lim = math.sin(math.radians(model.limits["pitch"].available))
    best: dict[str, tuple[float, Any]] = {}
    out: list[Check] = []
    for speed, rate in cases:
        if abs(rate) >= speed * sin_lim:
            angle = math.degrees(math.asin(min(1.0, abs(rate) / speed)))
            lim = model.limits["pitch"]
            out.append(Check("pitch, straight", angle, lim.available, "deg", angle / lim.available, lim.key,
                             _where(speed, rate), marginal))
            continue
        s = model.solve(speed, rate, 0.0)
        if s is None:
            out.append(Check("steady straight flight", math.nan, math.nan, "", math.inf,
                             "the solver finds no equilibrium", _where(speed, rate), marginal))
            continue
        for k, use in s.usage.items():
            if k not in best or use > best[k][0]:
                best[k] = (use, s)
    for k, (use, s) in best.items():
        lim = model.limits[k]
        if not math.isfinite(lim.available):
            continue
        what = "surge" if k in ("rpm", "tau_u") else "straight"
        out.append(Check(f"{lim.label}, {what}", abs(s.inputs[k]), lim.available, lim.unit, use, lim.key,
                         _where(s.speed, s.depth_rate), marginal))
    return out


def turn_checks(model: SteadyModel, pts: WaterPoints, bound: CurrentBound,
                marginal: float = MARGINAL_FRACTION) -> list[Check]:
    """Per side, the demanded water-relative curvature against the tightest steady turn.

    Parameters
    ----------
    model : SteadyModel
        The plant.
    pts : WaterPoints
        Water-relative demands.
    bound : CurrentBound
        The current's worst case (for the condition text).
    marginal : float
        Fraction above which a check is marginal.

    Returns
    -------
    list of Check
        At most two (starboard, port); none for a side the reference never turns to.
    """
    memo: dict[tuple, Any] = {}

    def turn(speed_h, rate, d):
        key = (round(speed_h, 9), round(rate, 9), d)
        if key not in memo:
            speed, rate = _flight(speed_h, rate)
            if abs(rate) >= speed * math.sin(math.radians(model.limits["pitch"].available)):
                memo[key] = None  # no steady flight: the trim checks report the pitch
            else:
                memo[key] = tightest_turn(model, speed, rate, d)
        return memo[key]

    def cap(t):
        return 0.0 if t is None else min(t.curvature, 10.0 * KAPPA_CAP)

    out = []
    for d, side in ((1.0, "starboard"), (-1.0, "port")):
        on = d * pts.curvature > TURN_EPS
        if not np.any(on):
            continue
        uh, zd, kw = np.maximum(pts.speed_h[on], MIN_SPEED), pts.depth_rate[on], d * pts.curvature[on]
        lo, hi = float(uh.min()), float(uh.max())
        grid = np.linspace(lo, hi, SPEED_GRID) if hi - lo > 0.02 else np.unique([lo, hi])
        kmax = np.full(uh.shape, np.inf)
        for z in sorted({float(zd.min()), float(zd.max())}):
            kmax = np.minimum(kmax, np.interp(uh, grid, [cap(turn(float(u), z, d)) for u in grid]))
        with np.errstate(divide="ignore", invalid="ignore"):
            j = int(np.argmax(np.where(kmax > 0.0, kw / kmax, np.inf)))
        sel = np.flatnonzero(on)[j]
        t = turn(float(uh[j]), float(zd[j]), d)
        available = 1.0 / cap(t) if cap(t) > 0.0 else math.inf
        usage = kw[j] / cap(t) if cap(t) > 0.0 else math.inf
        if t is None:
            limit = model.limits["pitch"].key
        elif t.limit in model.limits:
            limit = model.limits[t.limit].key
        else:
            limit = "no steady turn found beyond" if t.limit == "solver" else "no limit reached"
        where = (f"ground radius {1.0 / abs(pts.ground_curvature[sel]):.3g} m at {pts.ground_speed[sel]:.3g} m/s; "
                 + _where(math.hypot(uh[j], zd[j]), float(zd[j])))
        if bound.horizontal > 0.0:
            where += f", current {bound.horizontal:.3g} m/s at {math.degrees(pts.beta[sel]):.0f} deg from the track"
        out.append(Check(f"turn to {side}", 1.0 / kw[j], available, "m", usage, limit, where, marginal))
    return out


def assess(scenario: Any, overrides: Sequence[str] | Mapping[str, Any] | None = (), *,
           sigmas: float = CURRENT_SIGMAS, marginal: float = MARGINAL_FRACTION):
    """Assess whether the plant of a scenario can fly its reference, before anything is flown.

    Parameters
    ----------
    scenario : str, path-like, dict or Scenario
        As :func:`auvtrack.load_scenario` takes it.
    overrides : sequence of str or dict, optional
        ``--set``-style overrides.
    sigmas : float
        Standard deviations added to the mean of a Gauss-Markov current for its worst case
        (>= 0; default 3).
    marginal : float
        Fraction of a limit above which a check is marginal, in (0, 1] (default 0.8).

    Returns
    -------
    Feasibility
        The verdict, every check and a :meth:`~Feasibility.summary`.

    Raises
    ------
    ValueError
        Bad input (a :class:`~auvtrack.scenario.ScenarioError` for the scenario, or
        ``sigmas`` / ``marginal`` out of range), one line naming the field.
    """
    from ..reference import build_reference
    from ..scenario import load_scenario
    from .demands import check_sigmas

    check_sigmas(sigmas)
    if isinstance(marginal, bool) or not isinstance(marginal, (int, float)) or not 0.0 < marginal <= 1.0:
        raise ValueError(f"marginal: must be a number in (0, 1] (got {marginal!r})")
    sc = load_scenario(scenario, overrides)
    if sc.plant.model not in STEADY_MODELS:
        return Feasibility(scenario=sc.name, plant=f"plant.model {sc.plant.model!r}", verdict="unassessed", checks=(),
                           reference="not assessed", current=current_bound(sc.disturbance, sigmas), marginal=marginal,
                           notes=(f"steady states are modelled for plant.model {' and '.join(STEADY_MODELS)} only",))
    model = steady_model(sc)
    demands = reference_demands(build_reference(sc.reference), sc.sim.duration)
    bound = current_bound(sc.disturbance, sigmas)
    pts = water_points(demands, bound, vertical=model.vertical_current)
    checks = trim_checks(model, pts, marginal)
    notes = []
    if model.input_limited():
        checks += turn_checks(model, pts, bound, marginal)
    else:
        notes.append("turns not checked: no input limit (actuator.tau_max = inf)")
    if any(d.get("kind") in ("paper", "pulse") for d in sc.disturbance):
        notes.append("the [[disturbance]] forces (paper, pulse) are not part of the demands")
    verdict = max((c.status for c in checks), key=STATUSES.index, default="feasible")
    return Feasibility(scenario=sc.name, plant=model.description, verdict=verdict, checks=tuple(checks),
                       reference=demands.describe(), current=bound, marginal=marginal, notes=tuple(notes))

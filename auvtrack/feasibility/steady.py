"""Steady flight of a plant: straight trim and steady turns, solved on the model's own equations.

A *steady state* at speed U through the water, depth rate z_dot and signed horizontal curvature
kappa (1/m, positive turning to starboard) is a constant body velocity, constant roll and pitch
and a constant heading rate psi_dot = kappa U_h, U_h = sqrt(U^2 - z_dot^2) the horizontal speed,
with the inputs that hold it (Fossen 2021, ch. 6, the steady turn of a manoeuvring model; the trim is kappa = 0).
Each plant kind implements :class:`SteadyModel` (:mod:`auvtrack.feasibility.steady5`,
:mod:`auvtrack.feasibility.steady6`); this module holds what they share:

* :func:`solve_root`, Powell's hybrid method (SciPy ``root``, ``hybr``) on the model's residual
  with a central-difference Jacobian of absolute step (MINPACK's relative step fails for
  variables that are exactly or nearly zero, as p, q, r are in straight flight);
* :func:`tightest_turn`, the largest curvature reachable from straight flight along the branch
  of steady turns with every input inside its limit (natural-parameter continuation in kappa,
  then bisection on the first limit crossed);
* :func:`steady_turn`, the same continuation to a given curvature without limits.

References
----------
Fossen, T. I. (2021). Handbook of Marine Craft Hydrodynamics and Motion Control, 2nd ed., Wiley,
ch. 6 (maneuvering models: steady turning, the turning circle), ch. 8 (models for underwater vehicles).
"""
from __future__ import annotations

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

RESIDUAL_TOL = 1e-9      # accepted residual of a steady state (m/s^2, rad/s^2, m/s, rad/s)
JACOBIAN_STEP = 1e-7     # absolute central-difference step of the solver variables (all O(1))
KAPPA_STEP0 = 0.01       # 1/m: first continuation step (radius 100 m)
KAPPA_STEP_MAX = 0.5     # 1/m
KAPPA_CAP = 10.0         # 1/m: radius 0.1 m; no limit found below it counts as unlimited
KAPPA_RTOL = 1e-7        # relative tolerance of the bisection on a limit crossing


@dataclass(frozen=True)
class Limit:
    """One limit a steady state must respect.

    Attributes
    ----------
    key : str
        Scenario key that sets it (e.g. ``"plant.delta_max"``, ``"actuator.tau_max.1"``).
    label : str
        What it limits (``"stern plane"``).
    available : float
        The limit, in ``unit`` (``inf`` = none).
    unit : str
        Display unit (``"deg"``, ``"rpm"``, ``"N"``, ``"N m"``).
    """

    key: str
    label: str
    available: float
    unit: str


@dataclass(frozen=True)
class SteadyState:
    """A solved steady state and the inputs that hold it.

    Attributes
    ----------
    speed, depth_rate : float
        Speed through the water and depth rate (m/s, z down).
    curvature : float
        Signed horizontal curvature, 1/m (positive: to starboard).
    inputs : dict
        Input or attitude name -> value in the unit of its :class:`Limit` (signed).
    usage : dict
        Name -> |value| / limit (0 for an unlimited one).
    z : numpy.ndarray
        The solver's variables (a starting guess for a neighbouring state).
    """

    speed: float
    depth_rate: float
    curvature: float
    inputs: dict
    usage: dict
    z: np.ndarray = field(repr=False)

    @property
    def worst(self) -> tuple[str, float]:
        """(name, usage) of the most used limit."""
        name = max(self.usage, key=lambda k: self.usage[k])
        return name, self.usage[name]


class SteadyModel(ABC):
    """A plant's steady states (see the module docstring).

    Attributes
    ----------
    description : str
        The plant, for reports.
    limits : dict
        Name -> :class:`Limit` for every input and attitude a steady state is checked against.
    vertical_current : bool
        Whether the model's hydrodynamics see a vertical current component.
    """

    description: str
    limits: dict
    vertical_current: bool

    @abstractmethod
    def solve(self, speed: float, depth_rate: float, curvature: float,
              guess: np.ndarray | None = None) -> SteadyState | None:
        """The steady state at (speed, depth_rate, curvature), or None if the solver finds none.

        Parameters
        ----------
        speed : float
            Speed through the water, m/s (> 0).
        depth_rate : float
            z_dot, m/s, |depth_rate| < speed.
        curvature : float
            Signed horizontal curvature, 1/m.
        guess : numpy.ndarray, optional
            Starting point (the ``z`` of a neighbouring state).

        Returns
        -------
        SteadyState or None
            The state, or None when no root within :data:`RESIDUAL_TOL` is found.
        """

    def usage(self, inputs: dict) -> dict:
        """|value| / limit for each limit (0 for an unlimited one).

        Parameters
        ----------
        inputs : dict
            Name -> value in the limit's unit.

        Returns
        -------
        dict
            Name -> usage.
        """
        return {k: (abs(inputs[k]) / lim.available if math.isfinite(lim.available) else 0.0)
                for k, lim in self.limits.items()}

    def input_limited(self) -> bool:
        """Whether any input (not attitude) has a finite limit."""
        return any(math.isfinite(lim.available) for k, lim in self.limits.items() if k not in ("pitch", "roll"))


def check_flight(speed: float, depth_rate: float) -> None:
    """Refuse a speed or depth rate no steady flight can have.

    Parameters
    ----------
    speed, depth_rate : float
        m/s.

    Raises
    ------
    ValueError
        ``speed: must be a finite number > 0 m/s`` or ``depth_rate: |depth_rate| must be < speed``.
    """
    if not (math.isfinite(speed) and speed > 0.0):
        raise ValueError(f"speed: must be a finite number > 0 m/s (got {speed!r})")
    if not (math.isfinite(depth_rate) and abs(depth_rate) < speed):
        raise ValueError(f"depth_rate: |depth_rate| must be < speed = {speed:g} m/s (got {depth_rate!r})")


def solve_root(residual: Callable[[np.ndarray], np.ndarray], z0: np.ndarray) -> np.ndarray | None:
    """A root of ``residual`` near ``z0`` within :data:`RESIDUAL_TOL`, or None.

    Parameters
    ----------
    residual : callable
        z -> residual vector (same length as z).
    z0 : numpy.ndarray
        Starting point.

    Returns
    -------
    numpy.ndarray or None
        The root, or None when Powell's method does not reach the tolerance.
    """
    from scipy.optimize import root

    def jac(z):
        J = np.empty((z.size, z.size))
        for i in range(z.size):
            zp, zm = z.copy(), z.copy()
            zp[i] += JACOBIAN_STEP
            zm[i] -= JACOBIAN_STEP
            J[:, i] = (residual(zp) - residual(zm)) / (2.0 * JACOBIAN_STEP)
        return J
    with np.errstate(all="ignore"):
        try:
            sol = root(residual, np.asarray(z0, dtype=np.float64), jac=jac, method="hybr",
                       options={"xtol": 1e-13})
        except (ValueError, ArithmeticError):
            return None
        if not np.all(np.isfinite(sol.x)):
            return None
        r = residual(sol.x)
    if not np.all(np.isfinite(r)) or np.max(np.abs(r)) > RESIDUAL_TOL:
        return None
    return sol.x


@dataclass(frozen=True)
class TurnLimit:
    """The tightest steady turn of a plant at one speed and depth rate.

    Attributes
    ----------
    curvature : float
        Largest |kappa| (1/m) reachable from straight flight with every limit respected: 0 when
        straight flight itself is out of the limits (or not found), ``inf`` when no limit binds
        below :data:`KAPPA_CAP`.
    state : SteadyState or None
        The steady state at that curvature (None if none was found).
    limit : str
        Name of the limit that bounds it (a key of ``SteadyModel.limits``), ``"solver"`` when the
        branch of steady turns ends without a limit (a fold, or the solver's failure), ``""``
        when unlimited.
    """

    curvature: float
    state: SteadyState | None
    limit: str

    @property
    def radius(self) -> float:
        """Tightest radius, m (1 / curvature; inf when no turn is possible, 0 when unlimited)."""
        return math.inf if self.curvature == 0.0 else 1.0 / self.curvature


def _guess(prev: tuple[float, SteadyState] | None, ok: tuple[float, SteadyState], k: float) -> np.ndarray:
    """Linear extrapolation of the solver variables along the continuation."""
    k1, s1 = ok
    if prev is None or prev[0] == k1:
        return s1.z
    k0, s0 = prev
    return s1.z + (s1.z - s0.z) * (k - k1) / (k1 - k0)


def _continue(model: SteadyModel, speed: float, depth_rate: float, direction: float, stop_at: float,
              limited: bool) -> TurnLimit:
    """Continuation in |kappa| from straight flight up to ``stop_at`` or the first limit crossed."""
    s0 = model.solve(speed, depth_rate, 0.0)
    if s0 is None:
        return TurnLimit(0.0, None, "solver")
    name, use = s0.worst
    if limited and use > 1.0:
        return TurnLimit(0.0, s0, name)
    prev, ok, step = None, (0.0, s0), KAPPA_STEP0
    while ok[0] < stop_at:
        k = min(ok[0] + step, stop_at)
        s = model.solve(speed, depth_rate, direction * k, _guess(prev, ok, k))
        if s is None:
            if step <= KAPPA_RTOL * max(ok[0], KAPPA_STEP0):
                return TurnLimit(ok[0], ok[1], "solver")
            step *= 0.5
            continue
        if limited and s.worst[1] > 1.0:
            return _bisect(model, speed, depth_rate, direction, ok, k)
        prev, ok, step = ok, (k, s), min(2.0 * step, KAPPA_STEP_MAX)
    return TurnLimit(ok[0], ok[1], "")


def _bisect(model: SteadyModel, speed: float, depth_rate: float, direction: float,
            ok: tuple[float, SteadyState], k_bad: float) -> TurnLimit:
    """Bisection of the first limit crossing between a state inside (``ok``) and k_bad outside."""
    bad_name = ""
    while k_bad - ok[0] > KAPPA_RTOL * k_bad:
        k = 0.5 * (ok[0] + k_bad)
        s = model.solve(speed, depth_rate, direction * k, ok[1].z)
        if s is not None and s.worst[1] <= 1.0:
            ok = (k, s)
        else:
            k_bad = k
            bad_name = s.worst[0] if s is not None else "solver"
    if not bad_name:
        s = model.solve(speed, depth_rate, direction * k_bad, ok[1].z)
        bad_name = s.worst[0] if s is not None else "solver"
    return TurnLimit(ok[0], ok[1], bad_name)


def tightest_turn(model: SteadyModel, speed: float, depth_rate: float, direction: float) -> TurnLimit:
    """The tightest steady turn to one side at (speed, depth_rate) within every limit.

    Parameters
    ----------
    model : SteadyModel
        The plant.
    speed, depth_rate : float
        Speed through the water and depth rate, m/s.
    direction : float
        +1 to starboard, -1 to port.

    Returns
    -------
    TurnLimit
        The largest curvature on the branch of steady turns that starts at straight flight.

    Raises
    ------
    ValueError
        Bad speed, depth rate or direction (one line naming it).
    """
    check_flight(speed, depth_rate)
    if direction not in (1.0, -1.0):
        raise ValueError(f"direction: must be +1 (starboard) or -1 (port) (got {direction!r})")
    return _continue(model, speed, depth_rate, direction, KAPPA_CAP, limited=True)


def steady_turn(model: SteadyModel, speed: float, depth_rate: float, curvature: float) -> SteadyState | None:
    """The steady turn at a given curvature, reached by continuation from straight flight (limits ignored).

    Parameters
    ----------
    model : SteadyModel
        The plant.
    speed, depth_rate : float
        Speed through the water and depth rate, m/s.
    curvature : float
        Signed horizontal curvature, 1/m.

    Returns
    -------
    SteadyState or None
        The state, or None when the branch ends before ``curvature``.
    """
    check_flight(speed, depth_rate)
    if curvature == 0.0:
        return model.solve(speed, depth_rate, 0.0)
    res = _continue(model, speed, depth_rate, math.copysign(1.0, curvature), abs(curvature), limited=False)
    return res.state if res.curvature == abs(curvature) else None

"""What a reference asks of the vehicle: speed, depth rate and curvature, over ground and through the water.

**Over ground.**  The reference gives eta_d(t) and its exact first two derivatives
v = eta_d_dot, a = eta_d_ddot (:meth:`auvtrack.reference.Reference.evaluate`), for every kind.
On the horizontal plane (NED: x north, y east) the path has speed U_h = |v_h|, tangent
t = v_h / U_h, starboard normal n = (-t_y, t_x), tangential and normal accelerations
a_t = a . t, a_n = a . n, and signed curvature (positive turning to starboard)::

    kappa = (v_x a_y - v_y a_x) / U_h^3 = a_n / U_h^2                                  (1)

(0 where U_h = 0).  The depth rate is v_z.

**Through the water.**  The vehicle's hydrodynamics act on its velocity relative to the water
(Fossen 2021, eq. 10.1).  In a current V constant over the turn, the water-relative velocity is
v - V and its acceleration a (dV/dt = 0), so with V at angle beta from the tangent,
V = V_h (cos beta t + sin beta n)::

    U_w = sqrt((U_h - V_h cos beta)^2 + (V_h sin beta)^2)                              (2)
    kappa_w = ((U_h - V_h cos beta) a_n + V_h sin beta a_t) / U_w^3                      (3)

A ground circle (radius R, constant speed U, a_t = 0, a_n = U^2 / R) is a trochoid in the water:
the current sweeps every beta once per lap.  Its tightest water-relative radius is where the
current follows the vehicle (beta = 0): R_w = R (U - V_h)^2 / U^2 at speed U - V_h; where the
current is against it (beta = pi), R (U + V_h)^2 / U^2 at U + V_h.  Both the demanded radius and
the vehicle's tightest turn depend on the water speed, so the assessment checks every beta on a
grid (:data:`CURRENT_ANGLES`), quasi-steadily (the vehicle's steady-turn capability at each
instant's water speed).  Vertically the water-relative depth rate is v_z - V_z.

**Worst case of a Gauss-Markov current** (:class:`auvtrack.environment.GaussMarkovCurrent`: each
NED component stationary Gaussian with mean m_j and standard deviation sigma_j; several currents
add, their deviations independent): the bound is the mean's horizontal magnitude plus k times
the largest horizontal standard deviation, V_h = |(m_x, m_y)| + k max(sigma_x, sigma_y), and
V_z = |m_z| + k sigma_z vertically, with k = :data:`CURRENT_SIGMAS` = 3 by default.  Taken in
the worst direction (every beta): the component of the deviation along any fixed direction has a
standard deviation of at most max(sigma_x, sigma_y), so it exceeds k of them with probability
below 0.135 % (one-sided Gaussian tail at 3 sigma) at any instant.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Mapping, Sequence

import numpy as np

if TYPE_CHECKING:
    from ..reference import Reference

SAMPLE_DT = 0.05           # s between reference samples (bounded by MIN/MAX_SAMPLES)
MIN_SAMPLES, MAX_SAMPLES = 201, 20001
SPEED_EPS = 1e-9           # m/s: below it the horizontal direction is undefined (curvature 0)
CURRENT_SIGMAS = 3.0       # standard deviations in the current's worst case
CURRENT_ANGLES = 16        # directions beta of the current relative to the path (0 and pi included)


def horizontal_curvature(velocity: np.ndarray, acceleration: np.ndarray) -> np.ndarray:
    """Signed horizontal curvature kappa of eq. (1), 1/m (positive to starboard; 0 where U_h = 0).

    Parameters
    ----------
    velocity, acceleration : numpy.ndarray
        Shape (n, 3) (or (3,)), NED, m/s and m/s^2.

    Returns
    -------
    numpy.ndarray
        Shape (n,) (or scalar).
    """
    v, a = np.asarray(velocity, float), np.asarray(acceleration, float)
    uh = np.hypot(v[..., 0], v[..., 1])
    cross = v[..., 0] * a[..., 1] - v[..., 1] * a[..., 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(uh > SPEED_EPS, cross / np.maximum(uh, SPEED_EPS) ** 3, 0.0)


ArrayLike = float | np.ndarray


def water_relative(speed_h: ArrayLike, accel_t: ArrayLike, accel_n: ArrayLike, current_h: float,
                   beta: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Water-relative horizontal speed and curvature, eq. (2) and (3).

    Parameters
    ----------
    speed_h : float or numpy.ndarray
        Horizontal speed over ground U_h, m/s.
    accel_t, accel_n : float or numpy.ndarray
        Tangential and normal (starboard) accelerations, m/s^2.
    current_h : float
        Horizontal current speed V_h, m/s.
    beta : float or numpy.ndarray
        Direction of the current from the path's tangent towards starboard, rad.

    Returns
    -------
    speed_w, curvature_w : numpy.ndarray
        U_w (m/s) and signed kappa_w (1/m; 0 where U_w = 0).
    """
    along = np.asarray(speed_h, float) - current_h * np.cos(beta)
    across = current_h * np.sin(beta)
    uw = np.hypot(along, across)
    cross = along * np.asarray(accel_n, float) + across * np.asarray(accel_t, float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return uw, np.where(uw > SPEED_EPS, cross / np.maximum(uw, SPEED_EPS) ** 3, 0.0)


@dataclass(frozen=True)
class CurrentBound:
    """The worst-case current of a scenario (see the module docstring).

    Attributes
    ----------
    horizontal, vertical : float
        V_h, V_z, m/s.
    sigmas : float
        k, the number of standard deviations.
    mean, sigma : tuple of 3 float
        Summed mean (m/s, NED) and combined standard deviation of the currents.
    """

    horizontal: float
    vertical: float
    sigmas: float
    mean: tuple = (0.0, 0.0, 0.0)
    sigma: tuple = (0.0, 0.0, 0.0)

    def describe(self) -> str:
        """One phrase for reports."""
        if self.horizontal == 0.0 and self.vertical == 0.0:
            return "none"
        return (f"{self.horizontal:.3g} m/s horizontal, {self.vertical:.3g} m/s vertical "
                f"(mean + {self.sigmas:g} sigma, any direction)")


def check_sigmas(sigmas: float) -> float:
    """Return ``sigmas`` if it is a finite number >= 0, else raise a one-line ValueError.

    Parameters
    ----------
    sigmas : float
        Number of standard deviations.

    Returns
    -------
    float
        The value.

    Raises
    ------
    ValueError
        ``sigmas: must be a finite number >= 0 (got ...)``.
    """
    number = isinstance(sigmas, (int, float)) and not isinstance(sigmas, bool)
    if not (number and math.isfinite(sigmas) and sigmas >= 0):
        raise ValueError(f"sigmas: must be a finite number >= 0 (got {sigmas!r})")
    return float(sigmas)


def current_bound(disturbances: Sequence[Mapping], sigmas: float = CURRENT_SIGMAS) -> CurrentBound:
    """The worst-case current of the scenario's ``[[disturbance]]`` list.

    Parameters
    ----------
    disturbances : sequence of dict
        Resolved disturbance specs; those of kind ``"current"`` count (``mean``, ``sigma``).
    sigmas : float
        k, standard deviations added to the mean's magnitude (>= 0).

    Returns
    -------
    CurrentBound
        V_h = |(m_x, m_y)| + k max(sigma_x, sigma_y), V_z = |m_z| + k sigma_z.
    """
    k = check_sigmas(sigmas)
    mean, var = np.zeros(3), np.zeros(3)
    for spec in disturbances:
        if spec.get("kind") == "current":
            mean += np.asarray(spec["mean"], float)
            var += np.asarray(spec["sigma"], float) ** 2
    sd = np.sqrt(var)
    return CurrentBound(horizontal=float(math.hypot(mean[0], mean[1]) + k * max(sd[0], sd[1])),
                        vertical=float(abs(mean[2]) + k * sd[2]), sigmas=k,
                        mean=tuple(float(x) for x in mean), sigma=tuple(float(x) for x in sd))


def sample_times(reference: Reference, duration: float) -> np.ndarray:
    """Times at which the reference is evaluated on [0, duration]: a uniform grid, the joints and their midpoints.

    Parameters
    ----------
    reference : auvtrack.reference.Reference
        The reference.
    duration : float
        Horizon, s (> 0).

    Returns
    -------
    numpy.ndarray
        Sorted, unique times (s).
    """
    n = int(min(max(math.ceil(duration / SAMPLE_DT) + 1, MIN_SAMPLES), MAX_SAMPLES))
    joints = np.asarray(reference.breakpoints, float)
    joints = joints[(joints > 0.0) & (joints <= duration)]
    inside = np.concatenate([[0.0], joints, [duration]])
    extra = np.concatenate([joints, np.nextafter(joints, -np.inf), 0.5 * (inside[1:] + inside[:-1])])
    return np.unique(np.concatenate([np.linspace(0.0, duration, n), extra]))


@dataclass(frozen=True)
class ReferenceDemands:
    """The reference's velocity and acceleration over the run, and what follows from them.

    Attributes
    ----------
    t : numpy.ndarray
        Sample times, s.
    velocity, acceleration : numpy.ndarray
        Shape (n, 3), NED, m/s and m/s^2 (the reference's analytic derivatives).
    """

    t: np.ndarray = field(repr=False)
    velocity: np.ndarray = field(repr=False)
    acceleration: np.ndarray = field(repr=False)

    @property
    def speed(self) -> np.ndarray:
        """|v|, m/s."""
        return np.linalg.norm(self.velocity, axis=1)

    @property
    def horizontal_speed(self) -> np.ndarray:
        """U_h = |v_h|, m/s."""
        return np.hypot(self.velocity[:, 0], self.velocity[:, 1])

    @property
    def depth_rate(self) -> np.ndarray:
        """v_z, m/s (positive descending)."""
        return self.velocity[:, 2]

    @property
    def curvature(self) -> np.ndarray:
        """Signed horizontal curvature, eq. (1), 1/m."""
        return horizontal_curvature(self.velocity, self.acceleration)

    def path_accelerations(self) -> tuple[np.ndarray, np.ndarray]:
        """(a_t, a_n): tangential and starboard-normal horizontal accelerations, m/s^2.

        Where U_h = 0 the tangent is taken as north.
        """
        v, a = self.velocity, self.acceleration
        uh = self.horizontal_speed
        moving = uh > SPEED_EPS
        tx = np.where(moving, v[:, 0] / np.maximum(uh, SPEED_EPS), 1.0)
        ty = np.where(moving, v[:, 1] / np.maximum(uh, SPEED_EPS), 0.0)
        return a[:, 0] * tx + a[:, 1] * ty, -a[:, 0] * ty + a[:, 1] * tx

    def describe(self) -> str:
        """One phrase for reports: speed and depth-rate ranges, tightest ground radius."""
        def rng(x, unit):
            lo, hi = float(np.min(x)), float(np.max(x))
            if math.isclose(lo, hi, rel_tol=1e-6, abs_tol=1e-9):
                return f"{lo:.3g} {unit}"
            return f"{lo:.3g} to {hi:.3g} {unit}"
        k = np.max(np.abs(self.curvature))
        turn = "no turn" if k == 0.0 else f"tightest radius {1.0 / k:.3g} m"
        return f"speed over ground {rng(self.speed, 'm/s')}, depth rate {rng(self.depth_rate, 'm/s')}, {turn}"


def reference_demands(reference: Reference, duration: float) -> ReferenceDemands:
    """Sample the reference's velocity and acceleration over [0, duration].

    Parameters
    ----------
    reference : auvtrack.reference.Reference
        Any reference kind (its analytic derivatives are used).
    duration : float
        Horizon, s (> 0).

    Returns
    -------
    ReferenceDemands
        The samples.
    """
    t = sample_times(reference, duration)
    _, v, a = reference.evaluate(t)
    return ReferenceDemands(t=t, velocity=v, acceleration=a)


@dataclass(frozen=True)
class WaterPoints:
    """Distinct water-relative demands: one row per (reference sample, current direction, vertical sign).

    Attributes
    ----------
    speed_h : numpy.ndarray
        Horizontal speed through the water, m/s.
    depth_rate : numpy.ndarray
        Water-relative depth rate, m/s.
    curvature : numpy.ndarray
        Signed water-relative curvature, 1/m.
    ground_speed, ground_curvature : numpy.ndarray
        The reference sample's horizontal speed (m/s) and curvature (1/m) over ground.
    beta : numpy.ndarray
        Direction of the current from the path's tangent, rad.
    """

    speed_h: np.ndarray
    depth_rate: np.ndarray
    curvature: np.ndarray
    ground_speed: np.ndarray
    ground_curvature: np.ndarray
    beta: np.ndarray

    @property
    def speed(self) -> np.ndarray:
        """Speed through the water, m/s."""
        return np.hypot(self.speed_h, self.depth_rate)


def water_points(demands: ReferenceDemands, bound: CurrentBound, vertical: bool = True,
                 angles: int = CURRENT_ANGLES) -> WaterPoints:
    """The water-relative demands of every reference sample in the worst-case current, eq. (2) and (3).

    Parameters
    ----------
    demands : ReferenceDemands
        The reference's samples.
    bound : CurrentBound
        The current's worst case (a zero bound gives the ground demands).
    vertical : bool
        Whether the plant's hydrodynamics see a vertical current (then z_dot -+ V_z).
    angles : int
        Number of current directions beta on [0, 2 pi) (used when V_h > 0).

    Returns
    -------
    WaterPoints
        One row per distinct (U_h, a_t, a_n, z_dot) sample and current case.
    """
    at, an = demands.path_accelerations()
    key = np.stack([demands.horizontal_speed, at, an, demands.depth_rate], axis=1)
    rows = np.unique(np.round(key, 12), axis=0, return_index=True)[1]
    uh, at, an, zd = (key[rows, i] for i in range(4))
    kg = horizontal_curvature(demands.velocity[rows], demands.acceleration[rows])
    betas = np.linspace(0.0, 2.0 * np.pi, angles, endpoint=False) if bound.horizontal > 0.0 else np.zeros(1)
    signs = (-1.0, 1.0) if vertical and bound.vertical > 0.0 else (0.0,)
    B, S = np.meshgrid(betas, signs, indexing="ij")
    B, S = B.ravel(), S.ravel()
    uw, kw = water_relative(uh[:, None], at[:, None], an[:, None], bound.horizontal, B[None, :])
    n = uw.shape
    return WaterPoints(speed_h=uw.ravel(), depth_rate=(zd[:, None] + S[None, :] * bound.vertical).ravel(),
                       curvature=kw.ravel(), ground_speed=np.broadcast_to(uh[:, None], n).ravel(),
                       ground_curvature=np.broadcast_to(kg[:, None], n).ravel(),
                       beta=np.broadcast_to(B[None, :], n).ravel())

"""Steady states of the 5-DOF plant (paper eq. 1) with its tau limits.

The 5-DOF model has no roll; a steady state has q = 0 and constant (u, v, w, r, theta).  With
``generalized_forces`` g(nu, theta) = C(nu) nu + D nu + G(eta) of eq. (1) (the function the plant
itself integrates, :mod:`auvtrack.vehicle.dynamics`), M nu_dot = tau - g = 0 gives

    tau_u = g_u,  tau_q = g_q,  tau_r = g_r,  and for the unactuated axes  g_v = 0,  g_w = 0.

g_w = -c m11 u q + d33 w vanishes with q = w = 0, so the unknowns are z = (u, v, r, theta):

    g_v(u, v, r) = 0                          sway balance: v = -c m11 u r / d22
    u^2 + v^2 = U^2                           speed through the water (w = 0)
    -sin(theta) u = z_dot                     depth rate (eq. 1 kinematics with w = 0)
    r / cos(theta) = kappa U_h                heading rate of a circle of curvature kappa,
                                              U_h = sqrt(U^2 - z_dot^2)

The plant is the *true* 5-DOF vehicle (the scenario's ``[uncertainty]`` applied), the limits
``actuator.tau_max`` and ``sim.theta_limit``.  The current enters eq. (1) through the damping
on the water-relative velocity, so a straight steady state at speed U through the water is the
same in a constant current; in a turn the Coriolis term uses the velocity over ground, which the
water-relative state neglects (quasi-steady).
"""
from __future__ import annotations

import math

import numpy as np

from ..vehicle.dynamics import generalized_forces
from ..vehicle.kinematics import attitude
from .steady import Limit, SteadyModel, SteadyState, check_flight, solve_root


class Steady5(SteadyModel):
    """Steady states of the true 5-DOF vehicle ``vp`` (see the module docstring).

    Parameters
    ----------
    vp : numpy.ndarray
        Packed true vehicle (:mod:`auvtrack.vehicle.params`).
    tau_max : sequence of 3 float
        |tau_u| (N), |tau_q|, |tau_r| (N m) limits (``inf`` = none).
    theta_limit : float
        Pitch stop of the run, deg.
    name : str
        Vehicle preset, for the description.
    """

    def __init__(self, vp: np.ndarray, tau_max=(math.inf,) * 3, theta_limit: float = 85.0, name: str = "") -> None:
        self.vp = np.asarray(vp, dtype=np.float64)
        t = [float(x) for x in tau_max]
        self.limits = {"tau_u": Limit("actuator.tau_max.0", "surge force", t[0], "N"),
                       "tau_q": Limit("actuator.tau_max.1", "pitch moment", t[1], "N m"),
                       "tau_r": Limit("actuator.tau_max.2", "yaw moment", t[2], "N m"),
                       "pitch": Limit("sim.theta_limit", "pitch", float(theta_limit), "deg")}
        self.description = f"5-DOF plant (vehicle {name})" if name else "5-DOF plant"
        self.vertical_current = True

    def forces(self, z: np.ndarray) -> tuple:
        """g = C(nu) nu + D nu + G(eta) of eq. (1) at the steady state of z = (u, v, r, theta) (N, N m)."""
        u, v, r, theta = z
        return generalized_forces(attitude(theta, 0.0), (u, v, 0.0, 0.0, r), self.vp)

    def residual(self, z: np.ndarray, speed: float, depth_rate: float, curvature: float) -> np.ndarray:
        """The 4 residuals of the module docstring (N, m/s, m/s, rad/s)."""
        u, v, r, theta = z
        g = self.forces(z)
        horizontal = math.sqrt(max(speed * speed - depth_rate * depth_rate, 0.0))
        return np.array([g[1], math.sqrt(u * u + v * v) - speed, -math.sin(theta) * u - depth_rate,
                         r / math.cos(theta) - curvature * horizontal])

    def solve(self, speed: float, depth_rate: float, curvature: float,
              guess: np.ndarray | None = None) -> SteadyState | None:
        """The steady state at (speed, depth_rate, curvature), or None (see :meth:`SteadyModel.solve`).

        Parameters
        ----------
        speed : float
            Speed through the water, m/s (> 0).
        depth_rate : float
            z_dot, m/s, |depth_rate| < speed.
        curvature : float
            Signed horizontal curvature, 1/m (positive: to starboard).
        guess : numpy.ndarray, optional
            Starting point (default: straight flight along the body axis).

        Returns
        -------
        SteadyState or None
            Inputs ``tau_u`` (N), ``tau_q``, ``tau_r`` (N m) and ``pitch`` (deg) with their usage,
            or None when no root is found or the root is not forward flight with |theta| < 90 deg.
        """
        check_flight(speed, depth_rate)
        z0 = np.array([speed, 0.0, 0.0, -math.asin(depth_rate / speed)]) if guess is None else guess
        z = solve_root(lambda zz: self.residual(zz, speed, depth_rate, curvature), z0)
        if z is None or z[0] <= 0.0 or abs(z[3]) >= math.pi / 2:
            return None
        g = self.forces(z)
        inputs = {"tau_u": float(g[0]), "tau_q": float(g[3]), "tau_r": float(g[4]), "pitch": math.degrees(z[3])}
        return SteadyState(speed=speed, depth_rate=depth_rate, curvature=curvature, inputs=inputs,
                           usage=self.usage(inputs), z=z)

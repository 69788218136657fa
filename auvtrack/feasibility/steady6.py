"""Steady states of a 6-DOF truth model, solved on its own derivative.

Unknowns z = (u, v, w, p, q, r, phi, theta, delta_r, delta_s, n / n_max) (m/s, rad/s, rad, rpm
scaled to O(1)); the actuator states equal their commands (their lags at rest).  Residual, with
dx = f(x, cmd) the model's derivative in still water (:func:`derivative` of
:mod:`auvtrack.plant.sixdof.prestero` or :mod:`auvtrack.plant.sixdof.fossen`, the same function
the engine integrates)::

    dx[u..r] = 0                 (6)  constant body velocity
    d phi/dt = d theta/dt = 0    (2)  constant roll and pitch
    |(u, v, w)| = U              (1)  speed through the water
    dz/dt = z_dot                (1)  depth rate (NED kinematics of the model)
    d psi/dt = kappa U_h         (1)  heading rate of a horizontal circle of curvature kappa,
                                      U_h = |(dx/dt, dy/dt)|

11 equations in 11 unknowns (Fossen 2021, ch. 6: a steady turn has constant nu and
constant roll and pitch; the trim is kappa = 0, where p = q = r = 0 follows).  The fin and
propeller limits are lifted while solving (so the required angle is found even beyond the
limit) and compared afterwards with the preset's (with the scenario's ``[plant]`` overrides):
the usage of each limit is |delta| / delta_max, |n| / n_max, |theta| / theta_limit,
|phi| / phi_limit.

In a current the model's hydrodynamics act on the velocity relative to the water, so these
still-water states are the water-relative ones (Prestero's model: exactly, Fossen 2021
ch. 10 for a constant irrotational current, tested; Fossen's: except that its propeller's advance
speed is the speed over ground (PVS), which the still-water state takes equal to U).
"""
from __future__ import annotations

import math

import numpy as np

from ..vehicle.kinematics import attitude
from ..plant.sixdof.layout import IX_DR, IX_DS, IX_N, NX6, P_DMAX, P_NMAX
from ..plant.sixdof.truth import MODELS, pack_truth, trim_rpm
from .steady import Limit, SteadyModel, SteadyState, check_flight, solve_root

UNLIMITED = 1e9  # fin angle (rad) and propeller speed (rpm) limits while solving
NO_CURRENT = (0.0, 0.0, 0.0)
NO_FORCE = (0.0,) * 6
VERTICAL_CURRENT = {"remus100_prestero": True, "remus100_fossen": False}  # fossen.py: a vertical current is ignored


class Steady6(SteadyModel):
    """Steady states of the 6-DOF truth preset ``preset`` (see the module docstring).

    Parameters
    ----------
    preset : str
        ``remus100_prestero`` or ``remus100_fossen``.
    actuator_overrides : dict, optional
        The scenario's ``[plant]`` actuator keys (e.g. ``{"delta_max": 0.2}``).
    theta_limit, phi_limit : float
        Pitch and roll stops of the run, deg (``sim.theta_limit``, ``sim.phi_limit``).
    """

    def __init__(self, preset: str, actuator_overrides: dict | None = None, theta_limit: float = 85.0,
                 phi_limit: float = 85.0) -> None:
        self.preset = preset
        self.model = MODELS[preset]
        self.pp = pack_truth(preset, actuator_overrides)
        self.pp_free = self.pp.copy()
        self.pp_free[P_DMAX] = self.pp_free[P_NMAX] = UNLIMITED
        self.n_scale = float(self.pp[P_NMAX])
        dmax = math.degrees(self.pp[P_DMAX])
        self.limits = {"delta_r": Limit("plant.delta_max", "rudder", dmax, "deg"),
                       "delta_s": Limit("plant.delta_max", "stern plane", dmax, "deg"),
                       "rpm": Limit("plant.n_max", "propeller", self.n_scale, "rpm"),
                       "pitch": Limit("sim.theta_limit", "pitch", float(theta_limit), "deg"),
                       "roll": Limit("sim.phi_limit", "roll", float(phi_limit), "deg")}
        self.description = f"6-DOF truth {preset}"
        self.vertical_current = VERTICAL_CURRENT[preset]
        self._dx = np.zeros(NX6)
        self._cmd = np.zeros(6)

    def state_of(self, z: np.ndarray) -> np.ndarray:
        """The model state x (length 15, at the origin, heading 0) of solver variables z."""
        x = np.zeros(NX6)
        x[3], x[4] = z[6], z[7]
        x[6:12] = z[0:6]
        x[IX_DR], x[IX_DS], x[IX_N] = z[8], z[9], z[10] * self.n_scale
        return x

    def derivative(self, z: np.ndarray) -> np.ndarray:
        """The model's still-water derivative dx (15) at the state of z with commands equal to the actuator states."""
        x = self.state_of(z)
        self._cmd[0:3] = x[IX_DR], x[IX_DS], x[IX_N]
        self.model.derivative(x, attitude(z[7], 0.0), NO_CURRENT, NO_FORCE, self._cmd, self.pp_free, self._dx)
        return self._dx

    def residual(self, z: np.ndarray, speed: float, depth_rate: float, curvature: float) -> np.ndarray:
        """The 11 residuals of the module docstring (m/s^2, rad/s^2, rad/s, m/s, m/s, rad/s)."""
        dx = self.derivative(z)
        out = np.empty(11)
        out[0:6] = dx[6:12]
        out[6], out[7] = dx[3], dx[4]
        out[8] = math.sqrt(z[0] * z[0] + z[1] * z[1] + z[2] * z[2]) - speed
        out[9] = dx[2] - depth_rate
        out[10] = dx[5] - curvature * math.hypot(dx[0], dx[1])
        return out

    def straight_guess(self, speed: float, depth_rate: float) -> np.ndarray:
        """Starting point: level body axes along the path, fins at zero, surge-balance propeller speed."""
        theta = -math.asin(depth_rate / speed)
        n = trim_rpm(self.preset, self.pp_free, speed)
        return np.array([speed, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, theta, 0.0, 0.0, n / self.n_scale])

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
            Starting point (default: :meth:`straight_guess`).

        Returns
        -------
        SteadyState or None
            Inputs ``delta_r``, ``delta_s`` (deg, the preset's sign convention), ``rpm``,
            ``pitch``, ``roll`` (deg) with their usage, or None when no root is found or the
            root is not forward flight with |phi|, |theta| < 90 deg.
        """
        check_flight(speed, depth_rate)
        z0 = self.straight_guess(speed, depth_rate) if guess is None else guess
        z = solve_root(lambda zz: self.residual(zz, speed, depth_rate, curvature), z0)
        if z is None or z[0] <= 0.0 or abs(z[6]) >= math.pi / 2 or abs(z[7]) >= math.pi / 2:
            return None
        inputs = {"delta_r": math.degrees(z[8]), "delta_s": math.degrees(z[9]), "rpm": float(z[10] * self.n_scale),
                  "pitch": math.degrees(z[7]), "roll": math.degrees(z[6])}
        return SteadyState(speed=speed, depth_rate=depth_rate, curvature=curvature, inputs=inputs,
                           usage=self.usage(inputs), z=z)

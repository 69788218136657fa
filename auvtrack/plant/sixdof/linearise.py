"""Linearisations about straight, level running: a 6-DOF truth and the paper's 5-DOF model.

Both by central finite differences of the compiled right-hand sides (one source of truth per
equation: :func:`auvtrack.plant.sixdof.fossen.derivative` / ``prestero.derivative`` and
:func:`auvtrack.vehicle.dynamics.nu_dot`), so that the reduced design model
(:mod:`auvtrack.plant.sixdof.torpedo_reduction`) can be set against the truth it comes from.

* Truth, states z = (u, v, w, p, q, r, phi, theta), inputs tau = (tau_u, tau_q, tau_r): the
  actuators sit at the commands the plant's allocation gives for tau at the current velocity
  (instantaneous actuators), so tau is what a controller commands; the operating point is u = U0
  with the propeller trimmed (:func:`auvtrack.plant.sixdof.truth.trim_rpm`) and everything else 0.
* 5-DOF, states z5 = (u, v, w, q, r, theta), same inputs: eq. (1) with theta_dot = q at theta = 0.

:func:`step_response` gives the response of such a linear system to a step of one input
(exact, by the matrix exponential).
"""
from __future__ import annotations

import numpy as np
from scipy.linalg import expm

from ...vehicle.dynamics import nu_dot
from ...vehicle.kinematics import attitude
from . import prestero
from .truth import initial_state, model_of, pack_truth, trim_rpm

TRUTH_STATES = ("u", "v", "w", "p", "q", "r", "phi", "theta")
DESIGN_STATES = ("u", "v", "w", "q", "r", "theta")


def _truth_rhs(name: str, pp: np.ndarray, z: np.ndarray, tau: np.ndarray) -> np.ndarray:
    """d/dt z of the truth with the actuators at the allocated commands (module docstring)."""
    model = model_of(name)
    x = initial_state((0.0, 0.0, 0.0, z[6], z[7], 0.0), (z[0], z[1], z[2], z[3], z[4], z[5]), (0.0, 0.0, 0.0))
    cmd = np.zeros(6)
    if model is prestero:
        model.allocate_tau(tau[0], tau[1], tau[2], x[6], pp, cmd)
    else:
        model.allocate_tau(tau[0], tau[1], tau[2], x[6], x[7], x[8], pp, cmd)
    x[12], x[13], x[14] = cmd[0], cmd[1], cmd[2]
    dx = np.zeros(15)
    model.derivative(x, attitude(z[7], 0.0), (0.0, 0.0, 0.0), (0.0,) * 6, cmd, pp, dx)
    return np.array([dx[6], dx[7], dx[8], dx[9], dx[10], dx[11], dx[3], dx[4]])


def _jacobians(f, z0: np.ndarray, t0: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray]:
    A = np.column_stack([(f(z0 + h * e, t0) - f(z0 - h * e, t0)) / (2 * h) for e in np.eye(z0.size)])
    B = np.column_stack([(f(z0, t0 + h * e) - f(z0, t0 - h * e)) / (2 * h) for e in np.eye(t0.size)])
    return A, B


def truth_jacobian(name: str, u0: float, h: float = 1e-7) -> dict:
    """The truth ``name`` linearised at straight, level running at ``u0`` (module docstring).

    Parameters
    ----------
    name : str
        A 6-DOF truth (:func:`auvtrack.plant.sixdof.truth.truth_preset`).
    u0 : float
        Surge speed, m/s.
    h : float
        Finite-difference step (m/s, rad/s, rad; N and N m for the inputs).

    Returns
    -------
    dict
        ``A`` (8x8, 1/s), ``B`` (8x3), ``M`` (6x6 mass matrix, SI), ``K`` = M times the
        velocity block of A (the generalized-force slopes, N s/m ...), ``rpm0`` (trim),
        ``tau_u0`` (N, the thrust tau_u of the trim), ``f0`` (d/dt z at the operating point:
        roll acceleration from the propeller torque, the rest about 0).
    """
    model = model_of(name)
    pp = pack_truth(name)
    rpm0 = trim_rpm(name, pp, u0)
    if model is prestero:
        tau_u0 = model.produced(u0, 0.0, 0.0, rpm0, pp)[0]
    else:
        tau_u0 = model.produced(u0, 0.0, 0.0, 0.0, 0.0, rpm0, pp)[0]
    z0 = np.array([u0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    t0 = np.array([tau_u0, 0.0, 0.0])
    f = lambda z, t: _truth_rhs(name, pp, z, t)  # noqa: E731
    A, B = _jacobians(f, z0, t0, h)
    M = np.linalg.inv(pp[0:36].reshape(6, 6))
    return {"A": A, "B": B, "M": M, "K": M @ A[:6, :6], "rpm0": float(rpm0), "tau_u0": float(tau_u0),
            "f0": f(z0, t0)}


def design_jacobian(vp: np.ndarray, u0: float, h: float = 1e-7) -> dict:
    """The 5-DOF model of eq. (1) with packed vehicle ``vp`` linearised at u = ``u0``, theta = 0.

    Parameters
    ----------
    vp : numpy.ndarray
        Packed vehicle (:func:`auvtrack.vehicle.presets.pack_vehicle`).
    u0 : float
        Surge speed, m/s.
    h : float
        Finite-difference step.

    Returns
    -------
    dict
        ``A`` (6x6, states :data:`DESIGN_STATES`), ``B`` (6x3).
    """
    def f(z, tau):
        nd = nu_dot(attitude(z[5], 0.0), (z[0], z[1], z[2], z[3], z[4]), (tau[0], tau[1], tau[2]),
                    (0.0,) * 5, vp)
        return np.array([nd[0], nd[1], nd[2], nd[3], nd[4], z[3]])
    A, B = _jacobians(f, np.array([u0, 0.0, 0.0, 0.0, 0.0, 0.0]), np.zeros(3), h)
    return {"A": A, "B": B}


def step_response(A: np.ndarray, B: np.ndarray, col: int, amp: float, ts) -> np.ndarray:
    """States of dz/dt = A z + B u from z = 0 under the step u = amp e_col, at the times ``ts``.

    Parameters
    ----------
    A, B : numpy.ndarray
        System matrices (n x n, n x m).
    col : int
        The input stepped.
    amp : float
        Step size (the input's unit).
    ts : array_like
        Times, s (>= 0).

    Returns
    -------
    numpy.ndarray
        (len(ts), n).
    """
    n, m = B.shape
    big = np.zeros((n + m, n + m))
    big[:n, :n], big[:n, n:] = A, B
    u = np.zeros(m)
    u[col] = amp
    return np.array([(expm(big * t)[:n, n:]) @ u for t in np.asarray(ts, float)])

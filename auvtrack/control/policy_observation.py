"""The observation of a learned policy: one compiled function shared by the Gymnasium environment and the law.

Layout :data:`OBS` (float64, every entry clipped to +-:data:`OBS_BOUND` of its group):

==================  ====  ==========================================================================
``error``           3     reference position minus vehicle position at ``t``, body frame (m)
``velocity_error``  3     reference velocity (body frame) minus (u, v, w) (m/s)
``nu``              5     (u, v, w, q, r) (m/s, rad/s)
``attitude``        4     (cos theta, sin theta, cos psi, sin psi)
``heading_error``   2     (sin, cos) of the reference's course minus psi ((0, 1) when it hovers)
``preview``         9     reference position at t + :data:`PREVIEW` s minus vehicle position, body frame (m)
``last_action``     3     what the actuators produce now over the action scale (the held action)
==================  ====  ==========================================================================

The body frame is Rz(psi) Ry(theta) (roll is not measured, :class:`~auvtrack.control.contract.Measured`):
vectors are turned by :func:`auvtrack.vehicle.kinematics.body_from_ned`.
"""
from __future__ import annotations

import numpy as np

from ..jit import njit_noalloc
from ..packing import packed_layout
from ..reference.kernel import reference_point
from ..vehicle.kinematics import body_from_ned

OBS = packed_layout("PolicyObservation", error=3, velocity_error=3, nu=5, attitude=4, heading_error=2,
                    preview=9, last_action=3)
"""Observation layout."""
PREVIEW = (2.0, 5.0, 10.0)
"""Preview horizons (s)."""
BOUNDS = {"error": 100.0, "velocity_error": 20.0, "nu": 20.0, "attitude": 1.0, "heading_error": 1.0,
          "preview": 200.0, "last_action": 10.0}
"""Clip bound of each group (the Box of the environment)."""


def obs_bounds() -> np.ndarray:
    """The clip bound of every observation entry (shape ``(OBS.size,)``).

    Returns
    -------
    numpy.ndarray
        Positive bounds, in :data:`OBS` order.
    """
    b = np.empty(OBS.size)
    for name in OBS.names:
        b[OBS.span(name)] = BOUNDS[name]
    return b


OBS_BOUND = obs_bounds()


@njit_noalloc(inline="always")
def observe(t, eta, nu, att, path, applied, scale, bound, obs):
    """Write the observation of the measured state (eta, nu, att) at ``t`` into ``obs`` (layout :data:`OBS`).

    Parameters
    ----------
    t : float
        Time (s).
    eta, nu, att : tuple
        Measured pose, velocities and attitude (:class:`~auvtrack.control.contract.Measured`).
    path : numpy.ndarray
        The packed reference.
    applied : tuple of 3 float
        What the actuators produce now (the law's command units).
    scale : numpy.ndarray
        Action scale (3,): command = scale * action.
    bound : numpy.ndarray
        Clip bounds (:data:`OBS_BOUND`).
    obs : numpy.ndarray
        Written, shape (OBS.size,).
    """
    p, v, _ = reference_point(path, t)
    ex, ey, ez = body_from_ned(att, (p[0] - eta[0], p[1] - eta[1], p[2] - eta[2]))
    obs[OBS.error], obs[OBS.error + 1], obs[OBS.error + 2] = ex, ey, ez
    bx, by, bz = body_from_ned(att, (v[0], v[1], v[2]))
    obs[OBS.velocity_error], obs[OBS.velocity_error + 1], obs[OBS.velocity_error + 2] = bx - nu[0], by - nu[1], bz - nu[2]
    for i in range(5):
        obs[OBS.nu + i] = nu[i]
    for i in range(4):
        obs[OBS.attitude + i] = att[i]
    vh = (v[0] * v[0] + v[1] * v[1]) ** 0.5
    s, c = 0.0, 1.0
    if vh > 1e-9:
        c = (v[0] * att[2] + v[1] * att[3]) / vh
        s = (v[1] * att[2] - v[0] * att[3]) / vh
    obs[OBS.heading_error], obs[OBS.heading_error + 1] = s, c
    for j in range(3):
        q, _, _ = reference_point(path, t + PREVIEW[j])
        qx, qy, qz = body_from_ned(att, (q[0] - eta[0], q[1] - eta[1], q[2] - eta[2]))
        obs[OBS.preview + 3 * j], obs[OBS.preview + 3 * j + 1], obs[OBS.preview + 3 * j + 2] = qx, qy, qz
    for i in range(3):
        obs[OBS.last_action + i] = applied[i] / scale[i]
    for i in range(OBS.size):
        b = bound[i]
        x = obs[i]
        if not x <= b:  # also NaN
            x = b if x == x else 0.0
        if x < -b:
            x = -b
        obs[i] = x

"""Kinetics of the 5-DOF AUV (paper eq. 1 and its reduced form eq. 4).

    M nu_dot + C(nu) nu + D nu + G(eta) = tau + omega,    tau = [tau_u, 0, 0, tau_q, tau_r]

with M = diag(m11..m55), C(nu) = c_scale * C0(nu) (skew-symmetric C0 of eq. 1),
D = diag(d11..d55) and G = [0, 0, 0, rho g nabla GM_L sin(theta), 0].  Units: N, N m.
Parameters come packed in ``vp`` (layout in :mod:`auvtrack.vehicle.params`).  The same function
serves the true plant (uncertain ``vp``, disturbance ``omega``) and the nominal model used by
controllers (nominal ``vp``, ``omega = 0``), so there is one source of truth for eq. (1).
The unactuated sway and heave equations are simulated in full:
m22 v_dot = -c m11 u r - d22 v + omega_v,  m33 w_dot = c m11 u q - d33 w + omega_w.
Vectors are tuples (see :mod:`auvtrack.vehicle.kinematics`).
"""
from __future__ import annotations

from ..jit import njit_noalloc
from .params import VP


@njit_noalloc
def generalized_forces(att, nu, vp):
    """C(nu) nu + D nu + G(eta) of eq. (1) as a 5-tuple (N, N m); ``att`` gives sin(theta)."""
    u, v, w, q, r = nu[0], nu[1], nu[2], nu[3], nu[4]
    m11, m22, m33 = vp[VP.m], vp[VP.m + 1], vp[VP.m + 2]
    c = vp[VP.cscale]
    return (c * (m33 * w * q - m22 * v * r) + vp[VP.d] * u,
            c * (m11 * u * r) + vp[VP.d + 1] * v,
            c * (-m11 * u * q) + vp[VP.d + 2] * w,
            c * ((m11 - m33) * u * w) + vp[VP.d + 3] * q + vp[VP.wgml] * att[1],
            c * ((m22 - m11) * u * v) + vp[VP.d + 4] * r)


@njit_noalloc
def nu_dot(att, nu, tau3, omega, vp):
    """Kinetics eq. (1): d/dt nu (5-tuple; m/s^2 ×3, rad/s^2 ×2) for input tau3 = (tau_u (N), tau_q, tau_r (N m))."""
    g = generalized_forces(att, nu, vp)
    return ((tau3[0] + omega[0] - g[0]) / vp[VP.m],
            (omega[1] - g[1]) / vp[VP.m + 1],
            (omega[2] - g[2]) / vp[VP.m + 2],
            (tau3[1] + omega[3] - g[3]) / vp[VP.m + 3],
            (tau3[2] + omega[4] - g[4]) / vp[VP.m + 4])

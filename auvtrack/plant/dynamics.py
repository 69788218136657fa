"""Kinetics of the 5-DOF AUV (paper eq. 1 and its reduced form eq. 4).

    M nu_dot + C(nu) nu + D nu + G(eta) = tau + omega,    tau = [tau_u, 0, 0, tau_q, tau_r]

with M = diag(m11..m55), C(nu) = c_scale * C0(nu) (skew-symmetric C0 of eq. 1),
D = diag(d11..d55) and G = [0, 0, 0, rho g nabla GM_L sin(theta), 0].  Units: N, N m.
Parameters come packed in ``vp`` (layout in :mod:`auvtrack.plant.params`).  The same function
serves the true plant (uncertain ``vp``, disturbance ``omega``) and the nominal model used by
controllers (nominal ``vp``, ``omega = 0``), so there is one source of truth for eq. (1).
The unactuated sway and heave equations are simulated in full:
m22 v_dot = -c m11 u r - d22 v + omega_v,  m33 w_dot = c m11 u q - d33 w + omega_w.
"""
from __future__ import annotations

import math

from .._jit import njit
from .params import CSCALE, D0, M0, WGML


@njit
def generalized_forces(eta, nu, vp, out):
    """Write C(nu) nu + D nu + G(eta) (5,), in N and N m, into ``out`` (eq. 1)."""
    u, v, w, q, r = nu[0], nu[1], nu[2], nu[3], nu[4]
    m11, m22, m33 = vp[M0], vp[M0 + 1], vp[M0 + 2]
    c = vp[CSCALE]
    out[0] = c * (m33 * w * q - m22 * v * r) + vp[D0] * u
    out[1] = c * (m11 * u * r) + vp[D0 + 1] * v
    out[2] = c * (-m11 * u * q) + vp[D0 + 2] * w
    out[3] = c * ((m11 - m33) * u * w) + vp[D0 + 3] * q + vp[WGML] * math.sin(eta[3])
    out[4] = c * ((m22 - m11) * u * v) + vp[D0 + 4] * r


@njit
def nu_dot(eta, nu, tau3, omega, vp, out):
    """Kinetics eq. (1): write d/dt nu (5,) for input tau3 = [tau_u, tau_q, tau_r] into ``out``."""
    generalized_forces(eta, nu, vp, out)
    out[0] = (tau3[0] + omega[0] - out[0]) / vp[M0]
    out[1] = (omega[1] - out[1]) / vp[M0 + 1]
    out[2] = (omega[2] - out[2]) / vp[M0 + 2]
    out[3] = (tau3[1] + omega[3] - out[3]) / vp[M0 + 3]
    out[4] = (tau3[2] + omega[4] - out[4]) / vp[M0 + 4]

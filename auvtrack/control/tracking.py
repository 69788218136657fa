"""Virtual-point tracking error and the input map shared by every controller.

With eta1 the virtual point (eq. 2) and eta_d the reference,

    e      = eta1 - eta_d                                   (m)
    e_dot  = J3 v1 + J4 - eta_d_dot                         (eq. 14, m/s)
    e_ddot = f + J3 v1_dot,  f = J3_dot v1 + J4_dot - eta_d_ddot          (eq. 15 corrected, m/s^2)
    M_bar v1_dot = tau_bar - (C_bar v1 + D_bar v1 + G_bar)  (eq. 4, nominal model)

J4_dot needs the unactuated sway/heave accelerations; controllers take them from the nominal
model (ERRATA 4); everything the nominal model misses is the lumped disturbance chi.
:func:`input_for_accel` inverts the map: the nominal input that yields a desired e_ddot.
All functions are compiled and allocation-free; ``work`` is caller scratch of length >= 32.
"""
from __future__ import annotations

import math

from .._jit import njit
from ..plant.dynamics import generalized_forces
from ..plant.kinematics import j3_dot, j4, j4_dot, virtual_point
from ..plant.params import ELL, M0


@njit
def error_state(eta, nu, refm, vp, e, e_dot, f, work):
    """Write e, e_dot and the input-free part f of e_ddot (3,) for nominal model ``vp``.

    ``refm`` rows are eta_d, eta_d_dot, eta_d_ddot.  ``work`` needs 26 entries.
    """
    ell = vp[ELL]
    th, ps = eta[3], eta[4]
    ct, st = math.cos(th), math.sin(th)
    cp, sp = math.cos(ps), math.sin(ps)
    u, v, w, q, r = nu[0], nu[1], nu[2], nu[3], nu[4]
    p1 = work[0:3]
    virtual_point(eta, ell, p1)
    dr = work[3:6]
    j4(th, ps, v, w, dr)
    # J3 v1 written out (J3 of eq. 3, corrected)
    e_dot[0] = ct * cp * u - ell * st * cp * q - ell * sp * r + dr[0] - refm[1, 0]
    e_dot[1] = ct * sp * u - ell * st * sp * q + ell * cp * r + dr[1] - refm[1, 1]
    e_dot[2] = -st * u - ell * ct * q + dr[2] - refm[1, 2]
    for i in range(3):
        e[i] = p1[i] - refm[0, i]
    # nominal sway/heave accelerations for J4_dot (ERRATA 4)
    gf = work[6:11]
    generalized_forces(eta, nu, vp, gf)
    v_dot = -gf[1] / vp[M0 + 1]
    w_dot = -gf[2] / vp[M0 + 2]
    th_dot, ps_dot = q, r / ct
    jd = work[11:20].reshape((3, 3))
    j3_dot(th, ps, th_dot, ps_dot, ell, jd)
    j4d = work[20:23]
    j4_dot(th, ps, v, w, th_dot, ps_dot, v_dot, w_dot, j4d)
    for i in range(3):
        f[i] = jd[i, 0] * u + jd[i, 1] * q + jd[i, 2] * r + j4d[i] - refm[2, i]


@njit
def input_for_accel(eta, nu, vp, f, acc, tau, work):
    """Nominal input tau_bar = [tau_u, tau_q, tau_r] giving e_ddot = acc (ERRATA 13 route).

    v1_dot = J3^-1 (acc - f);  tau_bar = M_bar v1_dot + C_bar v1 + D_bar v1 + G_bar.
    ``work`` needs 5 entries.
    """
    ell = vp[ELL]
    th, ps = eta[3], eta[4]
    ct, st = math.cos(th), math.sin(th)
    cp, sp = math.cos(ps), math.sin(ps)
    b0, b1, b2 = acc[0] - f[0], acc[1] - f[1], acc[2] - f[2]
    # closed-form J3^-1 (det J3 = ell^2), see plant.kinematics.j3_inv
    u_dot = ct * cp * b0 + ct * sp * b1 - st * b2
    q_dot = (-st * cp * b0 - st * sp * b1 - ct * b2) / ell
    r_dot = (-sp * b0 + cp * b1) / ell
    gf = work[0:5]
    generalized_forces(eta, nu, vp, gf)
    tau[0] = vp[M0] * u_dot + gf[0]
    tau[1] = vp[M0 + 3] * q_dot + gf[3]
    tau[2] = vp[M0 + 4] * r_dot + gf[4]


@njit
def sig(x, p):
    """sig^p(x) = |x|^p sign(x) (Notation 1)."""
    if x > 0.0:
        return x**p
    if x < 0.0:
        return -((-x) ** p)
    return 0.0


@njit
def sign(x):
    """sign(x) with sign(0) = 0."""
    if x > 0.0:
        return 1.0
    if x < 0.0:
        return -1.0
    return 0.0


@njit
def lumped_disturbance(eta, nu_dot_true, nu_dot_nom, ell, out):
    """True lumped disturbance chi (m/s^2): e_ddot(true plant) - e_ddot(nominal model), same input.

    chi = J3 (v1_dot_true - v1_dot_nom) + dJ4_dot/d(v_dot, w_dot) (v_dot, w_dot differences),
    i.e. everything eq. (15) with the nominal model does not predict (ERRATA 4).
    """
    th, ps = eta[3], eta[4]
    ct, st = math.cos(th), math.sin(th)
    cp, sp = math.cos(ps), math.sin(ps)
    du = nu_dot_true[0] - nu_dot_nom[0]
    dv = nu_dot_true[1] - nu_dot_nom[1]
    dw = nu_dot_true[2] - nu_dot_nom[2]
    dq = nu_dot_true[3] - nu_dot_nom[3]
    dr = nu_dot_true[4] - nu_dot_nom[4]
    out[0] = ct * cp * du - ell * st * cp * dq - ell * sp * dr - dv * sp + dw * st * cp
    out[1] = ct * sp * du - ell * st * sp * dq + ell * cp * dr + dv * cp + dw * st * sp
    out[2] = -st * du - ell * ct * dq + dw * ct

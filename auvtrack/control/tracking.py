"""Virtual-point tracking error and the input map shared by every controller.

With eta1 the virtual point (eq. 2) and eta_d the reference,

    e      = eta1 - eta_d                                   (m)
    e_dot  = J3 v1 + J4 - eta_d_dot                         (eq. 14, m/s)
    e_ddot = f + J3 v1_dot,  f = J3_dot v1 + J4_dot - eta_d_ddot          (eq. 15 corrected, m/s^2)
    M_bar v1_dot = tau_bar - (C_bar v1 + D_bar v1 + G_bar)  (eq. 4, nominal model)

J4_dot needs the unactuated sway/heave accelerations; controllers take them from the nominal
model (ERRATA 4); everything the nominal model misses is the lumped disturbance chi.
:func:`input_for_accel` inverts the map: the nominal input that yields a desired e_ddot.
All functions are compiled and work on tuples (see :mod:`auvtrack.vehicle.kinematics`).
"""
from __future__ import annotations

from ..jit import njit, njit_noalloc
from ..vehicle.dynamics import generalized_forces
from ..vehicle.kinematics import j3, j3_dot, j3_inv, j4, j4_dot, virtual_point
from ..vehicle.params import VP


@njit
def mat_vec(A, x):
    """A x for a 3x3 tuple-of-rows A and a 3-tuple x."""
    return (A[0][0] * x[0] + A[0][1] * x[1] + A[0][2] * x[2],
            A[1][0] * x[0] + A[1][1] * x[1] + A[1][2] * x[2],
            A[2][0] * x[0] + A[2][1] * x[1] + A[2][2] * x[2])


@njit_noalloc
def error_state(eta, att, nu, refm, vp):
    """Return (e (m), e_dot (m/s), f (m/s^2)) as 3-tuples for the nominal model ``vp`` (eq. 14-15).

    ``refm`` rows are eta_d, eta_d_dot, eta_d_ddot; f is the input-free part of e_ddot.
    """
    e, ed, f, _ = error_state_forces(eta, att, nu, refm, vp)
    return e, ed, f


@njit_noalloc(inline="always")
def error_state_forces(eta, att, nu, refm, vp):
    """:func:`error_state` plus the nominal C nu + D nu + G of eq. (1) as a 5-tuple.

    The forces are reused by :func:`input_for_accel_forces` at the same state (one evaluation
    per controller call).
    """
    ell = vp[VP.ell]
    u, v, w, q, r = nu[0], nu[1], nu[2], nu[3], nu[4]
    v1 = (u, q, r)
    p1 = virtual_point(eta, att, ell)
    jv = mat_vec(j3(att, ell), v1)
    d4 = j4(att, v, w)
    e = (p1[0] - refm[0, 0], p1[1] - refm[0, 1], p1[2] - refm[0, 2])
    ed = (jv[0] + d4[0] - refm[1, 0], jv[1] + d4[1] - refm[1, 1], jv[2] + d4[2] - refm[1, 2])
    # nominal sway/heave accelerations for J4_dot (ERRATA 4)
    g = generalized_forces(att, nu, vp)
    v_dot, w_dot = -g[1] / vp[VP.m + 1], -g[2] / vp[VP.m + 2]
    th_dot, ps_dot = q, r / att[0]
    jd = mat_vec(j3_dot(att, th_dot, ps_dot, ell), v1)
    d4d = j4_dot(att, v, w, th_dot, ps_dot, v_dot, w_dot)
    f = (jd[0] + d4d[0] - refm[2, 0], jd[1] + d4d[1] - refm[2, 1], jd[2] + d4d[2] - refm[2, 2])
    return e, ed, f, g


@njit_noalloc
def input_for_accel(att, nu, vp, f, acc):
    """Nominal input tau_bar = (tau_u (N), tau_q, tau_r (N m)) giving e_ddot = acc (m/s^2): eq. (30)-(32) via ERRATA 13.

    v1_dot = J3^-1 (acc - f);  tau_bar = M_bar v1_dot + C_bar v1 + D_bar v1 + G_bar.
    """
    return input_for_accel_forces(att, vp, f, acc, generalized_forces(att, nu, vp))


@njit_noalloc
def input_for_accel_forces(att, vp, f, acc, g):
    """:func:`input_for_accel` with g = generalized_forces(att, nu, vp) already evaluated."""
    a = mat_vec(j3_inv(att, vp[VP.ell]), (acc[0] - f[0], acc[1] - f[1], acc[2] - f[2]))
    return vp[VP.m] * a[0] + g[0], vp[VP.m + 3] * a[1] + g[3], vp[VP.m + 4] * a[2] + g[4]


@njit
def lumped_disturbance(att, nu_dot_true, nu_dot_nom, ell):
    """True lumped disturbance chi of eq. (15) (m/s^2): e_ddot(true plant) - e_ddot(nominal model), same input.

    chi = J3 (v1_dot_true - v1_dot_nom) + the J4_dot terms of the sway/heave acceleration
    differences, i.e. everything eq. (15) with the nominal model does not predict (ERRATA 4).
    """
    d = (nu_dot_true[0] - nu_dot_nom[0], nu_dot_true[1] - nu_dot_nom[1], nu_dot_true[2] - nu_dot_nom[2],
         nu_dot_true[3] - nu_dot_nom[3], nu_dot_true[4] - nu_dot_nom[4])
    a = mat_vec(j3(att, ell), (d[0], d[3], d[4]))
    b = j4_dot(att, 0.0, 0.0, 0.0, 0.0, d[1], d[2])  # J4_dot is linear in (v_dot, w_dot)
    return a[0] + b[0], a[1] + b[1], a[2] + b[2]


@njit
def sig(x, p):
    """sig^p(x) = |x|^p sign(x) (Notation 1)."""
    if x > 0.0:
        return x**p
    if x < 0.0:
        return -((-x) ** p)
    return 0.0


@njit
def sig_pair(x, p):
    """(sig^p(x), sig^(2-p)(x)) with one pow, for 1 < p < 2 (FTSMC).

    With a = |x| and q = a^(p-1):  a^p = a q  and  a^(2-p) = a / q  (q >= min(a, 1): no overflow).
    """
    if not (x > 0.0 or x < 0.0):  # 0 (and NaN) -> 0, as sig
        return 0.0, 0.0
    a = abs(x)
    q = a ** (p - 1.0)
    s = 1.0 if x > 0.0 else -1.0
    return s * (a * q), s * (a / q)


@njit
def sign(x):
    """sign(x) with sign(0) = 0."""
    if x > 0.0:
        return 1.0
    if x < 0.0:
        return -1.0
    return 0.0

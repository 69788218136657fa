"""Kinematics of the 5-DOF AUV (paper eq. 1-3, corrected per ERRATA 1-2).

States
------
eta = (x, y, z, theta, psi)   position in the NED frame (m) and pitch, yaw (rad)
nu  = (u, v, w, q, r)         surge, sway, heave (m/s) and pitch, yaw rate (rad/s)
v1  = (u, q, r)               the actuated velocities of eq. (4)
att = (cos theta, sin theta, cos psi, sin psi), from :func:`attitude`

Roll is neglected (phi = 0), so J1 is the NED rotation with roll removed and
theta_dot = q, psi_dot = r / cos(theta).  The paper writes yaw as phi; we write psi.

The virtual point eta1 (eq. 2) sits ``ell`` metres ahead of the centre of gravity along the
body x axis.  Its velocity is ``d/dt eta1 = J3 v1 + J4`` (eq. 3) with the corrected
J3[2, 1] = -ell cos(theta) (ERRATA 2), so det J3 = ell**2.

All functions are compiled, take and return tuples (vectors as 3- or 5-tuples, matrices as
tuples of rows): no arrays and no slicing, which keeps the hot path free of allocation and
reference counting.  The trigonometric functions are evaluated once per call site through
``att``.

References
----------
Fossen, T. I. (2021). Handbook of Marine Craft Hydrodynamics and Motion Control, 2nd ed., ch. 2.
Paper eq. (1)-(3); ERRATA points 1, 2, 4.
"""
from __future__ import annotations


from ..jit import njit
from ..jit.vecmath import sincos4


@njit
def attitude(theta, psi):
    """Return att = (cos theta, sin theta, cos psi, sin psi), within 4 ulp (:func:`auvtrack.jit.vecmath.sincos4`)."""
    s, c = sincos4((theta, psi, 0.0, 0.0))
    return c[0], s[0], c[1], s[1]


@njit
def eta_dot(att, nu):
    """Kinematics eq. (1) with the corrected J1 (ERRATA 1): d/dt eta as a 5-tuple (m/s ×3, rad/s ×2)."""
    ct, st, cp, sp = att
    u, v, w, q, r = nu[0], nu[1], nu[2], nu[3], nu[4]
    return (ct * cp * u - sp * v + st * cp * w,
            ct * sp * u + cp * v + st * sp * w,
            -st * u + ct * w,
            q,
            r / ct)


@njit
def body_from_ned(att, v):
    """J1(theta, psi)^T v: a NED vector v (e.g. a current, m/s) in body axes (J1 of eq. 1, ERRATA 1)."""
    ct, st, cp, sp = att
    return (ct * cp * v[0] + ct * sp * v[1] - st * v[2],
            -sp * v[0] + cp * v[1],
            st * cp * v[0] + st * sp * v[1] + ct * v[2])


@njit
def virtual_point(eta, att, ell):
    """Virtual point eta1 of eq. (2), metres, as a 3-tuple."""
    ct, st, cp, sp = att
    return eta[0] + ell * ct * cp, eta[1] + ell * ct * sp, eta[2] - ell * st


@njit
def j3(att, ell):
    """Input matrix J3 of eq. (3), corrected (ERRATA 2), as a tuple of rows: J3 v1 in m/s for v1 = (u, q, r)."""
    ct, st, cp, sp = att
    return ((ct * cp, -ell * st * cp, -ell * sp),
            (ct * sp, -ell * st * sp, ell * cp),
            (-st, -ell * ct, 0.0))


@njit
def j3_inv(att, ell):
    """Closed-form inverse of J3 of eq. (3) (det J3 = ell**2), as a tuple of rows (maps m/s to (m/s, rad/s, rad/s))."""
    ct, st, cp, sp = att
    return ((ct * cp, ct * sp, -st),
            (-st * cp / ell, -st * sp / ell, -ct / ell),
            (-sp / ell, cp / ell, 0.0))


@njit
def j4(att, v, w):
    """Drift term J4 of eq. (3), m/s, as a 3-tuple."""
    ct, st, cp, sp = att
    return -v * sp + w * st * cp, v * cp + w * st * sp, w * ct


@njit
def j3_dot(att, theta_dot, psi_dot, ell):
    """Time derivative of J3 of eq. (3) along (theta_dot, psi_dot) (rad/s), as a tuple of rows (eq. 15)."""
    ct, st, cp, sp = att
    td, pd = theta_dot, psi_dot
    return ((-st * cp * td - ct * sp * pd, -ell * (ct * cp * td - st * sp * pd), -ell * cp * pd),
            (-st * sp * td + ct * cp * pd, -ell * (ct * sp * td + st * cp * pd), -ell * sp * pd),
            (-ct * td, ell * st * td, 0.0))


@njit
def j4_dot(att, v, w, theta_dot, psi_dot, v_dot, w_dot):
    """Time derivative of J4 of eq. (3) (m/s^2; needs the sway/heave accelerations, ERRATA 4), as a 3-tuple (eq. 15)."""
    ct, st, cp, sp = att
    td, pd = theta_dot, psi_dot
    return (-v_dot * sp - v * cp * pd + w_dot * st * cp + w * (ct * cp * td - st * sp * pd),
            v_dot * cp - v * sp * pd + w_dot * st * sp + w * (ct * sp * td + st * cp * pd),
            w_dot * ct - w * st * td)

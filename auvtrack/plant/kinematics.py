"""Kinematics of the 5-DOF AUV (paper eq. 1-3, corrected per ERRATA 1-2).

States
------
eta = [x, y, z, theta, psi]   position in the NED frame (m) and pitch, yaw (rad)
nu  = [u, v, w, q, r]         surge, sway, heave (m/s) and pitch, yaw rate (rad/s)
v1  = [u, q, r]               the actuated velocities of eq. (4)

Roll is neglected (phi = 0), so J1 is the NED rotation with roll removed and
theta_dot = q, psi_dot = r / cos(theta).  The paper writes yaw as phi; we write psi.

The virtual point eta1 (eq. 2) sits ``ell`` metres ahead of the centre of gravity along the
body x axis.  Its velocity is ``d/dt eta1 = J3 v1 + J4`` (eq. 3) with the corrected
J3[2, 1] = -ell cos(theta) (ERRATA 2), so det J3 = ell**2.

All functions are compiled and write into caller-provided output arrays (no allocation).

References
----------
Fossen, T. I. (2021). Handbook of Marine Craft Hydrodynamics and Motion Control, 2nd ed., ch. 2.
Paper eq. (1)-(3); ERRATA points 1, 2, 4.
"""
from __future__ import annotations

import math

from .._jit import njit


@njit
def eta_dot(eta, nu, out):
    """Kinematics eq. (1), corrected J1 (ERRATA 1): write d/dt eta (5,) into ``out``."""
    ct, st = math.cos(eta[3]), math.sin(eta[3])
    cp, sp = math.cos(eta[4]), math.sin(eta[4])
    u, v, w = nu[0], nu[1], nu[2]
    out[0] = ct * cp * u - sp * v + st * cp * w
    out[1] = ct * sp * u + cp * v + st * sp * w
    out[2] = -st * u + ct * w
    out[3] = nu[3]
    out[4] = nu[4] / ct


@njit
def virtual_point(eta, ell, out):
    """Virtual point eta1 (eq. 2), metres: write (3,) into ``out``."""
    ct, st = math.cos(eta[3]), math.sin(eta[3])
    out[0] = eta[0] + ell * ct * math.cos(eta[4])
    out[1] = eta[1] + ell * ct * math.sin(eta[4])
    out[2] = eta[2] - ell * st


@njit
def j3(theta, psi, ell, out):
    """Input matrix J3 of eq. (3), corrected (ERRATA 2): write (3, 3) into ``out``."""
    ct, st = math.cos(theta), math.sin(theta)
    cp, sp = math.cos(psi), math.sin(psi)
    out[0, 0] = ct * cp
    out[0, 1] = -ell * st * cp
    out[0, 2] = -ell * sp
    out[1, 0] = ct * sp
    out[1, 1] = -ell * st * sp
    out[1, 2] = ell * cp
    out[2, 0] = -st
    out[2, 1] = -ell * ct
    out[2, 2] = 0.0


@njit
def j3_inv(theta, psi, ell, out):
    """Closed-form inverse of J3 (det J3 = ell**2): write (3, 3) into ``out``."""
    ct, st = math.cos(theta), math.sin(theta)
    cp, sp = math.cos(psi), math.sin(psi)
    out[0, 0] = ct * cp
    out[0, 1] = ct * sp
    out[0, 2] = -st
    out[1, 0] = -st * cp / ell
    out[1, 1] = -st * sp / ell
    out[1, 2] = -ct / ell
    out[2, 0] = -sp / ell
    out[2, 1] = cp / ell
    out[2, 2] = 0.0


@njit
def j4(theta, psi, v, w, out):
    """Drift term J4 of eq. (3), m/s: write (3,) into ``out``."""
    ct, st = math.cos(theta), math.sin(theta)
    cp, sp = math.cos(psi), math.sin(psi)
    out[0] = -v * sp + w * st * cp
    out[1] = v * cp + w * st * sp
    out[2] = w * ct


@njit
def j3_dot(theta, psi, theta_dot, psi_dot, ell, out):
    """Time derivative of J3 along (theta_dot, psi_dot): write (3, 3) into ``out``."""
    ct, st = math.cos(theta), math.sin(theta)
    cp, sp = math.cos(psi), math.sin(psi)
    td, pd = theta_dot, psi_dot
    out[0, 0] = -st * cp * td - ct * sp * pd
    out[0, 1] = -ell * (ct * cp * td - st * sp * pd)
    out[0, 2] = -ell * cp * pd
    out[1, 0] = -st * sp * td + ct * cp * pd
    out[1, 1] = -ell * (ct * sp * td + st * cp * pd)
    out[1, 2] = -ell * sp * pd
    out[2, 0] = -ct * td
    out[2, 1] = ell * st * td
    out[2, 2] = 0.0


@njit
def j4_dot(theta, psi, v, w, theta_dot, psi_dot, v_dot, w_dot, out):
    """Time derivative of J4 (needs the sway/heave accelerations, ERRATA 4): write (3,)."""
    ct, st = math.cos(theta), math.sin(theta)
    cp, sp = math.cos(psi), math.sin(psi)
    td, pd = theta_dot, psi_dot
    out[0] = -v_dot * sp - v * cp * pd + w_dot * st * cp + w * (ct * cp * td - st * sp * pd)
    out[1] = v_dot * cp - v * sp * pd + w_dot * st * sp + w * (ct * sp * td + st * cp * pd)
    out[2] = w_dot * ct - w * st * td

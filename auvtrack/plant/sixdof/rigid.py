"""6-DOF rigid-body kinematics and kinetics shared by the truth plants (zyx Euler angles).

States
------
eta6 = (x, y, z, phi, theta, psi)   NED position (m) and roll, pitch, yaw (rad)
nu6  = (u, v, w, p, q, r)           body linear (m/s) and angular (rad/s) velocity

Kinematics (Fossen 2021, eq. 2.18, 2.29 and 2.41)::

    d/dt (x, y, z) = R(phi, theta, psi) (u, v, w)
    d/dt (phi, theta, psi) = T(phi, theta) (p, q, r)

Kinetics: ``M nu_dot + C(nu) nu + ... = tau`` with a constant symmetric positive definite M.
:func:`kirchhoff` gives ``C(nu) nu`` in the velocity-independent Kirchhoff form
(Fossen 2021, Theorem 3.2 / eq. 3.46 and 6.43)::

    C(nu) nu = [ nu2 x (M11 nu1 + M12 nu2) ;
                 nu2 x (M21 nu1 + M22 nu2) + nu1 x (M11 nu1 + M12 nu2) ]

which is the rigid-body Coriolis and centripetal term for M = M_RB (about any origin, CG offset
included) and the Munk / added-mass Coriolis term for M = M_A.  ``nu^T C(nu) nu = 0``, so with
no other force ``1/2 nu^T M nu`` is conserved.

Matrices live in a packed float64 array ``pp`` as 36 numbers, row-major, from an offset.  Every
compiled function here is allocation-free and works on tuples.  Python-side helpers build the
matrices (NumPy) for the presets.

References
----------
Fossen, T. I. (2021). Handbook of Marine Craft Hydrodynamics and Motion Control, 2nd ed., Wiley,
ch. 2 (kinematics), ch. 3 (rigid-body kinetics), ch. 4 (restoring forces), ch. 6 (added mass).
"""
from __future__ import annotations

import math

import numpy as np

from ...jit import njit_noalloc

G_ACC = 9.81  # m/s^2, used by both REMUS sources


@njit_noalloc(inline="always")
def trig6(phi, theta, psi):
    """(c_phi, s_phi, c_theta, s_theta, c_psi, s_psi) of the Euler angles (rad)."""
    return (math.cos(phi), math.sin(phi), math.cos(theta), math.sin(theta),
            math.cos(psi), math.sin(psi))


@njit_noalloc(inline="always")
def trig_att(phi, att):
    """:func:`trig6` from roll (rad) and att = (cos theta, sin theta, cos psi, sin psi)."""
    return math.cos(phi), math.sin(phi), att[0], att[1], att[2], att[3]


@njit_noalloc(inline="always")
def rotation(tr):
    """R(phi, theta, psi) of Fossen 2021 eq. (2.18) (body -> NED) as a tuple of rows; ``tr`` from :func:`trig6`."""
    cf, sf, ct, st, cp, sp = tr
    return ((cp * ct, -sp * cf + cp * st * sf, sp * sf + cp * cf * st),
            (sp * ct, cp * cf + sf * st * sp, -cp * sf + st * sp * cf),
            (-st, ct * sf, ct * cf))


@njit_noalloc(inline="always")
def ned_velocity(tr, u, v, w):
    """R(Theta) (u, v, w): NED velocity (m/s) of the body velocity, eq. (2.18)."""
    R = rotation(tr)
    return (R[0][0] * u + R[0][1] * v + R[0][2] * w,
            R[1][0] * u + R[1][1] * v + R[1][2] * w,
            R[2][0] * u + R[2][1] * v + R[2][2] * w)


@njit_noalloc(inline="always")
def body_from_ned6(tr, vx, vy, vz):
    """R(Theta)^T (vx, vy, vz): a NED vector (e.g. a current, m/s) in body axes."""
    R = rotation(tr)
    return (R[0][0] * vx + R[1][0] * vy + R[2][0] * vz,
            R[0][1] * vx + R[1][1] * vy + R[2][1] * vz,
            R[0][2] * vx + R[1][2] * vy + R[2][2] * vz)


@njit_noalloc(inline="always")
def euler_rates(tr, p, q, r):
    """T(phi, theta) (p, q, r) of Fossen 2021 eq. (2.41): (phi_dot, theta_dot, psi_dot), rad/s (singular at |theta| = 90 deg)."""
    cf, sf, ct, st = tr[0], tr[1], tr[2], tr[3]
    return (p + (sf * q + cf * r) * st / ct,
            cf * q - sf * r,
            (sf * q + cf * r) / ct)


@njit_noalloc(inline="always")
def matvec6(pp, off, a0, a1, a2, a3, a4, a5):
    """(M a) for the 6x6 row-major matrix ``pp[off:off+36]`` and the vector a (6-tuple)."""
    return (pp[off] * a0 + pp[off + 1] * a1 + pp[off + 2] * a2 + pp[off + 3] * a3 + pp[off + 4] * a4 + pp[off + 5] * a5,
            pp[off + 6] * a0 + pp[off + 7] * a1 + pp[off + 8] * a2 + pp[off + 9] * a3 + pp[off + 10] * a4 + pp[off + 11] * a5,
            pp[off + 12] * a0 + pp[off + 13] * a1 + pp[off + 14] * a2 + pp[off + 15] * a3 + pp[off + 16] * a4 + pp[off + 17] * a5,
            pp[off + 18] * a0 + pp[off + 19] * a1 + pp[off + 20] * a2 + pp[off + 21] * a3 + pp[off + 22] * a4 + pp[off + 23] * a5,
            pp[off + 24] * a0 + pp[off + 25] * a1 + pp[off + 26] * a2 + pp[off + 27] * a3 + pp[off + 28] * a4 + pp[off + 29] * a5,
            pp[off + 30] * a0 + pp[off + 31] * a1 + pp[off + 32] * a2 + pp[off + 33] * a3 + pp[off + 34] * a4 + pp[off + 35] * a5)


@njit_noalloc(inline="always")
def kirchhoff(pp, off, u, v, w, p, q, r):
    """C(nu) nu in Kirchhoff form (Fossen 2021 eq. 3.46 / 6.43) for the symmetric M at ``pp[off:]`` (N, N m)."""
    P0, P1, P2, L0, L1, L2 = matvec6(pp, off, u, v, w, p, q, r)
    return (q * P2 - r * P1,
            r * P0 - p * P2,
            p * P1 - q * P0,
            q * L2 - r * L1 + v * P2 - w * P1,
            r * L0 - p * L2 + w * P0 - u * P2,
            p * L1 - q * L0 + u * P1 - v * P0)


@njit_noalloc(inline="always")
def restoring(tr, W, B, xg, yg, zg, xb, yb, zb):
    """g(eta) of Fossen 2021 eq. (4.6): restoring forces and moments (N, N m) for weight W at r_g and buoyancy B at r_b (m)."""
    cf, sf, ct, st = tr[0], tr[1], tr[2], tr[3]
    e0, e1, e2 = -st, ct * sf, ct * cf  # R^T (0, 0, 1): the NED down axis in body axes
    fx, fy, fz = (W - B) * e0, (W - B) * e1, (W - B) * e2  # f_g + f_b in body axes
    # moments r_g x f_g + r_b x f_b, f_g = W e, f_b = -B e
    mx = (yg * W - yb * B) * e2 - (zg * W - zb * B) * e1
    my = (zg * W - zb * B) * e0 - (xg * W - xb * B) * e2
    mz = (xg * W - xb * B) * e1 - (yg * W - yb * B) * e0
    return -fx, -fy, -fz, -mx, -my, -mz


# --- Python side -------------------------------------------------------------------------------

def skew(a) -> np.ndarray:
    """S(a): the 3x3 skew-symmetric matrix with S(a) b = a x b (Fossen 2021 eq. 2.10)."""
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


def rigid_body_mass(m: float, inertia, r_g) -> np.ndarray:
    """M_RB about the body origin CO (Fossen 2021 eq. 3.44).

    Parameters
    ----------
    m : float
        Mass, kg.
    inertia : array_like, shape (3, 3)
        Inertia tensor about CO, kg m^2.
    r_g : array_like, shape (3,)
        CG with respect to CO, m.

    Returns
    -------
    numpy.ndarray
        Shape (6, 6): ``[[m I, -m S(r_g)], [m S(r_g), I_o]]``.
    """
    S = skew(np.asarray(r_g, float))
    M = np.zeros((6, 6))
    M[:3, :3] = m * np.eye(3)
    M[:3, 3:] = -m * S
    M[3:, :3] = m * S
    M[3:, 3:] = np.asarray(inertia, float)
    return M


def inertia_about_origin(m: float, inertia_cg, r_g) -> np.ndarray:
    """Parallel-axis theorem I_o = I_g - m S(r_g)^2 (Fossen 2021 eq. 3.37), kg m^2."""
    S = skew(np.asarray(r_g, float))
    return np.asarray(inertia_cg, float) - m * S @ S


def check_spd(M: np.ndarray, name: str) -> None:
    """Raise ValueError unless M is symmetric (to 1e-12 relative) and positive definite."""
    if not np.allclose(M, M.T, rtol=0.0, atol=1e-12 * np.abs(M).max()):
        raise ValueError(f"{name}: mass matrix is not symmetric")
    if np.linalg.eigvalsh(0.5 * (M + M.T)).min() <= 0.0:
        raise ValueError(f"{name}: mass matrix is not positive definite")

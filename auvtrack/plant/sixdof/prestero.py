"""6-DOF REMUS 100 of Prestero (2001): equations of motion, control effectiveness, allocation.

Model (P01 eq. 3.x with the coefficient tables of ch. 4; Fossen 2021 eq. 10.1 for currents)::

    (M_RB + M_A) nu_dot = - C_RB(nu) nu - C_A(nu_r) nu_r + tau_h(nu_r) + tau_f + tau_p - g(eta)
                          + M_A nu_c_dot + tau_d

* ``M_RB`` about the centre of buoyancy with the CG offset r_g (P01's rigid-body equations);
  ``M_A = -[X_udot ... ; Y_rdot, Z_qdot off-diagonal]``; both SPD (checked at packing).
* ``C_RB(nu) nu``, ``C_A(nu_r) nu_r``: Kirchhoff form (:func:`auvtrack.plant.sixdof.rigid.kirchhoff`);
  the second is P01's set of added-mass cross terms (X_wq, X_vr, Y_wp, Z_vp, M_uwa, N_uva, ...),
  derived from M_A instead of typed (a test checks them against P01's printed values).
* ``tau_h``: axial drag X_u|u| u|u|; cross-flow drag Y_v|v| v|v|, Y_r|r| r|r|, Z_w|w| w|w|,
  Z_q|q| q|q|, K_p|p| p|p|, M_w|w| w|w|, M_q|q| q|q|, N_v|v| v|v|, N_r|r| r|r|; body and fin lift
  Y_uv u v, Y_urf u r, Z_uw u w, Z_uqf u q, M_uwlf u w, M_uqf u q, N_uvlf u v, N_urf u r, where
  each lift coefficient is P01's combined coefficient minus its Munk part (M_uw = 24.0 kg in all,
  of which the Munk moment is 34.57 kg and lift -10.57 kg).
* ``tau_f``: fin lift Y_uu_dr u^2 dr, Z_uu_ds u^2 ds, M_uu_ds u^2 ds, N_uu_dr u^2 dr.
* ``tau_p``: thrust T = X_prop s|s| and roll torque K_prop s|s|, s = n/n0 (P01's constant thrust
  and torque, scaled by the propeller speed at constant advance ratio; an assumption).
* ``g(eta)``: W at r_g, B at r_b (P01: W = 299 N, B = 306 N).
* currents: ``nu_r = nu - [R^T V_c; 0]`` with V_c the NED current (constant over a step), so
  ``nu_c_dot = [-omega x nu_c1; 0]``; every hydrodynamic term uses nu_r, the rigid body nu.
* ``tau_d``: additive disturbance forces [X, Y, Z, K, M, N] (N, N m).

Units: SI, angles in rad, propeller speed in rpm.  Sign convention of the fins: P01's (see the
data file).  Control channels (what a 5-DOF controller commands): tau_u = T (N),
tau_q = M_uu_ds u^2 ds, tau_r = N_uu_dr u^2 dr (N m).

References
----------
[P01] Prestero, T. (2001). Verification of a six-degree of freedom simulation model for the REMUS
autonomous underwater vehicle. MSc thesis, MIT/WHOI.  [F21] Fossen (2021), ch. 3, 6, 10.
"""
from __future__ import annotations

import math

import numpy as np

from ...jit import njit_noalloc
from .actuators import actuator_rates, clip, effective, fin_angle_for
from .layout import (CMD_DR, CMD_DS, CMD_N, P_B, P_DMAX, P_MA, P_MINV, P_MODEL, P_MRB, P_NMAX, P_RB,
                      P_RG, P_W, PP6_SIZE)
from ...vehicle.truth_presets import Preset6
from .rigid import (body_from_ned6, check_spd, euler_rates, kirchhoff, matvec6, ned_velocity,
                     restoring, rigid_body_mass, trig_att)

# model block: quadratic drag (10), lift (8), fins (4), propeller (3)
(Q_XUU, Q_YVV, Q_YRR, Q_ZWW, Q_ZQQ, Q_KPP, Q_MWW, Q_MQQ, Q_NVV, Q_NRR,
 L_YUV, L_YUR, L_ZUW, L_ZUQ, L_MUW, L_MUQ, L_NUV, L_NUR,
 F_YDR, F_ZDS, F_MDS, F_NDR,
 R_XPROP, R_KPROP, R_N0) = range(P_MODEL, P_MODEL + 25)

_DRAG_KEYS = ("X_uu", "Y_vv", "Y_rr", "Z_ww", "Z_qq", "K_pp", "M_ww", "M_qq", "N_vv", "N_rr")
# combined coefficient -> (force row, velocity pair) of its term u*v etc. (indices into nu)
_LIFT_TERMS = (("Y_uv", 1, 0, 1), ("Y_ur", 1, 0, 5), ("Z_uw", 2, 0, 2), ("Z_uq", 2, 0, 4),
               ("M_uw", 4, 0, 2), ("M_uq", 4, 0, 4), ("N_uv", 5, 0, 1), ("N_ur", 5, 0, 5))


def mass_matrices(pr: Preset6) -> tuple[np.ndarray, np.ndarray]:
    """(M_RB, M_A) of the preset (kg, kg m, kg m^2), P01 ch. 4 and F21 eq. 3.44 / 6.x."""
    v = pr.values
    m = v["mass.W"] / v["mass.g"]
    I_o = np.diag([v["mass.Ixx"], v["mass.Iyy"], v["mass.Izz"]])
    M_rb = rigid_body_mass(m, I_o, v["mass.r_g"])
    a = {k.split(".", 1)[1]: x for k, x in v.items() if k.startswith("added_mass.")}
    M_a = -np.diag([a["X_udot"], a["Y_vdot"], a["Z_wdot"], a["K_pdot"], a["M_qdot"], a["N_rdot"]])
    M_a[1, 5] = M_a[5, 1] = -a["Y_rdot"]   # Y_rdot = N_vdot
    M_a[2, 4] = M_a[4, 2] = -a["Z_qdot"]   # Z_qdot = M_wdot
    return M_rb, M_a


def munk_coefficients(M_a: np.ndarray) -> np.ndarray:
    """Bilinear coefficients of -C_A(nu) nu: ``c[k, i, j]`` multiplies nu_i nu_j (i <= j) in force k.

    Computed from the Kirchhoff form by polarisation: c[k, i, j] = -(Q(e_i + e_j) - Q(e_i) - Q(e_j))
    for i < j and -Q(e_i) for i = j, with Q(nu) = C_A(nu) nu (Fossen 2021 eq. 6.43).
    """
    def Q(nu):
        P, L = M_a[:3] @ nu, M_a[3:] @ nu
        return np.concatenate([np.cross(nu[3:], P), np.cross(nu[3:], L) + np.cross(nu[:3], P)])
    e = np.eye(6)
    c = np.zeros((6, 6, 6))
    for i in range(6):
        c[:, i, i] = -Q(e[i])
        for j in range(i + 1, 6):
            c[:, i, j] = -(Q(e[i] + e[j]) - Q(e[i]) - Q(e[j]))
    return c


def lift_coefficients(pr: Preset6, M_a: np.ndarray) -> dict:
    """Lift part of P01's combined coefficients: combined minus the Munk part of the same term."""
    c = munk_coefficients(M_a)
    return {name: pr.values[f"combined.{name}"] - c[k, i, j] for name, k, i, j in _LIFT_TERMS}


def pack(pr: Preset6, common: np.ndarray) -> np.ndarray:
    """Fill the model block of ``pp`` (a copy of ``common``, which holds the actuator limits).

    Parameters
    ----------
    pr : Preset6
        ``remus100_prestero`` (or a variant with the same keys).
    common : numpy.ndarray
        Length :data:`PP6_SIZE` with the common actuator fields already set.

    Returns
    -------
    numpy.ndarray
        The packed parameters.
    """
    v = pr.values
    pp = np.array(common, dtype=np.float64, copy=True)
    assert pp.size == PP6_SIZE
    M_rb, M_a = mass_matrices(pr)
    M = M_rb + M_a
    check_spd(M_rb, "remus100_prestero M_RB")
    check_spd(M, "remus100_prestero M_RB + M_A")
    pp[P_MINV:P_MINV + 36] = np.linalg.inv(M).ravel()
    pp[P_MRB:P_MRB + 36] = M_rb.ravel()
    pp[P_MA:P_MA + 36] = M_a.ravel()
    pp[P_W], pp[P_B] = v["mass.W"], v["mass.B"]
    pp[P_RG:P_RG + 3] = v["mass.r_g"]
    pp[P_RB:P_RB + 3] = v["mass.r_b"]
    for k, key in enumerate(_DRAG_KEYS):
        pp[Q_XUU + k] = v[f"drag.{key}"]
    lift = lift_coefficients(pr, M_a)
    for k, (name, *_r) in enumerate(_LIFT_TERMS):
        pp[L_YUV + k] = lift[name]
    pp[F_YDR], pp[F_ZDS] = v["fins.Y_uudr"], v["fins.Z_uuds"]
    pp[F_MDS], pp[F_NDR] = v["fins.M_uuds"], v["fins.N_uudr"]
    pp[R_XPROP], pp[R_KPROP], pp[R_N0] = v["propeller.X_prop"], v["propeller.K_prop"], v["propeller.n0"]
    return pp


@njit_noalloc(inline="always")
def propeller(n, pp):
    """(thrust (N), roll torque (N m)) at propeller speed n (rpm)."""
    s = n / pp[R_N0]
    s2 = s * abs(s)
    return pp[R_XPROP] * s2, pp[R_KPROP] * s2


@njit_noalloc
def produced(u, dr, ds, n, pp):
    """(tau_u, tau_q, tau_r) the actuators produce at surge speed u (m/s): N, N m, N m."""
    uu = u * u
    return propeller(n, pp)[0], pp[F_MDS] * uu * ds, pp[F_NDR] * uu * dr


@njit_noalloc
def allocate_tau(tau_u, tau_q, tau_r, u, pp, cmd):
    """Invert :func:`produced` at surge speed u: write [delta_r, delta_s, n] into cmd[0:3].

    Returns the bitmask of channels that cannot be produced (bit 0 tau_u: rpm limit; bit 1
    tau_q: stern-plane limit; bit 2 tau_r: rudder limit); those are commanded at their limit.
    """
    uu = u * u
    dm = pp[P_DMAX]
    ds, sat_q = fin_angle_for(tau_q, pp[F_MDS] * uu, 1.0 if pp[F_MDS] > 0.0 else -1.0, dm)
    dr, sat_r = fin_angle_for(tau_r, pp[F_NDR] * uu, 1.0 if pp[F_NDR] > 0.0 else -1.0, dm)
    s = math.sqrt(abs(tau_u) / pp[R_XPROP])
    n = pp[R_N0] * (s if tau_u >= 0.0 else -s)
    nm = pp[P_NMAX]
    sat_u = abs(n) > nm
    cmd[CMD_DR] = dr
    cmd[CMD_DS] = ds
    cmd[CMD_N] = clip(n, -nm, nm)
    return (1 if sat_u else 0) | (2 if sat_q else 0) | (4 if sat_r else 0)


@njit_noalloc(inline="always")
def hydro(ur, vr, wr, p, q, r, dr, ds, n, pp):
    """tau_h + tau_f + tau_p of the module docstring (6-tuple, N and N m), on relative velocity."""
    T, K = propeller(n, pp)
    uu = ur * ur
    return (pp[Q_XUU] * ur * abs(ur) + T,
            pp[Q_YVV] * vr * abs(vr) + pp[Q_YRR] * r * abs(r) + pp[L_YUV] * ur * vr
            + pp[L_YUR] * ur * r + pp[F_YDR] * uu * dr,
            pp[Q_ZWW] * wr * abs(wr) + pp[Q_ZQQ] * q * abs(q) + pp[L_ZUW] * ur * wr
            + pp[L_ZUQ] * ur * q + pp[F_ZDS] * uu * ds,
            pp[Q_KPP] * p * abs(p) + K,
            pp[Q_MWW] * wr * abs(wr) + pp[Q_MQQ] * q * abs(q) + pp[L_MUW] * ur * wr
            + pp[L_MUQ] * ur * q + pp[F_MDS] * uu * ds,
            pp[Q_NVV] * vr * abs(vr) + pp[Q_NRR] * r * abs(r) + pp[L_NUV] * ur * vr
            + pp[L_NUR] * ur * r + pp[F_NDR] * uu * dr)


@njit_noalloc
def derivative(x, att, vc, dist, cmd, pp, dx):
    """dx[0:15] = f(x, cmd) of the module docstring.

    Parameters
    ----------
    x : ndarray (15,)
        State (layout :mod:`auvtrack.plant.sixdof.layout`).
    att : tuple of 4 float
        (cos theta, sin theta, cos psi, sin psi) of x (the engine computes them once per stage).
    vc : tuple of 3 float
        Current velocity in NED (m/s), constant over the call.
    dist : tuple of 6 float
        Disturbance forces and moments [X, Y, Z, K, M, N] (N, N m).
    cmd : ndarray
        Actuator commands [delta_r, delta_s, n] (rad, rad, rpm) at cmd[0:3].
    pp : ndarray
        Packed parameters.
    dx : ndarray (15,)
        Output.
    """
    tr = trig_att(x[3], att)
    u, v, w, p, q, r = x[6], x[7], x[8], x[9], x[10], x[11]
    uc, vcb, wc = body_from_ned6(tr, vc[0], vc[1], vc[2])
    ur, vr, wr = u - uc, v - vcb, w - wc
    dr, ds, n = effective(x, pp)
    h = hydro(ur, vr, wr, p, q, r, dr, ds, n, pp)
    crb = kirchhoff(pp, P_MRB, u, v, w, p, q, r)
    ca = kirchhoff(pp, P_MA, ur, vr, wr, p, q, r)
    g = restoring(tr, pp[P_W], pp[P_B], pp[P_RG], pp[P_RG + 1], pp[P_RG + 2],
                  pp[P_RB], pp[P_RB + 1], pp[P_RB + 2])
    # d/dt of the body-frame current for a constant NED current: -omega x nu_c
    ma = matvec6(pp, P_MA, r * vcb - q * wc, p * wc - r * uc, q * uc - p * vcb, 0.0, 0.0, 0.0)
    nd = matvec6(pp, P_MINV,
                 h[0] + dist[0] - crb[0] - ca[0] - g[0] + ma[0],
                 h[1] + dist[1] - crb[1] - ca[1] - g[1] + ma[1],
                 h[2] + dist[2] - crb[2] - ca[2] - g[2] + ma[2],
                 h[3] + dist[3] - crb[3] - ca[3] - g[3] + ma[3],
                 h[4] + dist[4] - crb[4] - ca[4] - g[4] + ma[4],
                 h[5] + dist[5] - crb[5] - ca[5] - g[5] + ma[5])
    pd = ned_velocity(tr, u, v, w)
    ed = euler_rates(tr, p, q, r)
    ad = actuator_rates(x, cmd[CMD_DR], cmd[CMD_DS], cmd[CMD_N], pp)
    dx[0], dx[1], dx[2] = pd[0], pd[1], pd[2]
    dx[3], dx[4], dx[5] = ed[0], ed[1], ed[2]
    for i in range(6):
        dx[6 + i] = nd[i]
    dx[12], dx[13], dx[14] = ad[0], ad[1], ad[2]

"""6-DOF REMUS 100 of Fossen (2021, Section 8.4.2) as implemented in PVS ``remus100.py``.

Written from the equations of the Handbook and the PVS documentation (no code copied); the data
and every source are in ``auvtrack/data/vehicles/6dof/remus100_fossen.toml``.  Model::

    nu_dot = nu_c_dot + M^-1 ( tau_act + tau_ld(nu_r) + tau_cf(nu_r) - C(nu_r) nu_r - D(nu_r) nu_r
                               - g(eta) + tau_d )

* rigid body of a prolate spheroid (a = L/2, b = diam/2) of mass m = 4/3 pi rho a b^2 (or the
  file's ``hull.mass``) with its CG r_g below the CO: ``M_RB = H(r_g)^T diag(m, m, m, Ix, Iy, Iz)
  H(r_g)`` (F21 eq. 3.42);
* added mass from Lamb's k-factors (F21 eq. 8.x) of the displaced water m_f = 4/3 pi rho a b^2:
  ``M_A = diag(m_f k1, m_f k2, m_f k2, r44 Ix, k' Iy_f, k' Iy_f)``; ``M = M_RB + M_A``;
* ``C = C_RB(nu_r) + C_A(nu_r)`` in Kirchhoff form, **with the model's simplification** that the
  added-mass terms C_A[4,0], C_A[0,4], C_A[4,2], C_A[2,4], C_A[5,0], C_A[0,5], C_A[5,1], C_A[1,5]
  (surge-pitch/heave-pitch quadratic terms and the Munk moments in pitch and yaw) are zero;
* ``D = diag(M11/T1 e^{-3U_r}, M22/T2 e^{-3U_r}, M33/T3, 2 zeta4 w4 M44, 2 zeta5 w5 M55,
  M66/T6)``: low-speed linear damping that fades where quadratic drag and lift dominate;
* ``tau_ld``: lift and drag of the hull as a wing of span diam and area S = 0.7 L diam at angle of
  attack alpha = atan2(w_r, u_r) (Beard and McLain 2012; F21 eq. 8.x): CL = CL_alpha alpha,
  CD = CD_0 + CL^2 / (pi e AR), rotated from flow to body axes (surge and heave only);
* ``tau_cf``: cross-flow drag by strip theory in the horizontal plane only (sway, yaw), Hoerner's
  2-D coefficient, 21 points x = -L/2 .. L/2 each of width L/20 (as PVS);
* ``tau_act``: propeller thrust (1 - t) X_prop and roll torque K_prop/10 (linear fits of the
  Wageningen KT, KQ in the advance number J = 0.944 U / (n D), U the speed over ground), and
  rudder / stern-plane lift and drag ``-1/2 rho U_rh^2 A_r CL_r delta_r`` (sway) etc. acting at
  x_r = x_s = -L/2;
* ``g``: restoring forces of W at r_g and B at r_b (F21 eq. 4.6); W = B unless the file gives
  ``hull.mass`` and ``hull.buoyancy``;
* currents (the model's simplification): the horizontal NED current (Vx, Vy) is rotated by the
  heading only, ``nu_c = (Vx cos psi + Vy sin psi, -Vx sin psi + Vy cos psi, 0, 0, 0, 0)``, with
  ``nu_c_dot = (r v_c, -r u_c, 0, 0, 0, 0)``; a vertical current is ignored.
* ``tau_d``: additive disturbance forces [X, Y, Z, K, M, N] (N, N m).

Control channels: tau_u = (1 - t) X_prop + X_r + X_s (N), tau_q = -x_s Z_s, tau_r = x_r Y_r
(N m).  PVS sign convention: delta_r > 0 turns to starboard, delta_s > 0 pitches nose down.

References
----------
[F21] Fossen, T. I. (2021). Handbook of Marine Craft Hydrodynamics and Motion Control, 2nd ed.,
Wiley, Section 8.4.2 and ch. 3, 4, 6.  [PVS] Fossen, Python Vehicle Simulator, remus100.py and
gnc.py (m2c, forceLiftDrag, crossFlowDrag, Hoerner, gvect).
"""
from __future__ import annotations

import math

import numpy as np

from ...jit import njit_noalloc
from .actuators import actuator_rates, clip, effective, fin_angle_for
from .layout import (CMD_DR, CMD_DS, CMD_N, P_B, P_DMAX, P_MA, P_MINV, P_MODEL, P_MRB, P_NMAX, P_RB,
                      P_RG, P_W, PP6_SIZE)
from ...vehicle.truth_presets import Preset6
from .rigid import (check_spd, euler_rates, inertia_about_origin, kirchhoff, matvec6, ned_velocity,
                     restoring, rigid_body_mass, trig_att)

(FZ_RHO, FZ_S, FZ_CD0, FZ_CLA, FZ_KIND, FZ_CCF, FZ_L, FZ_NSTRIP,
 FZ_D0, FZ_D1, FZ_D2, FZ_D3, FZ_D4, FZ_D5,
 FZ_KR, FZ_KS, FZ_XR, FZ_XS,
 FZ_DPROP, FZ_TPROP, FZ_WAKE, FZ_JMAX, FZ_KT0, FZ_KQ0, FZ_KTMAX, FZ_KQMAX, FZ_ROLL) = range(P_MODEL, P_MODEL + 27)


def lamb_k_factors(a: float, b: float) -> tuple[float, float, float]:
    """Lamb's k-factors (k1, k2, k') of a prolate spheroid with semi-axes a > b (F21 Section 8.4.2).

    e = sqrt(1 - (b/a)^2), alpha0 = 2 (1 - e^2)/e^3 (1/2 ln((1+e)/(1-e)) - e),
    beta0 = 1/e^2 - (1 - e^2)/(2 e^3) ln((1+e)/(1-e)); k1 = alpha0/(2 - alpha0),
    k2 = beta0/(2 - beta0), k' = e^4 (beta0 - alpha0) / ((2 - e^2)(2 e^2 - (2 - e^2)(beta0 - alpha0))).
    """
    e = math.sqrt(1.0 - (b / a) ** 2)
    lg = math.log((1.0 + e) / (1.0 - e))
    alpha0 = 2.0 * (1.0 - e * e) / e ** 3 * (0.5 * lg - e)
    beta0 = 1.0 / e ** 2 - (1.0 - e * e) / (2.0 * e ** 3) * lg
    k1 = alpha0 / (2.0 - alpha0)
    k2 = beta0 / (2.0 - beta0)
    kp = e ** 4 * (beta0 - alpha0) / ((2.0 - e * e) * (2.0 * e * e - (2.0 - e * e) * (beta0 - alpha0)))
    return k1, k2, kp


def derived(pr: Preset6) -> dict:
    """Every derived number of the model (mass, inertia, M_RB, M_A, damping, ...), SI units.

    The displaced water is the spheroid's, m_f = 4/3 pi rho a b^2; the vehicle's mass is
    ``hull.mass`` if given, else m_f (neutral, as PVS), its buoyancy ``hull.buoyancy`` if given,
    else B = W (trimmed neutral).  Rigid-body inertia of a uniform spheroid of the vehicle's mass
    (Ix = 2/5 m b^2, Iy = Iz = 1/5 m (a^2 + b^2)); added mass from Lamb's k-factors times the
    displaced water (roll: r44 Ix).  Righting coefficient W z_g - B z_b (N m; Prestero 2001
    eq. 9.7) sets the roll and pitch natural frequencies of the damping.
    """
    v = pr.values
    rho, L, d = v["hull.rho"], v["hull.L"], v["hull.diam"]
    a, b = L / 2.0, d / 2.0
    S = v["hull.S_ratio"] * L * d
    m_f = 4.0 / 3.0 * math.pi * rho * a * b * b
    m = v.get("hull.mass", m_f)
    Ix, Iy = 0.4 * m * b * b, 0.2 * m * (a * a + b * b)
    Iy_f = 0.2 * m_f * (a * a + b * b)
    r_g = np.asarray(v["hull.r_g"])
    M_rb = rigid_body_mass(m, inertia_about_origin(m, np.diag([Ix, Iy, Iy]), r_g), r_g)
    k1, k2, kp = lamb_k_factors(a, b)
    M_a = np.diag([m_f * k1, m_f * k2, m_f * k2, v["hull.r44"] * Ix, kp * Iy_f, kp * Iy_f])
    M = M_rb + M_a
    W = m * v["hull.g"]
    B = v.get("hull.buoyancy", W)
    gm = W * r_g[2] - B * v["hull.r_b"][2]
    w_roll, w_pitch = math.sqrt(gm / M[3, 3]), math.sqrt(gm / M[4, 4])
    dmp = v
    D = (M[0, 0] / dmp["damping.T_surge"], M[1, 1] / dmp["damping.T_sway"],
         M[2, 2] / dmp["damping.T_heave"], 2.0 * dmp["damping.zeta_roll"] * w_roll * M[3, 3],
         2.0 * dmp["damping.zeta_pitch"] * w_pitch * M[4, 4], M[5, 5] / dmp["damping.T_yaw"])
    AR = d * d / S
    return dict(m=m, m_f=m_f, Ix=Ix, Iy=Iy, W=W, B=B, gm=gm, S=S, M_rb=M_rb, M_a=M_a, M=M, k=(k1, k2, kp),
                w_roll=w_roll, w_pitch=w_pitch, D=D, AR=AR,
                CD_0=v["hull.Cd"] * math.pi * b * b / S,
                CL_alpha=math.pi * AR / (1.0 + math.sqrt(1.0 + (AR / 2.0) ** 2)),
                k_induced=1.0 / (math.pi * v["hull.oswald_e"] * AR))


def pack(pr: Preset6, common: np.ndarray) -> np.ndarray:
    """Fill the model block of ``pp`` (a copy of ``common``, which holds the actuator limits).

    Parameters
    ----------
    pr : Preset6
        ``remus100_fossen`` or a vehicle file of the same form
        (:mod:`auvtrack.plant.sixdof.vehicle_file`).
    common : numpy.ndarray
        Length :data:`PP6_SIZE` with the common actuator fields already set.

    Returns
    -------
    numpy.ndarray
        The packed parameters.
    """
    v = pr.values
    dd = derived(pr)
    pp = np.array(common, dtype=np.float64, copy=True)
    assert pp.size == PP6_SIZE
    check_spd(dd["M_rb"], f"{pr.name} M_RB")
    check_spd(dd["M"], f"{pr.name} M_RB + M_A")
    pp[P_MINV:P_MINV + 36] = np.linalg.inv(dd["M"]).ravel()
    pp[P_MRB:P_MRB + 36] = dd["M_rb"].ravel()
    pp[P_MA:P_MA + 36] = dd["M_a"].ravel()
    pp[P_W], pp[P_B] = dd["W"], dd["B"]
    pp[P_RG:P_RG + 3] = v["hull.r_g"]
    pp[P_RB:P_RB + 3] = v["hull.r_b"]
    rho, L = v["hull.rho"], v["hull.L"]
    n_strips = int(v["hull.n_strips"])
    pp[FZ_RHO], pp[FZ_S], pp[FZ_CD0] = rho, dd["S"], dd["CD_0"]
    pp[FZ_CLA], pp[FZ_KIND] = dd["CL_alpha"], dd["k_induced"]
    pp[FZ_CCF] = 0.5 * rho * v["hull.diam"] * v["hull.Cd_2D"] * (L / n_strips)
    pp[FZ_L], pp[FZ_NSTRIP] = L, n_strips
    pp[FZ_D0:FZ_D0 + 6] = dd["D"]
    A_fin = 2.0 * v["fins.S_fin"]
    pp[FZ_KR] = 0.5 * rho * A_fin * v["fins.CL_delta_r"]
    pp[FZ_KS] = 0.5 * rho * A_fin * v["fins.CL_delta_s"]
    pp[FZ_XR] = pp[FZ_XS] = v["fins.x_fin"]
    for slot, key in ((FZ_DPROP, "D_prop"), (FZ_TPROP, "t_prop"), (FZ_WAKE, "wake"),
                      (FZ_JMAX, "Ja_max"), (FZ_KT0, "KT_0"), (FZ_KQ0, "KQ_0"),
                      (FZ_KTMAX, "KT_max"), (FZ_KQMAX, "KQ_max"), (FZ_ROLL, "roll_torque_scale")):
        pp[slot] = v[f"propeller.{key}"]
    return pp


@njit_noalloc(inline="always")
def propeller(n, U, pp):
    """(X_prop (N), K_prop (N m)) at n (rpm) and speed over ground U (m/s): linear KT(J), KQ(J) fits for n > 0."""
    rho, D = pp[FZ_RHO], pp[FZ_DPROP]
    nr = n / 60.0
    D4 = D * D * D * D
    if nr > 0.0:
        va_d = pp[FZ_WAKE] * U / D
        x = rho * D4 * (pp[FZ_KT0] * nr * abs(nr) + (pp[FZ_KTMAX] - pp[FZ_KT0]) / pp[FZ_JMAX] * va_d * abs(nr))
        k = rho * D4 * D * (pp[FZ_KQ0] * nr * abs(nr) + (pp[FZ_KQMAX] - pp[FZ_KQ0]) / pp[FZ_JMAX] * va_d * abs(nr))
        return x, k
    return rho * D4 * pp[FZ_KT0] * abs(nr) * nr, rho * D4 * D * pp[FZ_KQ0] * abs(nr) * nr


@njit_noalloc(inline="always")
def fin_forces(U_rh, U_rv, dr, ds, pp):
    """(X_r + X_s, Y_r, Z_s): fin drag (N), rudder sway force (N), stern-plane heave force (N)."""
    kr, ks = pp[FZ_KR] * U_rh * U_rh, pp[FZ_KS] * U_rv * U_rv
    return -kr * dr * dr - ks * ds * ds, -kr * dr, -ks * ds


@njit_noalloc
def produced(u, v, w, dr, ds, n, pp):
    """(tau_u, tau_q, tau_r) the actuators produce at body velocity (u, v, w) (m/s): N, N m, N m."""
    U = math.sqrt(u * u + v * v + w * w)
    xf, yr, zs = fin_forces(math.sqrt(u * u + v * v), math.sqrt(u * u + w * w), dr, ds, pp)
    return ((1.0 - pp[FZ_TPROP]) * propeller(n, U, pp)[0] + xf, -pp[FZ_XS] * zs, pp[FZ_XR] * yr)


@njit_noalloc
def allocate_tau(tau_u, tau_q, tau_r, u, v, w, pp, cmd):
    """Invert :func:`produced` at (u, v, w): write [delta_r, delta_s, n] into cmd[0:3].

    Fin angles first (tau_q = x_s k_s U_rv^2 delta_s, tau_r = -x_r k_r U_rh^2 delta_r), then the
    propeller speed for the thrust that leaves tau_u after the fins' drag: for T >= 0 the larger
    root of rho D^4 (KT_0 n^2 + (KT_max - KT_0)/J_max (Va/D) n) = T (n in rps), for T < 0 the
    reverse branch rho D^4 KT_0 n|n| = T.  Returns the bitmask of channels that cannot be produced
    (bit 0 tau_u: rpm limit, bit 1 tau_q, bit 2 tau_r: fin limit); those are commanded at the limit.
    """
    U_rh, U_rv = math.sqrt(u * u + v * v), math.sqrt(u * u + w * w)
    U = math.sqrt(u * u + v * v + w * w)
    dm = pp[P_DMAX]
    cq = pp[FZ_XS] * pp[FZ_KS]     # tau_q per (U_rv^2 delta_s)
    cr = -pp[FZ_XR] * pp[FZ_KR]    # tau_r per (U_rh^2 delta_r)
    ds, sat_q = fin_angle_for(tau_q, cq * U_rv * U_rv, 1.0 if cq > 0.0 else -1.0, dm)
    dr, sat_r = fin_angle_for(tau_r, cr * U_rh * U_rh, 1.0 if cr > 0.0 else -1.0, dm)
    xf = fin_forces(U_rh, U_rv, dr, ds, pp)[0]
    T = (tau_u - xf) / (1.0 - pp[FZ_TPROP])
    rho, D = pp[FZ_RHO], pp[FZ_DPROP]
    a = rho * D * D * D * D * pp[FZ_KT0]
    if T >= 0.0:
        b = rho * D * D * D * D * (pp[FZ_KTMAX] - pp[FZ_KT0]) / pp[FZ_JMAX] * pp[FZ_WAKE] * U / D
        nr = (-b + math.sqrt(b * b + 4.0 * a * T)) / (2.0 * a)
    else:
        nr = -math.sqrt(-T / a)
    n = 60.0 * nr
    nm = pp[P_NMAX]
    sat_u = abs(n) > nm
    cmd[CMD_DR] = dr
    cmd[CMD_DS] = ds
    cmd[CMD_N] = clip(n, -nm, nm)
    return (1 if sat_u else 0) | (2 if sat_q else 0) | (4 if sat_r else 0)


@njit_noalloc(inline="always")
def lift_drag(ur, wr, U_r, pp):
    """(X, Z) of the hull lift and drag (N) at angle of attack atan2(w_r, u_r) and relative speed U_r."""
    alpha = math.atan2(wr, ur)
    CL = pp[FZ_CLA] * alpha
    CD = pp[FZ_CD0] + CL * CL * pp[FZ_KIND]
    qS = 0.5 * pp[FZ_RHO] * U_r * U_r * pp[FZ_S]
    fd, fl = qS * CD, qS * CL
    hyp = math.sqrt(ur * ur + wr * wr)  # cos alpha = u_r / hyp, sin alpha = w_r / hyp (alpha = 0 at rest)
    ca, sa = (ur / hyp, wr / hyp) if hyp > 0.0 else (1.0, 0.0)
    return -ca * fd + sa * fl, -sa * fd - ca * fl


@njit_noalloc(inline="always")
def cross_flow(vr, r, pp):
    """(Y, N) of the horizontal cross-flow drag (N, N m): strip sum over x = -L/2 ... L/2."""
    n = int(pp[FZ_NSTRIP])
    L = pp[FZ_L]
    dx = L / n
    c = pp[FZ_CCF]
    Y = 0.0
    N = 0.0
    for i in range(n + 1):
        xl = -0.5 * L + i * dx
        vl = vr + xl * r
        f = c * abs(vl) * vl
        Y -= f
        N -= xl * f
    return Y, N


@njit_noalloc
def derivative(x, att, vc, dist, cmd, pp, dx):
    """dx[0:15] = f(x, cmd) of the module docstring (arguments as :func:`auvtrack.plant.sixdof.prestero.derivative`)."""
    tr = trig_att(x[3], att)
    u, v, w, p, q, r = x[6], x[7], x[8], x[9], x[10], x[11]
    cps, sps = tr[4], tr[5]
    uc = vc[0] * cps + vc[1] * sps
    vcb = -vc[0] * sps + vc[1] * cps
    ur, vr, wr = u - uc, v - vcb, w
    U = math.sqrt(u * u + v * v + w * w)
    U_r = math.sqrt(ur * ur + vr * vr + wr * wr)
    dr, ds, n = effective(x, pp)
    X_prop, K_prop = propeller(n, U, pp)
    xf, yr, zs = fin_forces(math.sqrt(ur * ur + vr * vr), math.sqrt(ur * ur + wr * wr), dr, ds, pp)
    crb = kirchhoff(pp, P_MRB, ur, vr, wr, p, q, r)
    # C_A(nu_r) nu_r with the model's zeroed entries (M_A diagonal): momenta P = M_A11 nu1, L = M_A22 nu2
    P1, P2 = pp[P_MA + 7] * vr, pp[P_MA + 14] * wr  # (P0 = M_A11 u_r enters none of the terms kept below)
    L0, L1, L2 = pp[P_MA + 21] * p, pp[P_MA + 28] * q, pp[P_MA + 35] * r
    ca = (0.0, -P2 * p, P1 * p, P2 * vr - P1 * wr + L2 * q - L1 * r, -L2 * p + L0 * r, L1 * p - L0 * q)
    fade = math.exp(-3.0 * U_r)
    dmp = (pp[FZ_D0] * fade * ur, pp[FZ_D1] * fade * vr, pp[FZ_D2] * wr,
           pp[FZ_D3] * p, pp[FZ_D4] * q, pp[FZ_D5] * r)
    lx, lz = lift_drag(ur, wr, U_r, pp)
    cy, cn = cross_flow(vr, r, pp)
    g = restoring(tr, pp[P_W], pp[P_B], pp[P_RG], pp[P_RG + 1], pp[P_RG + 2],
                  pp[P_RB], pp[P_RB + 1], pp[P_RB + 2])
    tau = ((1.0 - pp[FZ_TPROP]) * X_prop + xf + lx, yr + cy, zs + lz, K_prop * pp[FZ_ROLL],
           -pp[FZ_XS] * zs, pp[FZ_XR] * yr + cn)
    nd = matvec6(pp, P_MINV,
                 tau[0] + dist[0] - crb[0] - ca[0] - dmp[0] - g[0],
                 tau[1] + dist[1] - crb[1] - ca[1] - dmp[1] - g[1],
                 tau[2] + dist[2] - crb[2] - ca[2] - dmp[2] - g[2],
                 tau[3] + dist[3] - crb[3] - ca[3] - dmp[3] - g[3],
                 tau[4] + dist[4] - crb[4] - ca[4] - dmp[4] - g[4],
                 tau[5] + dist[5] - crb[5] - ca[5] - dmp[5] - g[5])
    pd = ned_velocity(tr, u, v, w)
    ed = euler_rates(tr, p, q, r)
    ad = actuator_rates(x, cmd[CMD_DR], cmd[CMD_DS], cmd[CMD_N], pp)
    dx[0], dx[1], dx[2] = pd[0], pd[1], pd[2]
    dx[3], dx[4], dx[5] = ed[0], ed[1], ed[2]
    dx[6], dx[7], dx[8] = nd[0] + r * vcb, nd[1] - r * uc, nd[2]
    dx[9], dx[10], dx[11] = nd[3], nd[4], nd[5]
    dx[12], dx[13], dx[14] = ad[0], ad[1], ad[2]

"""LOS autopilot: adaptive line-of-sight path following with heading, depth and speed autopilots.

The baseline real torpedo AUVs fly (MSS ``SIMremus100``, PVS ``depthHeadingAutopilot``): guidance
turns the path into a heading, a pitch and a speed; three autopilots follow them with the rudder,
the stern planes and the propeller (docs/controllers.md, "LOS autopilot", eq. L1-L9).

Guidance (at the navigation point p, the vehicle's origin): the closest path point s
(:func:`auvtrack.reference.path.project`, warm-started from the state s), its azimuth pi_h and
elevation pi_v, the cross- and vertical-track errors y_e, z_e (Fossen & Aguiar 2024; MSS ``ALOS3D``)::

    psi_d   = pi_h - beta_hat  - c beta_m  - atan(y_e / Delta_h)                  (L1)
    theta_d = pi_v + alpha_hat + c alpha_m + atan(z_e / Delta_v)                  (L2)
    beta_hat_dot  = gamma_h Delta_h / sqrt(Delta_h^2 + y_e^2) Proj(beta_hat, y_e)   (L3)
    alpha_hat_dot = gamma_v Delta_v / sqrt(Delta_v^2 + z_e^2) Proj(alpha_hat, z_e)

the adaptive LOS (ALOS) of Fossen (2023) and Fossen & Aguiar (2024) as in MSS ``ALOS3D``, with the
measured crab angle beta_m = atan2(v, u) and angle of attack alpha_m = atan2(w, u) compensated
directly (weight c, ``crab``; the estimates take what is left).  Curvature feed-forward: the
desired rates are the exact derivatives of (L1)-(L2) along the motion, without the measured-angle
terms, r_d = cos(theta) psi_d_dot and q_d = theta_d_dot with (L4)::

    psi_d_dot   = pi_h'(s) s_dot - Delta_h y_e_dot / (Delta_h^2 + y_e^2) - beta_hat_dot
    theta_d_dot = pi_v'(s) s_dot + Delta_v z_e_dot / (Delta_v^2 + z_e^2) + alpha_hat_dot

where s_dot = p_dot . eta_d' / (|eta_d'|^2 + (eta_d - p) . eta_d'') is the closest point's rate
and y_e_dot, z_e_dot are p_dot on the path frame's normals; the state s follows the projection at
that rate plus K_S (s_projected - s).  Speed: the path's speed at s,
corrected for the timing error a = (s - t) |eta_d'(s)| (L5)::

    u_d = |eta_d'(s)| - k_a a,   clipped to |eta_d'(s)| (1 +- along_max)

Autopilots: PID pole placement on the nominal 5-DOF model's linear pitch, yaw and surge
equations m x'' + d x' + k x = tau (m, d, k from ``vp``: m44, d44, rho g nabla GM_L; m55, d55,
0; m11, d11), Fossen (2021), Section 15.3.4 and Algorithm 15.2 (MSS ``SIMmariner``,
``PIDnonlinearMIMO``), with the model's tau along the reference as feed-forward (L6)::

    tau = (d rate_d + k sin(angle_d)) - Kp e - Kd (rate - rate_d) - Ki I,   I_dot = e - (L9)
    Kp = m w^2 - k,   Kd = 2 zeta w m - d,   Ki = m w^3 / 10

so that on that model the error obeys e^(3) + 2 zeta w e'' + w^2 e' + (w^3/10) e = 0: the poles
(L7) are the roots of s^3 + 2 zeta w s^2 + w^2 s + w^3/10 (Hurwitz for zeta > 0.05).  Surge
speed: the PI tau_u = d11 u_d - (2 zeta w_u m11 - d11) e_u - m11 w_u^2 I_u (e'' + 2 zeta w_u e' +
w_u^2 e = 0).  The sway-yaw and heave-pitch couplings of the model (its Munk moments
(m22 - m11) u v and (m11 - m33) u w, which make the ``remus100`` design model directionally
unstable at cruise speed) are left to the feedback: the defaults (w = 3 rad/s, zeta = 2) keep the
coupled linearisation stable from 0.5 to 2.5 m/s (:func:`coupled_poles`; a note when a choice does
not).

Commands (``ctx.commands``): tau on a plant that takes tau (the 5-DOF plant); on a 6-DOF truth the
actuators themselves (L8): stern plane delta_s = tau_q / (c_q u_e^2), rudder delta_r = tau_r /
(c_r u_e^2) with the fin moments per (m/s)^2 and rad c_q, c_r of the plant's own fins
(``ctx.plant.applied``) and u_e = max(u, u_min); the propeller speed n from tau_u on the plant's
own thrust curve, T(n, u) = a n^2 + b n u (n >= 0; fitted to ``ctx.plant.applied`` at set-up,
exact for both REMUS 100 truths), T = -a n^2 in reverse.  Every command is clipped to what the
plant says its actuators can do (``args.lo``, ``args.hi``).

Anti-windup (L9): back-calculation (Astrom & Hagglund 2006, ch. 3) in tau: with Delta the tau
by which the clipped command falls short of the demanded one, I_dot = e - k_aw w Delta / Ki
(tracking rate k_aw w, ``kaw`` = 1), and the ALOS estimates do not adapt while their autopilot's
actuator is saturated (conditional integration); ``kaw`` = 0 gives the published forms (textbook
PID, ALOS without freezing).

Packed gains :data:`GAINS`; state xc = :data:`STATE` (s, beta_hat, alpha_hat, and the integrals
I_u (m), I_theta, I_psi (rad s)); logged channels :data:`AUX_NAMES`.

References
----------
Fossen, T. I. (2021). Handbook of Marine Craft Hydrodynamics and Motion Control, 2nd ed., Wiley,
Section 15.3.4 (PID pole placement), Algorithm 15.2 (MIMO nonlinear PID pole placement), ch. 12
(LOS guidance, course and crab angle).  Fossen, T. I. (2023). An adaptive line-of-sight (ALOS)
guidance law for path following of aircraft and marine craft. IEEE Transactions on Control
Systems Technology.
Fossen, T. I. and Aguiar, A. P. (2024). A uniform semiglobal exponential stable adaptive
line-of-sight (ALOS) guidance law for 3-D path following. Automatica 163, 111556.
Krstic, M., Kanellakopoulos, I. and Kokotovic, P. (1995). Nonlinear and Adaptive Control Design,
Wiley, Appendix E (parameter projection).  Astrom, K. J. and Hagglund, T. (2006). Advanced PID
Control, ISA, ch. 3 (back-calculation anti-windup).  MSS (github.com/cybergalactic/MSS):
``ALOS3D.m``, ``ILOSpsi.m``, ``SIMremus100.m``, ``SIMmariner.m``, ``PIDnonlinearMIMO.m``; PVS
(github.com/cybergalactic/PythonVehicleSimulator): ``remus100.depthHeadingAutopilot``.
"""
from __future__ import annotations

import math
from typing import Literal

import numpy as np
from pydantic import Field

from ..jit import njit_noalloc
from ..packing import packed_layout
from ..reference.path import SPEED2_MIN, path_errors, project
from ..vehicle.kinematics import eta_dot
from ..vehicle.params import VP
from .registry import CompiledController, ControllerParams, tunable

NAME = "los_autopilot"
COMMANDS = ("actuators", "tau")
AUX_NAMES = ("s_path", "xtrack", "vtrack", "psi_d", "theta_d", "u_d", "beta_hat", "alpha_hat", "i_u", "i_theta",
             "i_psi")
GAINS = packed_layout("LOSAutopilot", actuators=1, delta_h=1, delta_v=1, gamma_h=1, gamma_v=1, adapt_max=1,
                      crab=1, theta_max=1, k_along=1, along_max=1, wn=3, zeta=3, kaw=1, fin=2, thrust=2, u_min=1)
"""Packed gains; ``wn``, ``zeta`` per loop (surge, pitch, yaw); ``fin`` = (c_q, c_r) in N m per (m/s)^2
per rad; ``thrust`` = (a, b) of T(n, u) = a n^2 + b n u (N per rpm^2, N s per m rpm)."""
STATE = packed_layout("LOSAutopilotState", s=1, beta_hat=1, alpha_hat=1, i=3)
"""Controller state: path parameter (s), ALOS estimates (rad), integrals of the loop errors (u, q, r)."""

K_S = 5.0
"""Rate (1/s) at which the state s is pulled onto the projection (it only warm-starts it)."""
WINDOW = 10.0
"""Half-width (s of path time) of the projection's search around the state s."""
ADAPT_EPS = 0.01
"""Width (rad) of the projection band beyond adapt_max (Krstic et al. 1995, App. E)."""


class Params(ControllerParams):
    """ALOS path following with PID autopilots placed on the design model (docs/controllers.md, eq. L1-L9)."""

    kind: Literal["los_autopilot"] = "los_autopilot"
    delta_h: float = tunable(3.0, 1.0, 40.0, log=True, gt=0, le=1e3,
                             description="horizontal look-ahead distance Delta_h, m (L1)")
    delta_v: float = tunable(3.0, 1.0, 40.0, log=True, gt=0, le=1e3,
                             description="vertical look-ahead distance Delta_v, m (L2)")
    gamma_h: float = tunable(0.001, 0.0, 0.05, ge=0, le=1.0,
                             description="ALOS adaptation gain of the crab-angle estimate, 1/(m s) (L3)")
    gamma_v: float = tunable(0.001, 0.0, 0.05, ge=0, le=1.0,
                             description="ALOS adaptation gain of the angle-of-attack estimate, 1/(m s) (L3)")
    adapt_max: float = Field(0.35, gt=0, le=1.5, description="bound M of |beta_hat|, |alpha_hat|, rad (L3)")
    crab: float = Field(1.0, ge=0, le=1, description="weight of the measured crab angle and angle of attack "
                                                      "compensated in (L1)-(L2); 0: the ALOS estimates alone")
    theta_max: float = Field(0.5, gt=0, lt=math.pi / 2, description="limit of the pitch command |theta_d|, rad")
    k_along: float = tunable(0.1, 0.0, 1.0, ge=0, le=10.0,
                             description="speed correction per metre of along-track timing error, 1/s (L5)")
    along_max: float = Field(0.2, ge=0, lt=1, description="largest speed correction, fraction of the path speed (L5)")
    wn_u: float = tunable(0.5, 0.05, 3.0, log=True, gt=0, le=20.0,
                          description="natural frequency of the surge-speed loop, rad/s (L6)")
    wn_theta: float = tunable(3.0, 0.1, 6.0, log=True, gt=0, le=20.0,
                              description="natural frequency of the pitch loop, rad/s (L6)")
    wn_psi: float = tunable(3.0, 0.1, 6.0, log=True, gt=0, le=20.0,
                            description="natural frequency of the heading loop, rad/s (L6)")
    zeta: float = tunable(2.0, 0.3, 4.0, gt=0.05, le=5.0,
                          description="relative damping of the three loops (> 0.05: (L7) Hurwitz)")
    u_min: float = Field(0.3, gt=0, le=5.0, description="speed below which the fin gains stop growing, m/s (L8)")
    kaw: float = Field(1.0, ge=0, le=100.0, description="back-calculation rate of each integrator as a multiple of "
                                                        "its loop's wn (L9); 0: the published forms (textbook PID, "
                                                        "ALOS adapting in saturation)")


@njit_noalloc(inline="always")
def _ssa(a):
    """Smallest signed angle equal to ``a`` modulo 2 pi, in [-pi, pi) (rad)."""
    return a - 2.0 * math.pi * math.floor((a + math.pi) / (2.0 * math.pi))


@njit_noalloc(inline="always")
def _clip(x, lo, hi):
    return lo if x < lo else (hi if x > hi else x)


@njit_noalloc(inline="always")
def _proj(est, tau, bound):
    """Parameter projection of the update ``tau`` keeping |est| <= bound + ADAPT_EPS (Krstic et al. 1995, App. E)."""
    if abs(est) > bound and est * tau > 0.0:
        c = min(1.0, (est * est - bound * bound) / ((bound + ADAPT_EPS) ** 2 - bound * bound))
        return (1.0 - c) * tau
    return tau


@njit_noalloc(inline="always")
def thrust(n, u, a, b):
    """Propeller thrust T(n, u) = a n^2 + b n u for n >= 0, -a n^2 in reverse (N; n in rpm, u in m/s)."""
    if n >= 0.0:
        return a * n * n + b * n * u
    return -a * n * n


@njit_noalloc(inline="always")
def rpm_for(T, u, a, b):
    """The propeller speed (rpm) giving thrust T at surge speed u: the inverse of :func:`thrust`.

    The larger root of a n^2 + b u n = T on the forward branch; a thrust below that branch's least
    (-(b u)^2 / 4a when b u < 0) from the reverse branch -a n^2 = T.
    """
    bu = b * u
    disc = bu * bu + 4.0 * a * T
    if -1e-12 * bu * bu <= disc < 0.0:
        disc = 0.0  # the forward branch's vertex n = -b u / 2a, within rounding: both branches reach it
    if disc >= 0.0 and math.sqrt(disc) >= bu:
        return (-bu + math.sqrt(disc)) / (2.0 * a)
    return -math.sqrt(max(-T, 0.0) / a)


@njit_noalloc(inline="always")
def guidance(t, y, xc, path, cp):
    """Eq. (L1)-(L5) at the measured state.

    Returns (psi_d, theta_d, u_d, psi_d_dot, theta_d_dot, s_dot, beta_hat_dot, alpha_hat_dot, y_e,
    z_e, s): angles in rad, rates in rad/s, u_d in m/s, s_dot the state s's rate, y_e, z_e in m, s
    the closest point's path parameter.  The ALOS updates are returned unprojected and unfrozen
    (the law applies both).
    """
    eta, nu, att = y.eta, y.nu, y.att
    p = (eta[0], eta[1], eta[2])
    s, pt = project(path, xc[STATE.s], p, WINDOW)
    pos, vel, acc = pt
    e = path_errors(pt, p)
    y_e, z_e = e[1], e[2]
    vx, vy, vz = vel
    vh2 = vx * vx + vy * vy
    v2 = vh2 + vz * vz
    vh = math.sqrt(vh2)
    pi_h = math.atan2(vy, vx)
    pi_v = math.atan2(-vz, vh)
    dpi_h = (vx * acc[1] - vy * acc[0]) / vh2 if vh2 > SPEED2_MIN else 0.0
    dvh = (vx * acc[0] + vy * acc[1]) / vh if vh2 > SPEED2_MIN else 0.0
    dpi_v = (vz * dvh - acc[2] * vh) / v2 if v2 > SPEED2_MIN else 0.0
    pd = eta_dot(att, nu)
    if v2 > SPEED2_MIN:
        den = v2 + (pos[0] - p[0]) * acc[0] + (pos[1] - p[1]) * acc[1] + (pos[2] - p[2]) * acc[2]
        den = den if den >= 0.5 * v2 else v2
        s_geo = (pd[0] * vx + pd[1] * vy + pd[2] * vz) / den  # the closest point's rate
    else:  # the path stands still here: the parameter advances with time
        s_geo = 1.0
    s_dot = s_geo + K_S * (s - xc[STATE.s])
    ch, sh, cv, sv = math.cos(pi_h), math.sin(pi_h), math.cos(pi_v), math.sin(pi_v)
    ye_dot = -sh * pd[0] + ch * pd[1]
    ze_dot = sv * (ch * pd[0] + sh * pd[1]) + cv * pd[2]
    dh, dv = cp[GAINS.delta_h], cp[GAINS.delta_v]
    c = cp[GAINS.crab]
    u_ref = max(abs(nu[0]), 1e-9)
    beta_m = math.atan2(nu[1], u_ref)
    alpha_m = math.atan2(nu[2], u_ref)
    b_dot = cp[GAINS.gamma_h] * dh / math.sqrt(dh * dh + y_e * y_e) * y_e
    a_dot = cp[GAINS.gamma_v] * dv / math.sqrt(dv * dv + z_e * z_e) * z_e
    psi_d = pi_h - xc[STATE.beta_hat] - c * beta_m - math.atan(y_e / dh)
    theta_d = pi_v + xc[STATE.alpha_hat] + c * alpha_m + math.atan(z_e / dv)
    psi_d_dot = dpi_h * s_geo - dh * ye_dot / (dh * dh + y_e * y_e) - b_dot
    theta_d_dot = dpi_v * s_geo + dv * ze_dot / (dv * dv + z_e * z_e) + a_dot
    speed = math.sqrt(v2)
    du = cp[GAINS.along_max] * speed
    u_d = _clip(speed - cp[GAINS.k_along] * (s - t) * speed, speed - du, speed + du)
    return psi_d, theta_d, u_d, psi_d_dot, theta_d_dot, s_dot, b_dot, a_dot, y_e, z_e, s


@njit_noalloc(inline="always")
def loop_tau(m, d, k, ff, e, e_rate, integral, wn, zeta, pid):
    """Eq. (L6): the demand of one autopilot and its integral gain (N or N m per unit integral).

    PID pole placement on the linear model m x'' + d x' + k x = tau (Fossen 2021, Section 15.3.4):
    Kp = m wn^2 - k, Kd = 2 zeta wn m - d, Ki = m wn^3 / 10 (``pid``); for a speed (m x' + d x = tau)
    the PI Kp = 2 zeta wn m - d, Ki = m wn^2.  ``ff`` is the model's tau along the reference.
    """
    if pid:
        ki = m * wn * wn * wn / 10.0
        return ff - (m * wn * wn - k) * e - (2.0 * zeta * wn * m - d) * e_rate - ki * integral, ki
    ki = m * wn * wn
    return ff - (2.0 * zeta * wn * m - d) * e - ki * integral, ki


@njit_noalloc
def control(t, y, xc, args, out):
    """Compiled LOS autopilot, eq. (L1)-(L9): tau (N, N m) or (rpm, delta_s, delta_r) commands; returns 0."""
    cp, vp, dxc = args.cp, args.vp, out.dxc
    eta, nu, att = y.eta, y.nu, y.att
    psi_d, theta_d, u_d, psi_d_dot, theta_d_dot, s_dot, b_dot, a_dot, y_e, z_e, s = guidance(
        t, y, xc, args.path, cp)
    tmax = cp[GAINS.theta_max]
    theta_c = _clip(theta_d, -tmax, tmax)
    theta_d_dot = theta_d_dot if theta_c == theta_d else 0.0
    e_u = nu[0] - u_d
    e_q = eta[3] - theta_c
    e_r = _ssa(eta[4] - psi_d)
    q_d, r_d = theta_d_dot, att[0] * psi_d_dot
    wn, zt = GAINS.wn, cp[GAINS.zeta]
    m, d, k = VP.m, VP.d, vp[VP.wgml]
    tu, ki_u = loop_tau(vp[m], vp[d], 0.0, vp[d] * u_d, e_u, 0.0, xc[STATE.i], cp[wn], zt, False)
    tq, ki_q = loop_tau(vp[m + 3], vp[d + 3], k, vp[d + 3] * q_d + k * math.sin(theta_c), e_q, nu[3] - q_d,
                        xc[STATE.i + 1], cp[wn + 1], zt, True)
    tr, ki_r = loop_tau(vp[m + 4], vp[d + 4], 0.0, vp[d + 4] * r_d, e_r, nu[4] - r_d, xc[STATE.i + 2], cp[wn + 2], zt,
                        True)
    lo, hi = args.lo, args.hi
    if cp[GAINS.actuators] != 0.0:  # (L8): propeller speed, stern plane, rudder
        ue = max(nu[0], cp[GAINS.u_min])
        bq, br = cp[GAINS.fin] * ue * ue, cp[GAINS.fin + 1] * ue * ue
        a, b = cp[GAINS.thrust], cp[GAINS.thrust + 1]
        c0 = _clip(rpm_for(tu, nu[0], a, b), lo[0], hi[0])
        c1 = _clip(tq / bq, lo[1], hi[1])
        c2 = _clip(tr / br, lo[2], hi[2])
        du, dq, dr = thrust(c0, nu[0], a, b) - tu, bq * c1 - tq, br * c2 - tr
    else:
        c0, c1, c2 = _clip(tu, lo[0], hi[0]), _clip(tq, lo[1], hi[1]), _clip(tr, lo[2], hi[2])
        du, dq, dr = c0 - tu, c1 - tq, c2 - tr
    out.u[0], out.u[1], out.u[2] = c0, c1, c2
    # (L9) back-calculation with tracking rate wn; (L3) adaptation frozen while the autopilot saturates
    dxc[STATE.s] = s_dot
    bound, kaw = cp[GAINS.adapt_max], cp[GAINS.kaw]
    dxc[STATE.beta_hat] = _proj(xc[STATE.beta_hat], b_dot, bound) if dr == 0.0 or kaw == 0.0 else 0.0
    dxc[STATE.alpha_hat] = _proj(xc[STATE.alpha_hat], a_dot, bound) if dq == 0.0 or kaw == 0.0 else 0.0
    dxc[STATE.i] = e_u - kaw * cp[wn] / ki_u * du
    dxc[STATE.i + 1] = e_q - kaw * cp[wn + 1] / ki_q * dq
    dxc[STATE.i + 2] = e_r - kaw * cp[wn + 2] / ki_r * dr
    aux = out.aux
    aux[0], aux[1], aux[2], aux[3] = s, y_e, z_e, psi_d
    aux[4], aux[5], aux[6], aux[7] = theta_c, u_d, xc[STATE.beta_hat], xc[STATE.alpha_hat]
    aux[8], aux[9], aux[10] = xc[STATE.i], xc[STATE.i + 1], xc[STATE.i + 2]
    return 0


def error_poles(wn: float, zeta: float) -> np.ndarray:
    """Closed-loop poles (L7) of an angle loop on the nominal model: roots of s^3 + 2 zeta wn s^2 + wn^2 s + wn^3/10.

    Parameters
    ----------
    wn : float
        Natural frequency, rad/s.
    zeta : float
        Relative damping.

    Returns
    -------
    numpy.ndarray
        The three poles (complex, 1/s).
    """
    return np.roots([1.0, 2.0 * zeta * wn, wn * wn, wn ** 3 / 10.0])


def coupled_poles(vp, u0: float, params: Params) -> dict[str, np.ndarray]:
    """Closed-loop poles of guidance and autopilots on the nominal model linearised on a straight level path.

    The nominal 5-DOF model (``vp``) at surge speed ``u0`` on a straight, level path, with its
    sway-yaw and heave-pitch couplings (Munk moments) and the law's (L1)-(L6) linearised (no
    actuator limit): horizontal states (y_e, v, r, psi, I_psi, beta_hat), vertical states
    (z_e, w, q, theta, I_theta, alpha_hat).

    Parameters
    ----------
    vp : numpy.ndarray
        Packed nominal vehicle (:mod:`auvtrack.vehicle.params`).
    u0 : float
        Surge speed, m/s, > 0.
    params : Params
        The gains.

    Returns
    -------
    dict
        ``"heading"`` and ``"pitch"``: the six eigenvalues of each plane (1/s).
    """
    p, c = params, params.crab
    m11, m22, m33, m44, m55 = (float(vp[VP.m + i]) for i in range(5))
    d22, d33, d44, d55 = (float(vp[VP.d + i]) for i in range(1, 5))
    k, cs = float(vp[VP.wgml]), float(vp[VP.cscale])
    out = {}
    for plane, (dl, gam, wn, m, d, kk) in {"heading": (p.delta_h, p.gamma_h, p.wn_psi, m55, d55, 0.0),
                                           "pitch": (p.delta_v, p.gamma_v, p.wn_theta, m44, d44, k)}.items():
        Kp, Kd, Ki = m * wn * wn - kk, 2.0 * p.zeta * wn * m - d, m * wn ** 3 / 10.0
        A = np.zeros((6, 6))  # (err, vel, rate, angle, integral, estimate)
        if plane == "heading":  # y_e' = u0 psi + v; m22 v' = -m11 u0 r - d22 v; psi_d = -y_e/dl - c v/u0 - beta
            err_dot = np.array([0.0, 1.0, 0.0, u0, 0.0, 0.0])
            A[1] = np.array([0.0, -d22, -cs * m11 * u0, 0.0, 0.0, 0.0]) / m22
            model = np.array([0.0, -cs * (m22 - m11) * u0, 0.0, 0.0, 0.0, 0.0])  # Munk moment
            angle_d = np.array([-1.0 / dl, -c / u0, 0.0, 0.0, 0.0, -1.0])
            rate_d = -err_dot / dl - gam * np.eye(6)[0]
        else:  # z_e' = w - u0 theta; m33 w' = m11 u0 q - d33 w; theta_d = z_e/dl + c w/u0 + alpha
            err_dot = np.array([0.0, 1.0, 0.0, -u0, 0.0, 0.0])
            A[1] = np.array([0.0, -d33, cs * m11 * u0, 0.0, 0.0, 0.0]) / m33
            model = np.array([0.0, -cs * (m11 - m33) * u0, 0.0, -kk, 0.0, 0.0])  # Munk and restoring moments
            angle_d = np.array([1.0 / dl, c / u0, 0.0, 0.0, 0.0, 1.0])
            rate_d = err_dot / dl + gam * np.eye(6)[0]
        e = np.eye(6)[3] - angle_d
        tau = d * rate_d + kk * angle_d - Kp * e - Kd * (np.eye(6)[2] - rate_d) - Ki * np.eye(6)[4]
        A[0] = err_dot
        A[2] = (tau + model - d * np.eye(6)[2]) / m
        A[3] = np.eye(6)[2]
        A[4] = e
        A[5] = gam * np.eye(6)[0]
        out[plane] = np.linalg.eigvals(A)
    return out


def fin_coefficients(plant) -> tuple[float, float]:
    """(c_q, c_r): pitch and yaw moment of the plant's stern plane and rudder per (m/s)^2 and rad (N m).

    Parameters
    ----------
    plant : auvtrack.control.registry.PlantView
        The plant flown: its ``applied`` tau at u = 1 m/s with each fin at 0.05 rad.

    Returns
    -------
    tuple of 2 float
        c_q, c_r (N m s^2 / (m^2 rad)); their signs are the plant's fin conventions.
    """
    d = 0.05
    return (float(plant.applied(u=1.0, delta_s=d)[1]) / d, float(plant.applied(u=1.0, delta_r=d)[2]) / d)


def thrust_coefficients(plant, n_max: float, u0: float) -> tuple[float, float]:
    """(a, b) of T(n, u) = a n^2 + b n u fitted to the plant's propeller (least squares, n > 0).

    Parameters
    ----------
    plant : auvtrack.control.registry.PlantView
        The plant flown: its ``applied`` tau_u with the propeller at n and the fins at 0.
    n_max : float
        Propeller speed limit, rpm.
    u0 : float
        Cruise speed, m/s: the fit spans 0.5 u0 .. 1.5 u0 and 0.1 .. 1 n_max.

    Returns
    -------
    tuple of 2 float
        a (N / rpm^2) > 0 and b (N s / (m rpm)).

    Raises
    ------
    ValueError
        When the propeller gives no forward thrust (a <= 0).
    """
    rows, rhs = [], []
    for n in np.linspace(0.1, 1.0, 10) * n_max:
        for u in np.linspace(0.5, 1.5, 5) * u0:
            rows.append((n * n, n * u))
            rhs.append(float(plant.applied(u=float(u), n=float(n))[0]))
    (a, b), *_ = np.linalg.lstsq(np.asarray(rows), np.asarray(rhs), rcond=None)
    if not a > 0.0:
        raise ValueError("controller.kind: los_autopilot needs a propeller that pushes forward (fitted thrust "
                         f"coefficient a = {a:.3g} N/rpm^2)")
    return float(a), float(b)


def setup(params: Params, ctx) -> CompiledController:
    """Pack the gains, the plant's fin and propeller coefficients (actuator commands) and the initial state.

    The path parameter starts at s = 0 (the first projection searches the path from there); on a
    plant whose actuators it commands, the surge integrator starts where the command equals the
    propeller's thrust at the plant's initial speed and propeller speed (a bumpless start).

    Parameters
    ----------
    params : Params
        The ``[controller]`` section.
    ctx : auvtrack.control.registry.SetupContext
        Nominal vehicle, initial state, the plant's view, what the law commands.

    Returns
    -------
    CompiledController
        Packed gains, initial state, channel names and the derived numbers (closed-loop poles,
        fin and thrust coefficients).
    """
    p = params
    vp = np.asarray(ctx.vp_nom, dtype=np.float64)
    actuators = ctx.commands == "actuators"
    fin, thr = (0.0, 0.0), (0.0, 0.0)
    u0 = float(np.linalg.norm(ctx.refm0[1])) or max(abs(ctx.nu0[0]), 1.0)
    resolved: dict = {"commands": ctx.commands}
    if actuators:
        lo, hi, _ = ctx.plant.feedback()
        fin = fin_coefficients(ctx.plant)
        thr = thrust_coefficients(ctx.plant, float(hi[0]), u0)
        resolved.update(fin_moment_per_u2_rad=list(fin), thrust_a_b=list(thr))
    cp = GAINS.pack(actuators=float(actuators), delta_h=p.delta_h, delta_v=p.delta_v, gamma_h=p.gamma_h,
                    gamma_v=p.gamma_v, adapt_max=p.adapt_max, crab=p.crab, theta_max=p.theta_max, k_along=p.k_along,
                    along_max=p.along_max, wn=(p.wn_u, p.wn_theta, p.wn_psi), zeta=(p.zeta, p.zeta, p.zeta),
                    kaw=p.kaw, fin=fin, thrust=thr, u_min=p.u_min)
    nu = tuple(float(v) for v in ctx.nu0)
    xc0 = np.zeros(STATE.size)  # s(0) = 0: the first projection searches from the reference's start time
    if actuators:
        T0 = float(ctx.plant.applied(u=nu[0], n=ctx.plant.initial("n"))[0])
        xc0[STATE.i] = (vp[VP.d] * nu[0] - T0) / (vp[VP.m] * p.wn_u ** 2)
    resolved["error_poles"] = {k: [[float(z.real), float(z.imag)] for z in error_poles(w, p.zeta)]
                               for k, w in (("pitch", p.wn_theta), ("heading", p.wn_psi))}
    coupled = coupled_poles(vp, u0, p)
    resolved["coupled_poles"] = {k: [[float(z.real), float(z.imag)] for z in v] for k, v in coupled.items()}
    notes = tuple(f"los_autopilot: the {k} loop is unstable on the design model at {u0:.3g} m/s (pole "
                  f"{max(v, key=lambda z: z.real):.3g} 1/s): raise controller.zeta or controller.wn_"
                  f"{'psi' if k == 'heading' else 'theta'}" for k, v in coupled.items() if max(v.real) >= 0.0)
    return CompiledController(cp=cp, xc0=xc0, aux_names=AUX_NAMES, notes=notes, resolved=resolved)

"""PPC baseline: classical prescribed-performance control with a rigid exponential envelope.

The scheme the paper improves on (its Sec. 1: rigid bounds "may induce system instability under
large disturbances").  Per axis (docs/controllers.md, eq. R1-R4):

    rho(t)  = (rho0 - rho_inf) exp(-l t) + rho_inf                        (R1, m)
    xi = e / rho,  eps = atanh(xi) = 1/2 ln((1 + xi) / (1 - xi))          (R2)
    eps_dot = Omega e_dot - U e,  Omega = rho / D,  U = rho_dot / D,  D = rho^2 - e^2
    eps_ddot = Omega_dot e_dot + Omega e_ddot - U_dot e - U e_dot         (R3)
    e_ddot*  = (nu - Omega_dot e_dot + U_dot e + U e_dot) / Omega,
    nu       = -kp eps - kd eps_dot                                       (R4)

(R1) is the exponential performance function and (R2) the error transformation of
Bechlioulis & Rovithakis (2008) with a symmetric envelope (their M = 1, S = tanh): e stays
inside (-rho, rho) for as long as eps stays bounded.  The envelope is rigid: rho is a fixed
function of time, with no widening and no adjustment; a start on or outside it is refused by
:func:`setup`, and an error that reaches it stops the run (status 1).  As for every baseline
here, the transformed error is controlled through the nominal model (the input map of
tracking.py): on the disturbance-free nominal plant eps obeys eps_ddot = -kp eps - kd eps_dot
exactly, and on the true plant eps_ddot = nu + Omega chi, with Omega >= 1 / rho growing as the
envelope narrows -- the mechanism by which a large disturbance breaks a rigid envelope.
B&R's adaptive approximation of the unknown dynamics is not used (the baselines share the
nominal model; none of them estimates chi except ``backstepping``'s optional bias).

With ``saturation = "compensated"`` the envelope is imposed on the compensated error e~ = e - lam,
where lam is the response of an auxiliary system to the error acceleration d_a the actuators
could not produce (d_a = J3 M_bar^-1 (sat(tau) - tau), :mod:`auvtrack.control.saturation`):

    lam_ddot = -2 k_aux lam_dot - k_aux^2 lam + d_a                         (R5, per axis, m/s^2)
    a        = e_ddot*(e~, e~_dot) - 2 k_aux lam_dot - k_aux^2 lam           (R6)

(R4) evaluated at (e~, e~_dot).  On the nominal plant e~_ddot = e_ddot*(e~, e~_dot) + chi whatever
the actuators do: eps of e~ obeys the published law eps_ddot = nu + Omega chi while lam carries
what the saturation took, and lam -> 0 once the actuators deliver again (docs/derivation.md
section 7).  Without saturation lam = 0 and (R6) is (R4).  This is the modified tracking error of
command-filtered / auxiliary-system designs (Farrell, Polycarpou, Sharma & Dong 2009, IEEE TAC
54(6), 1391-1395; Chen, Ge & Ren 2011, Automatica 47(3), 452-465) put in front of Bechlioulis &
Rovithakis's transformation.

Source: Bechlioulis, C. P. & Rovithakis, G. A. (2008), Robust adaptive control of feedback
linearizable MIMO nonlinear systems with prescribed performance, IEEE Trans. Autom. Control
53(9), 2090-2099 (performance function, error transformation).

Packed ``cp`` = [kp, kd, l, rho0 (3), rho_inf (3), k_aux, saturation]; internal state: none, or
(lam (3, m), lam_dot (3, m/s)) when compensated; logged aux: rho_x, rho_y, rho_z, eps_x, eps_y,
eps_z, and lam as sat_comp_x, sat_comp_y, sat_comp_z when compensated.
"""
from __future__ import annotations

import math
from typing import Annotated, Literal

import numpy as np
from pydantic import Field

from ..jit import njit, njit_noalloc
from ..packing import packed_layout
from .gain_checks import fmt, require
from .registry import CompiledController, ControllerParams, tunable
from .saturation import COMPENSATED, SATURATION, accel_deficit, code
from .tracking import error_state_forces, input_for_accel_forces

NAME = "ppc"
AUX_NAMES = ("rho_x", "rho_y", "rho_z", "eps_x", "eps_y", "eps_z")
TIME_EXPONENTS = {"kp": 2, "kd": 1, "l": 1, "k_aux": 1}
"""Gain -> its time dimension n (units s^-n; the envelope rho0, rho_inf is kept): the gain design scales g by
omega^n (control/design.py, D1)."""
COMPENSATION_NAMES = ("sat_comp_x", "sat_comp_y", "sat_comp_z")
"""Channels added when compensated: lam of (R5), m."""
GAINS = packed_layout("PPCGains", kp=1, kd=1, l=1, rho0=3, rho_inf=3, k_aux=1, saturation=1)
AXES = ("x", "y", "z")
Pos = Annotated[float, Field(gt=0)]


class Params(ControllerParams):
    """Prescribed-performance control with the rigid envelope (R1) of Bechlioulis & Rovithakis (2008).

    rho_inf is the paper's Section 4 value; rho0 is its 5 m in x and larger in y and z so that
    every start of the tuning study lies strictly inside (the Section 4 start has |e_y(0)| =
    0.5 m, on the paper's rho_{2,0} = 0.5 m, and a rigid envelope cannot start there).
    """

    kind: Literal["ppc"] = "ppc"
    kp: float = tunable(16.0, 0.01, 200.0, log=True, gt=0, description="gain on eps, 1/s^2")
    kd: float = tunable(8.0, 0.05, 50.0, log=True, gt=0, description="gain on eps_dot, 1/s")
    l: float = tunable(0.3, 0.01, 2.0, log=True, gt=0, description="envelope decay rate, 1/s")
    rho0: tuple[Pos, Pos, Pos] = Field((5.0, 1.5, 1.0), description="rho(0) per axis, m")
    rho_inf: tuple[Pos, Pos, Pos] = tunable((0.005, 0.005, 0.005), 0.005, 1.0, log=True,
                                            description="rho(inf) per axis, m (searched as one value for the three axes)")
    k_aux: float = tunable(1.0, 0.01, 10.0, log=True, gt=0, description="rate of the auxiliary system (R5), 1/s (saturation = 'compensated')")
    saturation: Literal[SATURATION] = Field(
        "published", description="'published': eq. (R4); 'compensated': the envelope on the error less the "
        "auxiliary system's response to what the actuators could not produce (R5)-(R6)")


@njit
def envelope_x(x, r0, rinf, l):
    """(rho, rho_dot, rho_ddot) of eq. (R1) (m, m/s, m/s^2) given x = exp(-l t)."""
    d = (r0 - rinf) * x
    return d + rinf, -l * d, l * l * d


@njit
def envelope(t, r0, rinf, l):
    """(rho, rho_dot, rho_ddot) of eq. (R1) at time t (s)."""
    return envelope_x(math.exp(-l * t), r0, rinf, l)


@njit
def axis(e, ed, rho, rhod, rhodd, kp, kd):
    """(status, eps, e_ddot*) of one axis, eq. (R2)-(R4); status 1 when |e| >= rho."""
    xi = e / rho
    if not abs(xi) < 1.0:
        return 1, 0.0, 0.0
    D = rho * rho - e * e
    Om, U = rho / D, rhod / D
    eps = math.atanh(xi)
    epsd = Om * ed - U * e
    Dd = 2.0 * rho * rhod - 2.0 * e * ed
    Omd = rhod / D - rho * Dd / (D * D)
    Ud = rhodd / D - rhod * Dd / (D * D)
    nu = -kp * eps - kd * epsd
    return 0, eps, (nu - Omd * ed + Ud * e + U * ed) / Om


@njit_noalloc(inline="always")
def control(t, y, xc, args, out):
    """Compiled PPC law, eq. (R1)-(R4), or (R5)-(R6) when compensated (tau in N, N m); status 1 if an error reaches its envelope."""
    e, ed, f, gf = error_state_forces(y.eta, y.att, y.nu, args.ref, args.vp)
    cp, aux = args.cp, out.aux
    kp, kd, l = cp[GAINS.kp], cp[GAINS.kd], cp[GAINS.l]
    comp = cp[GAINS.saturation] == COMPENSATED
    if comp:  # the envelope acts on e~ = e - lam (R6)
        e = (e[0] - xc[0], e[1] - xc[1], e[2] - xc[2])
        ed = (ed[0] - xc[3], ed[1] - xc[4], ed[2] - xc[5])
    x = math.exp(-l * t)  # shared by the three axes
    r0 = envelope_x(x, cp[GAINS.rho0], cp[GAINS.rho_inf], l)
    r1 = envelope_x(x, cp[GAINS.rho0 + 1], cp[GAINS.rho_inf + 1], l)
    r2 = envelope_x(x, cp[GAINS.rho0 + 2], cp[GAINS.rho_inf + 2], l)
    aux[0], aux[1], aux[2] = r0[0], r1[0], r2[0]
    st0, eps0, a0 = axis(e[0], ed[0], r0[0], r0[1], r0[2], kp, kd)
    st1, eps1, a1 = axis(e[1], ed[1], r1[0], r1[1], r1[2], kp, kd)
    st2, eps2, a2 = axis(e[2], ed[2], r2[0], r2[1], r2[2], kp, kd)
    if st0 + st1 + st2 != 0:
        return 1
    aux[3], aux[4], aux[5] = eps0, eps1, eps2
    if not comp:
        out.u[0], out.u[1], out.u[2] = input_for_accel_forces(y.att, args.vp, f, (a0, a1, a2), gf)
        return 0
    k = cp[GAINS.k_aux]
    b0, b1, b2 = (-2.0 * k * xc[3] - k * k * xc[0], -2.0 * k * xc[4] - k * k * xc[1],
                  -2.0 * k * xc[5] - k * k * xc[2])  # the auxiliary system's own part of (R5)
    tau = input_for_accel_forces(y.att, args.vp, f, (a0 + b0, a1 + b1, a2 + b2), gf)
    out.u[0], out.u[1], out.u[2] = tau
    da = accel_deficit(y.att, args.vp, tau, args.lo, args.hi)[0]
    dxc = out.dxc
    dxc[0], dxc[1], dxc[2] = xc[3], xc[4], xc[5]
    dxc[3], dxc[4], dxc[5] = b0 + da[0], b1 + da[1], b2 + da[2]
    aux[6], aux[7], aux[8] = xc[0], xc[1], xc[2]
    return 0


def check(p: Params, e0) -> None:
    """Envelope conditions: rho_inf <= rho0 per axis, and the start strictly inside, |e_i(0)| < rho0_i.

    Parameters
    ----------
    p : Params
        The gains and envelope.
    e0 : sequence of 3 float
        Initial virtual-point error (m).

    Raises
    ------
    ValueError
        ``controller.rho_inf: ...`` or ``controller.rho0: ...`` naming the axis.
    """
    for i, a in enumerate(AXES):
        require(p.rho_inf[i] <= p.rho0[i], "rho_inf", f"must be <= rho0 = {fmt(list(p.rho0))} on axis {a} "
                "(a shrinking envelope)", list(p.rho_inf))
        require(abs(e0[i]) < p.rho0[i], "rho0",
                f"the start lies on or outside the rigid envelope on axis {a} (|e_{a}(0)| = {abs(e0[i]):.6g} m "
                f">= rho0_{a}); enlarge rho0 (a rigid PPC cannot widen)", list(p.rho0))


def setup(params: Params, ctx) -> CompiledController:
    """Check the envelope against the start ``ctx.e0`` and pack gains and envelope."""
    p = params
    check(p, ctx.e0)
    cp = GAINS.pack(kp=p.kp, kd=p.kd, l=p.l, rho0=p.rho0, rho_inf=p.rho_inf, k_aux=p.k_aux,
                    saturation=code(p.saturation))
    xi0 = [float(ctx.e0[i] / p.rho0[i]) for i in range(3)]
    comp = p.saturation == "compensated"
    return CompiledController(cp=cp, xc0=np.zeros(6 if comp else 0),
                              aux_names=AUX_NAMES + (COMPENSATION_NAMES if comp else ()), resolved={"xi0": xi0})


def nominal_axis(p: Params, axis_index: int, e0: float):
    """One axis of the nominal closed loop (R1)-(R4) from e(0) = e0 at rest, for the gain design's peak demand.

    Parameters
    ----------
    p : Params
        The gains.
    axis_index : int
        0, 1, 2 (x, y, z: the envelope rho0, rho_inf is per axis).
    e0 : float
        Initial error, m.

    Returns
    -------
    (callable, list)
        ``f(t, x) -> (x_dot, a)`` over x = (e, e_dot), and x(0).

    Raises
    ------
    ValueError
        ``e0`` leaves the envelope.
    """
    def f(t, x):
        r = envelope(t, p.rho0[axis_index], p.rho_inf[axis_index], p.l)
        status, _, a = axis(x[0], x[1], r[0], r[1], r[2], p.kp, p.kd)
        if status != 0:
            raise ValueError(f"controller.rho0: e_ref = {e0} m leaves the PPC envelope on axis {axis_index}")
        return np.array([x[1], a]), a
    return f, [e0, 0.0]

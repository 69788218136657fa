"""Backstepping baseline: Lyapunov backstepping on (e, e_dot) with an optional adaptive bias.

Per axis (docs/controllers.md, eq. B1-B4), with the lumped disturbance chi entering as
e_ddot = a + chi (eq. 15):

    z1 = e,   alpha1 = -c1 z1,   z2 = e_dot - alpha1 = e_dot + c1 e             (B1)
    a  = -c1 e_dot - z1 - c2 z2 - b_hat                                        (B2, m/s^2)
    b_hat_dot = gamma z2 - sigma b_hat   (adaptive = true; else b_hat = 0)     (B3)

so that z1_dot = z2 - c1 z1 and z2_dot = -z1 - c2 z2 + (chi - b_hat).  With
V = z1^2/2 + z2^2/2 + (chi - b_hat)^2 / (2 gamma) and a constant chi,

    V_dot = -c1 z1^2 - c2 z2^2 + sigma (chi - b_hat) b_hat / gamma             (B4)

(sigma = 0: V_dot <= 0 and z -> 0; sigma > 0, the leakage, trades the exact rejection of a
constant bias for a bounded estimate).  On the disturbance-free nominal plant (chi = 0) the
triple (z1, z2, b_hat) obeys a linear system exactly; that identity is what the tests check.

With ``saturation = "compensated"`` the bias estimate is conditioned on what the actuators could
not produce (back-calculation, as the PID's eq. P2):

    b_hat_dot = gamma z2 - sigma b_hat - kaw d_a                              (B3c)

with d_a = J3 M_bar^-1 (sat(tau) - tau) the error acceleration the actuators' reach removes on the
nominal model (:mod:`auvtrack.control.saturation`, docs/derivation.md section 7): the estimate does
not learn, as a disturbance, the part of e_ddot the actuators could not deliver.  d_a = 0 without
saturation, where (B3c) is (B3) exactly.  ``k0`` weighs z1 in V (V = k0 z1^2/2 + z2^2/2, so that
a = -c1 e_dot - k0 z1 - c2 z2 - b_hat and V_dot = -c1 k0 z1^2 - c2 z2^2 + ...); k0 = 1 is the
published law, and a gain with units 1/s^2 lets the design rule of docs/controllers.md scale the
whole law in time.

Sources: integrator backstepping and its adaptive version with a tuning-function-free update,
Krstic, Kanellakopoulos & Kokotovic (1995), *Nonlinear and Adaptive Control Design*, Wiley,
ch. 2 (integrator backstepping) and ch. 3-4 (adaptive backstepping); the sigma-modification
leakage, Ioannou & Sun (1996), *Robust Adaptive Control*, ch. 8.

Packed ``cp`` = [c1, c2, gamma (0 when not adaptive), sigma, k0, kaw, saturation]; internal state xc = b_hat (3,
m/s^2); logged aux: z2_x, z2_y, z2_z, b_hat_x, b_hat_y, b_hat_z.
"""
from __future__ import annotations

from typing import Literal

import numpy as np
from pydantic import Field

from ..jit import njit, njit_noalloc
from ..packing import packed_layout
from .gain_checks import require
from .registry import CompiledController, ControllerParams, tunable
from .saturation import COMPENSATED, SATURATION, accel_deficit, code
from .tracking import error_state_forces, input_for_accel_forces

NAME = "backstepping"
AUX_NAMES = ("z2_x", "z2_y", "z2_z", "b_hat_x", "b_hat_y", "b_hat_z")
TIME_EXPONENTS = {"c1": 1, "c2": 1, "k0": 2, "gamma": 2, "sigma": 1, "kaw": 1}
"""Gain -> its time dimension n (units s^-n): the gain design scales g by omega^n (control/design.py, D1)."""
GAINS = packed_layout("BacksteppingGains", c1=1, c2=1, gamma=1, sigma=1, k0=1, kaw=1, saturation=1)


class Params(ControllerParams):
    """Backstepping on (e, e_dot) with an optional adaptive estimate of the lumped disturbance (eq. B1-B4)."""

    kind: Literal["backstepping"] = "backstepping"
    c1: float = tunable(1.0, 0.01, 20.0, log=True, gt=0, description="first-step gain, 1/s")
    c2: float = tunable(2.0, 0.01, 20.0, log=True, gt=0, description="second-step gain, 1/s")
    adaptive: bool = Field(True, description="estimate a bias b_hat of the lumped disturbance (eq. B3)")
    gamma: float = tunable(2.0, 1e-4, 50.0, log=True, gt=0, description="adaptation gain, 1/s^2 (used when adaptive)")
    sigma: float = tunable(0.0, 0.0, 1.0, ge=0, description="leakage of b_hat (sigma-modification), 1/s")
    k0: float = Field(1.0, gt=0, description="weight of z1 in V, 1/s^2 (1: the published law)")
    kaw: float = tunable(1.0, 0.01, 10.0, log=True, ge=0, description="back-calculation gain of b_hat (saturation = 'compensated'), 1/s")
    saturation: Literal[SATURATION] = Field(
        "published", description="'published': eq. (B3); 'compensated': b_hat conditioned on the actuators' "
        "reach (B3c)")


@njit
def axis(e, ed, bh, c1, c2, gam, sig, k0):
    """(z2 (m/s), a (m/s^2), b_hat_dot (m/s^3)) of one axis, eq. (B1)-(B3) (k0 = 1: the published law)."""
    z2 = ed + c1 * e
    return z2, -c1 * ed - k0 * e - c2 * z2 - bh, gam * z2 - sig * bh


@njit_noalloc(inline="always")
def control(t, y, xc, args, out):
    """Compiled backstepping law, eq. (B1)-(B3), or (B3c) when compensated (tau in N, N m); returns 0."""
    e, ed, f, gf = error_state_forces(y.eta, y.att, y.nu, args.ref, args.vp)
    cp = args.cp
    c1, c2, gam, sig, k0 = cp[GAINS.c1], cp[GAINS.c2], cp[GAINS.gamma], cp[GAINS.sigma], cp[GAINS.k0]
    z0, a0, d0 = axis(e[0], ed[0], xc[0], c1, c2, gam, sig, k0)
    z1, a1, d1 = axis(e[1], ed[1], xc[1], c1, c2, gam, sig, k0)
    z2, a2, d2 = axis(e[2], ed[2], xc[2], c1, c2, gam, sig, k0)
    aux = out.aux
    aux[0], aux[1], aux[2], aux[3], aux[4], aux[5] = z0, z1, z2, xc[0], xc[1], xc[2]
    tau = input_for_accel_forces(y.att, args.vp, f, (a0, a1, a2), gf)
    out.u[0], out.u[1], out.u[2] = tau
    if cp[GAINS.saturation] == COMPENSATED and gam > 0.0:
        da, sat = accel_deficit(y.att, args.vp, tau, args.lo, args.hi)
        if sat:  # (B3c); without saturation d_a = 0 and (B3) stands as it is
            kaw = cp[GAINS.kaw]
            d0, d1, d2 = d0 - kaw * da[0], d1 - kaw * da[1], d2 - kaw * da[2]
    out.dxc[0], out.dxc[1], out.dxc[2] = d0, d1, d2
    return 0


def check(p: Params) -> None:
    """Conditions of eq. (B4): c1, c2 > 0 (model ranges), and no leakage without adaptation.

    Parameters
    ----------
    p : Params
        The gains.

    Raises
    ------
    ValueError
        ``controller.sigma: ...`` when a leakage is given with ``adaptive = false``.
    """
    require(p.adaptive or p.sigma == 0.0, "sigma", "a leakage needs adaptive = true (b_hat is fixed at 0 otherwise)",
            p.sigma)


def setup(params: Params, ctx) -> CompiledController:
    """Pack the gains; b_hat(0) = 0 (adaptation off: gamma = sigma = 0 and b_hat stays 0)."""
    p = params
    check(p)
    gam = p.gamma if p.adaptive else 0.0
    cp = GAINS.pack(c1=p.c1, c2=p.c2, gamma=gam, sigma=p.sigma, k0=p.k0, kaw=p.kaw, saturation=code(p.saturation))
    return CompiledController(cp=cp, xc0=np.zeros(3), aux_names=AUX_NAMES)


def nominal_axis(p: Params, axis_index: int, e0: float):
    """One axis of the nominal closed loop (B1)-(B4) from e(0) = e0 at rest, for the gain design's peak demand.

    Parameters
    ----------
    p : Params
        The gains.
    axis_index : int
        0, 1, 2 (x, y, z; the gains are shared by the axes).
    e0 : float
        Initial error, m.

    Returns
    -------
    (callable, list)
        ``f(t, x) -> (x_dot, a)`` over x = (e, e_dot, b_hat), and x(0).
    """
    gam = p.gamma if p.adaptive else 0.0

    def f(t, x):
        _, a, db = axis(x[0], x[1], x[2], p.c1, p.c2, gam, p.sigma, p.k0)
        return np.array([x[1], a, db]), a
    return f, [e0, 0.0, 0.0]

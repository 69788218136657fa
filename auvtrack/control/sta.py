"""STA baseline: super-twisting (continuous second-order sliding-mode) control of the virtual point.

Per axis (docs/controllers.md, eq. S1-S5), with e_ddot = a + chi (eq. 15):

    s     = e_dot + lam e                                                  (S1, m/s)
    a     = -lam e_dot - k1 |s|^(1/2) sign(s) + v                          (S2, m/s^2)
    v_dot = -k2 sign(s)                                                    (S3)

so that s_dot = -k1 |s|^(1/2) sign(s) + w, w_dot = -k2 sign(s) + chi_dot with w = v + chi: the
super-twisting algorithm of Levant (1993) driven by the perturbation chi_dot.  The input a is
continuous (the discontinuity is integrated).  With |chi_dot| <= L (m/s^3) the sliding set
s = s_dot = 0 is reached in finite time when

    Levant (1993):          k2 > L  and  k1^2 >= 4 L (k2 + L) / (k2 - L)   (S4)
    Moreno & Osorio (2012): k2 > L + 2 L^2 / k1^2                          (S5)

(S4) is Levant's sufficient condition with unit control gain (the nominal-model inverse makes
the gain 1); (S5) is the exact condition under which the quadratic Lyapunov function of Moreno
& Osorio, V = zeta^T P zeta with zeta = (|s|^(1/2) sign s, w), P = [[4 k2 + k1^2, -k1], [-k1,
2]] / 2, decreases for every perturbation |chi_dot| <= L (S-procedure, derived in
docs/controllers.md).  :func:`setup` checks the one named by ``gain_condition``.  On the
sliding set e_dot = -lam e: e -> 0 exponentially.

With ``saturation = "compensated"`` the integral is conditioned on what the actuators could not
produce (back-calculation, as the PID's eq. P2; Astrom & Hagglund 2006, ch. 3):

    v_dot = -k2 sign(s) + kaw d_a                                          (S3c)

with d_a = J3 M_bar^-1 (sat(tau) - tau) the error acceleration the actuators' reach [``args.lo``,
``args.hi``] removes on the nominal model (:mod:`auvtrack.control.saturation`, docs/derivation.md
section 7); d_a = 0 without saturation, where (S3c) is (S3) exactly.

Sources: Levant, A. (1993), Sliding order and sliding accuracy in sliding mode control,
Int. J. Control 58(6), 1247-1263 (the super-twisting algorithm and its convergence condition);
Moreno, J. A. & Osorio, M. (2012), Strict Lyapunov functions for the super-twisting algorithm,
IEEE Trans. Autom. Control 57(4), 1035-1040 (the Lyapunov function V).

Packed ``cp`` = [lam, k1, k2, kaw, saturation]; internal state xc = v (3, m/s^2); logged aux: sliding_x, sliding_y, sliding_z (s),
integral_x, integral_y, integral_z (v).
"""
from __future__ import annotations

import math
from typing import Literal

import numpy as np
from pydantic import Field

from ..jit import njit, njit_noalloc
from ..packing import packed_layout
from .gain_checks import require
from .registry import CompiledController, ControllerParams, tunable
from .saturation import COMPENSATED, SATURATION, accel_deficit, code
from .tracking import error_state_forces, input_for_accel_forces, sign

NAME = "sta"
AUX_NAMES = ("sliding_x", "sliding_y", "sliding_z", "integral_x", "integral_y", "integral_z")  # s and v
TIME_EXPONENTS = {"lam": 1, "k1": 1.5, "k2": 3, "L": 3, "kaw": 1}
"""Gain -> its time dimension n (units s^-n): the gain design scales g by omega^n (control/design.py, D1)."""
GAINS = packed_layout("STAGains", lam=1, k1=1, k2=1, kaw=1, saturation=1)


class Params(ControllerParams):
    """Super-twisting sliding-mode control on s = e_dot + lam e (eq. S1-S5).

    ``L`` is the bound on |d chi / dt| that the gain condition is checked against (the
    default holds on Section 4 with margin: ``tests/control/test_baselines.py`` measures it).
    """

    kind: Literal["sta"] = "sta"
    lam: float = tunable(1.0, 0.01, 20.0, log=True, gt=0, description="sliding-surface slope, 1/s")
    k1: float = tunable(1.0, 0.01, 20.0, log=True, gt=0, description="gain of |s|^(1/2) sign(s), m^(1/2)/s^(3/2)")
    k2: float = tunable(0.5, 0.001, 20.0, log=True, gt=0, description="gain of the integrated sign(s), m/s^3")
    L: float = Field(0.1, ge=0, description="assumed bound on |d chi/dt|, m/s^3")
    gain_condition: Literal["moreno_osorio", "levant", "none"] = Field(
        "moreno_osorio", description="which finite-time condition setup checks: (S5), (S4), or none")
    kaw: float = tunable(1.0, 0.01, 10.0, log=True, ge=0, description="back-calculation gain of the integral (saturation = 'compensated'), 1/s")
    saturation: Literal[SATURATION] = Field(
        "published", description="'published': eq. (S3); 'compensated': the integral conditioned on the "
        "actuators' reach (S3c)")


@njit
def axis(e, ed, v, lam, k1, k2):
    """(s (m/s), a (m/s^2), v_dot (m/s^3)) of one axis, eq. (S1)-(S3)."""
    s = ed + lam * e
    sg = sign(s)
    return s, -lam * ed - k1 * math.sqrt(abs(s)) * sg + v, -k2 * sg


@njit_noalloc(inline="always")
def control(t, y, xc, args, out):
    """Compiled super-twisting law, eq. (S1)-(S3), or (S3c) when compensated (tau in N, N m); returns 0."""
    e, ed, f, gf = error_state_forces(y.eta, y.att, y.nu, args.ref, args.vp)
    cp = args.cp
    lam, k1, k2 = cp[GAINS.lam], cp[GAINS.k1], cp[GAINS.k2]
    s0, a0, d0 = axis(e[0], ed[0], xc[0], lam, k1, k2)
    s1, a1, d1 = axis(e[1], ed[1], xc[1], lam, k1, k2)
    s2, a2, d2 = axis(e[2], ed[2], xc[2], lam, k1, k2)
    aux = out.aux
    aux[0], aux[1], aux[2], aux[3], aux[4], aux[5] = s0, s1, s2, xc[0], xc[1], xc[2]
    tau = input_for_accel_forces(y.att, args.vp, f, (a0, a1, a2), gf)
    out.u[0], out.u[1], out.u[2] = tau
    if cp[GAINS.saturation] == COMPENSATED:
        da, sat = accel_deficit(y.att, args.vp, tau, args.lo, args.hi)
        if sat:  # (S3c); without saturation d_a = 0 and (S3) stands as it is
            kaw = cp[GAINS.kaw]
            d0, d1, d2 = d0 + kaw * da[0], d1 + kaw * da[1], d2 + kaw * da[2]
    out.dxc[0], out.dxc[1], out.dxc[2] = d0, d1, d2
    return 0


def levant_k1_min(k2: float, L: float) -> float:
    """Smallest k1 allowed by Levant's condition (S4) for k2 > L (m^(1/2)/s^(3/2))."""
    return math.sqrt(4.0 * L * (k2 + L) / (k2 - L))


def moreno_osorio_k2_min(k1: float, L: float) -> float:
    """Infimum of the k2 allowed by the Moreno-Osorio Lyapunov condition (S5), m/s^3."""
    return L + 2.0 * L * L / (k1 * k1)


def check(p: Params) -> None:
    """The finite-time condition selected by ``p.gain_condition`` (eq. S4 or S5).

    Parameters
    ----------
    p : Params
        Gains and the perturbation bound L.

    Raises
    ------
    ValueError
        ``controller.k2: ...`` or ``controller.k1: ...`` naming the violated bound.
    """
    if p.gain_condition == "levant":
        require(p.k2 > p.L, "k2", f"must be > L = {p.L:.6g} m/s^3 (Levant's condition, eq. S4)", p.k2)
        k1min = levant_k1_min(p.k2, p.L)
        require(p.k1 >= k1min, "k1", f"must be >= sqrt(4 L (k2 + L) / (k2 - L)) = {k1min:.6g} "
                "(Levant's condition, eq. S4)", p.k1)
    elif p.gain_condition == "moreno_osorio":
        k2min = moreno_osorio_k2_min(p.k1, p.L)
        require(p.k2 > k2min, "k2", f"must be > L + 2 L^2 / k1^2 = {k2min:.6g} m/s^3 "
                "(Moreno-Osorio Lyapunov condition, eq. S5)", p.k2)


def setup(params: Params, ctx) -> CompiledController:
    """Check the gain condition and pack the gains; v(0) = 0."""
    p = params
    check(p)
    cp = GAINS.pack(lam=p.lam, k1=p.k1, k2=p.k2, kaw=p.kaw, saturation=code(p.saturation))
    return CompiledController(cp=cp, xc0=np.zeros(3), aux_names=AUX_NAMES,
                              resolved={"levant_k1_min": levant_k1_min(p.k2, p.L) if p.k2 > p.L else None,
                                        "moreno_osorio_k2_min": moreno_osorio_k2_min(p.k1, p.L)})


def nominal_axis(p: Params, axis_index: int, e0: float):
    """One axis of the nominal closed loop (S1)-(S7) from e(0) = e0 at rest, for the gain design's peak demand.

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
        ``f(t, x) -> (x_dot, a)`` over x = (e, e_dot, v), and x(0).
    """
    def f(t, x):
        _, a, dv = axis(x[0], x[1], x[2], p.lam, p.k1, p.k2)
        return np.array([x[1], a, dv]), a
    return f, [e0, 0.0, 0.0]

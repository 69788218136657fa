"""FTSMC baseline: nonsingular terminal sliding mode control of the virtual point (ERRATA 16).

The paper compares against "the FTSMC of [11]" without specifying it.  We use the standard
nonsingular terminal sliding mode controller (Feng, Yu & Man 2002, Automatica 38(12)) per axis:

    s = e + beta sig^gamma(e_dot),  1 < gamma < 2
    e_ddot = -(1 / (beta gamma)) sig^(2 - gamma)(e_dot) - k1 sign(s) - k2 s

mapped to the input through the same J3 / M_bar route as the paper's controller
(:func:`auvtrack.control.tracking.input_for_accel`), with no prescribed performance and no
estimator.  Then s_dot = -beta gamma |e_dot|^(gamma-1) (k1 sign s + k2 s + model error).

Packed parameters ``cp`` = [beta, gamma, k1, k2]; no internal state; logged aux: sliding_x,
sliding_y, sliding_z (s above).
"""
from __future__ import annotations

import numpy as np

from .._jit import njit, njit_noalloc
from .params import FTSMCParams
from .registry import CompiledController
from .tracking import error_state_forces, input_for_accel_forces, sig_pair, sign

CODE = 1
AUX_NAMES = ("sliding_x", "sliding_y", "sliding_z")  # formerly s_* (auvtrack/simulation/channels.py)


@njit
def reaching(e, ed, beta, gam, k1, k2):
    """Sliding variable s (m) and commanded e_ddot (m/s^2) of one axis (Feng, Yu & Man 2002; ERRATA 16)."""
    sg, s2g = sig_pair(ed, gam)  # sig^gamma(e_dot), sig^(2-gamma)(e_dot)
    s = e + beta * sg
    return s, -s2g / (beta * gam) - k1 * sign(s) - k2 * s


@njit_noalloc(inline="always")  # one function with dispatch.control for LLVM (docs/architecture.md)
def control(t, eta, nu, att, X, refm, vp, cp, tau, dX, aux, work):
    """Compiled FTSMC law; returns status 0 (it has no failure modes of its own)."""
    e, ed, f, gf = error_state_forces(eta, att, nu, refm, vp)
    s0, a0 = reaching(e[0], ed[0], cp[0], cp[1], cp[2], cp[3])
    s1, a1 = reaching(e[1], ed[1], cp[0], cp[1], cp[2], cp[3])
    s2, a2 = reaching(e[2], ed[2], cp[0], cp[1], cp[2], cp[3])
    aux[0], aux[1], aux[2] = s0, s1, s2
    tau[0], tau[1], tau[2] = input_for_accel_forces(att, vp, f, (a0, a1, a2), gf)
    return 0


def setup(scenario, ctx) -> CompiledController:
    """Pack the FTSMC gains of ``scenario.controller``."""
    p: FTSMCParams = scenario.controller
    cp = np.array([p.beta, p.gamma, p.k1, p.k2], dtype=np.float64)
    return CompiledController(code=CODE, cp=cp, xc0=np.zeros(0), aux_names=AUX_NAMES)

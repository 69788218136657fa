"""FTSMC baseline: nonsingular terminal sliding mode control of the virtual point (ERRATA 16).

The paper compares against "the FTSMC of [11]" without specifying it.  We use the standard
nonsingular terminal sliding mode controller (Feng, Yu & Man 2002, Automatica 38(12)) per axis:

    s = e + beta sig^gamma(e_dot),  1 < gamma < 2
    e_ddot = -(1 / (beta gamma)) sig^(2 - gamma)(e_dot) - k1 sign(s) - k2 s

mapped to the input through the same J3 / M_bar route as the paper's controller
(:func:`auvtrack.control.tracking.input_for_accel`), with no prescribed performance and no
estimator.  Then s_dot = -beta gamma |e_dot|^(gamma-1) (k1 sign s + k2 s + model error).

Packed parameters ``cp`` = [beta, gamma, k1, k2]; no internal state; logged aux: s_x, s_y, s_z.
"""
from __future__ import annotations

import numpy as np

from .._jit import njit
from .params import FTSMCParams
from .registry import CompiledController
from .tracking import error_state, input_for_accel, sig, sign

CODE = 1
AUX_NAMES = ("s_x", "s_y", "s_z")


@njit
def control(t, eta, nu, xc, refm, vp, cp, tau, dxc, aux, work):
    """Compiled FTSMC law; returns status 0 (it has no failure modes of its own)."""
    beta, gam, k1, k2 = cp[0], cp[1], cp[2], cp[3]
    e, ed, f, acc = work[0:3], work[3:6], work[6:9], work[9:12]
    error_state(eta, nu, refm, vp, e, ed, f, work[16:48])
    for i in range(3):
        s = e[i] + beta * sig(ed[i], gam)
        acc[i] = -sig(ed[i], 2.0 - gam) / (beta * gam) - k1 * sign(s) - k2 * s
        aux[i] = s
    input_for_accel(eta, nu, vp, f, acc, tau, work[16:48])
    return 0


def setup(scenario, ctx) -> CompiledController:
    """Pack the FTSMC gains of ``scenario.controller``."""
    p: FTSMCParams = scenario.controller
    cp = np.array([p.beta, p.gamma, p.k1, p.k2], dtype=np.float64)
    return CompiledController(code=CODE, cp=cp, xc0=np.zeros(0), aux_names=AUX_NAMES)

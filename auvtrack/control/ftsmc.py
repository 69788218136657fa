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

from typing import Literal

import numpy as np
from pydantic import Field

from ..jit import njit, njit_noalloc
from ..packing import packed_layout
from .registry import CompiledController, ControllerParams, tunable
from .tracking import error_state_forces, input_for_accel_forces, sig_pair, sign

NAME = "ftsmc"
AUX_NAMES = ("sliding_x", "sliding_y", "sliding_z")
TIME_EXPONENTS = {"beta": lambda p: -p.gamma, "k1": 2, "k2": 2}
"""Gain -> its time dimension n (units s^-n; beta's from gamma): the gain design scales g by omega^n (control/design.py, D1)."""
GAINS = packed_layout("FTSMCGains", beta=1, gamma=1, k1=1, k2=1)


class Params(ControllerParams):
    """Nonsingular terminal SMC baseline (ERRATA 16).

    ``s = e + beta * sig^gamma(e_dot)`` with ``gamma = p/q`` in (1, 2); reaching law
    ``e_ddot = -(1/(beta*gamma)) sig^(2-gamma)(e_dot) - k1 sign(s) - k2 s``.
    The defaults are hand-picked gains that predate the recorded tuning procedure; the gains
    found by that procedure are the gain preset ``ftsmc_tuned`` (scenario key
    ``controller.preset``, expanded into these fields when the scenario is loaded), see
    ``docs/tuning.md`` for how the two compare.
    """

    kind: Literal["ftsmc"] = "ftsmc"
    beta: float = tunable(1.0, 0.01, 20.0, log=True, gt=0, description="weight of the terminal term, s^gamma")
    gamma: float = tunable(1.5, 1.05, 1.95, gt=1, lt=2, description="terminal exponent p/q, in (1, 2)")
    k1: float = tunable(0.05, 1e-4, 1.0, log=True, ge=0, description="switching gain, m/s^2")
    k2: float = tunable(1.0, 0.01, 20.0, log=True, ge=0, description="linear reaching gain, 1/s")



@njit
def reaching(e, ed, beta, gam, k1, k2):
    """Sliding variable s (m) and commanded e_ddot (m/s^2) of one axis (Feng, Yu & Man 2002; ERRATA 16)."""
    sg, s2g = sig_pair(ed, gam)  # sig^gamma(e_dot), sig^(2-gamma)(e_dot)
    s = e + beta * sg
    return s, -s2g / (beta * gam) - k1 * sign(s) - k2 * s


@njit_noalloc(inline="always")  # one function with the engine for LLVM (docs/architecture.md)
def control(t, y, xc, args, out):
    """Compiled FTSMC law; returns status 0 (it has no failure modes of its own)."""
    e, ed, f, gf = error_state_forces(y.eta, y.att, y.nu, args.ref, args.vp)
    cp = args.cp
    beta, gam, k1, k2 = cp[GAINS.beta], cp[GAINS.gamma], cp[GAINS.k1], cp[GAINS.k2]
    s0, a0 = reaching(e[0], ed[0], beta, gam, k1, k2)
    s1, a1 = reaching(e[1], ed[1], beta, gam, k1, k2)
    s2, a2 = reaching(e[2], ed[2], beta, gam, k1, k2)
    out.aux[0], out.aux[1], out.aux[2] = s0, s1, s2
    out.u[0], out.u[1], out.u[2] = input_for_accel_forces(y.att, args.vp, f, (a0, a1, a2), gf)
    return 0


def setup(params: Params, ctx) -> CompiledController:
    """Pack the FTSMC gains."""
    p = params
    cp = GAINS.pack(beta=p.beta, gamma=p.gamma, k1=p.k1, k2=p.k2)
    return CompiledController(cp=cp, xc0=np.zeros(0), aux_names=AUX_NAMES)


def nominal_axis(p: Params, axis_index: int, e0: float):
    """One axis of the nominal closed loop (the reaching law) from e(0) = e0 at rest, for the gain design's peak demand.

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
        ``f(t, x) -> (x_dot, a)`` over x = (e, e_dot), and x(0).
    """
    def f(t, x):
        _, a = reaching(x[0], x[1], p.beta, p.gamma, p.k1, p.k2)
        return np.array([x[1], a]), a
    return f, [e0, 0.0]

"""Open-loop input: tau(t) = tau0 + amplitude * sin(2 pi frequency t), per input channel.

Useful to exercise the plant alone (manoeuvring checks) and, being smooth, to verify the
integrator's order of convergence on the real closed-loop engine.
Packed ``cp`` = [tau0 (3), amplitude (3), frequency (3)]; no internal state, no aux channels.
"""
from __future__ import annotations

import math

import numpy as np

from .._jit import njit
from .params import OpenLoopParams  # noqa: F401  (documented here, defined with the others)
from .registry import CompiledController

CODE = 3


@njit
def control(t, eta, nu, att, X, refm, vp, cp, tau, dX, aux, work):
    """Compiled open-loop input."""
    for i in range(3):
        tau[i] = cp[i] + cp[3 + i] * math.sin(2.0 * math.pi * cp[6 + i] * t)
    return 0


def setup(scenario, ctx) -> CompiledController:
    """Pack the open-loop input of ``scenario.controller``."""
    p = scenario.controller
    cp = np.array([*p.tau0, *p.amplitude, *p.frequency], dtype=np.float64)
    return CompiledController(code=CODE, cp=cp, xc0=np.zeros(0))

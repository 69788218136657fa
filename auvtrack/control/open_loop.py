"""Open-loop input: tau(t) = tau0 + amplitude * sin(2 pi frequency t), per input channel.

Useful to exercise the plant alone (manoeuvring checks) and, being smooth, to verify the
integrator's order of convergence on the real closed-loop engine.
Packed ``cp`` = [tau0 (3), amplitude (3), frequency (3)]; no internal state, no aux channels.
"""
from __future__ import annotations

import math
from typing import Literal

import numpy as np
from pydantic import Field

from ..engine.jit import njit
from .registry import CompiledController, ControllerParams

NAME = "open_loop"
AUX_NAMES: tuple[str, ...] = ()


class Params(ControllerParams):
    """Open-loop input tau(t) = tau0 + amplitude sin(2 pi frequency t) (plant checks, order tests)."""

    kind: Literal["open_loop"] = "open_loop"
    tau0: tuple[float, float, float] = (0.0, 0.0, 0.0)
    amplitude: tuple[float, float, float] = (0.0, 0.0, 0.0)
    frequency: tuple[float, float, float] = Field((0.0, 0.0, 0.0), description="Hz")



@njit
def control(t, eta, nu, att, xc, refm, vp, cp, tau, dxc, aux, work):
    """Compiled open-loop input."""
    for i in range(3):
        tau[i] = cp[i] + cp[3 + i] * math.sin(2.0 * math.pi * cp[6 + i] * t)
    return 0


def setup(scenario, ctx) -> CompiledController:
    """Pack the open-loop input of ``scenario.controller``."""
    p = scenario.controller
    cp = np.array([*p.tau0, *p.amplitude, *p.frequency], dtype=np.float64)
    return CompiledController(cp=cp, xc0=np.zeros(0))

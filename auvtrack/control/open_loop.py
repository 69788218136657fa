"""Open-loop input: tau(t) = tau0 + amplitude * sin(2 pi frequency t), per input channel.

Useful to exercise the plant alone (manoeuvring checks) and, being smooth, to verify the
integrator's order of convergence on the real closed-loop engine.
Packed :data:`GAINS`; no internal state, no aux channels.
"""
from __future__ import annotations

import math
from typing import Literal

import numpy as np
from pydantic import Field

from ..jit import njit
from ..packing import packed_layout
from .registry import CompiledController, ControllerParams

NAME = "open_loop"
AUX_NAMES: tuple[str, ...] = ()
TRACKS = False
GAINS = packed_layout("OpenLoopInput", tau0=3, amplitude=3, frequency=3)


class Params(ControllerParams):
    """Open-loop input tau(t) = tau0 + amplitude sin(2 pi frequency t) (plant checks, order tests)."""

    kind: Literal["open_loop"] = "open_loop"
    tau0: tuple[float, float, float] = (0.0, 0.0, 0.0)
    amplitude: tuple[float, float, float] = (0.0, 0.0, 0.0)
    frequency: tuple[float, float, float] = Field((0.0, 0.0, 0.0), description="Hz")



@njit
def control(t, y, xc, args, out):
    """Compiled open-loop input."""
    cp = args.cp
    for i in range(3):
        out.u[i] = cp[GAINS.tau0 + i] + cp[GAINS.amplitude + i] * math.sin(2.0 * math.pi * cp[GAINS.frequency + i] * t)
    return 0


def setup(params: Params, ctx) -> CompiledController:
    """Pack the open-loop input."""
    p = params
    cp = GAINS.pack(tau0=p.tau0, amplitude=p.amplitude, frequency=p.frequency)
    return CompiledController(cp=cp, xc0=np.zeros(0))

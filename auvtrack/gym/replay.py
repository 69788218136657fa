"""A plug-in law that replays a table of normalised actions: u = scale * a[k] at control sample k (zero-order hold).

The environment's step and an engine run of the same actions use this one law, so both integrate
the same numbers.  Packed: ``scale`` (3), ``n`` (samples), then the table (n rows of 3).
``controller.kind = "plugin"``, ``controller.module = "auvtrack.gym.replay"`` (tau) or
``"auvtrack.gym.replay_actuators"`` (actuator commands on a 6-DOF plant).
"""
from __future__ import annotations

import numpy as np
from pydantic import Field

from ..control.registry import CompiledController, ControllerParams
from ..jit import njit
from ..packing import packed_layout

NAME = "replay"
AUX_NAMES: tuple[str, ...] = ()
TRACKS = False
COMMANDS = "tau"
GAINS = packed_layout("Replay", scale=3, n=1, table=None)


class Params(ControllerParams):
    """The action scale and the actions (rows of 3 in [-1, 1]), one per control sample."""

    scale: tuple[float, float, float] = Field((1.0, 1.0, 1.0), description="command = scale * action")
    actions: list[tuple[float, float, float]] = Field(default_factory=list)
    samples: int = Field(1, ge=1, description="table rows (at least len(actions); the rest zero)")


@njit
def control(t, y, xc, args, out):
    """u = scale * table[k], k the control sample of ``t``."""
    cp = args.cp
    n = int(cp[GAINS.n])
    k = int(t / args.h + 0.5) if args.h > 0.0 else 0
    if k >= n:
        k = n - 1
    for i in range(3):
        out.u[i] = cp[GAINS.scale + i] * cp[GAINS.table + 3 * k + i]
    return 0


def setup(params: Params, ctx) -> CompiledController:
    """Pack the scale and the table."""
    n = max(params.samples, len(params.actions))
    table = np.zeros((n, 3))
    if params.actions:
        table[:len(params.actions)] = np.clip(np.asarray(params.actions, dtype=float), -1.0, 1.0)
    cp = np.concatenate([np.asarray(params.scale, float), [float(n)], table.ravel()])
    return CompiledController(cp=cp, xc0=np.zeros(0))

"""Open-loop actuator commands for the 6-DOF truth plants: turning circles, zig-zags, dives, checks.

The controller commands the actuators directly (the plant's allocation passes them through):
propeller speed ``rpm`` (rpm), stern-plane angle ``delta_s`` and rudder angle ``delta_r`` (rad,
in the plant preset's sign convention, docs/vehicles.md), the rudder put over at ``t_execute``;
with ``rpm_trim`` the propeller keeps the speed the plant starts with (trimmed to the initial surge speed).

Zig-zag (``zigzag_psi > 0``, the ITTC Z-manoeuvre): the rudder is ``s * delta_r`` with a relay
state s = +-1 reversed each time the heading change psi - psi0 reaches +-zigzag_psi against the
current turn.  The relay is written as one internal state with first-order switching,
``ds/dt = (s_target - s) / T_RELAY`` (T_RELAY = 0.02 s, fast against the 0.1 s fin servo), so the
engine integrates it like any other state (no hidden memory, same in both control modes).

Packed :data:`GAINS` (``turn``: the sign of the heading change that +delta_r produces on this
plant); ``xc`` = [s]; logged ``zigzag_s``.
"""
from __future__ import annotations

import math
from typing import Literal

import numpy as np
from pydantic import Field

from ..jit import njit
from ..packing import packed_layout
from .registry import CompiledController, ControllerParams

NAME = "open_loop_actuators"
AUX_NAMES: tuple[str, ...] = ("zigzag_s",)
T_RELAY = 0.02  # s
COMMANDS = "actuators"
TRACKS = False
GAINS = packed_layout("OpenLoopActuators", rpm=1, delta_s=1, delta_r=1, zigzag_psi=1, psi0=1, turn=1,
                      t_execute=1)


class Params(ControllerParams):
    """Constant propeller and fin commands (6-DOF plants), optionally a zig-zag rudder."""

    kind: Literal["open_loop_actuators"] = "open_loop_actuators"
    rpm: float = Field(0.0, ge=-1e4, le=1e4, description="propeller speed command, rpm (within plant.n_max)")
    delta_s: float = Field(0.0, ge=-math.pi / 2, le=math.pi / 2,
                           description="stern-plane angle, rad (within plant.delta_max)")
    delta_r: float = Field(0.0, ge=-math.pi / 2, le=math.pi / 2,
                           description="rudder angle, rad (within plant.delta_max)")
    zigzag_psi: float = Field(0.0, ge=0.0, lt=math.pi,
                              description="zig-zag: heading change (rad) at which the rudder reverses; 0 = constant rudder")
    t_execute: float = Field(0.0, ge=0.0, description="time the rudder is put over, s")
    rpm_trim: bool = Field(False, description="command the propeller speed of surge balance at initial.nu[0] "
                                              "(the plant's trim) instead of rpm")


@njit
def control(t, y, xc, args, out):
    """Compiled actuator commands: u = (rpm, delta_s, delta_r) for the plant's pass-through allocation."""
    cp, dxc = args.cp, out.dxc
    s = xc[0]
    dxc[0] = 0.0
    rudder = 0.0
    if t >= cp[GAINS.t_execute]:
        if cp[GAINS.zigzag_psi] > 0.0:
            turned = cp[GAINS.turn] * (y.eta[4] - cp[GAINS.psi0])  # heading change in the direction +delta_r turns
            target = 1.0 if s >= 0.0 else -1.0
            if turned >= cp[GAINS.zigzag_psi]:
                target = -1.0
            elif turned <= -cp[GAINS.zigzag_psi]:
                target = 1.0
            dxc[0] = (target - s) / T_RELAY
            rudder = s * cp[GAINS.delta_r]
        else:
            rudder = cp[GAINS.delta_r]
    out.u[0] = cp[GAINS.rpm]
    out.u[1] = cp[GAINS.delta_s]
    out.u[2] = rudder
    out.aux[0] = s
    return 0


def rudder_turn_sign(plant) -> float:
    """Sign of the yaw moment (hence of the heading change) a positive rudder angle gives on ``plant``.

    Parameters
    ----------
    plant : auvtrack.control.registry.PlantView
        The plant flown: its ``applied`` tau with the rudder at +0.1 rad at 1 m/s.

    Returns
    -------
    float
        +1 or -1.
    """
    tr = plant.applied(u=1.0, delta_r=0.1)[2]
    return 1.0 if tr > 0 else -1.0


def setup(params: Params, ctx) -> CompiledController:
    """Pack the commands, checked against the plant's actuator limits (``ctx.plant``)."""
    p = params
    lo, hi, _ = ctx.plant.feedback()  # the actuators' limits: (rpm, stern plane, rudder)
    for k, i, key in (("rpm", 0, "n_max"), ("delta_s", 1, "delta_max"), ("delta_r", 2, "delta_max")):
        v = getattr(p, k)
        if not lo[i] <= v <= hi[i]:
            raise ValueError(f"controller.{k}: beyond the actuator limit plant.{key} = {hi[i]:.6g} "
                             f"(got {v:.6g})")
    d = rudder_turn_sign(ctx.plant) * (1.0 if p.delta_r >= 0 else -1.0)
    rpm = ctx.plant.initial("n") if p.rpm_trim else p.rpm  # the plant starts with its propeller trimmed
    cp = GAINS.pack(rpm=rpm, delta_s=p.delta_s, delta_r=p.delta_r, zigzag_psi=p.zigzag_psi, psi0=ctx.eta0[4],
                    turn=d, t_execute=p.t_execute)
    return CompiledController(cp=cp, xc0=np.ones(1), aux_names=AUX_NAMES,
                              resolved={"rudder_turn_sign": d, "rpm": rpm})

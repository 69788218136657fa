"""Open-loop actuator commands for the 6-DOF truth plants: turning circles, zig-zags, dives, checks.

The controller commands the actuators directly (the plant's allocation passes them through):
propeller speed ``rpm`` (rpm), stern-plane angle ``delta_s`` and rudder angle ``delta_r`` (rad,
in the plant preset's sign convention, docs/vehicles.md), the rudder put over at ``t_execute``;
with ``rpm_trim`` the propeller holds the initial surge speed (:func:`auvtrack.plant.sixdof.truth.trim_rpm`).

Zig-zag (``zigzag_psi > 0``, the ITTC Z-manoeuvre): the rudder is ``s * delta_r`` with a relay
state s = +-1 reversed each time the heading change psi - psi0 reaches +-zigzag_psi against the
current turn.  The relay is written as one internal state with first-order switching,
``ds/dt = (s_target - s) / T_RELAY`` (T_RELAY = 0.02 s, fast against the 0.1 s fin servo), so the
engine integrates it like any other state (no hidden memory, same in both control modes).

Packed ``cp`` = [rpm, delta_s, delta_r, zigzag_psi, psi0, d, t_execute] with d the sign of the
heading change that +delta_r produces on this plant; ``xc`` = [s]; logged ``zigzag_s``.
"""
from __future__ import annotations

import math
from typing import Literal

import numpy as np
from pydantic import Field

from .._jit import njit
from .registry import CompiledController, ControllerParams

NAME = "open_loop_actuators"
AUX_NAMES: tuple[str, ...] = ("zigzag_s",)
T_RELAY = 0.02  # s
C_RPM, C_DS, C_DR, C_ZIG, C_PSI0, C_TURN, C_TEXE = range(7)


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
def control(t, eta, nu, att, xc, refm, vp, cp, tau, dxc, aux, work):
    """Compiled actuator commands: tau = (rpm, delta_s, delta_r) for the plant's pass-through allocation."""
    s = xc[0]
    dxc[0] = 0.0
    rudder = 0.0
    if t >= cp[C_TEXE]:
        if cp[C_ZIG] > 0.0:
            turned = cp[C_TURN] * (eta[4] - cp[C_PSI0])  # heading change in the direction +delta_r turns
            target = 1.0 if s >= 0.0 else -1.0
            if turned >= cp[C_ZIG]:
                target = -1.0
            elif turned <= -cp[C_ZIG]:
                target = 1.0
            dxc[0] = (target - s) / T_RELAY
            rudder = s * cp[C_DR]
        else:
            rudder = cp[C_DR]
    tau[0] = cp[C_RPM]
    tau[1] = cp[C_DS]
    tau[2] = rudder
    aux[0] = s
    return 0


def rudder_turn_sign(preset: str) -> float:
    """Sign of the yaw moment (hence of the heading change) a positive rudder angle gives on ``preset``."""
    from ..plant.sixdof import prestero
    from ..plant.sixdof.truth import model_of, pack_truth
    model, pp = model_of(preset), pack_truth(preset)
    if model is prestero:
        tr = model.produced(1.0, 0.1, 0.0, 0.0, pp)[2]
    else:
        tr = model.produced(1.0, 0.0, 0.0, 0.1, 0.0, 0.0, pp)[2]
    return 1.0 if tr > 0 else -1.0


def setup(scenario, ctx) -> CompiledController:
    """Pack the commands of ``scenario.controller`` (the schema checks them against the plant's limits)."""
    p = scenario.controller
    if scenario.plant.model != "6dof":
        raise ValueError("controller.kind: open_loop_actuators commands fins and propeller; it needs "
                         f"plant.model = \"6dof\" (got {scenario.plant.model!r})")
    d = rudder_turn_sign(scenario.plant.preset) * (1.0 if p.delta_r >= 0 else -1.0)
    rpm = p.rpm
    if p.rpm_trim:
        from ..plant.sixdof.truth import pack_truth, trim_rpm
        rpm = trim_rpm(scenario.plant.preset, pack_truth(scenario.plant.preset, scenario.plant.actuator_overrides()),
                       scenario.initial.nu[0])
    cp = np.array([rpm, p.delta_s, p.delta_r, p.zigzag_psi, scenario.initial.eta[4], d, p.t_execute],
                  dtype=np.float64)
    return CompiledController(cp=cp, xc0=np.ones(1), aux_names=AUX_NAMES,
                              resolved={"rudder_turn_sign": d, "rpm": rpm})

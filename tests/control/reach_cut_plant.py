"""A plug-in plant for the anti-windup tests: the 5-DOF plant whose actuator reach is cut for a while.

States: the 5-DOF plant's (eta, nu) and a clock (s, d clock/dt = 1).  Commands: tau.  The tau
limits are ``tau_max`` outside [t_on, t_off) and ``cut`` inside (read from the clock, so that every
RK4 stage sees the limits of its own time); the plant reports them to the law as ``feedback``
(lo = -limit, hi = limit) and applies the command clipped to them.  Equations: the paper's eq. (1)
with the true vehicle of the scenario (``[vehicle]`` with ``[uncertainty]``); the environment is
not modelled.

    [plant]
    model = "plugin"
    module = "tests/control/reach_cut_plant.py"
    params = { tau_max = [inf, inf, inf], cut = [20.0, 5.0, 5.0], t_on = 20.0, t_off = 35.0 }
"""
import math

import numpy as np
from pydantic import Field

from auvtrack.plant.plugin import CompiledPlant, PlantSection, njit_noalloc
from auvtrack.packing import packed_layout
from auvtrack.vehicle.dynamics import nu_dot
from auvtrack.vehicle.kinematics import eta_dot
from auvtrack.vehicle.params import VP

NAME = "reach_cut"
STATE = ("x", "y", "z", "theta", "psi", "u", "v", "w", "q", "r", "clock")
COMMAND = ("tau_u", "tau_q", "tau_r")
LOG_NAMES = ()
ACCEPTS = ("tau",)
PARAMS = packed_layout("ReachCut", vp=VP.size, tau_max=3, cut=3, t_on=1, t_off=1)
INF3 = (math.inf, math.inf, math.inf)


class Section(PlantSection):
    """The ``params`` table: the limits outside and inside the cut, and its times."""

    tau_max: tuple[float, float, float] = Field(INF3, description="|tau| limits outside the cut (N, N m, N m)")
    cut: tuple[float, float, float] = Field(INF3, description="|tau| limits during the cut (N, N m, N m)")
    t_on: float = Field(math.inf, description="start of the cut, s")
    t_off: float = Field(math.inf, description="end of the cut, s")


@njit_noalloc
def limits(x, pp):
    """The |tau| limits at the state's clock."""
    o = PARAMS.cut if pp[PARAMS.t_on] <= x[10] < pp[PARAMS.t_off] else PARAMS.tau_max
    return pp[o], pp[o + 1], pp[o + 2]


@njit_noalloc
def pose(x):
    """(eta, nu) of the state."""
    return (x[0], x[1], x[2], x[3], x[4]), (x[5], x[6], x[7], x[8], x[9])


@njit_noalloc
def accel5(dx):
    """(u_dot, v_dot, w_dot, q_dot, r_dot) of a state derivative."""
    return dx[5], dx[6], dx[7], dx[8], dx[9]


@njit_noalloc
def allocate(tau3, eta, nu, x, pp, prev, h, cmd):
    """The command clipped to the limits at the state's clock; bitmask of the clipped axes."""
    m = limits(x, pp)
    flags = 0
    for i in range(3):
        c = min(max(tau3[i], -m[i]), m[i])
        flags |= (1 << i) if c != tau3[i] else 0
        cmd[i] = c
    return flags


@njit_noalloc
def effort(x, cmd, pp):
    """|applied tau_j| / limit_j at the state's clock (0 when unlimited)."""
    m = limits(x, pp)
    return abs(cmd[0]) / m[0], abs(cmd[1]) / m[1], abs(cmd[2]) / m[2]


@njit_noalloc
def rhs(t, x, att, cmd, env, pp, scr, fresh, dx):
    """dx = (eta_dot, nu_dot, 1): eq. (1) with the applied tau, no environment."""
    eta, nu = pose(x)
    dx[0], dx[1], dx[2], dx[3], dx[4] = eta_dot(att, nu)
    dx[5], dx[6], dx[7], dx[8], dx[9] = nu_dot(att, nu, (cmd[0], cmd[1], cmd[2]), (0.0, 0.0, 0.0, 0.0, 0.0), pp)
    dx[10] = 1.0


@njit_noalloc
def applied(x, cmd, pp):
    """The tau acting: the applied command."""
    return cmd[0], cmd[1], cmd[2]


@njit_noalloc
def feedback(x, cmd, pp):
    """(lo, hi, applied): -+ the limits at the state's clock, and the applied tau."""
    m = limits(x, pp)
    return (-m[0], -m[1], -m[2]), (m[0], m[1], m[2]), (cmd[0], cmd[1], cmd[2])


@njit_noalloc
def attitude_cause(x, sf):
    """No plant-specific stop."""
    return 0


@njit_noalloc
def log_extra(x, cmd, pp, log, row, col):
    """No extra channels."""
    return


def setup(section, ctx):
    """Pack the true vehicle, the limits and the cut; start at the scenario's initial state, clock 0."""
    pp = PARAMS.pack(vp=ctx.vp_true, tau_max=section.tau_max, cut=section.cut, t_on=section.t_on, t_off=section.t_off)
    x0 = np.array([*ctx.eta0, *ctx.nu0, 0.0], dtype=np.float64)
    return CompiledPlant(pp=pp, x0=x0, resolved={"model": NAME})

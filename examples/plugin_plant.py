"""A plug-in plant for auvtrack: a 3-DOF horizontal-plane vehicle (surge, sway, yaw) at a fixed depth.

Use it from any folder, without touching the package:

    [plant]
    model = "plugin"
    module = "plugin_plant.py"        # relative to the scenario file, or absolute
    params = { tau_max = [200.0, 50.0] }   # validated by Section below (N, N m)

States (STATE): x, y, z (m, NED; z stays at its initial value), psi (rad), u, v (m/s), r (rad/s).
Commands (COMMAND): the controller's tau = [tau_u (N), tau_q (N m), tau_r (N m)], tau_u and tau_r
saturated at ``tau_max``; tau_q has nothing to act on here.

Equations: the paper's eq. (1) restricted to the horizontal plane (w = q = theta = 0), with the
scenario's vehicle (``[vehicle]`` with ``[uncertainty]``: the numbers the 5-DOF plant would use):

    x_dot   = u cos(psi) - v sin(psi)          y_dot = u sin(psi) + v cos(psi)      z_dot = 0
    psi_dot = r
    m11 u_dot = tau_u + c m22 v r - d11 u
    m22 v_dot =       - c m11 u r - d22 v
    m55 r_dot = tau_r - c (m22 - m11) u v - d55 r

(m55, d55: the yaw inertia and damping of the 5-DOF layout, c the Coriolis scale).  The
environment (disturbances, current) is not modelled.  The contract is in docs/plugins.md.
"""
import math

import numpy as np
from pydantic import Field

from auvtrack.plant.plugin import CompiledPlant, PlantSection, njit_noalloc
from auvtrack.packing import packed_layout
from auvtrack.vehicle.params import VP

NAME = "horizontal3"
STATE = ("x", "y", "z", "psi", "u", "v", "r")
COMMAND = ("tau_u", "tau_q", "tau_r")
LOG_NAMES = ()
ACCEPTS = ("tau",)
PARAMS = packed_layout("Horizontal3", m11=1, m22=1, m55=1, d11=1, d22=1, d55=1, c=1, tau_max=2)


class Section(PlantSection):
    """The ``params`` table of ``[plant]``."""

    tau_max: tuple[float, float] = Field((math.inf, math.inf), description="|tau_u| (N), |tau_r| (N m) limits")


@njit_noalloc
def pose(x):
    """(eta, nu) 5-tuples a controller measures: level, at its depth."""
    return (x[0], x[1], x[2], 0.0, x[3]), (x[4], x[5], 0.0, 0.0, x[6])


@njit_noalloc
def accel5(dx):
    """(u_dot, v_dot, w_dot, q_dot, r_dot) of a state derivative."""
    return dx[4], dx[5], 0.0, 0.0, dx[6]


@njit_noalloc
def allocate(tau3, eta, nu, x, pp, prev, h, cmd):
    """The command is tau, tau_u and tau_r saturated; returns the bitmask of the saturated axes."""
    tu, tr = pp[PARAMS.tau_max], pp[PARAMS.tau_max + 1]
    cmd[0] = min(max(tau3[0], -tu), tu)
    cmd[1] = tau3[1]
    cmd[2] = min(max(tau3[2], -tr), tr)
    return (1 if cmd[0] != tau3[0] else 0) | (4 if cmd[2] != tau3[2] else 0)


@njit_noalloc
def rhs(t, x, att, cmd, env, pp, scr, fresh, dx):
    """dx = f(x, tau) of the module docstring."""
    psi, u, v, r = x[3], x[4], x[5], x[6]
    c = pp[PARAMS.c]
    m11, m22 = pp[PARAMS.m11], pp[PARAMS.m22]
    dx[0] = u * math.cos(psi) - v * math.sin(psi)
    dx[1] = u * math.sin(psi) + v * math.cos(psi)
    dx[2] = 0.0
    dx[3] = r
    dx[4] = (cmd[0] + c * m22 * v * r - pp[PARAMS.d11] * u) / m11
    dx[5] = (-c * m11 * u * r - pp[PARAMS.d22] * v) / m22
    dx[6] = (cmd[2] - c * (m22 - m11) * u * v - pp[PARAMS.d55] * r) / pp[PARAMS.m55]


@njit_noalloc
def applied(x, cmd, pp):
    """(tau_u, tau_q, tau_r) acting: tau_q has nothing to act on."""
    return cmd[0], 0.0, cmd[2]


@njit_noalloc
def feedback(x, cmd, pp):
    """(lo, hi, applied) per axis: the tau limits (none on tau_q, which acts on nothing)."""
    tu, tr = pp[PARAMS.tau_max], pp[PARAMS.tau_max + 1]
    return (-tu, -math.inf, -tr), (tu, math.inf, tr), (cmd[0], 0.0, cmd[2])


@njit_noalloc
def effort(x, cmd, pp):
    """|tau_u| / tau_max_u, 0 (no actuator in pitch), |tau_r| / tau_max_r (0 without limits)."""
    return abs(cmd[0]) / pp[PARAMS.tau_max], 0.0, abs(cmd[2]) / pp[PARAMS.tau_max + 1]


@njit_noalloc
def attitude_cause(x, sf):
    """A level vehicle never stops on pitch or roll."""
    return 0


@njit_noalloc
def log_extra(x, cmd, pp, log, row, col):
    """No extra channels."""
    return


def setup(section, ctx):
    """Pack the vehicle's horizontal numbers and the limits; start at the scenario's initial state."""
    vp = ctx.vp_true
    pp = PARAMS.pack(m11=vp[VP.m], m22=vp[VP.m + 1], m55=vp[VP.m + 4], d11=vp[VP.d], d22=vp[VP.d + 1],
                     d55=vp[VP.d + 4], c=vp[VP.cscale], tau_max=section.tau_max)
    e, n = ctx.eta0, ctx.nu0
    x0 = np.array([e[0], e[1], e[2], e[4], n[0], n[1], n[4]], dtype=np.float64)
    return CompiledPlant(pp=pp, x0=x0, resolved={"model": NAME, "tau_max": list(section.tau_max)})

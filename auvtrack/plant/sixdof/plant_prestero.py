"""Plant module ``remus100_prestero``: the 6-DOF truth model of :mod:`auvtrack.plant.sixdof.prestero` behind the plant contract.

Contract (docs/architecture.md): ``pose``, ``accel5``, ``allocate``, ``rhs``, ``applied``,
``attitude_cause``, ``log_extra`` (compiled, allocation-free).  State layout, command and logged
channels: :mod:`auvtrack.plant.sixdof.layout`.  The controller commands tau = [tau_u, tau_q, tau_r];
``allocate`` maps it to rudder, stern-plane and propeller commands by inverting the actuator
model at the measured speed (or passes actuator commands through for ``open_loop_actuators``).
"""
from __future__ import annotations

from ...engine.jit import njit_noalloc
from . import prestero
from .actuators import effective
from .layout import CMD_TAU, LOG_NAMES6, N_CMD6, NX6, P_DIRECT
from .common import accel5, attitude_cause6, direct_command, environment, log_extra, pose

NAME = "remus100_prestero"
NX = NX6
N_CMD = N_CMD6
N_LOG = len(LOG_NAMES6)
LOG_NAMES = LOG_NAMES6
MODEL = prestero

__all__ = ["NAME", "NX", "N_CMD", "N_LOG", "LOG_NAMES", "pose", "accel5", "allocate", "rhs", "applied",
           "attitude_cause", "log_extra"]


@njit_noalloc
def allocate(tau3, eta, nu, x, pp, prev, h, cmd):
    """Actuator commands for tau3 (N, N m, N m) at the measured speed; bitmask of unmet channels."""
    if pp[P_DIRECT] != 0.0:
        return direct_command(tau3, pp, cmd)
    cmd[CMD_TAU], cmd[CMD_TAU + 1], cmd[CMD_TAU + 2] = tau3[0], tau3[1], tau3[2]
    return prestero.allocate_tau(tau3[0], tau3[1], tau3[2], nu[0], pp, cmd)


@njit_noalloc
def rhs(t, x, att, cmd, env, pp, scr, fresh, dx):
    """dx[0:NX] = f(t, x, cmd) with the environment's disturbance forces and current."""
    dist, vc = environment(env[0], env[1], t, scr, fresh)
    prestero.derivative(x, att, vc, dist, cmd, pp, dx)


@njit_noalloc
def applied(x, cmd, pp):
    """(tau_u, tau_q, tau_r) the actuators produce now (applied states, true speed over ground)."""
    dr, ds, n = effective(x, pp)
    return prestero.produced(x[6], dr, ds, n, pp)


attitude_cause = attitude_cause6

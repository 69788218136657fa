"""The 5-DOF plant: the paper's eq. (1) driven directly by tau = [tau_u, tau_q, tau_r].

States ``x`` (:data:`STATE`): eta = (x, y, z, theta, psi) (m, rad; NED, roll neglected) and
nu = (u, v, w, q, r) (m/s, rad/s; body).  Actuator command ``cmd`` (:data:`COMMAND`): the applied
tau (N, N m, N m) after the magnitude saturation and, in sampled-data mode, the slew-rate limit
of :mod:`auvtrack.plant.actuators`.  No extra logged channels.  Its ``[plant]`` section has no keys
of its own: the vehicle is ``[vehicle]`` with ``[uncertainty]``, the input limits ``[actuator]``.

Packed parameters ``pp`` = [vp_true (13, layout of :mod:`auvtrack.vehicle.params`), tau_max (3),
rate_max (3)]: the true vehicle (the scenario's ``[uncertainty]`` applied to its preset) and the
actuator limits.  Disturbance: omega of :func:`auvtrack.environment.eval_disturbance`, with the
current as the damping force on the relative velocity.

This is ``plant.model = "5dof"``, the default.

References
----------
Paper eq. (1)-(4); Fossen, T. I. (2021), Handbook of Marine Craft Hydrodynamics and Motion
Control, 2nd ed., ch. 8 (currents) and ch. 11 (actuator limits).
"""
from __future__ import annotations

from typing import Literal

import numpy as np

from ..jit import njit_noalloc
from ..environment import eval_disturbance
from .actuators import ACT_SIZE, ACT_TAU_MAX, pack_actuator, rate_limit, saturate
from .contract import CAUSE_PITCH, SF
from ..vehicle.dynamics import nu_dot
from ..vehicle.kinematics import eta_dot
from ..vehicle.params import VP
from .registry import CompiledPlant, PlantSection

NAME = "5dof"
STATE = ("x", "y", "z", "theta", "psi", "u", "v", "w", "q", "r")
COMMAND = ("tau_u", "tau_q", "tau_r")
LOG_NAMES: tuple[str, ...] = ()
ACCEPTS = ("tau",)
NX, N_CMD, N_LOG = len(STATE), len(COMMAND), len(LOG_NAMES)
PP_ACT = VP.size  # actuator limits start here in pp


@njit_noalloc
def pose(x):
    """(eta, nu) 5-tuples of the plant state."""
    return (x[0], x[1], x[2], x[3], x[4]), (x[5], x[6], x[7], x[8], x[9])


@njit_noalloc
def accel5(dx):
    """(u_dot, v_dot, w_dot, q_dot, r_dot) of a state derivative."""
    return dx[5], dx[6], dx[7], dx[8], dx[9]


@njit_noalloc
def allocate(tau3, eta, nu, x, pp, prev, h, cmd):
    """Applied tau: the command saturated and, for a sampling period h > 0, rate limited from ``prev``.

    Returns the bitmask of the inputs whose command exceeded its magnitude limit.
    """
    c = saturate(tau3, pp, PP_ACT)
    flags = int(c[0] != tau3[0]) | (int(c[1] != tau3[1]) << 1) | (int(c[2] != tau3[2]) << 2)
    if h > 0.0:
        c = rate_limit(c, (prev[0], prev[1], prev[2]), pp, PP_ACT, h)
    cmd[0], cmd[1], cmd[2] = c
    return flags


@njit_noalloc
def rhs(t, x, att, cmd, env, pp, scr, fresh, dx):
    """dx = (eta_dot, nu_dot) of eq. (1) with the applied tau ``cmd`` and omega(t) cached in ``scr[0:5]``."""
    eta, nu = pose(x)
    if fresh:
        eval_disturbance(env[0], env[1], t, eta, nu, pp, scr)
    dx[0], dx[1], dx[2], dx[3], dx[4] = eta_dot(att, nu)
    dx[5], dx[6], dx[7], dx[8], dx[9] = nu_dot(att, nu, (cmd[0], cmd[1], cmd[2]),
                                               (scr[0], scr[1], scr[2], scr[3], scr[4]), pp)


@njit_noalloc
def applied(x, cmd, pp):
    """The tau acting on the vehicle: the applied command itself."""
    return cmd[0], cmd[1], cmd[2]


@njit_noalloc(inline="always")
def feedback(x, cmd, pp):
    """(lo, hi, applied): the magnitude limits of tau (-tau_max, tau_max) and the applied tau (N, N m)."""
    a = VP.size + ACT_TAU_MAX
    return (-pp[a], -pp[a + 1], -pp[a + 2]), (pp[a], pp[a + 1], pp[a + 2]), (cmd[0], cmd[1], cmd[2])


@njit_noalloc(inline="always")
def effort(x, cmd, pp):
    """|applied tau_j| / tau_max_j per axis (0 when unlimited: tau_max = inf)."""
    a = VP.size + ACT_TAU_MAX
    return abs(cmd[0]) / pp[a], abs(cmd[1]) / pp[a + 1], abs(cmd[2]) / pp[a + 2]


@njit_noalloc
def attitude_cause(x, sf):
    """CAUSE_PITCH when |theta| exceeds ``sf[SF.theta_lim]`` (rad), else 0."""
    return CAUSE_PITCH if abs(x[3]) > sf[SF.theta_lim] else 0


@njit_noalloc
def log_extra(x, cmd, pp, log, row, col):
    """No extra channels."""
    return


class Section(PlantSection):
    """``[plant]`` of the 5-DOF plant: no keys besides ``model``."""

    model: Literal["5dof"] = "5dof"


def check_scenario(scenario) -> None:
    """Refuse a start with roll: the 5-DOF model has none.

    Parameters
    ----------
    scenario : auvtrack.scenario.Scenario
        The scenario being validated.

    Raises
    ------
    ValueError
        ``initial.phi: ...`` or ``initial.p: ...``.
    """
    from ..fields import format_value

    for k in ("phi", "p"):
        if getattr(scenario.initial, k) != 0.0:
            raise ValueError(f"initial.{k}: roll exists only with plant.model = \"6dof\" "
                             f"(got {format_value(getattr(scenario.initial, k))})")


def setup(section: Section, ctx) -> CompiledPlant:
    """Pack the true 5-DOF vehicle (the design vehicle with the uncertainty) and the input limits.

    Parameters
    ----------
    section : Section
        The ``[plant]`` section.
    ctx : auvtrack.plant.registry.PlantContext
        The true vehicle, the ``[actuator]`` limits, the initial state.

    Returns
    -------
    CompiledPlant
        Packed parameters and initial state.
    """
    act = ctx.actuator
    pp = np.concatenate([ctx.vp_true, pack_actuator(act.tau_max, act.rate_max)])
    assert pp.size == PP_ACT + ACT_SIZE
    x0 = np.array([*ctx.eta0, *ctx.nu0], dtype=np.float64)
    return CompiledPlant(pp=pp, x0=x0, resolved={"model": NAME, "vehicle": ctx.vehicle_record})

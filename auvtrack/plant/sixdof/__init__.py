"""The 6-DOF truth plants (``plant.model = "6dof"``): REMUS 100 models the controller does not know.

``plant.preset`` selects the vehicle: ``remus100_prestero`` (Prestero 2001, the default;
:mod:`auvtrack.plant.sixdof.prestero`) or ``remus100_fossen`` (Fossen 2021 / PVS;
:mod:`auvtrack.plant.sixdof.fossen`).  Both share the state (15: 6-DOF pose and velocity, rudder,
stern-plane and propeller states), the actuator command with the logged commanded tau, and the
logged channels (:mod:`auvtrack.plant.sixdof.layout`); the packed parameters say which equations of
motion run (``pp[P_EQUATIONS]``), so one compiled kernel per controller serves every preset.

The controller keeps its 5-DOF design model (``[vehicle]``) and measures the 5-DOF projection of
the true state; its tau goes through the plant's control allocation (docs/vehicles.md), or, for a
controller that commands the actuators (``COMMANDS = "actuators"``), its commands (rpm,
stern plane, rudder) pass through.
"""
from __future__ import annotations

from ...jit import njit_noalloc
from ...vehicle.presets import register_reach, register_source
from . import fossen, prestero
from .actuators import effective
from .common import accel5, attitude_cause6, direct_command, environment, log_extra, pose  # noqa: F401
from .layout import CMD_TAU, EQUATIONS_FOSSEN, LOG_NAMES6, NX6, P_DIRECT, P_DMAX, P_EQUATIONS, P_NMAX
from .reach import reach_at
from .section import Section, check_scenario  # noqa: F401
from .torpedo_reduction import SOURCE as _TORPEDO_DESIGNS

register_source(_TORPEDO_DESIGNS)  # a Fossen-type torpedo file is also a 5-DOF design preset
register_reach(reach_at)  # a reduced design preset knows its truth's actuator reach

NAME = "6dof"
STATE = ("x", "y", "z", "phi", "theta", "psi", "u", "v", "w", "p", "q", "r", "delta_r", "delta_s", "n")
COMMAND = ("delta_r", "delta_s", "n", "tau_u", "tau_q", "tau_r")
LOG_NAMES = LOG_NAMES6
ACCEPTS = ("tau", "actuators")
NX, N_CMD, N_LOG = len(STATE), len(COMMAND), len(LOG_NAMES)
assert NX == NX6
attitude_cause = attitude_cause6


@njit_noalloc
def allocate(tau3, eta, nu, x, pp, prev, h, cmd):
    """Actuator commands for tau3 (N, N m, N m) at the measured speed; bitmask of unmet channels."""
    if pp[P_DIRECT] != 0.0:
        return direct_command(tau3, pp, cmd)
    cmd[CMD_TAU], cmd[CMD_TAU + 1], cmd[CMD_TAU + 2] = tau3[0], tau3[1], tau3[2]
    if pp[P_EQUATIONS] == EQUATIONS_FOSSEN:
        return fossen.allocate_tau(tau3[0], tau3[1], tau3[2], nu[0], nu[1], nu[2], pp, cmd)
    return prestero.allocate_tau(tau3[0], tau3[1], tau3[2], nu[0], pp, cmd)


@njit_noalloc
def rhs(t, x, att, cmd, env, pp, scr, fresh, dx):
    """dx[0:NX] = f(t, x, cmd) with the environment's disturbance forces and current."""
    dist, vc = environment(env[0], env[1], t, scr, fresh)
    if pp[P_EQUATIONS] == EQUATIONS_FOSSEN:
        fossen.derivative(x, att, vc, dist, cmd, pp, dx)
    else:
        prestero.derivative(x, att, vc, dist, cmd, pp, dx)


@njit_noalloc(inline="always")
def produced(x, dr, ds, n, pp):
    """(tau_u, tau_q, tau_r) of actuator positions (dr, ds, n) at the state's speed (N, N m, N m)."""
    if pp[P_EQUATIONS] == EQUATIONS_FOSSEN:
        return fossen.produced(x[6], x[7], x[8], dr, ds, n, pp)
    return prestero.produced(x[6], dr, ds, n, pp)


@njit_noalloc
def applied(x, cmd, pp):
    """(tau_u, tau_q, tau_r) the actuators produce now (applied states, true speed over ground)."""
    dr, ds, n = effective(x, pp)
    return produced(x, dr, ds, n, pp)


@njit_noalloc(inline="always")
def feedback(x, cmd, pp):
    """(lo, hi, applied) for the controller, per axis (surge, pitch, yaw).

    A tau controller gets the tau each axis's actuator produces at its two limits at the current
    speed (propeller at -+n_max, stern plane and rudder at -+delta_max) and the tau produced now;
    an actuator controller gets the actuators' own limits and positions (rpm, rad, rad).
    """
    dr, ds, n = effective(x, pp)
    dm, nm = pp[P_DMAX], pp[P_NMAX]
    if pp[P_DIRECT] != 0.0:
        return (-nm, -dm, -dm), (nm, dm, dm), (n, ds, dr)
    a = produced(x, dm, dm, nm, pp)
    b = produced(x, -dm, -dm, -nm, pp)
    return ((min(a[0], b[0]), min(a[1], b[1]), min(a[2], b[2])),
            (max(a[0], b[0]), max(a[1], b[1]), max(a[2], b[2])), produced(x, dr, ds, n, pp))


@njit_noalloc(inline="always")
def effort(x, cmd, pp):
    """(|n| / n_max, |delta_s| / delta_max, |delta_r| / delta_max) of the applied actuator states."""
    dr, ds, n = effective(x, pp)
    dm = pp[P_DMAX]
    return abs(n) / pp[P_NMAX], abs(ds) / dm, abs(dr) / dm


def setup(section: Section, ctx):
    """Pack the 6-DOF truth of ``section`` (preset, actuator overrides) at the run's initial state.

    Parameters
    ----------
    section : Section
        The scenario's ``[plant]``.
    ctx : auvtrack.plant.registry.PlantContext
        Initial state, what the controller commands, the design vehicle's record.

    Returns
    -------
    CompiledPlant
        Packed parameters, initial state (propeller trimmed to the initial surge speed), the
        logged channel names, notes and the sourced record.

    Raises
    ------
    ValueError
        ``initial.nu: ...`` when the initial surge speed is beyond the propeller's reach.
    """
    from ..registry import CompiledPlant
    from .setup import prepare_truth

    truth = prepare_truth(section, ctx)
    design = {k: v for k, v in ctx.vehicle_record.items() if k != "true_plant"}  # the truth is the 6-DOF preset
    design["role"] = "the controller's 5-DOF design model"
    return CompiledPlant(pp=truth.pp, x0=truth.x0, log_names=truth.log_names, notes=truth.notes,
                         resolved={**truth.resolved, "vehicle": design})


__all__ = ["NAME", "STATE", "COMMAND", "LOG_NAMES", "ACCEPTS", "Section", "setup", "check_scenario", "pose", "accel5",
           "allocate", "rhs", "applied", "feedback", "effort", "attitude_cause", "log_extra"]

"""Compiled pieces of the plant contract shared by the 6-DOF truth plants.

The engine sees a 6-DOF plant through the contract of ``docs/architecture.md`` (plant module):
``pose`` projects the true state on the 5-DOF (eta, nu) a controller measures (roll and roll rate
are neither measured nor controlled), ``accel5`` picks the matching accelerations, and
``attitude_cause`` stops a run on pitch or roll.  :func:`environment` evaluates the additive
disturbance forces and the current velocity of the environment tables once per time.
"""
from __future__ import annotations

import math

from ...jit import njit_noalloc
from ...environment.dispatch import add_forces, current_of
from .actuators import effective
from ..contract import CAUSE_PITCH, CAUSE_ROLL, SF
from .layout import CMD_DR, CMD_DS, CMD_N, CMD_TAU, P_DIRECT, P_DMAX, P_NMAX

SCR_DIST, SCR_VC = 0, 5  # scratch: disturbance forces (5), current velocity (3)


@njit_noalloc
def pose(x):
    """(eta5, nu5): (x, y, z, theta, psi), (u, v, w, q, r) of the 6-DOF state (m, rad, m/s, rad/s)."""
    return (x[0], x[1], x[2], x[4], x[5]), (x[6], x[7], x[8], x[10], x[11])


@njit_noalloc
def accel5(dx):
    """(u_dot, v_dot, w_dot, q_dot, r_dot) from the state derivative."""
    return dx[6], dx[7], dx[8], dx[10], dx[11]


@njit_noalloc
def attitude_cause6(x, sf):
    """CAUSE_PITCH if |theta| > sf[SF.theta_lim], CAUSE_ROLL if |phi| > sf[SF.phi_lim], else 0 (rad)."""
    if abs(x[4]) > sf[SF.theta_lim]:
        return CAUSE_PITCH
    if abs(x[3]) > sf[SF.phi_lim]:
        return CAUSE_ROLL
    return 0


@njit_noalloc
def environment(rows, current, t, scr, fresh):
    """Disturbance forces [F_u, F_v, F_w, M_q, M_r] and current (Vx, Vy, Vz) at t, cached in ``scr``.

    With ``fresh`` false the values of the previous call (same t) are returned.  Returns
    (dist6, vc): the forces as [X, Y, Z, K, M, N] with K = 0 (N, N m), and the NED current (m/s).
    """
    if fresh:
        for i in range(8):
            scr[i] = 0.0
        for k in range(rows.shape[0]):
            if add_forces(rows, k, t, scr):
                continue
            hit, v = current_of(rows, k, current, t)
            if hit:
                scr[SCR_VC] += v[0]
                scr[SCR_VC + 1] += v[1]
                scr[SCR_VC + 2] += v[2]
            else:
                scr[0] = math.nan
    return ((scr[0], scr[1], scr[2], 0.0, scr[3], scr[4]),
            (scr[SCR_VC], scr[SCR_VC + 1], scr[SCR_VC + 2]))


@njit_noalloc
def direct_command(tau3, pp, cmd):
    """Copy open-loop actuator commands tau3 = (n, delta_s, delta_r) to cmd; bit j set if beyond its limit.

    The order is that of the channels they drive (surge, pitch, yaw); units rpm, rad, rad.
    """
    cmd[CMD_N], cmd[CMD_DS], cmd[CMD_DR] = tau3[0], tau3[1], tau3[2]
    cmd[CMD_TAU] = cmd[CMD_TAU + 1] = cmd[CMD_TAU + 2] = math.nan
    dm = pp[P_DMAX]
    return ((1 if abs(tau3[0]) > pp[P_NMAX] else 0) | (2 if abs(tau3[1]) > dm else 0)
            | (4 if abs(tau3[2]) > dm else 0))


@njit_noalloc
def log_extra(x, cmd, pp, log, row, col):
    """Write phi, p, delta_r, delta_s, rpm (applied) and the commanded tau into log[row, col:col+8]."""
    dr, ds, n = effective(x, pp)
    log[row, col] = x[3]
    log[row, col + 1] = x[9]
    log[row, col + 2] = dr
    log[row, col + 3] = ds
    log[row, col + 4] = n
    log[row, col + 5] = cmd[CMD_TAU]
    log[row, col + 6] = cmd[CMD_TAU + 1]
    log[row, col + 7] = cmd[CMD_TAU + 2]


def is_direct(pp) -> bool:
    """Whether ``pp`` is packed for open-loop actuator commands."""
    return bool(pp[P_DIRECT])

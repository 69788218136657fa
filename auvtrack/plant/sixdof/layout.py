"""Layouts shared by the 6-DOF truth plants: state, actuator command and packed parameters.

State ``x`` (NX6 = 15)
----------------------
====  ======================================  ============
0-2   x, y, z (NED position)                  m
3-5   phi, theta, psi (zyx Euler angles)      rad
6-8   u, v, w (body linear velocity)          m/s
9-11  p, q, r (body angular velocity)         rad/s
12    delta_r (rudder angle, applied)         rad
13    delta_s (stern-plane angle, applied)    rad
14    n (propeller speed, applied)            rpm
====  ======================================  ============

Command ``cmd`` (N_CMD6 = 6): the actuator commands [delta_r, delta_s, n] written by the
allocation, then the controller's commanded [tau_u, tau_q, tau_r] (logged next to the produced
tau).

Packed parameters ``pp`` (float64): the common block below, then the model's own block from
:data:`P_MODEL` (layouts in :mod:`auvtrack.plant.sixdof.prestero` and :mod:`auvtrack.plant.sixdof.fossen`).
Matrices are 6x6 row-major.
"""
from __future__ import annotations

NX6 = 15
IX_POS, IX_ATT, IX_NU, IX_DR, IX_DS, IX_N = 0, 3, 6, 12, 13, 14
CMD_DR, CMD_DS, CMD_N, CMD_TAU = 0, 1, 2, 3
N_CMD6 = 6

P_MINV = 0       # (M_RB + M_A)^-1
P_MRB = 36       # M_RB about the body origin
P_MA = 72        # M_A
P_W, P_B = 108, 109          # weight, buoyancy (N)
P_RG, P_RB = 110, 113        # CG, CB w.r.t. the origin (m), 3 each
P_DMAX, P_NMAX = 116, 117    # fin angle limit (rad), propeller speed limit (rpm)
P_TDELTA, P_TN = 118, 119    # actuator time constants (s)
P_DRATE, P_NRATE = 120, 121  # actuator rate limits (rad/s, rpm/s; inf = none)
P_DIRECT = 122               # 1: the controller commands the actuators directly (open loop)
P_EQUATIONS = 123            # which equations of motion: EQUATIONS_PRESTERO or EQUATIONS_FOSSEN
P_MODEL = 128                # start of the model's own block
EQUATIONS_PRESTERO, EQUATIONS_FOSSEN = 0.0, 1.0
PP6_SIZE = 192

LOG_NAMES6 = ("phi", "p", "delta_r", "delta_s", "rpm", "tau_u_cmd", "tau_q_cmd", "tau_r_cmd")

"""Actuator states of the 6-DOF plants: rudder, stern planes and propeller speed.

Each actuator a (angle in rad or speed in rpm) is a first-order lag towards its command c,
with a magnitude limit ``a_max`` and an optional rate limit ``rate_max``::

    a_eff = clip(a, -a_max, a_max)                      (the value the model applies)
    da/dt = clip((c - a_eff) / T, -rate_max, rate_max)  and 0 when |a| >= a_max pushing outwards

This is the continuous-time form of the PVS update (Fossen's ``remus100.dynamics``: the actual
value is clipped, then integrated towards the unclipped command with time constant T), so a
command beyond the limit holds the actuator at the limit.  The allocation reports such commands
as saturated (:mod:`auvtrack.plant.sixdof.prestero`, :mod:`auvtrack.plant.sixdof.fossen`).

References
----------
Fossen, T. I. (2021). Handbook of Marine Craft Hydrodynamics and Motion Control, 2nd ed.,
Section 8.4.2 (REMUS 100 actuator time constants and limits); ch. 11 (magnitude and rate limits).
"""
from __future__ import annotations

from ...jit import njit_noalloc
from .layout import (IX_DR, IX_DS, IX_N, P_DMAX, P_DRATE, P_NMAX, P_NRATE, P_TDELTA, P_TN)


@njit_noalloc(inline="always")
def clip(a, lo, hi):
    """a limited to [lo, hi]."""
    return lo if a < lo else (hi if a > hi else a)


@njit_noalloc(inline="always")
def lag_rate(a, c, a_max, T, rate_max):
    """da/dt of one actuator (units of a per s); see the module docstring."""
    d = (c - clip(a, -a_max, a_max)) / T
    d = clip(d, -rate_max, rate_max)
    if (a >= a_max and d > 0.0) or (a <= -a_max and d < 0.0):
        return 0.0
    return d


@njit_noalloc(inline="always")
def effective(x, pp):
    """(delta_r, delta_s, n) applied now: the actuator states clipped to their limits (rad, rad, rpm)."""
    dm, nm = pp[P_DMAX], pp[P_NMAX]
    return clip(x[IX_DR], -dm, dm), clip(x[IX_DS], -dm, dm), clip(x[IX_N], -nm, nm)


@njit_noalloc(inline="always")
def actuator_rates(x, cdr, cds, cn, pp):
    """(d delta_r/dt, d delta_s/dt, dn/dt) for the commands (rad/s, rad/s, rpm/s)."""
    dm, td, dr = pp[P_DMAX], pp[P_TDELTA], pp[P_DRATE]
    return (lag_rate(x[IX_DR], cdr, dm, td, dr),
            lag_rate(x[IX_DS], cds, dm, td, dr),
            lag_rate(x[IX_N], cn, pp[P_NMAX], pp[P_TN], pp[P_NRATE]))


@njit_noalloc(inline="always")
def fin_angle_for(tau, gain, sign_coef, d_max):
    """Fin angle producing moment ``tau = gain * delta`` (gain = coefficient x speed^2), limited.

    Returns (delta, saturated).  At zero speed (gain = 0) any nonzero moment saturates, towards
    the side whose sign the coefficient ``sign_coef`` gives.
    """
    cap = abs(gain) * d_max
    if abs(tau) > cap:
        s = 1.0 if tau > 0.0 else -1.0
        return s * sign_coef * d_max, True
    if tau == 0.0:
        return 0.0, False
    return tau / gain, False

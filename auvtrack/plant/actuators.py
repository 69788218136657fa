"""Actuator model: magnitude saturation and slew-rate limits of tau = [tau_u, tau_q, tau_r].

Inputs are N (surge force) and N m (pitch and yaw moments); limits are per input, ``inf``
disables one.  Two operations, applied in this order to the controller's command:

* saturation ``|tau_j| <= tau_max_j`` (every evaluation, continuous or sampled control);
* rate limit ``|tau_j(k) - tau_j(k-1)| <= rate_max_j h`` between two samples h seconds apart.
  A rate limit needs a sampling period, so it acts in sampled-data mode
  (``sim.control_rate > 0``) only; the scenario loader refuses it otherwise.

The packed limits are six numbers [tau_max (3), rate_max (3)] (N, N m; N/s, N m/s) stored in a
float64 array ``p`` from index ``off`` on (the engine keeps them in its settings vector ``sf``).

References
----------
Fossen, T. I. (2021). Handbook of Marine Craft Hydrodynamics and Motion Control, 2nd ed.,
ch. 11 (control allocation: actuator magnitude and rate constraints).
"""
from __future__ import annotations

import numpy as np

from ..jit import njit, njit_noalloc

ACT_TAU_MAX, ACT_RATE_MAX = 0, 3
ACT_SIZE = 6


@njit
def _clip(x, lo, hi):
    return lo if x < lo else (hi if x > hi else x)


@njit_noalloc
def saturate(tau3, p, off):
    """Clip each input to ``[-tau_max_j, tau_max_j]`` (limits at ``p[off:off+3]``); a 3-tuple."""
    m0, m1, m2 = p[off + ACT_TAU_MAX], p[off + ACT_TAU_MAX + 1], p[off + ACT_TAU_MAX + 2]
    return _clip(tau3[0], -m0, m0), _clip(tau3[1], -m1, m1), _clip(tau3[2], -m2, m2)


@njit_noalloc
def rate_limit(tau3, prev3, p, off, h):
    """Move from ``prev3`` towards ``tau3`` by at most ``rate_max_j * h`` per input (3-tuple)."""
    d0 = p[off + ACT_RATE_MAX] * h
    d1 = p[off + ACT_RATE_MAX + 1] * h
    d2 = p[off + ACT_RATE_MAX + 2] * h
    return (_clip(tau3[0], prev3[0] - d0, prev3[0] + d0),
            _clip(tau3[1], prev3[1] - d1, prev3[1] + d1),
            _clip(tau3[2], prev3[2] - d2, prev3[2] + d2))


def pack_actuator(tau_max, rate_max) -> np.ndarray:
    """Pack the limits into ``act_p`` (float64, length :data:`ACT_SIZE`).

    Parameters
    ----------
    tau_max : sequence of 3 float
        Magnitude limits of tau_u (N), tau_q, tau_r (N m); ``inf`` = none; each > 0.
    rate_max : sequence of 3 float
        Slew-rate limits (N/s, N m/s); ``inf`` = none; each > 0.

    Returns
    -------
    numpy.ndarray
        The packed limits.

    Raises
    ------
    ValueError
        If a limit is not > 0 or there are not three of each.
    """
    p = np.concatenate([np.asarray(tau_max, float).ravel(), np.asarray(rate_max, float).ravel()])
    if p.size != ACT_SIZE:
        raise ValueError(f"actuator: tau_max and rate_max need 3 values each (got {p.size} in all)")
    if not np.all(p > 0):
        raise ValueError(f"actuator: every limit must be > 0 (inf = no limit), got {p.tolist()}")
    return p

"""What the actuators cannot produce, in the error-acceleration space of the nominal model.

A tau law commands tau = input_for_accel(a) (tracking.py) for a desired error acceleration a.
The plant tells it what each axis can produce now, ``args.lo`` and ``args.hi``
(:mod:`auvtrack.control.contract`); the part of the command beyond that reach is

    d_tau = sat(tau) - tau,   sat(tau)_j = min(max(tau_j, lo_j), hi_j)       (N, N m, N m)     (A1)

and, on the nominal model (eq. 1, 4, 15), the error acceleration it takes away is

    d_a = J3 M_bar^-1 d_tau   (M_bar = diag(m11, m44, m55) of the u, q, r rows, m/s^2)      (A2)

exactly: the nominal sway and heave accelerations in J4_dot do not depend on tau (the model is
diagonal), so e_ddot(sat(tau)) = e_ddot(tau) + d_a.  Without saturation d_a = 0.  The
saturation-aware ("compensated") forms of the laws feed d_a back (docs/derivation.md, section 7);
the published forms ignore it.  ``sat(tau)`` is the current command's reach, not ``args.applied``:
the applied tau also contains the actuators' lag and, in continuous mode, is the previous stage's
command, which would make the compensated forms differ from the published ones without any
saturation.

All functions are compiled, allocation-free and work on tuples.
"""
from __future__ import annotations

from ..jit import njit_noalloc
from ..vehicle.kinematics import j3
from ..vehicle.params import VP
from .tracking import mat_vec

SATURATION = ("published", "compensated")
"""Values of a law's ``saturation`` field: the law as published, or its saturation-aware form."""
PUBLISHED, COMPENSATED = 0, 1
"""The packed codes of :data:`SATURATION`."""


@njit_noalloc(inline="always")
def clip(x, lo, hi):
    """x limited to [lo, hi] (lo if x < lo, hi if x > hi; x itself otherwise, also for infinite limits)."""
    return lo if x < lo else (hi if x > hi else x)


@njit_noalloc(inline="always")
def accel_deficit(att, vp, tau, lo, hi):
    """(d_a (3-tuple, m/s^2), saturated): eq. (A1)-(A2) for the command ``tau`` and the reach [lo, hi].

    Parameters are 3-tuples in the command's units (N, N m, N m); ``vp`` is the packed nominal
    vehicle.  ``saturated`` is True when some component of tau lies outside its reach.
    """
    c0, c1, c2 = clip(tau[0], lo[0], hi[0]), clip(tau[1], lo[1], hi[1]), clip(tau[2], lo[2], hi[2])
    dv = ((c0 - tau[0]) / vp[VP.m], (c1 - tau[1]) / vp[VP.m + 3], (c2 - tau[2]) / vp[VP.m + 4])
    sat = c0 != tau[0] or c1 != tau[1] or c2 != tau[2]
    return mat_vec(j3(att, vp[VP.ell]), dv), sat


def code(saturation: str) -> int:
    """The packed code of a ``saturation`` value (:data:`SATURATION`).

    Parameters
    ----------
    saturation : str
        ``"published"`` or ``"compensated"``.

    Returns
    -------
    int
        :data:`PUBLISHED` or :data:`COMPENSATED`.
    """
    return SATURATION.index(saturation)

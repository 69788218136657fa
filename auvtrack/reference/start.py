"""Where a run starts relative to its reference: the start on the reference, and a warning when far off.

The default initial state is Section 4's (``initial.eta = [0, 0.5, 0, 0, 0]``), which suits the
default helix.  Other references start elsewhere: the default lawnmower at a depth of 5 m, a
circle at its ``depth``.  From the Section 4 start a large depth step drives the pitch to the
limit (``sim.theta_limit``) within seconds, because the virtual point can only reach a new
depth by pitching the whole vehicle.  :func:`start_note` says so before the run, with the
``initial.eta`` that starts on the reference (:func:`start_on_reference`).
"""
from __future__ import annotations

import math

import numpy as np

from .base import Reference

DEPTH_STEP_WARN = 1.0
"""Depth offset (m) of the virtual point's start above which :func:`start_note` warns.

Section 4 with a circle of radius 4 m at 0.1 rad/s, default start and gains: both controllers
track a start 2 m above or below the circle, and stop at the pitch limit within 3 s from 2.5 m
on (``tests/reference/test_reference_start.py`` runs these cases).  The warning starts at half that, as a
margin for other gains, vehicles and references.
"""
NOTE_PREFIX = "start: the virtual point starts"


def start_on_reference(ref: Reference, ell: float) -> list[float]:
    """Initial ``eta = [x, y, z, theta, psi]`` that puts the virtual point on ``ref`` at t = 0.

    The vehicle is level (theta = 0) and heads along the reference's horizontal velocity (north
    if it has none); the centre of gravity is ``ell`` behind the virtual point (paper eq. 2).

    Parameters
    ----------
    ref : Reference
        The reference.
    ell : float
        Virtual-point offset ``vehicle.l`` (m).

    Returns
    -------
    list of float
        ``initial.eta`` (m, m, m, rad, rad).
    """
    p, v, _ = ref.evaluate(0.0)
    psi = math.atan2(v[1], v[0]) if math.hypot(v[0], v[1]) > 0 else 0.0
    return [float(p[0] - ell * math.cos(psi)), float(p[1] - ell * math.sin(psi)), float(p[2]), 0.0, psi]


def start_note(ref: Reference, vp0, ell: float) -> str | None:
    """A warning when the virtual point starts more than :data:`DEPTH_STEP_WARN` off the reference's depth.

    Parameters
    ----------
    ref : Reference
        The reference.
    vp0 : sequence of float
        The virtual point eta1 at t = 0 (m, NED), from ``initial.eta`` by paper eq. (2).
    ell : float
        Virtual-point offset ``vehicle.l`` (m), for the suggested start.

    Returns
    -------
    str or None
        One line naming the offset and the ``--set initial.eta=[...]`` that starts on the
        reference, or ``None`` when the start is close enough in depth.
    """
    vp = np.asarray(vp0, dtype=float)
    p0 = ref.evaluate(0.0)[0]
    dz = float(vp[2] - p0[2])
    if abs(dz) <= DEPTH_STEP_WARN:
        return None
    eta = ", ".join(f"{a:.6g}" for a in start_on_reference(ref, ell))
    return (f"{NOTE_PREFIX} {np.linalg.norm(vp - p0):.3g} m from the reference's start, {abs(dz):.3g} m "
            f"{'above' if dz < 0 else 'below'} it (z {vp[2]:.3g} m vs {p0[2]:.3g} m); a depth step of a few "
            f"metres can drive the pitch to sim.theta_limit within seconds; to start on the reference set "
            f"initial.eta = [{eta}] (--set 'initial.eta=[{eta}]')")


__all__ = ["start_on_reference", "start_note", "DEPTH_STEP_WARN", "NOTE_PREFIX"]

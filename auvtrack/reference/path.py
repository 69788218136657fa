"""The reference as a path: the closest point to a position, and the errors in the path frame.

Every reference is a curve eta_d(s) of its time parameter s (:func:`reference_point` gives
eta_d, eta_d' and eta_d'' at any s).  A path-following controller and the path-following metrics
ask two questions of it, answered here once for every reference kind:

* :func:`project`: the s of the point of the path closest to a position p, near a guess;
* :func:`path_errors`: p - eta_d(s) in the path frame (cross-track, vertical-track and
  along-track components), and :func:`along_track_error`, the timing error (s - t) |eta_d'(s)|.

Projection (the closest point near ``s_guess``)
------------------------------------------------
The squared distance D(s) = |eta_d(s) - p|^2 has D'(s) = 2 g(s) with g = (eta_d - p) . eta_d',
g' = |eta_d'|^2 + (eta_d - p) . eta_d''.  From ``s_guess``, at most :data:`MAX_ITER` safeguarded
Newton steps on g(s) = 0:

* the Newton step -g/g' where g' >= :data:`NEWTON_MIN` |eta_d'|^2 (the distance clearly convex in
  s: p nearer to the path than to its centre of curvature); elsewhere (p near or beyond the centre
  of curvature, where D may be concave) the Gauss-Newton step -g/|eta_d'|^2, which always points
  downhill;
* every step is clipped to the window [s_guess - window, s_guess + window], and halved (at most
  :data:`MAX_HALVINGS` times) until D strictly decreases at a point where the path moves
  (|eta_d'|^2 > :data:`SPEED2_MIN`); a step that cannot do so ends the search (at once when the
  step falls below half an ulp of s, where every further trial is s itself); a step cut short
  by a standing part of the path is then lengthened by bisection towards that part's edge (at
  most MAX_HALVINGS times), where the moving path is closest;
* the search stops when a step is below :data:`S_TOL` (s), or at once when the path stands still
  at the guess itself.

A part of the path that stands still (a reference holding its start before t = 0, or its end
point after a ``hold`` end) adds no point the moving part does not have: the search never enters
one, and a vehicle behind the start or beyond a held end projects on the end of the moving part.

Near the path the steps converge quadratically (from the previous step's answer, 2 or 3 steps);
for p near a centre of curvature, where the closest point is ill-defined, convergence is only
linear and the search may stop short after MAX_ITER steps.  So the answer is the local minimum of the distance reached downhill from ``s_guess`` inside the
window: the closest point of the path near the guess, not the global one (a lawnmower's
neighbouring leg is never chosen while the vehicle follows its own leg).

Path frame
----------
At s, with pi_h = atan2(yd', xd') (azimuth of the horizontal tangent) and pi_v = atan2(-zd',
|(xd', yd')|) (elevation, positive climbing), the errors are those of Fossen & Aguiar (2024),
as in MSS ``ALOS3D``: e = R_y(pi_v)^T R_z(pi_h)^T (p - eta_d(s)), i.e.

* along-track x_e along the 3-D tangent (0 at a closest point: the projection's condition g = 0);
* cross-track y_e horizontal, perpendicular to the horizontal tangent, positive to the right of
  the path (starboard when facing along it: north-going path, y_e = east offset);
* vertical-track z_e in the vertical plane of the tangent, perpendicular to it, positive below
  the path (NED: z down; the depth error on a level path).

Where the path stands still (only when the guess itself is there) the frame is undefined: y_e is
then the horizontal distance |p - eta_d| (>= 0) and z_e the depth difference.  The along-track *timing* error is (s - t)
|eta_d'(s)| (m): positive when the closest point is ahead of where the reference is at time t.

References
----------
Fossen, T. I. and Aguiar, A. P. (2024). A uniform semiglobal exponential stable adaptive
line-of-sight (ALOS) guidance law for 3-D path following. Automatica 163, 111556.
Nocedal, J. and Wright, S. J. (2006). Numerical Optimization, 2nd ed., ch. 3 (backtracking line
search) and ch. 10 (Gauss-Newton).
"""
from __future__ import annotations

import math

from ..jit import njit_noalloc
from .kernel import reference_point

MAX_ITER = 8
"""Newton steps per projection (from a warm start, 2 or 3 are taken)."""
MAX_HALVINGS = 30
"""Step halvings before a step that does not decrease the distance ends the search."""
S_TOL = 1e-9
"""Steps shorter than this (s of path time) end the search."""
NEWTON_MIN = 0.05
"""Newton steps where g' >= NEWTON_MIN |eta_d'|^2, Gauss-Newton steps elsewhere."""
SPEED2_MIN = 1e-20
"""|eta_d'|^2 (m^2/s^2) below which the path stands still at s."""


@njit_noalloc(inline="always")
def _distance2(pt, p):
    """|eta_d - p|^2 (m^2) and (eta_d - p) of a path point ``pt`` = (position, velocity, acceleration)."""
    dx, dy, dz = pt[0][0] - p[0], pt[0][1] - p[1], pt[0][2] - p[2]
    return dx * dx + dy * dy + dz * dz, (dx, dy, dz)


@njit_noalloc(inline="always")
def _speed2(pt):
    """|eta_d'|^2 (m^2/s^2) of a path point."""
    v = pt[1]
    return v[0] * v[0] + v[1] * v[1] + v[2] * v[2]


@njit_noalloc
def project(path, s_guess, p, window):
    """The path parameter of the point of the path closest to ``p`` near ``s_guess`` (module docstring).

    Parameters
    ----------
    path : numpy.ndarray
        Packed reference (:mod:`auvtrack.reference.kernel`).
    s_guess : float
        Start of the search (s of path time), e.g. the previous answer.
    p : tuple of 3 float
        Position (m, NED).
    window : float
        Half-width of the search window around ``s_guess`` (s of path time), > 0.

    Returns
    -------
    (float, tuple)
        s (s of path time) and the path point there: (position (m), velocity (m/s), acceleration
        (m/s^2)), 3-tuples, as :func:`~auvtrack.reference.kernel.reference_point` gives them.
    """
    return project_from(path, s_guess, reference_point(path, s_guess), p, window)


@njit_noalloc
def project_from(path, s_guess, pt_guess, p, window):
    """:func:`project` given the path point at ``s_guess``, e.g. the one the previous projection returned.

    A search warm-started from its previous answer would evaluate the path there again; passing
    that point saves the evaluation and gives the same bits (the evaluation is a function of
    ``s_guess`` alone).

    Parameters
    ----------
    path : numpy.ndarray
        Packed reference (:mod:`auvtrack.reference.kernel`).
    s_guess : float
        Start of the search (s of path time).
    pt_guess : tuple
        ``reference_point(path, s_guess)``: (position, velocity, acceleration), 3-tuples.
    p : tuple of 3 float
        Position (m, NED).
    window : float
        Half-width of the search window around ``s_guess`` (s of path time), > 0.

    Returns
    -------
    (float, tuple)
        As :func:`project`.
    """
    lo = s_guess - window
    hi = s_guess + window
    s = s_guess
    pt = pt_guess
    dist2, d = _distance2(pt, p)
    for _ in range(MAX_ITER):
        v, a = pt[1], pt[2]
        vv = v[0] * v[0] + v[1] * v[1] + v[2] * v[2]
        if not vv > SPEED2_MIN:
            break
        g = d[0] * v[0] + d[1] * v[1] + d[2] * v[2]
        gp = vv + d[0] * a[0] + d[1] * a[1] + d[2] * a[2]
        step = -g / gp if gp >= NEWTON_MIN * vv else -g / vv
        s_new = min(max(s + step, lo), hi)
        step = s_new - s
        if abs(step) <= S_TOL:
            break
        accepted = False
        standing = 0.0  # the shortest step tried that ended where the path stands still (0: none)
        for _h in range(MAX_HALVINGS):
            if s + step == s:  # below half an ulp of s: every further trial is the point s itself, never accepted
                break
            pt_new = reference_point(path, s + step)
            dist2_new, d_new = _distance2(pt_new, p)
            if not _speed2(pt_new) > SPEED2_MIN:
                standing = step
            elif dist2_new < dist2:
                accepted = True
                break
            step = 0.5 * step
        if not accepted:
            break
        # a step cut short by a standing part: D decreases up to it, so bisect towards its edge
        for _h in range(MAX_HALVINGS if standing != 0.0 else 0):
            mid = 0.5 * (step + standing)
            pt_mid = reference_point(path, s + mid)
            dist2_mid, d_mid = _distance2(pt_mid, p)
            if not _speed2(pt_mid) > SPEED2_MIN:
                standing = mid
            elif dist2_mid < dist2_new:
                step, pt_new, dist2_new, d_new = mid, pt_mid, dist2_mid, d_mid
            else:
                break
        s = s + step
        pt, dist2, d = pt_new, dist2_new, d_new
    return s, pt


@njit_noalloc(inline="always")
def path_errors(pt, p):
    """(x_e, y_e, z_e): along-, cross- and vertical-track components of p - eta_d in the path frame (m).

    Parameters
    ----------
    pt : tuple
        The path point (position, velocity, acceleration) at s, as :func:`project` returns it.
    p : tuple of 3 float
        Position (m, NED).

    Returns
    -------
    tuple of 3 float
        x_e along the tangent, y_e horizontal and positive to the right of the path, z_e positive
        below it (m; Fossen & Aguiar 2024, MSS ``ALOS3D``).  Where the path stands still: (0, the
        horizontal distance, the depth difference).
    """
    dx, dy, dz = p[0] - pt[0][0], p[1] - pt[0][1], p[2] - pt[0][2]
    vx, vy, vz = pt[1][0], pt[1][1], pt[1][2]
    vh2 = vx * vx + vy * vy
    if not vh2 + vz * vz > SPEED2_MIN:
        return 0.0, math.sqrt(dx * dx + dy * dy), dz
    vh = math.sqrt(vh2)
    speed = math.sqrt(vh2 + vz * vz)
    ch, sh = (vx / vh, vy / vh) if vh > 0.0 else (1.0, 0.0)  # cos, sin of pi_h
    cv, sv = vh / speed, -vz / speed  # cos, sin of pi_v
    return (cv * (ch * dx + sh * dy) - sv * dz,
            -sh * dx + ch * dy,
            sv * (ch * dx + sh * dy) + cv * dz)


@njit_noalloc(inline="always")
def along_track_error(pt, s, t):
    """Timing error along the path, (s - t) |eta_d'(s)| (m): positive ahead of the reference at time t.

    Parameters
    ----------
    pt : tuple
        The path point at s (:func:`project`).
    s : float
        Path parameter of the closest point (s).
    t : float
        Time (s).

    Returns
    -------
    float
        The along-track timing error (m).
    """
    v = pt[1]
    return (s - t) * math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])


__all__ = ["project", "project_from", "path_errors", "along_track_error", "MAX_ITER", "MAX_HALVINGS", "NEWTON_MIN", "S_TOL", "SPEED2_MIN"]

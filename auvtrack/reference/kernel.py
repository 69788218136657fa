"""Packed reference layout and the compiled evaluator shared by every reference kind.

Every reference is stored as a sequence of *segments*.  Segment ``i`` starts at time ``T[i]`` and
is used on ``[T[i], T[i+1])``; the first segment is also used for ``t < T[1]`` and the last one for
every ``t >= T[m-1]``, so each kind encodes its own behaviour before the start and after the end
(as extra segments, see the kinds).  In the local time ``s = t - T[i]`` each axis is

    p(s) = c0 + c1 s + c2 s**2 + c3 s**3 + A cos(w s) + B sin(w s)

with one angular rate ``w`` (rad/s) per segment.  A helix is one harmonic segment, a line one
linear segment, a lawnmower alternating linear and harmonic segments and a cubic spline a run of
cubic segments.  Velocity and acceleration are the exact derivatives of this expression.

Packed layout (1-D ``float64``, length ``n = HEADER + m * (1 + SEG)``):

==================  =======================================================
index               content
==================  =======================================================
0                   family code, ``FAMILY_SEGMENTS`` (= 1)
1                   total length ``n``
2                   ``m``, number of segments (>= 1)
3                   ``SEG``, floats per segment record (= 19)
4 .. 4+m-1          ``T``, segment start times, strictly increasing (s)
4+m + i*SEG + 0     ``w`` of segment i (rad/s); 0 means no harmonic part
4+m + i*SEG + 1+6k  ``c0, c1, c2, c3, A, B`` of axis k (x, y, z), SI units
==================  =======================================================
"""
from __future__ import annotations

import math

import numpy as np

from ..jit import njit, njit_noalloc

FAMILY_SEGMENTS = 1
H_FAMILY, H_LEN, H_NSEG, H_STRIDE = 0, 1, 2, 3
HEADER = 4
NCOEF = 6  # c0, c1, c2, c3, A, B per axis
SEG = 1 + 3 * NCOEF


@njit_noalloc(inline="always")
def _axis(ref_p, b, s, harmonic, w, cw, sw):
    """(position, velocity, acceleration) of one axis whose coefficients start at ``ref_p[b]``."""
    c0, c1, c2, c3 = ref_p[b], ref_p[b + 1], ref_p[b + 2], ref_p[b + 3]
    p = c0 + s * (c1 + s * (c2 + s * c3))
    v = c1 + s * (2.0 * c2 + 3.0 * c3 * s)
    a = 2.0 * c2 + 6.0 * c3 * s
    if harmonic:
        A, B = ref_p[b + 4], ref_p[b + 5]
        hc = A * cw + B * sw
        p += hc
        v += w * (B * cw - A * sw)
        a -= w * w * hc
    return p, v, a


@njit_noalloc(inline="always")
def reference_point(ref_p, t):
    """Position, velocity and acceleration of a packed reference at time ``t``, as tuples.

    Parameters
    ----------
    ref_p : ndarray of float64
        Packed reference (see the module docstring).
    t : float
        Time (s); any finite value is allowed.

    Returns
    -------
    (tuple, tuple, tuple)
        Position (m), velocity (m/s) and acceleration (m/s^2), NED, 3 floats each.  A malformed
        pack gives NaN everywhere (never reads out of bounds).
    """
    n = ref_p.shape[0]
    m = 0
    if n >= HEADER and ref_p[H_FAMILY] == FAMILY_SEGMENTS and ref_p[H_STRIDE] == SEG:
        mf = ref_p[H_NSEG]
        if mf >= 1.0 and mf <= n:  # also rejects NaN
            m = int(mf)
    if m < 1 or HEADER + m * (1 + SEG) > n:
        nan3 = (math.nan, math.nan, math.nan)
        return nan3, nan3, nan3
    # largest i with T[i] <= t (0 if t < T[0])
    lo = 0
    hi = m - 1
    while lo < hi:
        mid = (lo + hi + 1) >> 1
        if ref_p[HEADER + mid] <= t:
            lo = mid
        else:
            hi = mid - 1
    s = t - ref_p[HEADER + lo]
    r = HEADER + m + lo * SEG
    w = ref_p[r]
    harmonic = w != 0.0
    cw = 0.0
    sw = 0.0
    if harmonic:
        cw = math.cos(w * s)
        sw = math.sin(w * s)
    x = _axis(ref_p, r + 1, s, harmonic, w, cw, sw)
    y = _axis(ref_p, r + 1 + NCOEF, s, harmonic, w, cw, sw)
    z = _axis(ref_p, r + 1 + 2 * NCOEF, s, harmonic, w, cw, sw)
    return (x[0], y[0], z[0]), (x[1], y[1], z[1]), (x[2], y[2], z[2])


@njit_noalloc(inline="always")
def eval_reference(ref_p, t, out):
    """Evaluate a packed reference at time ``t`` into an array (:func:`reference_point`).

    Parameters
    ----------
    ref_p : ndarray of float64
        Packed reference (see the module docstring).
    t : float
        Time (s); any finite value is allowed.
    out : ndarray of float64, shape (3, 3)
        Written: ``out[0]`` position (m), ``out[1]`` velocity (m/s), ``out[2]`` acceleration
        (m/s^2), NED.  A malformed pack writes NaN everywhere (never reads out of bounds).
    """
    p, v, a = reference_point(ref_p, t)
    out[0, 0], out[0, 1], out[0, 2] = p
    out[1, 0], out[1, 1], out[1, 2] = v
    out[2, 0], out[2, 1], out[2, 2] = a


@njit
def eval_reference_batch(ref_p, ts, out):
    """Call :func:`eval_reference` for every ``ts[j]``, writing ``out[j]`` (shape (n, 3, 3))."""
    for j in range(ts.shape[0]):
        eval_reference(ref_p, ts[j], out[j])


def segment_record(w: float = 0.0, c0=(0.0, 0.0, 0.0), c1=(0.0, 0.0, 0.0), c2=(0.0, 0.0, 0.0),
                   c3=(0.0, 0.0, 0.0), A=(0.0, 0.0, 0.0), B=(0.0, 0.0, 0.0)) -> np.ndarray:
    """Build one segment record (length ``SEG``) from per-axis coefficient triples.

    Parameters
    ----------
    w : float
        Angular rate of the harmonic part (rad/s).  If 0, ``A`` is folded into ``c0`` (cos 0 = 1)
        and ``B`` dropped (sin 0 = 0) because the evaluator skips the harmonic part.
    c0, c1, c2, c3, A, B : sequence of 3 float
        Coefficients of each axis in the local time ``s`` (see the module docstring).

    Returns
    -------
    ndarray of float64, shape (SEG,)
    """
    coef = np.array([c0, c1, c2, c3, A, B], dtype=np.float64).T  # (3 axes, NCOEF)
    if w == 0.0:
        coef[:, 0] += coef[:, 4]
        coef[:, 4:] = 0.0
    rec = np.empty(SEG)
    rec[0] = w
    rec[1:] = coef.ravel()
    return rec


def pack_segments(times, records) -> np.ndarray:
    """Assemble segment start times and records into the packed layout.

    Parameters
    ----------
    times : sequence of float, length m >= 1
        Segment start times (s), finite and strictly increasing.
    records : sequence of ndarray, each of length ``SEG``
        Segment records from :func:`segment_record`.

    Returns
    -------
    ndarray of float64, shape (HEADER + m * (1 + SEG),)

    Raises
    ------
    ValueError
        If the times are not strictly increasing or any number is not finite.
    """
    T = np.asarray(times, dtype=np.float64).ravel()
    R = np.asarray(records, dtype=np.float64).reshape(len(T), SEG)
    m = T.size
    if m < 1 or not np.all(np.isfinite(T)) or not np.all(np.isfinite(R)):
        raise ValueError("reference segments must be at least one, with finite times and coefficients")
    if np.any(np.diff(T) <= 0.0):
        raise ValueError("reference segment start times must be strictly increasing")
    n = HEADER + m * (1 + SEG)
    out = np.empty(n)
    out[:HEADER] = (FAMILY_SEGMENTS, n, m, SEG)
    out[HEADER : HEADER + m] = T
    out[HEADER + m :] = R.ravel()
    return out


def segment_times(ref_p: np.ndarray) -> np.ndarray:
    """Return the segment start times ``T`` of a packed reference (a copy)."""
    m = int(ref_p[H_NSEG])
    return np.array(ref_p[HEADER : HEADER + m])

"""Smooth path through waypoints: a natural cubic spline in time with chord-length timing.

Waypoint ``i`` is reached at ``t_i = (sum of straight-line distances up to i) / speed``, so
``speed`` is the nominal (mean straight-line) speed.  Each axis is the C2 cubic spline through
``(t_i, p_i)`` with *natural* ends (zero acceleration at the first and last waypoint).

Before t = 0 the first waypoint is held at rest.  After the last waypoint the reference either
continues along the final tangent at the final velocity (``end="continue"``; the natural end has
zero acceleration, so this continuation keeps the path C2) or holds the last waypoint at rest
(``end="hold"``; the velocity steps to zero).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from .base import Reference, check_choice, check_real, set_field
from .kernel import segment_record

_ENDS = ("continue", "hold")
_MAX_POINTS = 100_000


def _clean_points(owner: str, value) -> tuple[tuple[float, float, float], ...]:
    msg = f"{owner}.points must be a list of 2 to {_MAX_POINTS} [x, y, z] finite points (m)"
    try:
        arr = np.array(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{msg}, got {value!r}") from None
    if arr.ndim != 2 or arr.shape[1] != 3 or not 2 <= arr.shape[0] <= _MAX_POINTS or not np.all(np.isfinite(arr)):
        raise ValueError(f"{msg}, got shape {arr.shape}")
    chords = np.linalg.norm(np.diff(arr, axis=0), axis=1)
    if np.any(chords <= 0.0):
        i = int(np.argmin(chords))
        raise ValueError(f"{owner}.points must have distinct consecutive points, points {i} and {i + 1} coincide")
    return tuple(tuple(float(c) for c in row) for row in arr)


@dataclass(frozen=True, kw_only=True)
class Waypoints(Reference):
    """C2 path through waypoints (natural cubic spline in time, chord-length timing).

    Attributes
    ----------
    points : sequence of [x, y, z]
        Waypoints, metres (NED), 2 to 100000 finite points, consecutive points distinct.
    speed : float
        Nominal speed, m/s, in (0, 100]: waypoint i is reached at (path chord length to i) / speed.
    end : str
        Continuation after the last waypoint: "continue" (final tangent) or "hold" (stop).
    """

    kind: ClassVar[str] = "waypoints"
    points: tuple[tuple[float, float, float], ...]
    speed: float = 1.0
    end: str = "continue"

    def __post_init__(self) -> None:
        o = type(self).__name__
        set_field(self, "points", _clean_points(o, self.points))
        set_field(self, "speed", check_real(o, "speed", self.speed, 0.0, 100.0, True, False))
        check_choice(o, "end", self.end, _ENDS)

    @property
    def times(self) -> np.ndarray:
        """Time at which each waypoint is reached, s (chord-length timing, first is 0)."""
        P = np.asarray(self.points)
        chords = np.linalg.norm(np.diff(P, axis=0), axis=1)
        return np.concatenate([[0.0], np.cumsum(chords) / self.speed])

    @property
    def duration(self) -> float:
        """Time at which the last waypoint is reached, s."""
        return float(self.times[-1])

    def _segments(self):
        from scipy.interpolate import CubicSpline  # lazy: keep `import auvtrack.reference` light

        P = np.asarray(self.points)
        t = self.times
        sp = CubicSpline(t, P, bc_type="natural")
        c = sp.c  # (4, n-1, 3), highest power first, local variable s = t - t_i
        times = [-1.0]
        recs = [segment_record(c0=P[0])]  # t < 0: hold the first waypoint
        for i in range(len(t) - 1):
            times.append(t[i])
            # c0 = p_i exactly, so the spline interpolates every waypoint at its start time
            recs.append(segment_record(c0=P[i], c1=c[2, i], c2=c[1, i], c3=c[0, i]))
        times.append(t[-1])
        if self.end == "continue":
            recs.append(segment_record(c0=P[-1], c1=sp(t[-1], 1)))
        else:
            recs.append(segment_record(c0=P[-1]))
        return times, recs

"""Lawnmower (boustrophedon) survey pattern at constant depth and constant along-track speed.

``legs`` parallel straight legs of length ``leg_length`` are joined by semicircular turns of
radius ``spacing / 2``, so neighbouring legs are ``spacing`` apart.  The path is represented
exactly (straight legs are linear segments, turns harmonic segments): position and velocity are
continuous (C1, velocity = speed along the path everywhere), and the acceleration is bounded
(0 on legs, ``speed**2 / (spacing/2)`` towards the turn centre on turns) with a step at each
leg/turn joint.

Before t = 0 the start point is held at rest.  After the last leg (t >= ``duration``) the
reference either continues along the last leg at the same speed (``end="continue"``, smooth) or
holds the final point at rest (``end="hold"``, velocity steps to zero).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from .base import Reference, check_choice, check_int, check_real, check_vector, set_field
from .kernel import segment_record

_ENDS = ("continue", "hold")


@dataclass(frozen=True, kw_only=True)
class Lawnmower(Reference):
    """Survey pattern of parallel legs joined by semicircular turns, at constant depth.

    Attributes
    ----------
    start : tuple of 2 float
        (x, y) of the start of the first leg, metres, finite.
    heading : float
        Direction of the first leg, rad, clockwise from north (NED yaw), finite.
    leg_length : float
        Length of each straight leg, metres, in (0, 1e6).
    spacing : float
        Distance between neighbouring legs, metres, in (0, 1e6); turn radius is spacing / 2.
    legs : int
        Number of legs, in [1, 10000].
    speed : float
        Constant along-track speed, m/s, in (0, 100].
    depth : float
        z, metres (positive down), finite.
    first_turn : str
        "right" (legs stack to starboard of ``heading``) or "left" (to port).
    end : str
        Continuation after the last leg: "continue" (along the last leg) or "hold" (stop).
    """

    kind: ClassVar[str] = "lawnmower"
    start: tuple[float, float] = (0.0, 0.0)
    heading: float = 0.0
    leg_length: float = 50.0
    spacing: float = 10.0
    legs: int = 4
    speed: float = 1.0
    depth: float = 5.0
    first_turn: str = "right"
    end: str = "continue"

    def __post_init__(self) -> None:
        o = type(self).__name__
        set_field(self, "start", check_vector(o, "start", self.start, 2))
        set_field(self, "heading", check_real(o, "heading", self.heading))
        set_field(self, "leg_length", check_real(o, "leg_length", self.leg_length, 0.0, 1e6))
        set_field(self, "spacing", check_real(o, "spacing", self.spacing, 0.0, 1e6))
        set_field(self, "legs", check_int(o, "legs", self.legs, 1, 10000))
        set_field(self, "speed", check_real(o, "speed", self.speed, 0.0, 100.0, True, False))
        set_field(self, "depth", check_real(o, "depth", self.depth))
        check_choice(o, "first_turn", self.first_turn, ("right", "left"))
        check_choice(o, "end", self.end, _ENDS)

    @property
    def turn_radius(self) -> float:
        """Radius of the semicircular turns, metres (``spacing / 2``)."""
        return 0.5 * self.spacing

    @property
    def leg_time(self) -> float:
        """Time on one leg, s."""
        return self.leg_length / self.speed

    @property
    def turn_time(self) -> float:
        """Time on one turn, s (half circumference over speed)."""
        return math.pi * self.turn_radius / self.speed

    @property
    def duration(self) -> float:
        """Time at which the last leg ends, s."""
        return self.legs * self.leg_time + (self.legs - 1) * self.turn_time

    def leg_endpoints(self) -> np.ndarray:
        """Ideal (start, end) points of every leg, shape (legs, 2, 3), metres (from geometry)."""
        d, n = self._axes()
        x0 = np.array([*self.start, self.depth])
        out = np.empty((self.legs, 2, 3))
        for i in range(self.legs):
            base = x0 + i * self.spacing * n
            a, b = (base, base + self.leg_length * d) if i % 2 == 0 else (base + self.leg_length * d, base)
            out[i, 0], out[i, 1] = a, b
        return out

    def _axes(self) -> tuple[np.ndarray, np.ndarray]:
        """Unit along-track direction of leg 0 and unit offset direction between legs."""
        ch, sh = math.cos(self.heading), math.sin(self.heading)
        side = 1.0 if self.first_turn == "right" else -1.0
        return np.array([ch, sh, 0.0]), side * np.array([-sh, ch, 0.0])

    def _segments(self):
        V, R = self.speed, self.turn_radius
        d, n = self._axes()
        side = 1.0 if self.first_turn == "right" else -1.0
        ends = self.leg_endpoints()
        times = [-1.0]
        recs = [segment_record(c0=ends[0, 0])]  # t < 0: hold the start point
        t = 0.0
        for i in range(self.legs):
            di = d if i % 2 == 0 else -d
            times.append(t)
            recs.append(segment_record(c0=ends[i, 0], c1=V * di))
            t += self.leg_time
            if i == self.legs - 1:
                break
            # semicircle from ends[i, 1] about centre C; sigma = +1 turns right (psi increasing)
            C = ends[i, 1] + R * n
            phi0 = math.atan2(-n[1], -n[0])
            sigma = side * (1.0 if i % 2 == 0 else -1.0)
            c, s = R * math.cos(phi0), R * math.sin(phi0)
            times.append(t)
            recs.append(segment_record(w=sigma * V / R, c0=C, A=(c, s, 0.0), B=(-s, c, 0.0)))
            t += self.turn_time
        if self.end == "hold":
            times.append(self.duration)
            recs.append(segment_record(c0=ends[-1, 1]))
        # "continue": the last leg's linear segment simply extends past the end
        return times, recs

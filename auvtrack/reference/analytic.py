"""Analytic references defined for all time: helix, horizontal circle, straight line.

Each is a single "linear + harmonic" segment per axis starting at t = 0,
``p(t) = c0 + c1 t + A cos(w t) + B sin(w t)``, so the formula (and its exact derivatives) also
holds for t < 0 and beyond any horizon.  The default :class:`Helix` is the reference of the
paper's Section 4, eta_d = [4 cos(0.1 t), 4 sin(0.1 t), -0.1 t].
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

from .base import Reference, check_real, check_vector, set_field
from .kernel import segment_record

_R_MAX = 1e6  # m, generous bound on radii
_W_MAX = 100.0  # rad/s
_V_MAX = 1e3  # m/s, bound on speeds and climb rates


def _harmonic(omega: float, radius: float, phase: float, center, climb: float):
    """One segment: centre + climb t on z, radius (cos, sin)(omega t + phase) on x, y."""
    ca, sa = math.cos(phase), math.sin(phase)
    # R cos(wt + ph) = R cos ph cos wt - R sin ph sin wt; R sin(wt + ph) = R sin ph cos wt + R cos ph sin wt
    return segment_record(
        w=omega,
        c0=center,
        c1=(0.0, 0.0, climb),
        A=(radius * ca, radius * sa, 0.0),
        B=(-radius * sa, radius * ca, 0.0),
    )


@dataclass(frozen=True, kw_only=True)
class Helix(Reference):
    """Helix about a vertical axis (the Section 4 reference).

    ``x = cx + R cos(omega t + phase)``, ``y = cy + R sin(omega t + phase)``, ``z = cz + climb t`` (NED, z down).

    Attributes
    ----------
    radius : float
        R, metres, in (0, 1e6).
    omega : float
        Angular rate, rad/s, in [-100, 100]; positive turns from north towards east.
    climb : float
        Vertical rate dz/dt, m/s, in [-1000, 1000]; negative rises (z is down).
    center : tuple of 3 float
        (cx, cy, cz), metres, finite.
    phase : float
        Phase at t = 0, rad, finite.
    """

    kind: ClassVar[str] = "helix"
    radius: float = 4.0
    omega: float = 0.1
    climb: float = -0.1
    center: tuple[float, float, float] = (0.0, 0.0, 0.0)
    phase: float = 0.0

    def __post_init__(self) -> None:
        o = type(self).__name__
        set_field(self, "radius", check_real(o, "radius", self.radius, 0.0, _R_MAX))
        set_field(self, "omega", check_real(o, "omega", self.omega, -_W_MAX, _W_MAX, False, False))
        set_field(self, "climb", check_real(o, "climb", self.climb, -_V_MAX, _V_MAX, False, False))
        set_field(self, "center", check_vector(o, "center", self.center, 3))
        set_field(self, "phase", check_real(o, "phase", self.phase))

    def _segments(self):
        return [0.0], [_harmonic(self.omega, self.radius, self.phase, self.center, self.climb)]


@dataclass(frozen=True, kw_only=True)
class Circle(Reference):
    """Horizontal circle at constant depth (a :class:`Helix` with zero climb).

    ``x = cx + R cos(omega t + phase)``, ``y = cy + R sin(omega t + phase)``, ``z = depth``.

    Attributes
    ----------
    radius : float
        R, metres, in (0, 1e6).
    omega : float
        Angular rate, rad/s, in [-100, 100]; positive turns from north towards east.
    depth : float
        z, metres (positive down), finite.
    center : tuple of 2 float
        (cx, cy), metres, finite.
    phase : float
        Phase at t = 0, rad, finite.
    """

    kind: ClassVar[str] = "circle"
    radius: float
    omega: float
    depth: float
    center: tuple[float, float] = (0.0, 0.0)
    phase: float = 0.0

    def __post_init__(self) -> None:
        o = type(self).__name__
        set_field(self, "radius", check_real(o, "radius", self.radius, 0.0, _R_MAX))
        set_field(self, "omega", check_real(o, "omega", self.omega, -_W_MAX, _W_MAX, False, False))
        set_field(self, "depth", check_real(o, "depth", self.depth))
        set_field(self, "center", check_vector(o, "center", self.center, 2))
        set_field(self, "phase", check_real(o, "phase", self.phase))

    def _segments(self):
        c = (self.center[0], self.center[1], self.depth)
        return [0.0], [_harmonic(self.omega, self.radius, self.phase, c, 0.0)]


@dataclass(frozen=True, kw_only=True)
class Line(Reference):
    """Straight line at constant velocity: ``p(t) = start + velocity t`` (also for t < 0).

    Attributes
    ----------
    start : tuple of 3 float
        Position at t = 0, metres (NED), finite.
    velocity : tuple of 3 float
        Constant velocity, m/s (NED), each component in [-1000, 1000].
    """

    kind: ClassVar[str] = "line"
    start: tuple[float, float, float] = (0.0, 0.0, 0.0)
    velocity: tuple[float, float, float]

    def __post_init__(self) -> None:
        o = type(self).__name__
        set_field(self, "start", check_vector(o, "start", self.start, 3))
        vel = check_vector(o, "velocity", self.velocity, 3)
        if max(abs(vi) for vi in vel) > _V_MAX:
            raise ValueError(f"{o}.velocity must be 3 numbers in [{-_V_MAX:g}, {_V_MAX:g}] (m/s), got {list(vel)}")
        set_field(self, "velocity", vel)

    def _segments(self):
        return [0.0], [segment_record(c0=self.start, c1=self.velocity)]

"""Common base of the reference kinds and the field validators they share.

A kind is a frozen, keyword-only dataclass whose ``_segments`` method returns the segment start
times and records of :mod:`auvtrack.reference.kernel`.  This base turns those into the packed
array, evaluates through the compiled kernel and describes itself for ``run.json``.
"""
from __future__ import annotations

import math
import numbers
from dataclasses import fields
from functools import cached_property
from typing import ClassVar

import numpy as np

from .kernel import eval_reference_batch, pack_segments, segment_times


class Reference:
    """Base class of every reference kind (desired virtual-point position, NED, metres)."""

    kind: ClassVar[str] = ""

    def _segments(self) -> tuple[list[float], list[np.ndarray]]:  # pragma: no cover - abstract
        raise NotImplementedError

    @cached_property
    def _packed(self) -> np.ndarray:
        times, records = self._segments()
        return pack_segments(times, records)

    def pack(self) -> np.ndarray:
        """Return the packed 1-D ``float64`` array for compiled code (a fresh copy).

        See :mod:`auvtrack.reference.kernel` for the layout.
        """
        return self._packed.copy()

    @property
    def duration(self) -> float:
        """Time (s) at which a finite path ends; ``inf`` for unbounded kinds."""
        return math.inf

    @property
    def breakpoints(self) -> np.ndarray:
        """Times (s) >= 0 at which the representation switches segment (joints), ascending."""
        T = segment_times(self._packed)
        return T[T >= 0.0]

    def evaluate(self, t):
        """Evaluate position, velocity and acceleration through the compiled evaluator.

        Parameters
        ----------
        t : float or array_like of shape (n,)
            Time(s) in seconds.

        Returns
        -------
        p, v, a : ndarray
            Position (m), velocity (m/s), acceleration (m/s^2) in NED; shape (3,) for a scalar
            ``t``, (n, 3) for an array.
        """
        scalar = np.ndim(t) == 0
        ts = np.ascontiguousarray(np.atleast_1d(np.asarray(t, dtype=np.float64)))
        if ts.ndim != 1:
            raise ValueError(f"t must be a scalar or a 1-D array, got shape {np.shape(t)}")
        out = np.empty((ts.size, 3, 3))
        eval_reference_batch(self._packed, ts, out)
        p, v, a = out.transpose(1, 0, 2).copy()
        if scalar:
            return p[0], v[0], a[0]
        return p, v, a

    def describe(self) -> dict:
        """Return the fully resolved, JSON-serialisable spec (``kind`` plus every field).

        ``build_reference(ref.describe())`` rebuilds an identical reference.
        """
        spec: dict = {"kind": self.kind}
        for f in fields(self):  # type: ignore[arg-type]
            spec[f.name] = _jsonable(getattr(self, f.name))
        return spec


def _jsonable(value):
    if isinstance(value, tuple):
        return [_jsonable(v) for v in value]
    return value


# --- validators: each returns the cleaned value or raises a one-line ValueError ----------------

def _is_number(value) -> bool:
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def _interval(lo: float, hi: float, lo_open: bool, hi_open: bool) -> str:
    return f"{'(' if lo_open else '['}{lo:g}, {hi:g}{')' if hi_open else ']'}"


def check_real(owner: str, name: str, value, lo: float = -math.inf, hi: float = math.inf,
               lo_open: bool = True, hi_open: bool = True) -> float:
    """Return ``float(value)`` if it is a finite number in the interval, else raise ValueError."""
    rng = _interval(lo, hi, lo_open, hi_open)
    if not _is_number(value):
        raise ValueError(f"{owner}.{name} must be a finite number in {rng}, got {value!r}")
    x = float(value)
    ok = math.isfinite(x) and (x > lo if lo_open else x >= lo) and (x < hi if hi_open else x <= hi)
    if not ok:
        raise ValueError(f"{owner}.{name} must be a finite number in {rng}, got {x!r}")
    return x


def check_int(owner: str, name: str, value, lo: int, hi: int) -> int:
    """Return ``int(value)`` if it is an integer in ``[lo, hi]``, else raise ValueError."""
    ok = isinstance(value, numbers.Integral) and not isinstance(value, bool) and lo <= value <= hi
    if not ok:
        raise ValueError(f"{owner}.{name} must be an integer in [{lo}, {hi}], got {value!r}")
    return int(value)


def check_vector(owner: str, name: str, value, n: int) -> tuple[float, ...]:
    """Return a tuple of ``n`` finite floats, else raise ValueError."""
    try:
        items = list(value)
    except TypeError:
        items = None
    if items is None or len(items) != n or not all(_is_number(v) and math.isfinite(v) for v in items):
        raise ValueError(f"{owner}.{name} must be a sequence of {n} finite numbers, got {value!r}")
    return tuple(float(v) for v in items)


def check_choice(owner: str, name: str, value, choices: tuple[str, ...]) -> str:
    """Return ``value`` if it is one of ``choices``, else raise ValueError."""
    if value not in choices:
        raise ValueError(f"{owner}.{name} must be one of {list(choices)}, got {value!r}")
    return value


def set_field(obj, name: str, value) -> None:
    """Store a cleaned value on a frozen dataclass during ``__post_init__``."""
    object.__setattr__(obj, name, value)

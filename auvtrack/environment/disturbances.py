"""Deterministic external disturbances omega(t) acting on the 5-DOF AUV.

omega = [F_u, F_v, F_w, M_q, M_r] enters the kinetics as ``M nu_dot + ... = tau + omega``
(:mod:`auvtrack.vehicle.dynamics`): forces in N along the body surge, sway and heave axes and
moments in N m about the body pitch and yaw axes.

* :class:`PaperDisturbance` -- the sinusoidal disturbance of the paper's simulation study
  (Section 4): ``omega = a [3 sin(0.2 pi t + p), sin(0.2 pi t + p), cos(0.1 pi t + p),
  cos(0.2 pi t + p), sin(0.1 pi t + p) + cos(0.1 pi t + p)]``.
* :class:`Pulse` -- a constant force/moment vector on the window ``start <= t < start + duration``
  (``duration = inf`` gives a step).

The stochastic ocean current lives in :mod:`auvtrack.environment.current`.

References
----------
Paper, Section 4 (simulation study), disturbance omega(t).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from ..jit import njit_noalloc
from ..jit.vecmath import sincos4
from . import _validate as val
from .layout import KIND_PAPER, KIND_PULSE, P_AMP, P_PHASE, ROW_SIZE, U_END, U_FORCE, U_START


@dataclass(frozen=True, kw_only=True)
class PaperDisturbance:
    """The paper's Section 4 disturbance, scaled by ``amplitude`` and shifted by ``phase``.

    Parameters
    ----------
    amplitude : float
        Dimensionless scale factor, >= 0 (1 reproduces the paper).
    phase : float
        Phase offset added to every sine/cosine argument, rad (0 reproduces the paper).
    """

    KIND: ClassVar[str] = "paper"
    CODE: ClassVar[float] = KIND_PAPER
    EFFECT: ClassVar[str] = "force"
    TIME_ONLY: ClassVar[bool] = True
    TERM: ClassVar[str] = "add_paper"

    amplitude: float = 1.0
    phase: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "amplitude", val.real("paper", "amplitude", self.amplitude, lo=0.0,
                                                       rng_text="a finite real number >= 0"))
        object.__setattr__(self, "phase", val.real("paper", "phase", self.phase))

    def describe(self) -> dict:
        """JSON-serialisable description (``build_disturbance`` reads it back)."""
        return {"kind": "paper", "amplitude": self.amplitude, "phase": self.phase}

    def pack_row(self) -> np.ndarray:
        """Packed row (see :mod:`auvtrack.environment.layout`)."""
        row = np.zeros(ROW_SIZE)
        row[0], row[P_AMP], row[P_PHASE] = KIND_PAPER, self.amplitude, self.phase
        return row


@dataclass(frozen=True, kw_only=True)
class Pulse:
    """Constant force/moment ``force`` applied for ``start <= t < start + duration``.

    Parameters
    ----------
    start : float
        Switch-on time, s, >= 0.
    duration : float
        Length of the window, s, > 0; ``math.inf`` (or ``"inf"``) for a step.
    force : sequence of 5 float
        [F_u, F_v, F_w] in N and [M_q, M_r] in N m, body frame.
    """

    KIND: ClassVar[str] = "pulse"
    CODE: ClassVar[float] = KIND_PULSE
    EFFECT: ClassVar[str] = "force"
    TIME_ONLY: ClassVar[bool] = True
    TERM: ClassVar[str] = "add_pulse"

    start: float
    duration: float
    force: tuple[float, ...]

    def __post_init__(self) -> None:
        object.__setattr__(self, "start", val.real("pulse", "start", self.start, lo=0.0,
                                                   rng_text="a finite real number >= 0 (s)"))
        object.__setattr__(self, "duration", val.real(
            "pulse", "duration", self.duration, lo=0.0, lo_open=True, allow_inf=True,
            rng_text="a real number > 0 (s), or inf for a step"))
        object.__setattr__(self, "force", val.vector(
            "pulse", "force", self.force, 5, rng_text="finite numbers (N, N, N, N m, N m)"))

    def describe(self) -> dict:
        """JSON-serialisable description; an infinite duration is written as the string ``"inf"``."""
        dur = "inf" if math.isinf(self.duration) else self.duration
        return {"kind": "pulse", "start": self.start, "duration": dur, "force": list(self.force)}

    def pack_row(self) -> np.ndarray:
        """Packed row (see :mod:`auvtrack.environment.layout`)."""
        row = np.zeros(ROW_SIZE)
        row[0], row[U_START], row[U_END] = KIND_PULSE, self.start, self.start + self.duration
        row[U_FORCE:U_FORCE + 5] = self.force
        return row


@njit_noalloc
def add_paper(rows, k, t, out):
    """Add the paper's disturbance of packed row ``k`` at time ``t`` (s) to ``out`` (5,)."""
    a, p = rows[k, P_AMP], rows[k, P_PHASE]
    s, c = sincos4((0.2 * math.pi * t + p, 0.1 * math.pi * t + p, 0.0, 0.0))  # one vector call, within 4 ulp
    s2, c2, s1, c1 = s[0], c[0], s[1], c[1]
    out[0] += a * 3.0 * s2
    out[1] += a * s2
    out[2] += a * c1
    out[3] += a * c2
    out[4] += a * (s1 + c1)


@njit_noalloc
def add_pulse(rows, k, t, out):
    """Add the pulse of packed row ``k`` to ``out`` (5,) when ``start <= t < end``."""
    if rows[k, U_START] <= t < rows[k, U_END]:
        for i in range(5):
            out[i] += rows[k, U_FORCE + i]

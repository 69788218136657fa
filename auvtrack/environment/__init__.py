"""External disturbances omega(t) on the 5-DOF AUV: [F_u, F_v, F_w] in N, [M_q, M_r] in N m.

Components (frozen dataclasses, keyword construction, validated):

* :class:`PaperDisturbance` -- the paper's Section 4 sinusoids (amplitude/phase adjustable);
* :class:`Pulse` -- a constant force/moment on a time window (or a step);
* :class:`GaussMarkovCurrent` -- a first-order Gauss-Markov ocean current in NED whose force is
  ``diag(d11, d22, d33) J1^T V_c`` (damping on the relative velocity; Fossen 2021, ch. 8).

A list of components is a sum.  :func:`pack_disturbances` packs a list into arrays for the
compiled evaluator :func:`eval_disturbance`; see ``docs/environment.md``.
"""
from .current import GaussMarkovCurrent
from .disturbances import PaperDisturbance, Pulse
from .registry import DISTURBANCES, build_disturbance
from .tables import (DisturbanceTables, eval_current_velocity, eval_disturbance,
                     pack_disturbances)

__all__ = [
    "DISTURBANCES",
    "DisturbanceTables",
    "GaussMarkovCurrent",
    "PaperDisturbance",
    "Pulse",
    "build_disturbance",
    "eval_current_velocity",
    "eval_disturbance",
    "pack_disturbances",
]

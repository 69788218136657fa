"""Tuning a controller's gains for the vehicle it flies (``auvtrack tune``).

:mod:`.space` reads the search space a controller declares on its ``Params`` model
(:func:`auvtrack.control.registry.tunable`) and the set-up conditions a candidate must meet.
"""
from .space import Dimension, constraint_violations, distributions, search_space
from .study import TuneResult, tune

__all__ = ["Dimension", "TuneResult", "constraint_violations", "distributions", "search_space", "tune"]

"""Feasibility of a scenario before anything is flown: can its plant make the trims and turns its reference asks?

:func:`assess` (also ``auvtrack.feasibility``) returns a :class:`Feasibility`: a verdict
("feasible", "marginal", "infeasible") and one :class:`Check` per requirement (trim, surge, the
tightest turn on each side) with the required and available values, the margin and the limit
that binds.  ``auvtrack check`` prints it, ``auvtrack run`` warns in one line when it is not
feasible.  Method and sources: docs/vehicles.md, section "Feasibility".

Modules: :mod:`~auvtrack.feasibility.demands` (what the reference asks, over ground and
through the water in the current's worst case), :mod:`~auvtrack.feasibility.steady`
(steady states, continuation to the tightest turn), :mod:`~auvtrack.feasibility.steady5`
and :mod:`~auvtrack.feasibility.steady6` (the 5-DOF plant and the 6-DOF truths),
:mod:`~auvtrack.feasibility.assess` (the checks and the verdict).
"""
from .assess import MARGINAL_FRACTION, Check, Feasibility, assess, steady_model
from .demands import CURRENT_SIGMAS, CurrentBound, current_bound, reference_demands, water_relative
from .steady import SteadyState, TurnLimit, steady_turn, tightest_turn

__all__ = ["assess", "Feasibility", "Check", "MARGINAL_FRACTION", "CURRENT_SIGMAS", "CurrentBound",
           "current_bound", "reference_demands", "water_relative", "steady_model", "SteadyState",
           "TurnLimit", "steady_turn", "tightest_turn"]

"""auvtrack: trajectory-tracking control of underactuated AUVs.

The main entry point is :func:`simulate`, which takes a scenario (a path to a TOML file, a dict
or a :class:`~auvtrack.scenario.Scenario`) and returns a :class:`~auvtrack.simulation.Result`.
"""
from __future__ import annotations

__version__ = "0.2.0"

__all__ = ["__version__", "simulate", "load_scenario", "Result"]


def __getattr__(name):  # lazy: importing auvtrack must not compile anything
    if name == "simulate":
        from .simulation.pipeline import simulate

        return simulate
    if name == "load_scenario":
        from .scenario import load_scenario

        return load_scenario
    if name == "Result":
        from .simulation.result import Result

        return Result
    raise AttributeError(name)

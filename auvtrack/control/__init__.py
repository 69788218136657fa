"""Controllers: registry, shared tracking kinematics and the compiled laws.

Registering a built-in controller is one line: its module in :data:`BUILTIN` (checked against
:mod:`auvtrack.control.contract`).  ``policy`` (a learned law flying a trained file,
:mod:`auvtrack.control.policy`; ``policy_actuators`` for a file commanding a 6-DOF plant's actuators) and ``plugin`` are registered after them: the first enters a
comparison when named, the second is the loader of controllers from outside the package (kind ``"plugin"``).
"""
from importlib import import_module

from . import plugin
from .registry import (CONTROLLERS, CompiledController, ControllerParams, ControllerSpec, SetupContext,
                       check_controller, get, register)

BUILTIN = tuple(import_module(f"{__name__}.{name}") for name in (
    "fxtntsmc",
    "ftsmc",
    "pid",
    "backstepping",
    "sta",
    "ppc",
    "los_autopilot",
    "open_loop",
    "open_loop_actuators",
))
"""The built-in controller modules, in registry order (add one: its module name here)."""
BUILTIN_NAMES: tuple[str, ...] = tuple(m.NAME for m in BUILTIN)
"""Kinds of the built-in controllers (``plugin``, the loader of outside controllers, is not one)."""
for _module in BUILTIN:
    register(_module)
register(import_module(f"{__name__}.policy"))  # a learned law flying a trained file: not among the default competitors
register(import_module(f"{__name__}.policy_actuators"))  # the same, commanding a 6-DOF plant's actuators
register(ControllerSpec(plugin.NAME, plugin.__name__, plugin.Params, plugin.setup,
                        "a controller module from outside the package (controller.module)"))

__all__ = ["BUILTIN", "BUILTIN_NAMES", "CONTROLLERS", "CompiledController", "ControllerParams", "ControllerSpec",
           "SetupContext", "check_controller", "get", "register", "spec_for"]


def spec_for(section) -> ControllerSpec:
    """The record of the controller a validated ``[controller]`` section selects (a plug-in's own for ``"plugin"``).

    Parameters
    ----------
    section : pydantic model
        The scenario's ``[controller]``.

    Returns
    -------
    ControllerSpec
        The registered record, or the plug-in's checked record.
    """
    if section.kind == plugin.NAME:
        return plugin.spec_of(section)
    return get(section.kind)

"""Controllers: registry, shared tracking kinematics and the compiled laws.

Registering a built-in controller is one line: its module in :data:`BUILTIN`.  ``plugin`` is
registered after them: it is the loader of controllers from outside the package (kind ``"plugin"``).
"""
from . import backstepping, ftsmc, fxtntsmc, open_loop, open_loop_actuators, pid, plugin, ppc, sta
from .gain_presets import FTSMCParams, FXTNTSMCParams, OpenLoopParams
from .registry import CONTROLLERS, CompiledController, ControllerParams, ControllerSpec, get, register

BUILTIN = (
    fxtntsmc,
    ftsmc,
    pid,
    backstepping,
    sta,
    ppc,
    open_loop,
    open_loop_actuators,
)
BUILTIN_NAMES: tuple[str, ...] = tuple(m.NAME for m in BUILTIN)
"""Kinds of the built-in controllers (``plugin``, the loader of outside controllers, is not one)."""
for _module in BUILTIN:
    register(ControllerSpec.from_module(_module))
register(ControllerSpec.from_module(plugin))

__all__ = ["BUILTIN", "BUILTIN_NAMES", "CONTROLLERS", "CompiledController", "ControllerParams", "ControllerSpec", "get",
           "register", "FTSMCParams", "FXTNTSMCParams", "OpenLoopParams"]

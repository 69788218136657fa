"""Controllers: registry, shared tracking kinematics and the compiled laws.

Registering a built-in controller is one line: its module in :data:`BUILTIN`.
"""
from . import ftsmc, fxtntsmc, open_loop, open_loop_actuators
from .params import FTSMCParams, FXTNTSMCParams, OpenLoopParams
from .registry import CONTROLLERS, CompiledController, ControllerParams, ControllerSpec, get, register

BUILTIN = (
    fxtntsmc,
    ftsmc,
    open_loop,
    open_loop_actuators,
)
for _module in BUILTIN:
    register(ControllerSpec.from_module(_module))

__all__ = ["BUILTIN", "CONTROLLERS", "CompiledController", "ControllerParams", "ControllerSpec", "get",
           "register", "FTSMCParams", "FXTNTSMCParams", "OpenLoopParams"]

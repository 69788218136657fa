"""Controllers: registry, shared tracking kinematics and the compiled laws."""
from . import ftsmc, fxtntsmc, open_loop
from .params import FTSMCParams, FXTNTSMCParams, OpenLoopParams
from .registry import CONTROLLERS, CompiledController, ControllerSpec, get, register

register(ControllerSpec("ftsmc", ftsmc.CODE, FTSMCParams, ftsmc.setup,
                        "nonsingular terminal SMC baseline (ERRATA 16)"))
register(ControllerSpec("fxtntsmc", fxtntsmc.CODE, FXTNTSMCParams, fxtntsmc.setup,
                        "the paper's FXTNTSMC with flexible prescribed performance and RBF network"))
register(ControllerSpec("open_loop", open_loop.CODE, OpenLoopParams, open_loop.setup,
                        "open-loop sinusoidal input (plant checks)"))

__all__ = ["CONTROLLERS", "CompiledController", "ControllerSpec", "get", "register",
           "FTSMCParams", "FXTNTSMCParams"]

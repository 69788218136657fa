"""Plants: vehicle models (kinematics, kinetics, presets), actuators, and the registry of truth models.

Registering a plant is one line here: ``register(PlantSpec.from_module(module))``.
"""
from . import five_dof, sixdof
from .registry import PLANTS, CompiledPlant, PlantSpec, get, register

register(PlantSpec.from_module(five_dof))
register(PlantSpec.from_module(sixdof))

__all__ = ["PLANTS", "CompiledPlant", "PlantSpec", "get", "register"]

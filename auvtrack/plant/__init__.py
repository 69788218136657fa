"""Plants: vehicle models (kinematics, kinetics, presets), actuators, and the registry of truth models.

Registering a plant is one line here: ``register(PlantSpec.from_module(module))``.
"""
from . import five_dof, six_dof
from .registry import PLANTS, CompiledPlant, PlantSpec, get, register

register(PlantSpec.from_module(five_dof))
register(PlantSpec.from_module(six_dof))

__all__ = ["PLANTS", "CompiledPlant", "PlantSpec", "get", "register"]

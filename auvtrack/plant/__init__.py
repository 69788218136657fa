"""Plants: the truth models the engine integrates (the 5-DOF model, the 6-DOF REMUS 100), and plug-in plants.

Registering a plant is one line here: ``register(module)`` (checked against
:mod:`auvtrack.plant.contract`).  ``plugin`` is registered after them: it is the loader of plants
from outside the package (``plant.model = "plugin"``).
"""
from importlib import import_module

from . import plugin
from .registry import PLANTS, CompiledPlant, PlantContext, PlantSpec, check_plant, get, register

BUILTIN = tuple(import_module(f"{__name__}.{name}") for name in (
    "five_dof",
    "sixdof",
))
"""The built-in plant modules (add one: its module name here)."""
BUILTIN_NAMES: tuple[str, ...] = tuple(m.NAME for m in BUILTIN)
"""Models of the built-in plants (``plugin``, the loader of outside plants, is not one)."""
for _module in BUILTIN:
    register(_module)
register(PlantSpec(plugin.NAME, plugin.__name__, plugin.Section, plugin.setup,
                   "a plant module from outside the package (plant.module)", accepts=("tau", "actuators")))

__all__ = ["BUILTIN", "BUILTIN_NAMES", "PLANTS", "CompiledPlant", "PlantContext", "PlantSpec", "check_plant", "get", "register", "spec_for"]


def spec_for(section) -> PlantSpec:
    """The record of the plant a validated ``[plant]`` section selects (a plug-in's own for ``"plugin"``).

    Parameters
    ----------
    section : pydantic model
        The scenario's ``[plant]``.

    Returns
    -------
    PlantSpec
        The registered record, or the plug-in's checked record.
    """
    if section.model == plugin.NAME:
        return plugin.spec_of(section)
    return get(section.model)

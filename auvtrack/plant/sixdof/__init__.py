"""The 6-DOF truth plants (``plant.model = "6dof"``): REMUS 100 models the controller does not know.

``plant.preset`` selects the model: ``remus100_prestero`` (Prestero 2001, the default;
:mod:`auvtrack.plant.sixdof.plant_prestero`) or ``remus100_fossen`` (Fossen 2021 / PVS;
:mod:`auvtrack.plant.sixdof.plant_fossen`), or a Fossen-type vehicle file (a shipped one such as
``remus600``, or a path; :mod:`auvtrack.plant.sixdof.vehicle_file`), which runs on the Fossen model.  Both share the state (15: 6-DOF pose and velocity, rudder,
stern-plane and propeller states), the actuator command with the logged commanded tau, and the
logged channels (:mod:`auvtrack.plant.sixdof.layout`); :func:`setup` names the preset's module in the
:class:`CompiledPlant`, so each preset has its own compiled kernel.  The compiled functions bound
here are the default preset's (they satisfy the registry's contract check).

The controller keeps its 5-DOF design model (``[vehicle]``) and measures the 5-DOF projection of
the true state; its tau goes through the plant's control allocation (docs/vehicles.md).
"""
from __future__ import annotations

from ..registry import CompiledPlant
from .plant_prestero import (LOG_NAMES, N_CMD, N_LOG, NX, accel5, allocate, applied, attitude_cause,  # noqa: F401
                             log_extra, pose, rhs)

NAME = "6dof"
MODULES = {"remus100_prestero": "auvtrack.plant.sixdof.plant_prestero", "remus100_fossen": "auvtrack.plant.sixdof.plant_fossen"}
DIRECT_KINDS = ("open_loop_actuators",)  # controllers that command the actuators, not tau


def module_for(preset: str) -> str:
    """The plant module (kernel) of a truth: its entry of :data:`MODULES`; a vehicle file runs on ``plant_fossen``."""
    return MODULES.get(preset, MODULES["remus100_fossen"])


def setup(scenario) -> CompiledPlant:
    """Pack the 6-DOF truth of ``scenario`` (preset, actuator overrides, initial state).

    Parameters
    ----------
    scenario : auvtrack.scenario.Scenario
        Validated, with ``plant.model == "6dof"``.

    Returns
    -------
    CompiledPlant
        Packed parameters, initial state (propeller trimmed to the initial surge speed), the
        logged channel names, notes, the sourced record and the preset's module.

    Raises
    ------
    ValueError
        ``initial.nu: ...`` when the initial surge speed is beyond the propeller's reach.
    """
    from ..presets import vehicle_arrays
    from .setup import prepare_truth

    truth = prepare_truth(scenario, direct=scenario.controller.kind in DIRECT_KINDS)
    _, _, design = vehicle_arrays(scenario)
    design = {k: v for k, v in design.items() if k != "true_plant"}  # the truth is the 6-DOF preset
    design["role"] = "the controller's 5-DOF design model"
    return CompiledPlant(pp=truth.pp, x0=truth.x0, log_names=truth.log_names, notes=truth.notes,
                         resolved={**truth.resolved, "vehicle": design}, module=module_for(scenario.plant.preset))

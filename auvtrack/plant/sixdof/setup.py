"""Python side of the 6-DOF plants: packed parameters, initial state and the run record.

:func:`prepare_truth` turns a validated scenario with ``plant.model = "6dof"`` into what the
engine needs (``pp``, ``x0``, the logged channel names) and a JSON record of every number with
its source (``run.json``: ``scenario.resolved.plant``).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .layout import LOG_NAMES6
from .truth import initial_state, pack_truth, trim_rpm, truth_preset
from ...vehicle.vehicle_file import file_digest, is_vehicle_ref


@dataclass(frozen=True)
class Truth6:
    """A prepared 6-DOF truth plant.

    Attributes
    ----------
    pp : numpy.ndarray
        Packed parameters (:mod:`auvtrack.plant.sixdof.layout`).
    x0 : numpy.ndarray
        Initial state (15,).
    log_names : tuple of str
        Extra logged channels.
    notes : tuple of str
        One-line remarks for the run record (assumptions in force).
    resolved : dict
        JSON record: preset, actuator numbers, initial actuator states, every coefficient with
        unit and source.
    """

    pp: np.ndarray
    x0: np.ndarray
    log_names: tuple[str, ...]
    notes: tuple[str, ...]
    resolved: dict


def prepare_truth(section, ctx) -> Truth6:
    """Prepare the 6-DOF truth of a ``[plant]`` section at the run's initial state.

    Parameters
    ----------
    section : auvtrack.plant.sixdof.Section
        The validated section (preset, actuator overrides).
    ctx : auvtrack.plant.registry.PlantContext
        Initial state, what the controller commands, the design vehicle's preset.

    Returns
    -------
    Truth6
        Packed parameters, initial state, channel names and record.

    Raises
    ------
    ValueError
        ``initial.nu: ...`` when the initial surge speed is beyond the propeller's reach.
    """
    name = section.preset
    limits = section.actuator_limits()
    pp = pack_truth(name, section.actuator_overrides(), direct=ctx.commands == "actuators")
    e, n = ctx.eta0, ctx.nu0
    rpm0 = trim_rpm(name, pp, n[0])
    x0 = initial_state((e[0], e[1], e[2], ctx.phi0, e[3], e[4]), (n[0], n[1], n[2], ctx.p0, n[3], n[4]),
                       (0.0, 0.0, rpm0))
    pr, model = truth_preset(name)
    notes = (f"6-DOF truth {name}: the controller's design model is the 5-DOF vehicle "
             f"{ctx.design_preset!r}; it measures the 5-DOF projection (no roll)",
             f"initial propeller speed {rpm0:.6g} rpm: surge balance at u = {n[0]:g} m/s",)
    resolved = {"model": "6dof", "preset": name, "description": pr.description,
                "equations": model.__name__, "actuators": limits, "initial_rpm": rpm0,
                "coefficients": pr.record}
    if is_vehicle_ref(name):
        resolved["file"] = {"path": name, "sha256": file_digest(name)}
    return Truth6(pp=pp, x0=x0, log_names=LOG_NAMES6, notes=notes, resolved=resolved)

"""Default gains designed for the scenario's vehicle (the rule of :mod:`auvtrack.control.design`).

Applied to the raw scenario before validation, so that the validated (and resolved) scenario
holds the designed gains explicitly, as it holds a gain preset's (``run.json``,
``scenario.toml``, ``load_scenario(s.to_dict()) == s``).  Which gains a ``[controller]`` gets:

=============================================  =====================================================
section                                        gains
=============================================  =====================================================
``preset = "<name>_tuned"`` (a gain preset)    the preset's (the design is not applied)
``preset = "defaults"``                        the law's fixed defaults, whatever the vehicle
``preset = "designed"``                        designed for the vehicle (an error without a reach)
only ``kind`` (and ``saturation``)             designed when the design vehicle has a reach
                                               (``vehicle.preset = "remus100"``, a vehicle file),
                                               the law's defaults otherwise (``paper``)
any gain given                                 the given gains, the law's defaults for the rest
=============================================  =====================================================

Designed gains come with ``saturation = "compensated"`` unless the section sets ``saturation``.
Explicit keys always win over designed ones.
"""
from __future__ import annotations

from typing import Any, Mapping

from ..control import design
from ..vehicle.presets import get_preset

DEFAULTS, DESIGNED = "defaults", "designed"
"""The two ``controller.preset`` values that are not gain-preset files."""
FREE_KEYS = ("kind", "saturation")
"""Keys a ``[controller]`` section may set and still get designed gains."""


def gain_design(kind: str, vehicle: Mapping[str, Any]) -> design.GainDesign | None:
    """The rule for ``kind`` on a (raw or resolved) ``[vehicle]`` section, or None without a reach.

    Parameters
    ----------
    kind : str
        ``controller.kind``.
    vehicle : mapping
        ``preset``, ``u0`` and optional overrides ``m``, ``l``.

    Returns
    -------
    GainDesign or None
        None when the law has no design or the vehicle no reach (or the section is invalid: its
        own validator reports that).
    """
    from ..control import CONTROLLERS

    if kind not in CONTROLLERS or not design.designable(kind):
        return None
    try:
        pre = get_preset(vehicle.get("preset", "paper"), u0=vehicle.get("u0"))
    except (KeyError, ValueError, TypeError):
        return None
    if pre.reach is None:
        return None
    m = vehicle.get("m") if vehicle.get("m") is not None else pre.m
    ell = vehicle.get("l") if vehicle.get("l") is not None else pre.l
    try:
        return design.design(kind, [float(x) for x in m], float(ell), pre.reach)
    except (TypeError, ValueError, IndexError):
        return None


def designed_controller(data: Mapping[str, Any], default_kind: str) -> Mapping[str, Any]:
    """``data`` with its ``[controller]`` given the designed gains where the table above says so.

    Parameters
    ----------
    data : mapping
        The raw scenario, ``vehicle.u0`` of a reduced preset already filled in.
    default_kind : str
        The controller kind of a section without ``kind``.

    Returns
    -------
    mapping
        ``data``, or a copy with a new ``controller`` section.

    Raises
    ------
    ValueError
        ``controller.preset: ...`` for ``"designed"`` with a vehicle without a reach or a law
        without a design.
    """
    ctrl = data.get("controller")
    if not isinstance(ctrl, Mapping):
        return data
    preset = ctrl.get("preset")
    rest = {k: v for k, v in ctrl.items() if k != "preset"}
    if preset == DEFAULTS:
        return {**data, "controller": rest}
    if preset not in (None, DESIGNED) or (preset is None and set(ctrl) - set(FREE_KEYS)):
        return data
    kind = ctrl.get("kind", default_kind)
    vehicle = data.get("vehicle", {})
    found = gain_design(kind, vehicle) if isinstance(kind, str) and isinstance(vehicle, Mapping) else None
    if found is None:
        if preset == DESIGNED:
            raise ValueError(f"controller.preset: \"designed\" needs a law with a design ({', '.join(design.designable_kinds())}) "
                             f"and a design vehicle with a known actuator reach (vehicle.preset = \"remus100\" or a vehicle "
                             f"file) (got kind {kind!r}, vehicle.preset {vehicle.get('preset', 'paper')!r})")
        return {**data, "controller": rest} if preset is not None else data
    return {**data, "controller": {**found.gains, **rest}}


def design_record(scenario) -> dict:
    """``{"gain_design": ...}`` for ``run.json``: the rule's numbers for the scenario's law and vehicle.

    Parameters
    ----------
    scenario : auvtrack.scenario.Scenario
        A validated scenario.

    Returns
    -------
    dict
        Empty when the law has no design or the vehicle no reach; otherwise the design
        (:meth:`auvtrack.control.design.GainDesign.record`) and ``applied``: whether the run's
        gains are the designed ones.
    """
    veh = scenario.vehicle
    found = gain_design(scenario.controller.kind, {"preset": veh.preset, "u0": getattr(veh, "u0", None),
                                                   "m": veh.m, "l": veh.l})
    if found is None:
        return {}
    applied = all(getattr(scenario.controller, k, None) == v for k, v in found.gains.items())
    return {"gain_design": {**found.record(), "applied": applied}}

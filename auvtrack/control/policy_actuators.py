"""The ``policy`` law commanding the actuators of a 6-DOF plant: u = (rpm, stern plane, rudder).

The same network, observation and file as :mod:`auvtrack.control.policy`; the file's header says
``"commands": "actuators"`` and its ``scale`` is the plant's actuator limits (what
``auvtrack train --action actuators`` and the environment's ``action="actuators"`` use).  The
plant's allocation passes the commands through, with its limits and lags.
"""
from __future__ import annotations

from typing import Literal

from pydantic import Field

from .policy import AUX_NAMES, DEFAULT_ACTUATOR_POLICY, ControllerParams, control, setup  # noqa: F401

__all__ = ["NAME", "COMMANDS", "AUX_NAMES", "Params", "control", "setup"]

NAME = "policy_actuators"
COMMANDS = "actuators"


class Params(ControllerParams):
    """A policy file whose header commands the actuators (:func:`auvtrack.control.policy.save_policy`)."""

    kind: Literal["policy_actuators"] = "policy_actuators"
    file: str = Field(DEFAULT_ACTUATOR_POLICY, min_length=1,
                      description="a shipped policy's name (auvtrack/data/policies) or a .npz file commanding "
                                  "(rpm, stern plane, rudder)")

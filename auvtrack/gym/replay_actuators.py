"""The replay law (:mod:`auvtrack.gym.replay`) commanding the actuators of a 6-DOF plant (rpm, stern plane, rudder)."""
from __future__ import annotations

from .replay import AUX_NAMES, GAINS, TRACKS, Params, control, setup  # noqa: F401

NAME = "replay_actuators"
COMMANDS = "actuators"

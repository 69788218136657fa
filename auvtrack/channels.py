"""The logged row: which channel sits in which column of a run's log, declared once.

Every run logs :data:`BASE_CHANNELS` (SI units: s, m, rad, m/s, rad/s, N, N m), then the
controller's own channels (its ``AUX_NAMES``), then :data:`CHI_CHANNELS` (the lumped disturbance
chi of eq. 5 on the nominal model, m/s^2), then the plant's extra channels (its ``LOG_NAMES``).
The engine writes the base part at the offsets of :data:`LOG_ROW`.
"""
from __future__ import annotations

from typing import Sequence

from .packing import packed_layout

_BASE = (("t", ("t",)),
         ("eta", ("x", "y", "z", "theta", "psi")),
         ("nu", ("u", "v", "w", "q", "r")),
         ("tau", ("tau_u", "tau_q", "tau_r")),
         ("eta_d", ("xd", "yd", "zd")),
         ("e", ("ex", "ey", "ez")))

LOG_ROW = packed_layout("LogRow", **{field: len(names) for field, names in _BASE})
"""Column offsets of the base channels: time, eta, nu, applied tau, the reference eta_d, the error e."""
BASE_CHANNELS: tuple[str, ...] = tuple(n for _, names in _BASE for n in names)
"""Channels every result starts with, in column order."""
CHI_CHANNELS: tuple[str, ...] = ("chi_x", "chi_y", "chi_z")
"""The lumped disturbance chi of eq. (5), logged after the controller's channels."""


def channel_names(aux: Sequence[str], plant_log: Sequence[str]) -> tuple[str, ...]:
    """Every column name of a run's log, in order.

    Parameters
    ----------
    aux : sequence of str
        The controller's channels.
    plant_log : sequence of str
        The plant's extra channels.

    Returns
    -------
    tuple of str
        :data:`BASE_CHANNELS`, ``aux``, :data:`CHI_CHANNELS`, ``plant_log``.
    """
    return BASE_CHANNELS + tuple(aux) + CHI_CHANNELS + tuple(plant_log)

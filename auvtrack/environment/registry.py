"""Registry of disturbance kinds and construction from plain dicts (scenario files, JSON).

``build_disturbance({"kind": "pulse", "start": 10, "duration": 5, "force": [5, 0, 0, 0, 0]})``;
``build_disturbance(c.describe()) == c`` for every component ``c``.
"""
from __future__ import annotations

from dataclasses import fields

from .current import GaussMarkovCurrent
from .disturbances import PaperDisturbance, Pulse

DISTURBANCES: dict[str, type] = {
    "paper": PaperDisturbance,
    "pulse": Pulse,
    "current": GaussMarkovCurrent,
}


def build_disturbance(spec: dict):
    """Build a component from ``spec`` = ``{"kind": ..., **fields}``.

    Parameters
    ----------
    spec : dict
        ``kind`` is one of :data:`DISTURBANCES`; the other keys are that class's fields.  The
        key ``stream`` (written by ``DisturbanceTables.describe``) is ignored.

    Returns
    -------
    PaperDisturbance, Pulse or GaussMarkovCurrent
        The validated component.

    Raises
    ------
    ValueError
        Unknown kind, unknown or missing fields, or an invalid value.
    """
    spec = dict(spec)
    kind = spec.pop("kind", None)
    spec.pop("stream", None)
    if kind not in DISTURBANCES:
        raise ValueError(f"disturbance kind must be one of {sorted(DISTURBANCES)}, got {kind!r}")
    cls = DISTURBANCES[kind]
    names = {f.name for f in fields(cls)}
    unknown = sorted(set(spec) - names)
    if unknown:
        raise ValueError(f"unknown field(s) {unknown} for disturbance {kind!r}; allowed: {sorted(names)}")
    try:
        return cls(**spec)
    except TypeError as exc:  # missing required field
        raise ValueError(f"disturbance {kind!r}: {exc}") from None

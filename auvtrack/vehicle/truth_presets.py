"""6-DOF truth-model presets: coefficient tables stored as data, each number with unit and source.

Files live in ``auvtrack/data/vehicles/6dof/<name>.toml``: sections of entries
``key = { value = ..., unit = "...", source = "...", note = "..." }`` (``note`` optional).
:func:`load_preset6` returns the values by ``"section.key"`` together with the full record, which
goes into ``run.json`` so every number of a run can be traced to its source.  Shipped:

* ``remus100_prestero`` -- Prestero (2001), :mod:`auvtrack.plant.sixdof.prestero`;
* ``remus100_fossen`` -- Fossen (2021) / PVS ``remus100.py``, :mod:`auvtrack.plant.sixdof.fossen`.

The same folder holds Fossen-type *vehicle files* (:data:`SHIPPED_FILES6`, checked by
:mod:`auvtrack.plant.sixdof.vehicle_file`), which run on the Fossen model.
"""
from __future__ import annotations

import copy
import functools
import math
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass
from importlib import resources
from types import MappingProxyType

SHIPPED6: tuple[str, ...] = ("remus100_prestero", "remus100_fossen")
SHIPPED_FILES6: tuple[str, ...] = ("remus600",)  # Fossen-type vehicle files of other vehicles


@dataclass(frozen=True)
class Preset6:
    """A 6-DOF preset's numbers.

    Attributes
    ----------
    name, description : str
        Identifier and one-line description.
    values : dict
        ``"section.key" -> float`` (or tuple of float for vectors).
    record : dict
        The file's content: per section, per key, ``{value, unit, source[, note]}``.
    """

    name: str
    description: str
    values: dict
    record: dict

    def __getitem__(self, key: str):
        return self.values[key]


def available6() -> list[str]:
    """Names of the 6-DOF presets shipped with the package."""
    root = resources.files("auvtrack") / "data" / "vehicles" / "6dof"
    return sorted(p.name[:-5] for p in root.iterdir() if p.name.endswith(".toml"))


@functools.lru_cache(maxsize=None)
def _parsed(name: str) -> dict:
    path = resources.files("auvtrack") / "data" / "vehicles" / "6dof" / f"{name}.toml"
    return tomllib.loads(path.read_text())


def _number(section: str, key: str, v):
    if isinstance(v, list):
        return tuple(_number(section, key, x) for x in v)
    if isinstance(v, bool) or not isinstance(v, (int, float)) or math.isnan(v):
        raise ValueError(f"preset {section}.{key}: value must be a number (got {v!r})")
    return float(v)


def load_preset6(name: str) -> Preset6:
    """Load and check a 6-DOF preset.

    Parameters
    ----------
    name : str
        ``"remus100_prestero"`` or ``"remus100_fossen"``.

    Returns
    -------
    Preset6
        Values and the sourced record.

    Raises
    ------
    KeyError
        Unknown preset (the message names the available ones).
    ValueError
        An entry without value, unit or source, or a non-numeric value.
    """
    if name not in available6():
        raise KeyError(f"unknown 6-DOF preset {name!r}; choose one of {available6()}")
    raw = copy.deepcopy(_parsed(name))
    values, record = {}, {}
    for section, entries in raw.items():
        if not isinstance(entries, dict):
            continue
        record[section] = entries
        for key, e in entries.items():
            for field in ("value", "unit", "source"):
                if field not in e or (field != "value" and not str(e[field]).strip()):
                    raise ValueError(f"preset {name}: {section}.{key} has no {field}")
            values[f"{section}.{key}"] = _number(section, key, e["value"])
    return Preset6(name=raw["name"], description=raw.get("description", ""), values=values,
                   record=record)


@functools.lru_cache(maxsize=None)
def preset6_values(name: str) -> Mapping[str, float | tuple[float, ...]]:
    """The checked values of a 6-DOF preset, read once per process (read-only).

    Parameters
    ----------
    name : str
        ``"remus100_prestero"`` or ``"remus100_fossen"``.

    Returns
    -------
    Mapping
        :func:`load_preset6` ``(name).values`` (numbers and tuples of numbers), not to be modified.
    """
    return MappingProxyType(load_preset6(name).values)

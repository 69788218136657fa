"""Gain presets: controller gains stored as data, each with its provenance.

A preset is ``auvtrack/data/gains/<name>.toml``: the controller ``kind``, a ``[gains]`` table of
its ``[controller]`` keys, a description and how the gains were produced.  ``controller.preset``
in a scenario expands a preset into those keys.  A key holds a number (read as a float), a
string or boolean (e.g. ``saturation = "compensated"``), a list of numbers (a vector field) or,
for a plug-in, a table (its ``params``): a preset states every field of the controller it
reproduces, not only the numeric gains.
"""
from __future__ import annotations

import tomllib
from dataclasses import dataclass
from importlib import resources

__all__ = ["GainPreset", "available_gain_presets", "get_gain_preset"]

# --------------------------------------------------------------------------- gain presets

@dataclass(frozen=True)
class GainPreset:
    """Controller gains stored as data in ``auvtrack/data/gains/<name>.toml``.

    Attributes
    ----------
    name : str
        Preset name (the file name without ``.toml``).
    kind : str
        Controller kind the gains belong to (``"ftsmc"`` or ``"fxtntsmc"``).
    description : str
        One line: where the gains come from.
    gains : dict
        Scenario keys of ``[controller]`` and their values (numbers as floats).
    provenance : dict
        How the gains were produced (study, optimiser, seed, budget, objective values).
    """

    name: str
    kind: str
    description: str
    gains: dict
    provenance: dict


def _gains_root():
    return resources.files("auvtrack") / "data" / "gains"


def available_gain_presets() -> list[str]:
    """Names of the gain presets shipped with the package.

    Returns
    -------
    list of str
        Sorted file names of ``auvtrack/data/gains/*.toml`` without the suffix.
    """
    root = _gains_root()
    if not root.is_dir():
        return []
    return sorted(p.name[:-5] for p in root.iterdir() if p.name.endswith(".toml"))


def get_gain_preset(name: str) -> GainPreset:
    """Load gain preset ``name``.

    Parameters
    ----------
    name : str
        One of :func:`available_gain_presets`.

    Returns
    -------
    GainPreset
        Kind, gains and provenance of the preset.

    Raises
    ------
    KeyError
        Unknown name (the message lists the available presets).
    ValueError
        A malformed preset file (missing ``kind`` or ``[gains]``, or a value that is not a
        number, string, boolean, list of numbers or table of those).
    """
    names = available_gain_presets()
    if name not in names:
        raise KeyError(f"unknown gain preset {name!r}; choose one of {names}")
    raw = tomllib.loads((_gains_root() / f"{name}.toml").read_text())
    kind, gains = raw.get("kind"), raw.get("gains")
    if not isinstance(kind, str) or not isinstance(gains, dict):
        raise ValueError(f"gain preset {name!r}: needs a string 'kind' and a [gains] table")
    gains = {k: _preset_value(f"gain preset {name!r}: gains.{k}", v) for k, v in gains.items()}
    return GainPreset(name=name, kind=kind, description=str(raw.get("description", "")),
                      gains=gains,
                      provenance=dict(raw.get("provenance", {})))


def _preset_value(where: str, v, nested: bool = True):
    """A ``[gains]`` value as the scenario reads it: numbers as floats, strings, booleans, lists, tables."""
    if isinstance(v, bool) or isinstance(v, str):
        return v
    if isinstance(v, (int, float)):
        return float(v)
    if isinstance(v, list) and all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in v):
        return [float(x) for x in v]
    if isinstance(v, dict) and nested:
        return {k: _preset_value(f"{where}.{k}", x, nested=False) for k, x in v.items()}
    raise ValueError(f"{where} must be a number, string, boolean, list of numbers or (plug-in params) a table "
                     f"of those (got {v!r})")

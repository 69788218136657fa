"""Gain presets: controller gains stored as data, each with its provenance.

A preset is ``auvtrack/data/gains/<name>.toml``: the controller ``kind``, a ``[gains]`` table of
its ``[controller]`` keys, a description and how the gains were produced.  ``controller.preset``
in a scenario expands a preset into those keys.
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
    gains : dict of str to float
        Scenario keys of ``[controller]`` and their values.
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
        A malformed preset file (missing ``kind`` or ``[gains]``, or a gain that is not a number).
    """
    names = available_gain_presets()
    if name not in names:
        raise KeyError(f"unknown gain preset {name!r}; choose one of {names}")
    raw = tomllib.loads((_gains_root() / f"{name}.toml").read_text())
    kind, gains = raw.get("kind"), raw.get("gains")
    if not isinstance(kind, str) or not isinstance(gains, dict):
        raise ValueError(f"gain preset {name!r}: needs a string 'kind' and a [gains] table")
    for k, v in gains.items():
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise ValueError(f"gain preset {name!r}: gains.{k} must be a number (got {v!r})")
    return GainPreset(name=name, kind=kind, description=str(raw.get("description", "")),
                      gains={k: float(v) for k, v in gains.items()},
                      provenance=dict(raw.get("provenance", {})))

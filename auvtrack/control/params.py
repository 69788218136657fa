"""Pydantic parameter models of the registered controllers (the ``[controller]`` section).

Kept apart from the compiled code so that loading and validating a scenario never compiles.
Field names are the stable scenario keys; ranges here are the *basic* admissibility ranges.
Theorem 1's stricter conditions are checked by :mod:`auvtrack.control.theory`.
"""
from __future__ import annotations

import tomllib
from dataclasses import dataclass
from importlib import resources
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field


class _Params(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class FTSMCParams(_Params):
    """Nonsingular terminal SMC baseline (ERRATA 16).

    ``s = e + beta * sig^gamma(e_dot)`` with ``gamma = p/q`` in (1, 2); reaching law
    ``e_ddot = -(1/(beta*gamma)) sig^(2-gamma)(e_dot) - k1 sign(s) - k2 s``.
    The defaults are hand-picked gains that predate the recorded tuning procedure; the gains
    found by that procedure are the gain preset ``ftsmc_tuned`` (scenario key
    ``controller.preset``, expanded into these fields when the scenario is loaded), see
    ``docs/tuning.md`` for how the two compare.
    """

    kind: Literal["ftsmc"] = "ftsmc"
    beta: float = Field(1.0, gt=0, description="weight of the terminal term, s^gamma")
    gamma: float = Field(1.5, gt=1, lt=2, description="terminal exponent p/q, in (1, 2)")
    k1: float = Field(0.05, ge=0, description="switching gain, m/s^2")
    k2: float = Field(1.0, ge=0, description="linear reaching gain, 1/s")


class OpenLoopParams(_Params):
    """Open-loop input tau(t) = tau0 + amplitude sin(2 pi frequency t) (plant checks, order tests)."""

    kind: Literal["open_loop"] = "open_loop"
    tau0: tuple[float, float, float] = (0.0, 0.0, 0.0)
    amplitude: tuple[float, float, float] = (0.0, 0.0, 0.0)
    frequency: tuple[float, float, float] = Field((0.0, 0.0, 0.0), description="Hz")


class FXTNTSMCParams(_Params):
    """Fixed-time nonsingular terminal SMC of the paper (eq. 26-32, corrected per ERRATA 11-13).

    Names follow the paper: ``a3 = b1`` and ``a4 = b2`` (ERRATA 11); ``varsigma1`` is the
    approximation-error bound written "zeta1 = 0.05" in Section 4.
    """

    kind: Literal["fxtntsmc"] = "fxtntsmc"
    kappa1: float = Field(0.005, gt=0, description="switching gain")
    kappa2: float = Field(0.8, gt=0, description="cubic reaching gain")
    kappa3: float = Field(0.6, gt=0, description="linear reaching gain")
    a1: float = Field(0.8, gt=0)
    a2: float = Field(0.8, gt=0, lt=1, description="fractional power, 0.5 <= a2 < 1 in Theorem 1")
    a3: float = Field(0.8, gt=0, description="b1 of Theorem 1")
    a4: float = Field(2.0, gt=1, description="b2 of Theorem 1")
    alpha: float = Field(0.6, gt=0)
    sigma: float = Field(0.005, gt=0, description="switch threshold of eq. (27)")
    varsigma1: float = Field(0.05, gt=0, description="RBF approximation-error bound (Theorem 1)")
    surface: Literal["nonsingular", "printed"] = Field(
        "nonsingular",
        description="'nonsingular': C1 switch on |z| replaces sig^a2 near 0 (ERRATA 12); "
        "'printed': eq. (28) as printed, with |z| floored at z_floor",
    )
    z_switch: float = Field(0.01, gt=0, description="|z| below which the nonsingular switch is used")
    z_floor: float = Field(1e-6, gt=0, description="floor on |z| in the printed form's |z|^(a2-1)")


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

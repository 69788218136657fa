"""``[plant]`` of the 6-DOF truth plants: the preset and its actuator overrides, validated."""
from __future__ import annotations

import math
from typing import Annotated, Any, Literal, Mapping

from pydantic import Field, field_validator, model_validator

from ...fields import Num, Pos, PosOrInf, Str, format_value, inf_words
from ...vehicle.truth_presets import available6
from ...vehicle.vehicle_file import is_vehicle_ref, resolve_path
from ..registry import PlantSection
from .truth import ACTUATOR_KEYS, actuator_values, truth_preset

DEFAULT_PRESET = "remus100_prestero"


class Section(PlantSection):
    """``[plant]`` with ``model = "6dof"``: a truth preset with fins, propeller and actuator states.

    The controller does not know it (it keeps ``[vehicle]`` as its design model).  The actuator
    keys override the preset's.
    """

    model: Literal["6dof"] = "6dof"
    preset: Str = Field(DEFAULT_PRESET, description="6-DOF preset: remus100_prestero (default), remus100_fossen, "
                                                     "remus600, or a Fossen-type vehicle file (.toml)")
    delta_max: Annotated[Num, Field(gt=0, le=math.pi / 2)] | None = Field(None, description="fin angle limit, rad")
    n_max: Pos | None = Field(None, description="propeller speed limit, rpm")
    T_delta: Pos | None = Field(None, description="fin time constant, s")
    T_n: Pos | None = Field(None, description="propeller time constant, s")
    delta_rate_max: PosOrInf | None = Field(None, description="fin rate limit, rad/s (inf = none)")
    n_rate_max: PosOrInf | None = Field(None, description="propeller rate limit, rpm/s (inf = none)")

    @field_validator("delta_rate_max", "n_rate_max", mode="before")
    @classmethod
    def _word(cls, v: Any) -> Any:
        return inf_words([v])[0] if isinstance(v, str) else v

    @model_validator(mode="before")
    @classmethod
    def _default_preset(cls, data: Any) -> Any:
        if isinstance(data, Mapping) and data.get("preset") is None:
            return {**data, "preset": DEFAULT_PRESET}
        if isinstance(data, Mapping) and is_vehicle_ref(data.get("preset")):  # relative to the working directory
            return {**data, "preset": resolve_path(data["preset"])}
        return data

    @model_validator(mode="after")
    def _preset(self) -> "Section":
        names = available6()
        if self.preset not in names and not is_vehicle_ref(self.preset):
            raise ValueError(f"preset: unknown 6-DOF preset (allowed: {', '.join(names)} or a vehicle file .toml) "
                             f"(got {self.preset!r})")
        try:
            pr = truth_preset(self.preset)[0]
        except ValueError as exc:  # a vehicle file: "<file>: <section.key>: ..."
            raise ValueError(f"preset: {exc}") from None
        try:
            actuator_values(pr, self.actuator_overrides())
        except ValueError as exc:  # "plant.<key>: ..." -> "<key>: ..."
            raise ValueError(str(exc).removeprefix("plant.")) from None
        return self

    def actuator_overrides(self) -> dict[str, float]:
        """The actuator keys given: name -> value."""
        return {k: getattr(self, k) for k in ACTUATOR_KEYS if getattr(self, k) is not None}

    def actuator_limits(self) -> dict[str, float]:
        """Effective actuator numbers (the preset's with the overrides)."""
        return actuator_values(truth_preset(self.preset)[0], self.actuator_overrides())


def check_scenario(scenario) -> None:
    """Refuse the options that act on the 5-DOF plant only.

    Parameters
    ----------
    scenario : auvtrack.scenario.Scenario
        The scenario being validated.

    Raises
    ------
    ValueError
        ``uncertainty.<k>: ...`` or ``actuator.<k>: ...``.
    """
    default = type(scenario.uncertainty)()  # the section's defaults
    for k in ("C", "D", "M", "G"):
        if getattr(scenario.uncertainty, k) != getattr(default, k):
            raise ValueError(f"uncertainty.{k}: scales the 5-DOF plant only; with plant.model = \"6dof\" "
                             f"the truth is the preset {scenario.plant.preset!r} "
                             f"(got {format_value(getattr(scenario.uncertainty, k))})")
    for k in ("tau_max", "rate_max"):
        v = getattr(scenario.actuator, k)
        if any(math.isfinite(x) for x in v):
            raise ValueError(f"actuator.{k}: limits the 5-DOF input only; with plant.model = \"6dof\" the fins "
                             f"and propeller limit it (plant.delta_max, plant.n_max, ...) (got {format_value(v)})")

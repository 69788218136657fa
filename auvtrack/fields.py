"""Validated field types and messages shared by every section of a scenario, a suite or a plug-in.

Numbers are strict: a quoted ``"0.1"`` is not a number and ``true`` is not 1; finite unless the
type says otherwise.  :func:`format_value` renders a user's value for the ``(got ...)`` of a
one-line error.
"""
from __future__ import annotations

import math
from typing import Annotated, Any

from pydantic import AllowInfNan, BaseModel, ConfigDict, Field, Strict

_MAX_VALUE_CHARS = 48


class Section(BaseModel):
    """Base of every section model: frozen, unknown keys refused."""

    model_config = ConfigDict(extra="forbid", frozen=True)


# --- strict scalar types ------------------------------------------------------------------------
Num = Annotated[float, Strict(), AllowInfNan(False)]  # finite; int accepted, str/bool refused
Pos = Annotated[Num, Field(gt=0)]
NonNeg = Annotated[Num, Field(ge=0)]
Int = Annotated[int, Strict()]
Bool = Annotated[bool, Strict()]
Str = Annotated[str, Strict()]
Vec3 = tuple[Num, Num, Num]
Vec5 = tuple[Num, Num, Num, Num, Num]
Pos3 = tuple[Pos, Pos, Pos]
Pos5 = tuple[Pos, Pos, Pos, Pos, Pos]
NonNeg5 = tuple[NonNeg, NonNeg, NonNeg, NonNeg, NonNeg]
Range2 = tuple[Num, Num]
Fraction = Annotated[Num, Field(ge=-0.9, le=2.0)]
# physically meaningful vehicle numbers (a 1 kg model to a 10 000 t submarine; docs/scenarios.md)
Mass = Annotated[Num, Field(ge=1e-3, le=1e7)]
Coefficient = Annotated[Num, Field(ge=0, le=1e7)]
Mass5 = tuple[Mass, Mass, Mass, Mass, Mass]
Coefficient5 = tuple[Coefficient, Coefficient, Coefficient, Coefficient, Coefficient]
Open01 = Annotated[Num, Field(gt=0, lt=1)]


def inf_words(value: Any) -> Any:
    """Accept ``"inf"`` (as written by a resolved scenario) for an unlimited actuator."""
    if isinstance(value, (list, tuple)):
        return [math.inf if isinstance(x, str) and x.strip().lower() in ("inf", "+inf") else x for x in value]
    return value


PosOrInf = Annotated[float, Strict(), Field(gt=0)]  # +inf allowed (no limit); NaN refused by gt
PosOrInf3 = tuple[PosOrInf, PosOrInf, PosOrInf]


def one_line(text: str) -> str:
    """Collapse all whitespace (newlines included) of ``text`` to single spaces."""
    return " ".join(str(text).split())


def format_value(value: Any) -> str:
    """Short TOML-like rendering of a user value for ``(got ...)``."""
    if isinstance(value, bool):
        s = "true" if value else "false"
    elif isinstance(value, float) and not math.isfinite(value):
        s = "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf")
    elif isinstance(value, dict):
        s = "a table {" + ", ".join(f"{k} = {format_value(v)}" for k, v in value.items()) + "}"
    elif isinstance(value, (list, tuple)):
        s = "[" + ", ".join(format_value(v) for v in value) + "]"
    else:
        s = repr(value)
    return one_line(s if len(s) <= _MAX_VALUE_CHARS else s[: _MAX_VALUE_CHARS - 3] + "...")

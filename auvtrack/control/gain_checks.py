"""One-line gain-condition errors shared by the controllers' ``setup`` functions.

A controller's ``setup`` checks the conditions its stability argument needs (Routh-Hurwitz,
Levant's or Moreno-Osorio's inequalities, a start inside the envelope) and raises
``ValueError("controller.<field>: <what is wrong> (got <value>)")``: the CLI prints that line
with exit code 2, and ``auvtrack check`` refuses exactly the same scenarios.
"""
from __future__ import annotations

from typing import Any


def fmt(value: Any) -> str:
    """A number, or a sequence of numbers, written with 6 significant digits."""
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(fmt(v) for v in value) + "]"
    if isinstance(value, float):
        return f"{value:.6g}"
    return repr(value)


def require(ok: bool, field: str, what: str, got: Any) -> None:
    """Raise ``ValueError("controller.<field>: <what> (got <got>)")`` unless ``ok``.

    Parameters
    ----------
    ok : bool
        The condition holds.
    field : str
        The offending ``[controller]`` key.
    what : str
        What the key must satisfy, with the bound written out.
    got : Any
        The offending value.

    Raises
    ------
    ValueError
        If ``ok`` is false.
    """
    if not ok:
        raise ValueError(f"controller.{field}: {what} (got {fmt(got)})")

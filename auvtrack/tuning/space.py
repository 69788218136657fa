"""The search space of a controller: the gains its ``Params`` model declares tunable, and its constraints.

A gain is tunable when its field was made by :func:`auvtrack.control.registry.tunable`: the range
searched and the scale are stored in the field's ``json_schema_extra["tune"]``.  A vector field
(a tuple default, e.g. the PPC's ``rho_inf``) is searched as one scalar shared by its items, or
with ``per_item`` as one scalar per item (dimensions ``name[0]``, ``name[1]``...);
:func:`field_values` turns a candidate's searched values back into field values.  Built-ins and
plug-ins declare it the same way, in the controller's own module; :func:`search_space` is the
only reader.  The conditions a controller checks at set-up (Theorem 1 for the FXTNTSMC through
its ``warnings``, the STA's Levant / Moreno-Osorio inequalities, the PID's Routh-Hurwitz bound,
the PPC's start inside its envelope) are constraints of the search: :func:`constraint_violations`
returns them, and the tuner counts a candidate that breaks one as a failed trial.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping

from pydantic import BaseModel

__all__ = ["Dimension", "search_space", "distributions", "field_values", "searched_fields", "constraint_violations"]


@dataclass(frozen=True)
class Dimension:
    """One searched scalar: a tunable gain, or the items of a vector gain (shared or one of them).

    Attributes
    ----------
    name : str
        The dimension's name: the ``Params`` field, or ``field[i]`` for one item of a vector.
    low, high : float
        The range searched (inclusive).
    log : bool
        Searched on a logarithmic scale.
    default : float
        The field's default (a vector's: the mean of its items when shared, the item's otherwise).
    field : str
        The ``Params`` field set (``name`` when empty).
    size : int
        Items of a vector field (0: a scalar field).
    item : int or None
        The item this dimension sets (None: a scalar, or every item of a shared vector).
    """

    name: str
    low: float
    high: float
    log: bool
    default: float
    field: str = ""
    size: int = 0
    item: int | None = None

    @property
    def target(self) -> str:
        """The ``Params`` field this dimension sets."""
        return self.field or self.name

    def contains(self, value: float) -> bool:
        """Whether ``value`` lies in [low, high]."""
        return self.low <= value <= self.high


def search_space(params: type[BaseModel]) -> dict[str, Dimension]:
    """The tunable gains a ``Params`` model declares, in field order.

    Parameters
    ----------
    params : type
        A controller's pydantic ``Params`` model (built-in or plug-in).

    Returns
    -------
    dict of str to Dimension
        Field name -> its search range and scale; empty when nothing is declared tunable.

    Raises
    ------
    ValueError
        A declared range that is empty, not finite, or on a log scale with ``low <= 0``.
    """
    space = {}
    for name, info in params.model_fields.items():
        extra = info.json_schema_extra if isinstance(info.json_schema_extra, Mapping) else {}
        tune = extra.get("tune")
        if tune is None:
            continue
        low, high, log = float(tune["low"]), float(tune["high"]), bool(tune["log"])
        if not (math.isfinite(low) and math.isfinite(high) and low < high) or (log and low <= 0):
            raise ValueError(f"{params.__module__}.Params.{name}: tunable range [{low}, {high}] "
                             f"(log={log}) is not a valid search range")
        default = info.default
        if not isinstance(default, (tuple, list)):
            space[name] = Dimension(name, low, high, log, float(default))
        elif tune.get("per_item"):
            for i, v in enumerate(default):
                space[f"{name}[{i}]"] = Dimension(f"{name}[{i}]", low, high, log, float(v), name, len(default), i)
        else:
            space[name] = Dimension(name, low, high, log, math.fsum(default) / len(default), name, len(default))
    return space


def searched_fields(space: Mapping[str, Dimension]) -> set[str]:
    """The ``Params`` fields a search space sets.

    Parameters
    ----------
    space : mapping of str to Dimension
        From :func:`search_space`.

    Returns
    -------
    set of str
        Field names (a vector field once, whether shared or per item).
    """
    return {d.target for d in space.values()}


def field_values(space: Mapping[str, Dimension], values: Mapping[str, float]) -> dict[str, Any]:
    """The ``Params`` field values of a candidate's searched values.

    Parameters
    ----------
    space : mapping of str to Dimension
        From :func:`search_space`.
    values : mapping of str to float
        Dimension name -> value (an Optuna trial's ``params``).

    Returns
    -------
    dict
        Field -> a float, or a list of floats for a vector field (a shared value repeated on
        every item).

    Raises
    ------
    KeyError
        A dimension of the space without a value.
    """
    out: dict[str, Any] = {}
    for name, d in space.items():
        v = float(values[name])
        if d.size == 0:
            out[name] = v
        elif d.item is None:
            out[d.target] = [v] * d.size
        else:
            out.setdefault(d.target, [math.nan] * d.size)[d.item] = v
    return out


def distributions(space: Mapping[str, Dimension]) -> dict[str, Any]:
    """Optuna's distributions for a search space.

    Parameters
    ----------
    space : mapping of str to Dimension
        From :func:`search_space`.

    Returns
    -------
    dict of str to optuna.distributions.FloatDistribution
        One per gain, with its range and log flag.
    """
    from optuna.distributions import FloatDistribution

    return {k: FloatDistribution(d.low, d.high, log=d.log) for k, d in space.items()}


def constraint_violations(scenario) -> list[str]:
    """The set-up conditions a scenario's controller gains break (empty: the candidate is admissible).

    The controller's ``warnings`` (the FXTNTSMC's Theorem 1) and the conditions its ``setup``
    enforces, through the same :func:`auvtrack.simulation.pipeline.prepare` every run uses.

    Parameters
    ----------
    scenario : Scenario
        A validated scenario holding the candidate gains.

    Returns
    -------
    list of str
        One line per broken condition.
    """
    from ..control import spec_for as controller_spec_for
    from ..simulation.pipeline import prepare

    section = scenario.controller
    spec = controller_spec_for(section)
    problems = []
    if spec.warnings is not None and isinstance(section, spec.params):
        problems += list(spec.warnings(section))
    try:
        prepare(scenario)
    except ValueError as exc:
        problems.append(str(exc))
    return problems

"""Validation of the ``[reference]`` and ``[[disturbance]]`` tables through their own modules.

The reference and disturbance modules are the single source of their kinds, fields and ranges:
this module only calls ``build_reference`` / ``build_disturbance``, rewrites their error
messages into the ``field: text (got value)`` form of :mod:`auvtrack.scenario.errors`, and
returns the fully resolved spec (every default filled, JSON-serialisable).
"""
from __future__ import annotations

import dataclasses
import importlib
import math
import re
from typing import Any, Callable, Mapping

from .errors import format_value, one_line

__all__ = ["check_reference", "check_disturbances", "jsonable"]

DEFAULT_REFERENCE_KIND = "helix"

_UNKNOWN = re.compile(r"unknown (?:field|key)\(?s?\)? \[?'?(\w+)'?.*?(?:allowed: \[?([^\]]*)\]?)?$")
_UNEXPECTED = re.compile(r"unexpected keyword argument '(\w+)'")
_MISSING = re.compile(r"missing \d+ required (?:keyword-only |positional )?arguments?: '(\w+)'")
_KIND = re.compile(r"^(?:\w+ )?kind (must .*|is .*|should .*)$")
_FIELD = re.compile(r"^(?:\w+\.)?([A-Za-z_]\w*)(?::\s+| (?=must |should |is |has ))(.*)$")
_GOT = re.compile(r"^(.*?),? got (.+)$")


def jsonable(value: Any) -> Any:
    """Convert tuples, numpy scalars/arrays and non-finite floats to plain JSON-able values.

    ``inf``/``-inf``/``nan`` become the strings ``"inf"``, ``"-inf"``, ``"nan"``.
    """
    if isinstance(value, Mapping):
        return {str(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [jsonable(v) for v in value]
    if hasattr(value, "tolist") and not isinstance(value, (str, bytes)):  # numpy
        return jsonable(value.tolist())
    if isinstance(value, float) and not math.isfinite(value):
        return "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf")
    return value


def _builder(module: str, name: str) -> Callable[[dict], Any]:
    fn = getattr(importlib.import_module(module), name, None)
    if fn is None:  # a packaging problem, not a user error
        raise RuntimeError(f"{module}.{name} is not available")
    return fn


def _rewrite(text: str) -> str:
    """Rewrite a component's error message as ``field: text (got value)`` where possible."""
    text = one_line(text)
    m = _UNKNOWN.search(text)
    if m:
        allowed = ", ".join(a.strip(" '\"") for a in (m.group(2) or "").split(",") if a.strip())
        return f"{m.group(1)}: unknown key" + (f" (allowed: {allowed})" if allowed else "")
    m = _UNEXPECTED.search(text)
    if m:
        return f"{m.group(1)}: unknown key"
    m = _MISSING.search(text)
    if m:
        return f"{m.group(1)}: required key is missing"
    field, rest = None, text
    m = _KIND.match(text)
    if m:
        field, rest = "kind", m.group(1)
    else:
        m = _FIELD.match(text)
        if m:
            field, rest = m.group(1), m.group(2)
    g = _GOT.match(rest)
    if g and "(got" not in rest:
        rest = f"{g.group(1)} (got {g.group(2)})"
    return f"{field}: {rest}" if field else rest


def _describe(obj: Any, spec: dict) -> dict:
    """Fully resolved spec of a built component (``describe()``, dataclass fields or ``spec``)."""
    if hasattr(obj, "describe"):
        out = dict(obj.describe())
    elif dataclasses.is_dataclass(obj):
        out = {f.name: getattr(obj, f.name) for f in dataclasses.fields(obj) if f.init}
    else:
        out = dict(spec)
    out.pop("stream", None)
    return jsonable({"kind": spec["kind"], **{k: v for k, v in out.items() if k != "kind"}})


def _strict_arrays(spec: Mapping[str, Any]) -> None:
    """Arrays of a component hold finite numbers (or arrays of them): a string or boolean is
    refused here, naming its index, before NumPy would silently read ``"2"`` as 2.0."""
    def walk(path: str, value: Any) -> None:
        for i, x in enumerate(value):
            where = f"{path}.{i}"
            if isinstance(x, (list, tuple)):
                walk(where, x)
            elif isinstance(x, bool) or not isinstance(x, (int, float)):
                raise ValueError(f"{where}: must be a number (got {format_value(x)})")
            elif not math.isfinite(x):
                raise ValueError(f"{where}: must be a finite number (got {format_value(x)})")

    for key, value in spec.items():
        if isinstance(value, (list, tuple)):
            walk(str(key), value)


def _build(builder: Callable[[dict], Any], spec: dict) -> dict:
    _strict_arrays(spec)
    try:
        obj = builder(dict(spec))
    except (ValueError, TypeError, KeyError) as exc:
        text = exc.args[0] if isinstance(exc, KeyError) and exc.args else str(exc)
        raise ValueError(_rewrite(str(text))) from None
    return _describe(obj, spec)


def _table(value: Any, where: str) -> dict:
    if not isinstance(value, Mapping):
        raise ValueError(f"{where}must be a table (got {format_value(value)})")
    return dict(value)


def check_reference(value: Any) -> dict:
    """Validate a ``[reference]`` table with ``auvtrack.reference.build_reference``.

    Parameters
    ----------
    value : mapping
        ``kind`` (default ``"helix"``) and the fields of that kind.

    Returns
    -------
    dict
        The resolved spec, every field filled.

    Raises
    ------
    ValueError
        ``"field: text (got value)"`` naming the offending field.
    """
    spec = _table(value, "")
    spec.setdefault("kind", DEFAULT_REFERENCE_KIND)
    if not isinstance(spec["kind"], str):
        raise ValueError(f"kind: must be a string (got {format_value(spec['kind'])})")
    return _build(_builder("auvtrack.reference", "build_reference"), spec)


def check_disturbances(value: Any) -> list[dict]:
    """Validate the ``[[disturbance]]`` list with ``auvtrack.environment.build_disturbance``.

    Parameters
    ----------
    value : sequence of mapping
        Each table has ``kind`` and the fields of that kind; ``[]`` means no disturbance.

    Returns
    -------
    list of dict
        The resolved specs.

    Raises
    ------
    ValueError
        ``"<index>.field: text (got value)"`` naming the offending entry and field.
    """
    if isinstance(value, Mapping):
        raise ValueError("must be an array of tables ([[disturbance]]), not a single table")
    if not isinstance(value, (list, tuple)):
        raise ValueError(f"must be an array of tables (got {format_value(value)})")
    build = _builder("auvtrack.environment", "build_disturbance")
    out = []
    for i, item in enumerate(value):
        spec = _table(item, f"{i}: ")
        if "kind" not in spec:
            raise ValueError(f"{i}.kind: required key is missing")
        if not isinstance(spec["kind"], str):
            raise ValueError(f"{i}.kind: must be a string (got {format_value(spec['kind'])})")
        try:
            out.append(_build(build, spec))
        except ValueError as exc:
            raise ValueError(f"{i}.{exc}" if re.match(r"^[A-Za-z_][\w.]*: ", str(exc)) else f"{i}: {exc}") from None
    return out

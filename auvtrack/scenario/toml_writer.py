"""Write a resolved scenario as TOML that :func:`tomllib.loads` reads back to the same values.

Only what scenarios hold is supported: tables, arrays (of values, of arrays, of inline tables),
arrays of tables (``[[disturbance]]``), strings, booleans, integers and floats.  Floats are
written with ``repr`` (the shortest text that round-trips bit for bit; ``inf``, ``-inf``,
``nan`` spelled as TOML spells them).  TOML has no null: a key whose value is ``None`` is left
out.  ``tomllib.loads(dumps(doc)) == doc`` for every such document without ``None`` (tested).
"""
from __future__ import annotations

import math
import re
from typing import Any, Mapping

__all__ = ["dumps"]

_BARE_KEY = re.compile(r"[A-Za-z0-9_-]+")
_ESCAPES = {"\\": "\\\\", '"': '\\"', "\b": "\\b", "\t": "\\t", "\n": "\\n", "\f": "\\f", "\r": "\\r"}


def _string(s: str) -> str:
    out = []
    for ch in s:
        if ch in _ESCAPES:
            out.append(_ESCAPES[ch])
        elif ord(ch) < 0x20 or ord(ch) == 0x7F:
            out.append(f"\\u{ord(ch):04X}")
        elif 0xD800 <= ord(ch) <= 0xDFFF:
            raise ValueError(f"cannot write a lone surrogate {ch!r} in TOML")
        else:
            out.append(ch)
    return '"' + "".join(out) + '"'


def _key(k: Any) -> str:
    k = str(k)
    return k if _BARE_KEY.fullmatch(k) else _string(k)


def _value(v: Any, where: str) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        if not -2 ** 63 <= v < 2 ** 63:
            raise ValueError(f"{where}: integer {v} does not fit TOML's 64 bits")
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return _string(v)
    if isinstance(v, Mapping):
        items = [f"{_key(k)} = {_value(x, f'{where}.{k}')}" for k, x in v.items() if x is not None]
        return "{" + ", ".join(items) + "}"
    if isinstance(v, (list, tuple)):
        if any(x is None for x in v):
            raise ValueError(f"{where}: TOML arrays cannot hold null")
        return "[" + ", ".join(_value(x, f"{where}.{i}") for i, x in enumerate(v)) + "]"
    if hasattr(v, "tolist"):  # numpy scalar or array
        return _value(v.tolist(), where)
    raise ValueError(f"{where}: cannot write a {type(v).__name__} in TOML")


def _is_table_array(v: Any) -> bool:
    return isinstance(v, (list, tuple)) and len(v) > 0 and all(isinstance(x, Mapping) for x in v)


def _emit(table: Mapping[str, Any], prefix: tuple[str, ...], lines: list[str]) -> None:
    """Write the plain keys of ``table``, then its sub-tables and arrays of tables."""
    where = ".".join(prefix) or "scenario"
    for k, v in table.items():
        if v is None or isinstance(v, Mapping) or _is_table_array(v):
            continue
        lines.append(f"{_key(k)} = {_value(v, f'{where}.{k}')}")
    for k, v in table.items():
        name = prefix + (_key(k),)
        if isinstance(v, Mapping):
            lines += ["", f"[{'.'.join(name)}]"]
            _emit(v, name, lines)
        elif _is_table_array(v):
            for item in v:
                lines += ["", f"[[{'.'.join(name)}]]"]
                _emit(item, name, lines)


def dumps(doc: Mapping[str, Any], header: str = "") -> str:
    """Render ``doc`` as a TOML document.

    Parameters
    ----------
    doc : mapping
        Nested dicts, lists, str, bool, int and float (``None`` values are left out).
    header : str, optional
        Comment lines put first (each prefixed with ``# ``).

    Returns
    -------
    str
        The document, ending with a newline.

    Raises
    ------
    ValueError
        A value TOML cannot hold (an integer beyond 64 bits, ``None`` inside an array, a lone
        surrogate, an unsupported type), naming its dotted path.
    """
    lines = [f"# {line}".rstrip() for line in header.splitlines()]
    _emit(doc, (), lines)
    return "\n".join(lines).lstrip("\n") + "\n"

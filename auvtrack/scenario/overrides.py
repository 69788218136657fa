"""``dotted.key=value`` overrides applied to a raw scenario dict before validation.

* ``sim.dt=0.002``: the value is parsed as a TOML value (numbers, booleans, strings, arrays,
  inline tables, ``inf``); a bare word such as ``ftsmc`` is read as the string ``"ftsmc"``, and so
  is a bare ``.toml`` or ``.py`` file path such as ``../auvs/my_auv.toml``.
* List entries are addressed by index: ``disturbance.0.amplitude=2``, ``initial.eta.1=0.7``;
  index ``len`` appends a new entry (``disturbance.1.kind=pulse``).
* Kind switch: setting the ``kind`` of a section whose keys depend on it (``controller``,
  ``reference``, each ``disturbance.<i>``) to a *different* kind resets that table to just
  ``{kind = <new>}`` before the later overrides apply, so ``controller.kind=ftsmc`` works on a
  file that sets fxtntsmc gains.  ``envelope.kind`` and ``estimator.kind`` select modes that
  share their keys and never reset anything.
"""
from __future__ import annotations

import copy
import re
import tomllib
from dataclasses import dataclass
from typing import Any, Callable, Mapping, Sequence

from .errors import ScenarioError, format_value
from .reading import MAX_FILE_BYTES, MAX_NESTING, check_nesting, check_text_nesting, override_value

__all__ = ["Override", "parse_overrides", "apply_overrides", "KIND_DEFAULTS"]

Segment = str | int
_SEGMENT = re.compile(r"^(?:[A-Za-z_][A-Za-z0-9_\-]*|\d+)$")
# a bare word may start with a digit when it has a letter (``plant.model=6dof``)
_BARE_WORD = re.compile(r"^(?=.*[A-Za-z_])[A-Za-z0-9_][A-Za-z0-9_.\-+]*$")
# a bare file path (a vehicle file, a plug-in): plant.preset=../auvs/my_auv.toml
_BARE_PATH = re.compile(r"^[A-Za-z0-9_.~/\-+]+\.(?:toml|py)$")

# Sections whose keys depend on ``kind`` (path without indices) and their default kind
# (None: the kind is required).
KIND_DEFAULTS: dict[str, str | None] = {"controller": "fxtntsmc", "reference": "helix", "disturbance.#": None}


@dataclass(frozen=True)
class Override:
    """One parsed override.

    Attributes
    ----------
    text : str
        The override as the user wrote it (for messages).
    path : tuple of str or int
        Key path; integers index arrays.
    value : object
        The new value.
    """

    text: str
    path: tuple[Segment, ...]
    value: Any

    @property
    def dotted(self) -> str:
        """The key path joined with dots."""
        return ".".join(str(s) for s in self.path)


def _parse_path(key: str, text: str) -> tuple[Segment, ...]:
    parts = key.strip().split(".")
    if len(parts) > MAX_NESTING:
        raise ScenarioError(f"override {_short(text)}: a key of more than {MAX_NESTING} parts "
                            f"(got {len(parts)})")
    for p in parts:
        if not _SEGMENT.match(p):
            raise ScenarioError(f"override {_short(text)}: bad key segment {_short(p)} (use dotted.key=value, "
                                f"indices as numbers: disturbance.0.amplitude=2)")
    if parts[0].isdigit():
        raise ScenarioError(f"override {_short(text)}: a key cannot start with an index")
    return tuple(int(p) if p.isdigit() else p for p in parts)


def parse_value(text: str) -> Any:
    """Parse the right-hand side of an override as a TOML value (bare words are strings).

    Raises
    ------
    ValueError
        The text is neither a TOML value nor a bare word.
    """
    if len(text) > MAX_FILE_BYTES:
        raise ValueError(f"longer than the {MAX_FILE_BYTES} characters a value may have")
    try:
        check_text_nesting(f"v = {text}", "value")
        doc = tomllib.loads(f"v = {text}")
    except ScenarioError as exc:
        raise ValueError(str(exc).removeprefix("value: ")) from None
    except tomllib.TOMLDecodeError as exc:
        if _BARE_WORD.match(text) or _BARE_PATH.match(text):
            return text
        raise ValueError(f"not a TOML value ({exc})") from None
    except ValueError as exc:  # e.g. an integer over sys.get_int_max_str_digits()
        raise ValueError(f"not a value Python can hold ({' '.join(str(exc).split())})") from None
    if set(doc) != {"v"}:
        raise ValueError("not a single TOML value")
    check_nesting(doc["v"], "value")
    return doc["v"]


def _short(text: str, n: int = 60) -> str:
    """``repr`` of an override for a message, shortened to about ``n`` characters."""
    return repr(text if len(text) <= n else text[: n - 3] + "...")


def parse_overrides(overrides: Sequence[str] | Mapping[str, Any] | str | None) -> list[Override]:
    """Parse ``["a.b=1", ...]`` or ``{"a.b": 1}`` into :class:`Override` records.

    Parameters
    ----------
    overrides : list or tuple of str, str, mapping or None
        ``"dotted.key=value"`` strings in a list or tuple, a single such string (one override),
        or a mapping ``{dotted_key: value}`` whose values are TOML values: numbers, booleans,
        strings, dates, lists and dicts, with NumPy scalars and arrays taken as the Python
        values they hold (:func:`auvtrack.scenario.reading.override_value`; ``None`` is
        refused).  None: no overrides.

    Returns
    -------
    list of Override
        In the given order.

    Raises
    ------
    ScenarioError
        Overrides of another type (a set, bytes, an array of strings...), a malformed override
        (no ``=``, empty key, bad segment, unparseable value, a value that is not a TOML value),
        or a key or value nested beyond :data:`~auvtrack.scenario.reading.MAX_NESTING`.
    """
    if overrides is None:
        return []
    if isinstance(overrides, str):
        overrides = [overrides]
    out: list[Override] = []
    if isinstance(overrides, Mapping):
        for key, value in overrides.items():
            if not isinstance(key, str) or not key.strip():
                raise ScenarioError(f"override {format_value(key)}: the key must be a non-empty dotted string")
            path = _parse_path(key, key)
            plain = override_value(value, key.strip())
            out.append(Override(f"{key}={format_value(plain)}", path, plain))
        return out
    if not isinstance(overrides, (list, tuple)):
        raise ScenarioError(f"overrides: must be a list of 'dotted.key=value' strings, one such string or a dict "
                            f"{{dotted.key: value}} (got {type(overrides).__name__})")
    for item in overrides:
        if not isinstance(item, str):
            raise ScenarioError(f"override {format_value(item)}: must be a string 'dotted.key=value'")
        text = item.strip()
        key, sep, raw = text.partition("=")
        if not sep or not key.strip():
            raise ScenarioError(f"override {_short(text)}: expected dotted.key=value (e.g. sim.dt=0.002)")
        raw = raw.strip()
        if not raw:
            raise ScenarioError(f"override {_short(text)}: missing value after '='")
        path = _parse_path(key, text)
        try:
            value = parse_value(raw)
        except ValueError as exc:
            tip = "; quote strings with spaces (name=\"my run\")" if " " in raw else ""
            raise ScenarioError(f"override {_short(text)}: value {_short(raw)} is {exc}{tip}") from None
        out.append(Override(text, path, value))
    return out


def _pattern(path: Sequence[Segment]) -> str:
    return ".".join("#" if isinstance(s, int) else str(s) for s in path)


def apply_overrides(data: Mapping[str, Any], overrides: Sequence[Override],
                    default_at: Callable[[dict, tuple[Segment, ...]], Any]) -> dict[str, Any]:
    """Return a deep copy of ``data`` with ``overrides`` applied in order.

    Parameters
    ----------
    data : mapping
        Raw scenario (as read from TOML).
    overrides : sequence of Override
        Parsed overrides.
    default_at : callable
        ``default_at(data, path)`` returns the effective default value at ``path`` (used when
        an override indexes into an array the file does not spell out), or None.

    Returns
    -------
    dict
        The modified copy; ``data`` is left untouched.

    Raises
    ------
    ScenarioError
        An override that walks through a non-table or indexes out of range.
    """
    out = copy.deepcopy(dict(data))
    for ov in overrides:
        _apply_one(out, ov, default_at)
    return out


def _apply_one(root: dict, ov: Override, default_at: Callable[[dict, tuple[Segment, ...]], Any]) -> None:
    node: Any = root
    path = ov.path
    for depth, seg in enumerate(path[:-1]):
        where = ".".join(str(s) for s in path[: depth + 1])
        nxt = path[depth + 1]
        if isinstance(node, dict) and isinstance(seg, str):
            if node.get(seg) is None:
                default = default_at(root, path[: depth + 1]) if isinstance(nxt, int) else None
                node[seg] = copy.deepcopy(default) if default is not None else ([] if isinstance(nxt, int) else {})
            node = node[seg]
        elif isinstance(node, list) and isinstance(seg, int):
            if seg == len(node):
                node.append({} if isinstance(nxt, str) else [])
            elif seg > len(node):
                raise ScenarioError(f"override {ov.text!r}: {where}: index out of range "
                                    f"(it has {len(node)} entries; index {len(node)} appends one)")
            node = node[seg]
        else:
            kind = "an array (use an index)" if isinstance(node, list) else \
                "a table (use a key)" if isinstance(node, dict) else f"a value ({format_value(node)})"
            raise ScenarioError(f"override {ov.text!r}: {'.'.join(str(s) for s in path[:depth])  or 'scenario'} "
                                f"is {kind}")
        if not isinstance(node, (dict, list)):
            raise ScenarioError(f"override {ov.text!r}: {where} is a value ({format_value(node)}), "
                                f"not a table or array")
    last = path[-1]
    parent = path[:-1]
    if last == "kind" and isinstance(node, dict) and _pattern(parent) in KIND_DEFAULTS:
        current = node.get("kind", KIND_DEFAULTS[_pattern(parent)])
        if ov.value != current:  # kind switch: drop the keys of the old kind
            node.clear()
    if isinstance(node, dict) and isinstance(last, str):
        node[last] = copy.deepcopy(ov.value)
    elif isinstance(node, list) and isinstance(last, int):
        if last == len(node):
            node.append(copy.deepcopy(ov.value))
        elif last < len(node):
            node[last] = copy.deepcopy(ov.value)
        else:
            raise ScenarioError(f"override {ov.text!r}: {ov.dotted}: index out of range "
                                f"(it has {len(node)} entries; index {len(node)} appends one)")
    else:
        kind = "an array (use an index)" if isinstance(node, list) else "a table (use a key)"
        raise ScenarioError(f"override {ov.text!r}: {'.'.join(str(s) for s in parent) or 'scenario'} is {kind}")

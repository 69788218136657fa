"""Load a scenario from a TOML file, a dict or a :class:`Scenario`, with overrides.

Every bad input raises :class:`~auvtrack.scenario.errors.ScenarioError` with a one-line
message ``<source>: <dotted.path>: <rule> (got <value>)``.
"""
from __future__ import annotations

import copy
import functools
import os
import tomllib
from pathlib import Path
from typing import Any, Mapping, Sequence

from pydantic import ValidationError

from .catalog import available_scenarios, is_scenario_name, scenario_path
from .errors import ScenarioError, one_line, translate
from .overrides import Override, Segment, apply_overrides, parse_overrides
from .reading import check_nesting, check_text_nesting, plain_data, read_bounded
from .schema import Scenario


def paper_scenario_path() -> Path:
    """Path of the packaged Section 4 scenario (``auvtrack/data/scenarios/paper.toml``).

    Returns
    -------
    pathlib.Path
        The file; an empty scenario means the same thing.
    """
    return scenario_path("paper")


__all__ = ["load_scenario", "read_toml", "parse_toml_text", "paper_scenario_path"]

Source = str | os.PathLike | Mapping[str, Any] | Scenario


def read_toml(path: str | os.PathLike) -> dict[str, Any]:
    """Read a TOML file; any failure is a one-line :class:`ScenarioError` naming the file.

    The file must be a regular file of at most :data:`~auvtrack.scenario.reading.MAX_FILE_BYTES`
    nesting tables and arrays at most :data:`~auvtrack.scenario.reading.MAX_NESTING` levels
    deep (:mod:`auvtrack.scenario.reading`): a directory, FIFO or device is refused without
    reading it.

    Parameters
    ----------
    path : str or path-like
        The TOML file.

    Returns
    -------
    dict
        The parsed document.
    """
    label = os.fspath(path)
    data = read_bounded(path, label)
    try:
        return copy.deepcopy(_parse_bytes(data, label))
    except UnicodeDecodeError:
        raise ScenarioError(f"{label}: not a UTF-8 text file") from None


def parse_toml_text(text: str, label: str) -> dict[str, Any]:
    """Parse TOML text after the nesting checks of :mod:`auvtrack.scenario.reading`.

    Parameters
    ----------
    text : str
        The document.
    label : str
        Source named in messages.

    Returns
    -------
    dict
        The parsed document.

    Raises
    ------
    ScenarioError
        A syntax error or nesting beyond the bound, one line.
    """
    check_text_nesting(text, label)
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f"{label}: TOML syntax error: {one_line(str(exc))}") from None
    except RecursionError:  # the scan above bounds the nesting; this guards the parser itself
        raise ScenarioError(f"{label}: nested too deeply to parse") from None
    except ValueError as exc:  # a value Python refuses, e.g. an integer over sys.get_int_max_str_digits()
        raise ScenarioError(f"{label}: TOML value error: {one_line(str(exc))}") from None
    check_nesting(doc, label)
    return doc


@functools.lru_cache(maxsize=64)
def _parse_bytes(data: bytes, label: str) -> dict[str, Any]:
    """Parsed TOML, cached by content: a sweep preparing thousands of samples from one file
    parses it once, and an edited file is parsed again (its bytes differ)."""
    return parse_toml_text(data.decode("utf-8"), label)


def _read_source(source: Source) -> tuple[str, dict[str, Any]]:
    """Return (label for messages, raw dict)."""
    if isinstance(source, Scenario):
        return "<Scenario>", source.to_dict()
    if isinstance(source, Mapping):
        return "<dict>", plain_data(dict(source), "<dict>")
    if isinstance(source, (str, os.PathLike)):
        from ..user_modules import anchor_module  # a plug-in path is relative to its scenario file
        from ..vehicle.vehicle_file import anchor_vehicle_files  # so is a vehicle file's

        path = scenario_path(source) if is_scenario_name(source) else source
        try:
            data = read_toml(path)
        except ScenarioError as exc:
            stem = Path(path).stem
            if str(exc).endswith(": file not found") and stem in available_scenarios():
                raise ScenarioError(f"{exc} (a packaged scenario has that name: give the string {stem!r})") from None
            raise
        try:
            return os.fspath(source), anchor_vehicle_files(anchor_module(data, Path(path).parent), Path(path).parent)
        except ValueError as exc:  # a plug-in path that cannot be resolved
            raise ScenarioError(f"{os.fspath(source)}: {exc}") from None
    raise ScenarioError(f"scenario source must be a packaged scenario's name, a TOML file path, a dict or a "
                        f"Scenario (got {type(source).__name__})")


@functools.lru_cache(maxsize=1)
def _paper_defaults() -> dict[str, Any]:
    return Scenario().to_dict()


def _walk(value: Any, path: Sequence[Segment]) -> Any:
    for seg in path:
        if isinstance(value, dict) and isinstance(seg, str):
            value = value.get(seg)
        elif isinstance(value, list) and isinstance(seg, int) and seg < len(value):
            value = value[seg]
        else:
            return None
    return value


def _default_at(data: dict, path: tuple[Segment, ...]) -> Any:
    """Effective value at ``path`` when ``data`` does not spell it out (for indexed overrides).

    The section is resolved as written so far (its kind, preset, ...); if it does not validate
    yet, the paper default is used.
    """
    section = path[0]
    if isinstance(section, str) and section in data:
        try:
            resolved = Scenario.model_validate({section: data[section]}).to_dict()
            return _walk(resolved, path)
        except (ValidationError, ScenarioError):
            pass
    return _walk(_paper_defaults(), path)


def _hint(overrides: Sequence[Override]):
    """Message suffix naming the override that set (part of) the failing field."""
    def hint(path: str) -> str:
        for ov in reversed(overrides):
            d = ov.dotted
            if not path or d == path or path.startswith(d + ".") or d.startswith(path + "."):
                shown = ov.text if len(ov.text) <= 60 else ov.text[:57] + "..."
                return f" (set by override {shown!r})"
        return ""
    return hint


def load_scenario(source: Source, overrides: Sequence[str] | str | Mapping[str, Any] | None = ()) -> Scenario:
    """Load and validate a scenario.

    Parameters
    ----------
    source : str, path-like, dict or Scenario
        A packaged scenario's name (``"paper"``, ``"lawnmower"``: letters, digits, ``_`` and
        ``-`` only, :mod:`auvtrack.scenario.catalog`), a TOML file path (any other string, or a
        path-like object; a file without a dot in its name is ``./name``), a raw scenario dict
        (as TOML would give; NumPy scalars and arrays are taken as the Python values they hold)
        or an already loaded scenario.
    overrides : sequence of str, str, dict or None, optional
        ``"dotted.key=value"`` strings in a list or tuple (value parsed as TOML; bare words are
        strings; array entries addressed by index, e.g. ``disturbance.0.amplitude=2``), one
        such string on its own, or a dict ``{dotted_key: value}`` whose values are TOML values
        (numbers, booleans, strings, dates, lists, dicts; NumPy scalars and arrays are
        converted; ``None`` is refused), applied in order; None means no overrides.  Setting
        the ``kind`` of ``controller``, ``reference`` or a ``disturbance`` entry to a different
        kind first resets that table to just the new kind.

    Returns
    -------
    Scenario
        The validated, frozen scenario.

    Raises
    ------
    ScenarioError
        Any bad input (unknown scenario name, missing file, a directory, FIFO or device, a file
        over :data:`~auvtrack.scenario.reading.MAX_FILE_BYTES`, nesting beyond
        :data:`~auvtrack.scenario.reading.MAX_NESTING`, TOML syntax, unknown key, wrong type,
        value out of range, unknown preset or kind, malformed override or overrides of another
        type), with a one-line message naming the source and the dotted field path.

    Examples
    --------
    >>> from auvtrack.scenario import load_scenario
    >>> sc = load_scenario({}, ["controller.kind=ftsmc", "sim.duration=10"])
    >>> sc.controller.kind, sc.sim.duration
    ('ftsmc', 10.0)
    >>> load_scenario("lawnmower").reference["kind"]
    'lawnmower'
    """
    parsed = parse_overrides(overrides)
    if isinstance(source, Scenario) and not parsed:
        return source
    label, data = _read_source(source)
    if parsed:
        data = apply_overrides(data, parsed, _default_at)
    try:
        return Scenario.model_validate(data)
    except ValidationError as exc:
        raise translate(exc, Scenario, label, _hint(parsed)) from None

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

from .errors import ScenarioError, one_line, translate
from .overrides import Override, Segment, apply_overrides, parse_overrides
from .schema import Scenario

_DATA = Path(__file__).resolve().parents[1] / "data"


def paper_scenario_path() -> Path:
    """Path of the packaged Section 4 scenario (``auvtrack/data/scenarios/paper.toml``).

    Returns
    -------
    pathlib.Path
        The file; an empty scenario means the same thing.
    """
    return _DATA / "scenarios" / "paper.toml"

__all__ = ["load_scenario", "read_toml"]

Source = str | os.PathLike | Mapping[str, Any] | Scenario


def read_toml(path: str | os.PathLike) -> dict[str, Any]:
    """Read a TOML file; any failure is a one-line :class:`ScenarioError` naming the file.

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
    try:
        with open(path, "rb") as fh:
            data = fh.read()
        return copy.deepcopy(_parse_bytes(data))
    except FileNotFoundError:
        raise ScenarioError(f"{label}: file not found") from None
    except IsADirectoryError:
        raise ScenarioError(f"{label}: is a directory, not a TOML file") from None
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f"{label}: TOML syntax error: {one_line(str(exc))}") from None
    except UnicodeDecodeError:
        raise ScenarioError(f"{label}: not a UTF-8 text file") from None
    except OSError as exc:
        raise ScenarioError(f"{label}: cannot read file ({one_line(exc.strerror or str(exc))})") from None


@functools.lru_cache(maxsize=64)
def _parse_bytes(data: bytes) -> dict[str, Any]:
    """Parsed TOML, cached by content: a sweep preparing thousands of samples from one file
    parses it once, and an edited file is parsed again (its bytes differ)."""
    return tomllib.loads(data.decode("utf-8"))


def _read_source(source: Source) -> tuple[str, dict[str, Any]]:
    """Return (label for messages, raw dict)."""
    if isinstance(source, Scenario):
        return "<Scenario>", source.to_dict()
    if isinstance(source, Mapping):
        return "<dict>", copy.deepcopy(dict(source))
    if isinstance(source, (str, os.PathLike)):
        from ..user_modules import anchor_module  # a plug-in path is relative to its scenario file
        from ..vehicle.vehicle_file import anchor_vehicle_files  # so is a vehicle file's

        return os.fspath(source), anchor_vehicle_files(anchor_module(read_toml(source), Path(source).parent),
                                                       Path(source).parent)
    raise ScenarioError(f"scenario source must be a TOML file path, a dict or a Scenario "
                        f"(got {type(source).__name__})")


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
                return f" (set by override {ov.text!r})"
        return ""
    return hint


def load_scenario(source: Source, overrides: Sequence[str] | Mapping[str, Any] | None = ()) -> Scenario:
    """Load and validate a scenario.

    Parameters
    ----------
    source : str, path-like, dict or Scenario
        A TOML file, a raw scenario dict (as TOML would give) or an already loaded scenario.
    overrides : sequence of str or dict, optional
        ``"dotted.key=value"`` strings (value parsed as TOML; bare words are strings; array
        entries addressed by index, e.g. ``disturbance.0.amplitude=2``) or a dict
        ``{dotted_key: value}``, applied in order.  Setting the ``kind`` of ``controller``,
        ``reference`` or a ``disturbance`` entry to a different kind first resets that table to
        just the new kind.

    Returns
    -------
    Scenario
        The validated, frozen scenario.

    Raises
    ------
    ScenarioError
        Any bad input (missing file, TOML syntax, unknown key, wrong type, value out of range,
        unknown preset or kind, malformed override), with a one-line message naming the source
        and the dotted field path.

    Examples
    --------
    >>> from auvtrack.scenario import load_scenario
    >>> sc = load_scenario({}, ["controller.kind=ftsmc", "sim.duration=10"])
    >>> sc.controller.kind, sc.sim.duration
    ('ftsmc', 10.0)
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

"""Scenarios shipped with the package (``auvtrack/data/scenarios/``), reachable by name from any folder.

A **name** is letters, digits, ``_`` and ``-`` only, starting with a letter, digit or ``_``
(``paper``, ``lawnmower``, ``remus100_zigzag``): it holds no ``/``, no ``\\`` and no ``.``, so it
can be neither a folder path nor a file name with an extension such as ``.toml``.  Every other
string, and every :class:`os.PathLike`, is a **file path**.  A file in the current folder
whose name has no dot is reached as ``./name``; ``load_scenario("paper")`` is always the
packaged Section 4, whatever the current folder holds.
"""
from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Any

from .errors import ScenarioError

__all__ = ["NAME_PATTERN", "is_scenario_name", "available_scenarios", "scenario_path", "scenario_summary",
           "copy_scenario"]

NAME_PATTERN = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_-]*")
"""What a scenario name is (anything else is a path)."""
_ROOT = Path(__file__).resolve().parents[1] / "data" / "scenarios"


def is_scenario_name(source: Any) -> bool:
    """True when ``source`` is a packaged scenario's *name* rather than a file path.

    Parameters
    ----------
    source : object
        A scenario source as given to :func:`auvtrack.load_scenario`.

    Returns
    -------
    bool
        A ``str`` matching :data:`NAME_PATTERN` (no ``/``, ``\\`` or ``.``); a path-like object
        is never a name.
    """
    return isinstance(source, str) and NAME_PATTERN.fullmatch(source) is not None


def available_scenarios() -> list[str]:
    """Names of the packaged scenarios, sorted.

    Returns
    -------
    list of str
        One per ``auvtrack/data/scenarios/<name>.toml``.
    """
    if not _ROOT.is_dir():
        return []
    return sorted(p.stem for p in _ROOT.glob("*.toml") if NAME_PATTERN.fullmatch(p.stem))


def scenario_path(name: str) -> Path:
    """The file of a packaged scenario.

    Parameters
    ----------
    name : str
        A name from :func:`available_scenarios`.

    Returns
    -------
    pathlib.Path
        ``auvtrack/data/scenarios/<name>.toml``.

    Raises
    ------
    ScenarioError
        One line listing the packaged names and how to give a file instead.
    """
    names = available_scenarios()
    if not is_scenario_name(name) or name not in names:
        hint = f"; a file path has a '/' or a '.': ./{name}" if is_scenario_name(name) else ""
        raise ScenarioError(f"{name}: unknown packaged scenario (packaged: {', '.join(names) or 'none'}{hint})")
    return _ROOT / f"{name}.toml"


def scenario_summary(name: str) -> str:
    """The ``description`` of a packaged scenario (empty when it has none).

    Parameters
    ----------
    name : str
        A packaged scenario's name.

    Returns
    -------
    str
        One line.
    """
    from .loader import read_toml

    text = read_toml(scenario_path(name)).get("description", "")
    return " ".join(text.split()) if isinstance(text, str) else ""


def copy_scenario(name: str, dest: str | os.PathLike | None = None, *, overwrite: bool = False) -> Path:
    """Copy a packaged scenario to a file the user can edit.

    Parameters
    ----------
    name : str
        A packaged scenario's name.
    dest : str or path-like, optional
        The new file, or an existing folder to put ``<name>.toml`` in (default: ``./<name>.toml``).
    overwrite : bool, optional
        Replace an existing file (never a folder or anything but a regular file).

    Returns
    -------
    pathlib.Path
        The file written, a byte-for-byte copy.

    Raises
    ------
    ScenarioError
        An unknown name, or a destination that exists (without ``overwrite``), is not a regular
        file, or cannot be written; one line.
    """
    src = scenario_path(name)
    target = Path(f"{name}.toml") if dest is None else Path(dest)
    if target.is_dir():
        target = target / f"{name}.toml"
    if target.exists() or target.is_symlink():
        if target.is_symlink() or not target.is_file():
            raise ScenarioError(f"{target}: exists and is not a regular file; choose another destination")
        if not overwrite:
            raise ScenarioError(f"{target}: exists; choose another destination (or overwrite it with --force)")
    data = src.read_bytes()
    try:
        with open(target, "wb" if overwrite else "xb") as fh:
            fh.write(data)
    except FileExistsError:
        raise ScenarioError(f"{target}: exists; choose another destination (or overwrite it with --force)") from None
    except OSError as exc:
        raise ScenarioError(f"{target}: cannot write ({exc.strerror or exc})") from None
    return target

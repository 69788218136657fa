"""Bounded reading of user input: what is read is checked for type, size and depth first.

A scenario, suite or study file is read only if it is a regular file (symbolic links followed)
of at most :data:`MAX_FILE_BYTES`; a directory, FIFO, device (``/dev/zero``) or socket is
refused from its file type, without reading (it is opened non-blocking, so a FIFO cannot hang
the open).  The TOML text, an override's value and a Python dict given as a scenario or as an
override may nest tables and arrays at most :data:`MAX_NESTING` levels deep, and a dotted key
may have at most that many parts; the text is scanned for both before the parser sees it, so the
parser's recursion and its time on long dotted keys stay small.  Every refusal is one line
(:class:`~auvtrack.scenario.errors.ScenarioError`).  ``docs/scenarios.md`` ("Reading") documents
the bounds.
"""
from __future__ import annotations

import copy
import datetime
import os
import re
import stat
from typing import Any, Mapping

import numpy as np

from .errors import ScenarioError

__all__ = ["MAX_FILE_BYTES", "MAX_NESTING", "read_bounded", "check_text_nesting", "check_nesting",
           "plain_data", "override_value"]

MAX_FILE_BYTES = 16 * 2 ** 20
"""Largest file read as TOML, bytes (the longest waypoint list, in full precision, fits)."""
MAX_NESTING = 32
"""Most levels of nested tables and arrays, and most parts of one dotted key."""

_KINDS = ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
          (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"))

# One TOML token per match: strings and comments whole (their brackets and dots do not count),
# dotted keys (bare or quoted parts; a float such as 1.5 is two parts) and brackets.
_PART = r"""(?:[A-Za-z0-9_-]++|"(?:[^"\\\n]|\\.)*+"|'[^'\n]*+')"""
_TOKEN = re.compile(rf"""
      (?P<mlb>\"\"\"(?:[^\\]|\\[\s\S])*?\"\"\"\"{{0,2}})
    | (?P<mll>'''[\s\S]*?''''{{0,2}})
    | (?P<key>(?<![A-Za-z0-9_-]){_PART}(?:[ \t]*+\.[ \t]*+{_PART})++)
    | (?P<bs>"(?:[^"\\\n]|\\.)*+"?)
    | (?P<ls>'[^'\n]*+'?)
    | (?P<comment>\#[^\n]*+)
    | (?P<open>[\[{{])
    | (?P<close>[\]}}])
""", re.X)
_KEY_DOT = re.compile(rf"""{_PART}|(?P<dot>\.)""")


def _kind(mode: int) -> str:
    return next((name for test, name in _KINDS if test(mode)), "not a regular file")


def read_bounded(path: str | os.PathLike, label: str | None = None, limit: int = MAX_FILE_BYTES) -> bytes:
    """The bytes of a regular file of at most ``limit`` bytes; anything else is one line.

    The file type is checked before the file is opened (a device or FIFO is never opened), and
    again on the descriptor, opened without blocking, so that a file swapped in after the first
    check cannot slip through.  At most ``limit + 1`` bytes are read, even from a file that grows
    meanwhile.

    Parameters
    ----------
    path : str or path-like
        The file.
    label : str, optional
        How messages name it (default: ``path`` as given).
    limit : int, optional
        Largest size accepted, bytes.

    Returns
    -------
    bytes
        The file's contents.

    Raises
    ------
    ScenarioError
        ``<label>: file not found``, ``<label>: is a directory ...``, ``<label>: is a FIFO ...``,
        ``<label>: is N bytes, more than ...`` or ``<label>: cannot read file (...)``.
    """
    label = os.fspath(path) if label is None else label
    if not isinstance(label, str) or "\0" in label:
        raise ScenarioError(f"{label!r}: not a file path (it holds a NUL character)")
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0) | getattr(os, "O_BINARY", 0)
    try:
        mode = os.stat(path).st_mode  # a device is never opened (opening some has effects)
        if not stat.S_ISREG(mode):
            raise ScenarioError(f"{label}: is {_kind(mode)}, not a TOML file (a regular file is needed)")
        fd = os.open(path, flags)  # then checked again on the descriptor: the file may have been swapped
    except ScenarioError:
        raise
    except FileNotFoundError:
        raise ScenarioError(f"{label}: file not found") from None
    except IsADirectoryError:
        raise ScenarioError(f"{label}: is a directory, not a TOML file") from None
    except (OSError, ValueError) as exc:
        text = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        raise ScenarioError(f"{label}: cannot read file ({text})") from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise ScenarioError(f"{label}: is {_kind(st.st_mode)}, not a TOML file (a regular file is needed)")
        if st.st_size > limit:
            raise ScenarioError(f"{label}: is {st.st_size} bytes, more than the {limit} bytes "
                                f"({limit / 2 ** 20:g} MiB) a TOML file may have")
        chunks, size = [], 0
        while size <= limit:
            chunk = os.read(fd, min(1 << 20, limit + 1 - size))
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
        if size > limit:
            raise ScenarioError(f"{label}: grew beyond the {limit} bytes a TOML file may have while being read")
        return b"".join(chunks)
    except OSError as exc:
        raise ScenarioError(f"{label}: cannot read file ({exc.strerror or exc})") from None
    finally:
        os.close(fd)


def check_text_nesting(text: str, label: str, limit: int = MAX_NESTING) -> None:
    """Refuse TOML text nesting arrays and inline tables, or dotted keys, beyond ``limit``.

    Brackets and dots inside strings and comments do not count; a table header ``[[a]]`` counts
    its two brackets.  The scan is linear in the text.

    Parameters
    ----------
    text : str
        TOML text.
    label : str
        Source named in the message.
    limit : int, optional
        Most levels (and most parts of one dotted key).

    Raises
    ------
    ScenarioError
        ``<label>: nested more than N levels deep (line L)`` or ``<label>: a dotted key of more
        than N parts (line L)``.
    """
    depth = 0
    for m in _TOKEN.finditer(text):
        kind = m.lastgroup
        if kind == "open":
            depth += 1
            if depth > limit:
                raise ScenarioError(f"{label}: nested more than {limit} levels deep (arrays and inline tables; "
                                    f"line {text.count(chr(10), 0, m.start()) + 1})")
        elif kind == "close":
            depth = max(depth - 1, 0)
        elif kind == "key":
            parts = 1 + sum(1 for d in _KEY_DOT.finditer(m.group()) if d.group("dot"))
            if parts > limit:
                raise ScenarioError(f"{label}: a dotted key of more than {limit} parts "
                                    f"(line {text.count(chr(10), 0, m.start()) + 1})")


def _too_deep(label: str, where: str, limit: int) -> ScenarioError:
    at = f"{where}: " if where else ""
    return ScenarioError(f"{label}: {at}nested more than {limit} levels deep (tables and arrays; "
                         "or a table that contains itself)", where)


def check_nesting(value: Any, label: str, limit: int = MAX_NESTING) -> None:
    """Refuse data nesting dicts, lists and tuples more than ``limit`` levels deep.

    Parameters
    ----------
    value : object
        Parsed data (a scenario dict, an override value).
    label : str
        Source named in the message.
    limit : int, optional
        Most levels.

    Raises
    ------
    ScenarioError
        ``<label>: <top key>: nested more than N levels deep ...`` (also for a dict that
        contains itself).
    """
    stack = [(value, 0, "")]
    while stack:
        node, depth, top = stack.pop()
        if isinstance(node, Mapping):
            children = ((v, str(k) if depth == 0 else top) for k, v in node.items())
        elif isinstance(node, (list, tuple)):
            children = ((v, top) for v in node)
        else:
            continue
        if depth >= limit:
            raise _too_deep(label, top, limit)
        stack.extend((v, depth + 1, t) for v, t in children)


def _numpy_plain(value: Any) -> Any:
    """A NumPy scalar or array as the Python value it holds (lists for arrays)."""
    if isinstance(value, np.ndarray):
        return value.tolist()
    return value.item()


def plain_data(value: Any, label: str, limit: int = MAX_NESTING) -> Any:
    """A copy of scenario data with NumPy scalars and arrays as Python values, depth-checked.

    Dicts, lists and tuples are copied (tuples stay tuples), NumPy values become the Python
    numbers, booleans, strings and lists they hold, other leaves are deep-copied; validation
    then judges the values.

    Parameters
    ----------
    value : object
        A scenario as a dict (``load_scenario(dict)``).
    label : str
        Source named in a message.
    limit : int, optional
        Most levels of nesting.

    Returns
    -------
    object
        The converted copy.

    Raises
    ------
    ScenarioError
        Nesting beyond ``limit`` (or a dict that contains itself).
    """
    check_nesting(value, label, limit)
    return _convert(value)


def _convert(value: Any) -> Any:
    if isinstance(value, (np.generic, np.ndarray)):
        return _convert(_numpy_plain(value))
    if isinstance(value, Mapping):
        return {k: _convert(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_convert(v) for v in value]
    if isinstance(value, tuple):
        return tuple(_convert(v) for v in value)
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    return copy.deepcopy(value)


_TOML_LEAVES = (bool, int, float, str, datetime.date, datetime.time)  # datetime is a date


def override_value(value: Any, text: str, limit: int = MAX_NESTING) -> Any:
    """The value of a dict override as a TOML value: what ``--set`` could have written.

    Numbers, booleans, strings, dates and times, lists and tuples (as lists) and dicts with
    string keys (as tables) are taken; NumPy scalars and arrays become the Python values they
    hold.  ``None`` (TOML has no null) and any other object are refused.

    Parameters
    ----------
    value : object
        The value given for one dotted key.
    text : str
        The key, for messages (``override 'sim.dt'``).
    limit : int, optional
        Most levels of nesting.

    Returns
    -------
    object
        A plain copy.

    Raises
    ------
    ScenarioError
        One line naming the override and what is accepted.
    """
    check_nesting(value, f"override {text!r}", limit)
    return _toml(value, text)


def _toml(value: Any, text: str) -> Any:
    if isinstance(value, (np.generic, np.ndarray)):
        return _toml(_numpy_plain(value), text)
    if isinstance(value, Mapping):
        bad = [k for k in value if not isinstance(k, str)]
        if bad:
            raise ScenarioError(f"override {text!r}: a table's keys must be strings (got {bad[0]!r})")
        return {k: _toml(v, text) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_toml(v, text) for v in value]
    if isinstance(value, _TOML_LEAVES):
        return value
    what = "None (TOML has no null: leave the key out to keep its value)" if value is None \
        else f"a {type(value).__name__}"
    raise ScenarioError(f"override {text!r}: the value is {what}; an override takes a number, boolean, "
                        "string, date, array or table (NumPy scalars and arrays are converted)")

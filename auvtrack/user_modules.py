"""Importing a user's module (a controller or plant plug-in) by module name or by file path."""
from __future__ import annotations

import hashlib
import importlib
import importlib.util
import re
import sys
from pathlib import Path

__all__ = ["load_module", "resolve", "anchor_module", "first_line", "identifier", "file_digest"]


def file_digest(path: str | Path) -> str:
    """First 12 hex digits of the SHA-256 of a file's bytes (a plug-in's kernel is named by its content)."""
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()[:12]


def identifier(text: str) -> str:
    """``text`` with every character that cannot be in a Python identifier replaced by ``_``."""
    return re.sub(r"\W", "_", text)


def load_module(spec: str):
    """Import a user's module: a controller or plant plug-in, given by module name or ``.py`` path.

    Parameters
    ----------
    spec : str
        An importable module name, or the path of a ``.py`` file (imported once per content under a
        name derived from its path and hash, never by pasting the path into code).

    Returns
    -------
    module
        The module.

    Raises
    ------
    ImportError
        If the module or file cannot be imported (the message names it).
    """
    if not spec.endswith(".py"):
        return importlib.import_module(spec)
    try:
        path = Path(spec).resolve()
        found = path.is_file()
    except (OSError, ValueError) as exc:
        raise ImportError(f"{spec[:60]}: cannot be read ({getattr(exc, 'strerror', None) or exc})") from None
    if not found:
        raise ImportError(f"{path}: no such file")
    name = f"auvtrack_plugin_{identifier(path.stem)}_{file_digest(path)}"
    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.spec_from_file_location(name, path)
    if spec is None or spec.loader is None:
        raise ImportError(f"{path}: not an importable Python file")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    try:
        spec.loader.exec_module(module)
    except BaseException:
        del sys.modules[name]
        raise
    return module


def resolve(module: str, base_dir: str | Path | None = None) -> str:
    """The plug-in's law as the kernels name it: an absolute ``.py`` path or the dotted module name.

    Parameters
    ----------
    module : str
        ``controller.module`` or ``plant.module``: a ``.py`` path or a dotted module name.
    base_dir : str or path, optional
        Folder of the scenario file, for a relative path (default: the current folder).

    Returns
    -------
    str
        The absolute path (``.py``) or ``module`` itself.

    Raises
    ------
    ValueError
        A path the system cannot resolve (too long, a NUL character), one line naming it.
    """
    if not module.endswith(".py"):
        return module
    try:
        path = Path(module).expanduser()
        if not path.is_absolute():
            path = Path(base_dir or Path.cwd()) / path
        path.is_file()  # raises for a name the system refuses (too long); a missing file is the loader's to report
        return str(path.resolve())
    except (OSError, ValueError) as exc:
        shown = module if len(module) <= 60 else module[:57] + "..."
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        raise ValueError(f"module: the path {shown!r} cannot be resolved ({reason})") from None


def anchor_module(data: dict, folder: str | Path) -> dict:
    """Make relative ``controller.module`` and ``plant.module`` ``.py`` paths of a file's data relative to ``folder``.

    Called by the loaders on what a scenario file holds, so that the path written in a file is
    relative to that file (paths given in a dict or by ``--set`` are relative to the current
    folder).

    Parameters
    ----------
    data : dict
        Parsed scenario (modified in place).
    folder : str or path
        The folder of the scenario file.

    Returns
    -------
    dict
        ``data``.

    Raises
    ------
    ValueError
        ``<section>.module: the path ... cannot be resolved (...)``.
    """
    for section in ("controller", "plant"):
        table = data.get(section) if isinstance(data, dict) else None
        module = table.get("module") if isinstance(table, dict) else None
        if isinstance(module, str) and module.endswith(".py"):
            try:
                table["module"] = resolve(module, Path(folder).resolve())
            except ValueError as exc:
                raise ValueError(f"{section}.{exc}") from None
    return data


def first_line(exc: BaseException) -> str:
    """``Type: first line of the message`` of an exception raised by a user's code."""
    text = str(exc).strip().splitlines()
    return f"{type(exc).__name__}: {text[0] if text else ''}".rstrip(": ")

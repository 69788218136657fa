"""A compiler report turned into one line that names the user's own file and line.

Numba's reports of a law or plant that cannot compile run over dozens of lines and point into the
generated kernel file; :func:`compile_error_line` keeps the last location in the user's own code
and the cause.
"""
from __future__ import annotations

import os
import re
from pathlib import Path

from . import cache_dir

__all__ = ["CompileError", "compile_error_line"]


class CompileError(ValueError):
    """A law or plant that Numba cannot compile.

    ``str(err)`` is one line naming the user's file and line and the cause; ``err.details`` is the
    compiler's whole report (``auvtrack --verbose`` prints it).
    """

    def __init__(self, message: str, details: str = ""):
        super().__init__(message)
        self.details = details


_LOCATION = re.compile(r'File "(.+?)", line (\d+)')  # a path may hold quotes
_ANSI = re.compile(r"\x1b\[[0-9;]*m")  # Numba's highlighting (its colour scheme may be on)
_NOISE = ("Failed in ", "During:", "File ", "Enable logging", "This error may have been", "Traceback",
          "numba.core.errors", "raise ", "^", "Exception", "<source", "    ")


def compile_error_line(text: str, label: str) -> str:
    """One line for a compiler report: the last location in the user's own files, and the cause.

    Parameters
    ----------
    text : str
        The Numba error message (or a child process's report).
    label : str
        The kernel, e.g. ``"plugin on 5dof"``.

    Returns
    -------
    str
        ``"<label>: cannot compile: <file>:<line>: <cause>"`` (the generated kernel file and the
        package's own files are never named: the user's code is).
    """
    text = _ANSI.sub("", text)
    package = str(Path(__file__).resolve().parents[1])
    cache = str(cache_dir().parent)
    found = [(os.path.abspath(f), n) for f, n in _LOCATION.findall(text)]  # Numba may report paths relative to cwd
    user = [(f, n) for f, n in found
            if not f.startswith(package) and not f.startswith(cache) and "site-packages" not in f]
    cause = ""
    for line in text.splitlines():
        line = line.strip()
        if not line or line.startswith(_NOISE) or line.startswith("-") or set(line) <= set("^ "):
            continue
        if line.startswith(("numba.core.errors.", "TypingError:", "LoweringError:", "UnsupportedError:")):
            line = line.split(":", 1)[1].strip()
            if not line or line.startswith("Failed in"):
                continue
        cause = line
        break
    where = f"{user[-1][0]}:{user[-1][1]}: " if user else ""
    return f"{label}: cannot compile: {where}{cause or 'the compiler failed (auvtrack --verbose shows its report)'}"

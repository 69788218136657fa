"""Default run folders of ``auvtrack run``: one new folder per run, never a silent overwrite.

Without ``--out``, a run of scenario ``name`` with controller ``kind`` goes to
``runs/<name>-<kind>``; when that folder exists, to ``runs/<name>-<kind>-2``, ``-3``, ... (the
first free one).  An explicit ``--out`` is used as given and overwritten (docs/metrics.md).
"""
from __future__ import annotations

import re
from pathlib import Path

_UNSAFE = re.compile(r"[^A-Za-z0-9._-]+")


def default_run_folder(name: str, kind: str, root: str | Path = "runs") -> Path:
    """First free folder ``<root>/<name>-<kind>[-<n>]`` for a new run.

    Parameters
    ----------
    name : str
        Scenario name (``name`` key).
    kind : str
        Controller kind.
    root : str or pathlib.Path, optional
        Parent folder.

    Returns
    -------
    pathlib.Path
        A path that does not exist yet (``-2``, ``-3``, ... appended as needed).
    """
    base = _UNSAFE.sub("_", f"{name}-{kind}").strip("._") or "run"
    root = Path(root)
    path, n = root / base, 1
    while path.exists():
        n += 1
        path = root / f"{base}-{n}"
    return path


__all__ = ["default_run_folder"]

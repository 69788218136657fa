"""Compilation settings shared by every compiled kernel.

Numba's on-disk cache is keyed by the timestamp of the file that defines a function, not by the
files it calls, so editing ``plant/dynamics.py`` would leave a stale cached ``simulation/engine.py``
kernel.  We therefore place the cache in a directory named by a hash of *all* package sources:
any source change selects a fresh directory.  The name also carries the vector-math back end of
:mod:`auvtrack._vecmath` (compiled code differs between them).  Set ``AUVTRACK_CACHE_DIR`` to
override the root.
"""
from __future__ import annotations

import hashlib
import os
from pathlib import Path

import numba

from . import _vecmath

_PKG = Path(__file__).resolve().parent


def source_hash() -> str:
    """Return a SHA-256 digest of every ``*.py`` file of the package (paths and contents)."""
    h = hashlib.sha256()
    for path in sorted(_PKG.rglob("*.py")):
        h.update(str(path.relative_to(_PKG)).encode())
        h.update(path.read_bytes())
    return h.hexdigest()


def cache_dir() -> Path:
    """Return the numba cache directory for the current package sources."""
    root = Path(os.environ.get("AUVTRACK_CACHE_DIR", Path.home() / ".cache" / "auvtrack"))
    return root / f"numba-{numba.__version__}-{source_hash()[:16]}-{_vecmath.BACKEND}"


numba.config.CACHE_DIR = str(cache_dir())


def njit(*args, **kwargs):
    """``numba.njit`` with the project's defaults: on-disk cache, NumPy error model (1/0 -> inf)."""
    kwargs.setdefault("cache", True)
    kwargs.setdefault("error_model", "numpy")
    return numba.njit(*args, **kwargs)


def njit_noalloc(*args, **kwargs):
    """:func:`njit` for hot-path functions that never allocate: no reference counting.

    Numba increments and decrements the reference count of every array argument on entry and
    exit of a compiled function (an atomic operation each); for the small functions called at
    every RK4 stage this cost more than their arithmetic (FXTNTSMC 2.9 -> 2.0 us per step, FTSMC
    2.3 -> 1.1, results bit-identical).  ``_nrt=False`` (a private Numba option) compiles the
    function without the runtime: an allocation added to it fails to compile instead of leaking.
    Remove the option here to revert every such function at once.
    """
    kwargs["_nrt"] = False
    return njit(*args, **kwargs)

"""Compilation settings shared by every compiled function: the decorators, inlining and the cache.

This package sits below the physics (every equation module imports its decorators) and the
engine (which compiles the loop over them); it imports nothing else of auvtrack.

Numba's on-disk cache is keyed by the timestamp of the file that defines a function, not by the
files it calls, so editing ``vehicle/dynamics.py`` would leave a stale cached kernel.  The cache
therefore lives in a directory named by a hash of the sources of :data:`COMPILED`, the parts of
the package that compiled code comes from (a test checks that every module defining compiled
functions, and every module they import, is among them): any edit there selects a fresh
directory, an edit elsewhere (the command line, studies, reports) keeps the compiled kernels.
The name also carries the vector-math back end of :mod:`auvtrack.jit.vecmath` and whether the
lane kernels use its 8-lane AVX-512 functions (compiled code differs between them).  Set
``AUVTRACK_CACHE_DIR`` to override the root.
"""
from __future__ import annotations

import functools
import hashlib
import os
import types as pytypes
from pathlib import Path

import numba
from numba.core import types
from numba.core.registry import CPUDispatcher

from . import lane_values as _lanes  # noqa: F401  (lane types registered before anything compiles)
from . import vecmath as _vecmath

_PKG = Path(__file__).resolve().parents[1]
COMPILED = ("jit", "packing.py", "channels.py", "metrics.py", "fields.py", "user_modules.py", "_seeding.py",
            "interrupt.py", "vehicle", "plant", "environment", "reference", "control", "engine",
            "gym/stepping.py", "gym/replay.py", "gym/replay_actuators.py")
"""Packages and modules (relative to the package root) whose sources compiled code is made of."""


def compiled_sources() -> list[Path]:
    """The ``*.py`` files of :data:`COMPILED`, sorted."""
    files: list[Path] = []
    for entry in COMPILED:
        path = _PKG / entry
        files += [path] if path.suffix == ".py" else list(path.rglob("*.py"))
    return sorted(files)


def _digest(files: list[Path]) -> str:
    h = hashlib.sha256()
    for path in files:
        h.update(str(path.relative_to(_PKG)).encode())
        h.update(path.read_bytes())
    return h.hexdigest()


@functools.lru_cache(maxsize=None)
def compiled_hash() -> str:
    """SHA-256 of the sources compiled code is made of (:func:`compiled_sources`: paths and contents).

    Names the kernel cache.  Computed once per process (Numba does not reload edited sources in a
    running process either).
    """
    return _digest(compiled_sources())


@functools.lru_cache(maxsize=None)
def source_hash() -> str:
    """SHA-256 of every ``*.py`` file of the package: the provenance of a result (sweeps, comparisons, reports)."""
    return _digest(sorted(_PKG.rglob("*.py")))


def cache_dir() -> Path:
    """Return the numba cache directory for the current package sources."""
    root = Path(os.environ.get("AUVTRACK_CACHE_DIR", Path.home() / ".cache" / "auvtrack"))
    wide = "-avx512" if _vecmath.WIDE else ""  # the lane kernels' 8-lane libmvec calls (AUVTRACK_LIBMVEC_AVX512)
    return root / f"numba-{numba.__version__}-{compiled_hash()[:16]}-{_vecmath.BACKEND}{wide}"


numba.config.CACHE_DIR = str(cache_dir())
LLVM_INLINE = os.environ.get("AUVTRACK_LLVM_INLINE", "1") != "0"


class PlainArgsDispatcher(CPUDispatcher):
    """A CPU dispatcher that compiles a call from compiled code for the non-literal argument types.

    Numba types a constant argument as a literal (``Literal[int](0)``, ``Literal[bool](True)``)
    and compiles the callee once per literal value: ``stage(..., True)`` and
    ``stage(..., not reuse)`` were two compilations of the whole stage with the law inlined, a
    counter starting at 0 another copy of ``log_row``, ``axis_baseline(..., i)`` three
    (``benchmarks/profile.md``).  This dispatcher compiles the plain types (``int64``, ``bool``)
    instead, once; a callee that only types with a literal (e.g. indexing a heterogeneous tuple
    by it) still gets its literal specialisation.  Functions inlined by Numba
    (``inline="always"``) are not dispatcher calls and keep seeing literals.
    """

    def get_call_template(self, args, kws):
        """Resolve a call for the unliteral argument types (falling back to the literal ones)."""
        from numba.core.errors import TypingError  # not ``errors``: the package's own ``errors`` module shadows it

        plain = tuple(types.unliteral(a) for a in args)
        plain_kws = {k: types.unliteral(v) for k, v in kws.items()}
        if plain != tuple(args) or plain_kws != kws:
            try:
                return super().get_call_template(plain, plain_kws)
            except TypingError:
                pass
        return super().get_call_template(args, kws)


def _plain(disp):
    if isinstance(disp, CPUDispatcher) and type(disp) is CPUDispatcher:
        disp.__class__ = PlainArgsDispatcher
    return disp


def njit(*args, **kwargs):
    """``numba.njit`` with the project's defaults: on-disk cache, NumPy error model (1/0 -> inf).

    Calls from compiled code compile the callee for plain (non-literal) argument types
    (:class:`PlainArgsDispatcher`).
    """
    kwargs.setdefault("cache", True)
    kwargs.setdefault("error_model", "numpy")
    if kwargs.get("inline") == "always" and LLVM_INLINE:
        kwargs.pop("inline")
        kwargs["forceinline"] = True
    out = numba.njit(*args, **kwargs)
    if args and callable(args[0]):
        return _plain(out)
    return lambda fn: _plain(out(fn))


def njit_noalloc(*args, **kwargs):
    """:func:`njit` for hot-path functions that never allocate: no reference counting.

    Numba increments and decrements the reference count of every array argument on entry and
    exit of a compiled function (an atomic operation each); for the small functions called at
    every RK4 stage this costs more than their arithmetic (the measurement: ``benchmarks/profile.md``;
    results bit-identical).  ``_nrt=False`` (a private Numba option) compiles the
    function without the runtime: an allocation added to it fails to compile instead of leaking.
    Remove the option here to revert every such function at once.
    """
    kwargs["_nrt"] = False
    return njit(*args, **kwargs)


_LLVM_INLINE: dict = {}


def llvm_inline(disp):
    """A copy of the compiled function ``disp`` that LLVM, not Numba, inlines into its callers.

    ``inline="always"`` makes Numba copy a function's typed IR into every caller, and type and
    lower each copy again; for a law of a few hundred lines inlined into two callers that was most
    of a kernel's compile time (``benchmarks/profile.md``).  The copy returned here is compiled once
    (``inline="never"``) and marked ``alwaysinline`` for LLVM (Numba's ``forceinline``), so each
    caller still gets the law's code in its own body, from one compilation.  Same operations,
    same numbers.  The copy is a distinct function (its own qualified name, hence its own cache
    files: Numba's cache key does not include the compile options) and is made once per process.

    Parameters
    ----------
    disp : numba dispatcher
        A function compiled with :func:`njit` or :func:`njit_noalloc`.

    Returns
    -------
    numba dispatcher
        The LLVM-inlined copy.
    """
    got = _LLVM_INLINE.get(disp)
    if got is not None:
        return got
    fn = disp.py_func
    copy = pytypes.FunctionType(fn.__code__, fn.__globals__, fn.__name__, fn.__defaults__, fn.__closure__)
    copy.__qualname__ = fn.__qualname__ + "__llvm_inline"
    copy.__module__ = fn.__module__
    copy.__doc__ = fn.__doc__
    options = {k: v for k, v in disp.targetoptions.items() if k not in ("inline", "nopython", "boundscheck")}
    options.pop("cache", None)
    options["forceinline"] = True
    out = njit(**options)(copy)
    _LLVM_INLINE[disp] = out
    return out

"""A plug-in plant's compiled functions bounds-checked, for the probe run of its first seconds.

A plant function that writes past an array's end (``dx[7] = ...`` in a 7-state plant) corrupts
memory in the compiled loop without a message.  :func:`bounds_checked_plant` gives a copy of the
plant module whose compiled functions (:data:`auvtrack.plant.registry.COMPILED`) are recompiled
with ``boundscheck=True``, each behind a guard: when one raises, the guard calls the function
once more as plain Python with the same arguments (in Numba's object mode) to learn its file,
line and error, records that (:func:`take_fault`) and raises, which ends the probe's kernel call.
The probe kernel (``KernelKey(..., checked=True)``) binds it for a plant that is not built in.
Only the plant's own functions are checked, not the compiled helpers they call.
"""
from __future__ import annotations

import functools
import traceback
import types
from typing import Any, Callable

__all__ = ["bounds_checked_plant", "take_fault", "PlantFunctionFault"]

_FAULTS: list[str] = []
_CHECKED: dict[str, types.ModuleType] = {}


class PlantFunctionFault(IndexError):
    """Raised by a guarded plant function after recording its fault (:func:`take_fault`)."""


def take_fault() -> str | None:
    """The first fault recorded since the last call (``file:line: rhs raised IndexError: ...``), or None; clears the record.

    Returns
    -------
    str or None
        One line naming the function, its file and line, and the error.
    """
    first = _FAULTS[0] if _FAULTS else None
    _FAULTS.clear()
    return first


def _record(name: str, fn: Callable, args: tuple) -> None:
    """Call the plant function ``fn`` as plain Python on ``args``; keep where it raised (called from object mode)."""
    from ..user_modules import first_line

    origin = getattr(fn, "__code__", None)
    args = tuple(_unbox(a) for a in args)
    try:
        fn(*args)
    except Exception as exc:  # noqa: BLE001 - what the user's plant raised, named with its file and line
        own = [f for f in traceback.extract_tb(exc.__traceback__)
               if origin is not None and f.filename == origin.co_filename]
        where = f"{own[-1].filename}:{own[-1].lineno}: " if own else ""
        _FAULTS.append(f"{where}{name} raised {first_line(exc)}")
        return
    _FAULTS.append(f"{origin.co_filename if origin else name}: {name} raised an exception in the compiled "
                   f"code (as plain Python it does not)")


_ARRAY = -7.0e300
"""First item of the tuple that stands for an array on its way to Python (:func:`_boxable`)."""
_DTYPES = ("float64", "int64", "bool", "int32", "float32")


def _boxable(a):
    """``a`` as Python may receive it from the loop: an array as (marker, address, shape, strides, dtype code).

    The loop's arrays may carry no reference count (``njit_noalloc``), so they cannot be handed to
    Python as arrays; :func:`_unbox` rebuilds a copy from the address.
    """
    return a


def _unbox(a):
    """The Python value of what :func:`_boxable` made (arrays copied from their address)."""
    import ctypes

    import numpy as np

    if isinstance(a, tuple) and len(a) == 5 and isinstance(a[0], float) and a[0] == _ARRAY:
        _, addr, shape, strides, code = a
        dtype = np.dtype(_DTYPES[code])
        span = sum((n - 1) * abs(st) for n, st in zip(shape, strides)) + dtype.itemsize if all(shape) else 0
        raw = (ctypes.c_char * span).from_address(addr) if span else b""
        return np.ndarray(shape, dtype, buffer=bytearray(raw), strides=strides).copy() if span else np.zeros(shape, dtype)
    if isinstance(a, tuple):
        return tuple(_unbox(x) for x in a)
    return a


@functools.cache
def _register_boxable() -> None:
    from numba.core import types as nbt
    from numba.extending import overload

    @overload(_boxable)
    def _boxable_impl(a):
        if isinstance(a, nbt.Array):
            code = _DTYPES.index(str(a.dtype)) if str(a.dtype) in _DTYPES else 0
            return lambda a: (_ARRAY, a.ctypes.data, a.shape, a.strides, code)
        if isinstance(a, nbt.BaseTuple):
            n = len(a)
            items = ", ".join(f"_boxable(a[{i}])" for i in range(n)) + ("," if n == 1 else "")
            scope: dict[str, Any] = {"_boxable": _boxable}
            exec(f"def impl(a):\n    return ({items})\n", scope)  # noqa: S102 - source made of indices only
            return scope["impl"]
        return lambda a: a


def _guard(name: str, dispatcher: Any):
    """The compiled plant function ``dispatcher`` recompiled bounds-checked, behind a guard that records a fault."""
    import inspect

    import numba

    _register_boxable()
    fn = dispatcher.py_func
    copy = types.FunctionType(fn.__code__, fn.__globals__, fn.__name__, fn.__defaults__, fn.__closure__)
    copy.__qualname__ = fn.__qualname__ + "__bounds_checked"
    copy.__module__ = fn.__module__
    checked = numba.njit(boundscheck=True, error_model="numpy")(copy)
    n = len(inspect.signature(fn).parameters)
    params = ", ".join(f"a{i}" for i in range(n))
    copies = "".join(f"        c{i} = _boxable(a{i})\n" for i in range(n))
    boxed = ", ".join(f"c{i}" for i in range(n)) + ("," if n == 1 else "")
    source = (f"def guarded({params}):\n"
              f"    ok = False\n"
              f"    try:\n"
              f"        value = checked({params})\n"
              f"        ok = True\n"
              f"    except Exception:\n"
              f"        pass\n"
              f"    if not ok:\n"
              f"{copies}"
              f"        with numba.objmode():\n"
              f"            _record(name, fn, ({boxed}))\n"
              f"        raise PlantFunctionFault('a plant function raised in the bounds-checked probe run')\n"
              f"    return value\n")
    scope = {"checked": checked, "numba": numba, "_boxable": _boxable, "_record": _record, "name": name, "fn": fn,
             "PlantFunctionFault": PlantFunctionFault}
    exec(source, scope)  # noqa: S102 - generated from the parameter count only; no user text reaches it
    return numba.njit(boundscheck=True, error_model="numpy")(scope["guarded"])


def bounds_checked_plant(module: types.ModuleType) -> types.ModuleType:
    """A copy of the plant ``module`` whose compiled functions are bounds-checked and guarded (made once per module).

    Parameters
    ----------
    module : module
        A plant module (its sizes set, :func:`auvtrack.plant.contract.with_sizes`).

    Returns
    -------
    module
        A module object with every attribute of ``module``, the compiled functions replaced.
    """
    from .registry import COMPILED

    key = f"{module.__name__}:{getattr(module, '__file__', '')}"
    got = _CHECKED.get(key)
    if got is None:
        got = types.ModuleType(f"{module.__name__}__bounds_checked")
        got.__dict__.update({k: v for k, v in vars(module).items() if k not in ("__name__", "__spec__", "__loader__")})
        for name in COMPILED:
            setattr(got, name, _guard(name, getattr(module, name)))
        _CHECKED[key] = got
    return got

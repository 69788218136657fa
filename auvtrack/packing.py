"""Packed float64 layouts: named fields and their sizes, declared once; the offsets are generated.

Compiled code receives parameters (gains, vehicle numbers, plant coefficients) as flat float64
arrays.  A layout names the fields of such an array once::

    GAINS = packed_layout("PIDGains", kp=1, ki=1, kd=1, kaw_ki=1, tau_max=3)

``GAINS`` is a named tuple of offsets (``GAINS.kp == 0``, ``GAINS.tau_max == 4``) with the total
``GAINS.size``; compiled code indexes with it (``cp[GAINS.tau_max + 1]``: Numba reads a global
named tuple as constants, so this costs what a literal index costs), and Python code packs and
unpacks with it (``GAINS.pack(kp=3.0, ...)``, ``GAINS.unpack(cp)``).  A last field of size
``None`` is a variable-length tail (e.g. the RBF network's centres).
"""
from __future__ import annotations

from collections import namedtuple
from typing import Any, Mapping

import numpy as np

__all__ = ["packed_layout", "PackedLayout"]


class PackedLayout:
    """Methods shared by every generated layout (mixed into its named tuple of offsets)."""

    __slots__ = ()
    sizes: Mapping[str, int | None] = {}
    layout_name: str = ""

    @property
    def names(self) -> tuple[str, ...]:
        """Field names in packing order."""
        return tuple(self.sizes)

    def span(self, name: str) -> slice:
        """Slice of field ``name`` in a packed array (the tail: to the end)."""
        start, size = getattr(self, name), self.sizes[name]
        return slice(start, None if size is None else start + size)

    def pack(self, dtype: Any = np.float64, **values: Any) -> np.ndarray:
        """An array holding ``values`` in this layout.

        Parameters
        ----------
        dtype : numpy dtype, optional
            Of the packed array (float64; int64 for integer settings).
        **values
            One value per field: a number for a field of size 1, a sequence of the field's size
            otherwise (any length for the tail).

        Returns
        -------
        numpy.ndarray
            The packed array, ``size`` long plus the tail.

        Raises
        ------
        ValueError
            A field missing, unknown, or of the wrong size (the message names it).
        """
        unknown = sorted(set(values) - set(self.sizes))
        missing = [n for n in self.sizes if n not in values]
        if unknown or missing:
            raise ValueError(f"{self.layout_name}: " + "; ".join(
                ([f"unknown field(s) {', '.join(unknown)}"] if unknown else [])
                + ([f"missing field(s) {', '.join(missing)}"] if missing else [])))
        parts = []
        for name, size in self.sizes.items():
            v = np.atleast_1d(np.asarray(values[name], dtype=dtype)).ravel()
            if size is not None and v.size != size:
                raise ValueError(f"{self.layout_name}.{name}: needs {size} value(s) (got {v.size})")
            parts.append(v)
        return np.concatenate(parts) if parts else np.zeros(0, dtype=dtype)

    def unpack(self, packed: np.ndarray) -> dict[str, Any]:
        """The fields of a packed array: floats for size-1 fields, arrays otherwise.

        Parameters
        ----------
        packed : numpy.ndarray
            An array in this layout.

        Returns
        -------
        dict
            Field name -> value.
        """
        a = np.asarray(packed, dtype=np.float64)
        if a.size < self.size:
            raise ValueError(f"{self.layout_name}: needs at least {self.size} values (got {a.size})")
        return {n: (float(a[getattr(self, n)]) if s == 1 else a[self.span(n)].copy()) for n, s in self.sizes.items()}


def packed_layout(name: str, **sizes: int | None) -> Any:
    """Declare a packed layout: fields in order with their sizes; offsets and the total size generated.

    Parameters
    ----------
    name : str
        Name of the layout (a Python identifier), for messages.
    **sizes
        Field name -> number of float64 entries (>= 1); the last field may be ``None``: a
        variable-length tail.

    Returns
    -------
    PackedLayout
        A named tuple of the fields' offsets and ``size`` (the fixed part's length), with the
        methods of :class:`PackedLayout`.

    Raises
    ------
    ValueError
        A size that is not a positive integer, a tail that is not last, or the name ``size``.
    """
    if "size" in sizes:
        raise ValueError(f"{name}: 'size' is reserved for the total")
    offsets, at = [], 0
    items = list(sizes.items())
    for i, (field, n) in enumerate(items):
        if n is None:
            if i != len(items) - 1:
                raise ValueError(f"{name}.{field}: only the last field may have a variable size")
        elif isinstance(n, bool) or not isinstance(n, int) or n < 1:
            raise ValueError(f"{name}.{field}: size must be a positive integer (got {n!r})")
        offsets.append(at)
        at += n or 0
    base = namedtuple(name, [f for f, _ in items] + ["size"])
    cls = type(name, (PackedLayout, base), {"__slots__": (), "sizes": dict(sizes), "layout_name": name})
    return cls(*offsets, at)

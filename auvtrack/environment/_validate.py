"""Field validation shared by the disturbance components (one-line ``ValueError`` messages)."""
from __future__ import annotations

import math
import numbers


def real(kind: str, name: str, value, *, lo: float = -math.inf, lo_open: bool = False,
         allow_inf: bool = False, rng_text: str = "a finite real number") -> float:
    """Return ``value`` as float or raise ``ValueError`` naming ``kind.name`` and ``rng_text``.

    Strings are accepted only for infinity ("inf", "infinity"), so that a JSON description with
    ``"inf"`` can be read back.
    """
    if isinstance(value, str) and allow_inf and value.strip().lower() in ("inf", "+inf", "infinity"):
        value = math.inf
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ValueError(f"{kind}.{name} must be {rng_text}, got {value!r}")
    x = float(value)
    ok = not math.isnan(x) and (allow_inf and x == math.inf or math.isfinite(x))
    ok = ok and (x > lo if lo_open else x >= lo)
    if not ok:
        raise ValueError(f"{kind}.{name} must be {rng_text}, got {value!r}")
    return x


def vector(kind: str, name: str, value, size: int, *, lo: float = -math.inf,
           rng_text: str = "finite numbers") -> tuple[float, ...]:
    """Return ``value`` as a tuple of ``size`` floats, each finite and >= ``lo``, else ``ValueError``."""
    try:
        items = list(value)
    except TypeError:
        items = None
    if items is None or len(items) != size:
        raise ValueError(f"{kind}.{name} must be a sequence of {size} {rng_text}, got {value!r}")
    out = []
    for v in items:
        if isinstance(v, bool) or not isinstance(v, numbers.Real) or not math.isfinite(float(v)) \
                or float(v) < lo:
            raise ValueError(f"{kind}.{name} must be a sequence of {size} {rng_text}, got {value!r}")
        out.append(float(v))
    return tuple(out)

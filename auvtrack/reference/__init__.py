"""Reference trajectories eta_d(t) = [xd, yd, zd] (m, NED, z down) with exact derivatives.

Kinds (scenario ``kind`` string -> class):

* ``"helix"``: :class:`Helix`, the paper's Section 4 reference by default;
* ``"circle"``: :class:`Circle`, horizontal circle at constant depth;
* ``"line"``: :class:`Line`, constant-velocity straight line;
* ``"lawnmower"``: :class:`Lawnmower`, survey legs joined by semicircular turns;
* ``"waypoints"``: :class:`Waypoints`, natural cubic spline through points.

Every kind packs into one ``float64`` array (:meth:`Reference.pack`) evaluated by the compiled,
allocation-free :func:`eval_reference` (layout in :mod:`auvtrack.reference.kernel`).
"""
from __future__ import annotations

from dataclasses import fields as _fields

from .analytic import Circle, Helix, Line
from .base import Reference
from .kernel import eval_reference, eval_reference_batch
from .lawnmower import Lawnmower
from .spline import Waypoints

__all__ = [
    "Reference", "Helix", "Circle", "Line", "Lawnmower", "Waypoints",
    "REFERENCES", "build_reference", "eval_reference", "eval_reference_batch",
]

REFERENCES: dict[str, type[Reference]] = {
    cls.kind: cls for cls in (Helix, Circle, Line, Lawnmower, Waypoints)
}


def build_reference(spec: dict) -> Reference:
    """Build a reference from a scenario spec.

    Parameters
    ----------
    spec : dict
        ``{"kind": <one of REFERENCES>, **fields}``; omitted fields take the class defaults.

    Returns
    -------
    Reference
        The reference, with analytic first and second derivatives.

    Raises
    ------
    ValueError
        Unknown or missing ``kind``, unknown or missing fields, or a field out of range.
    """
    kw = dict(spec)
    kind = kw.pop("kind", None)
    if not isinstance(kind, str) or kind not in REFERENCES:
        raise ValueError(f"reference.kind must be one of {sorted(REFERENCES)}, got {kind!r}")
    cls = REFERENCES[kind]
    known = {f.name for f in _fields(cls)}
    unknown = sorted(set(kw) - known)
    if unknown:
        raise ValueError(f"unknown field(s) {unknown} for reference kind {kind!r}; allowed: {sorted(known)}")
    try:
        return cls(**kw)
    except TypeError as exc:  # a required field is missing
        raise ValueError(f"reference kind {kind!r}: {exc}") from None

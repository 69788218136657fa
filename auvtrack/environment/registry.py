"""Registry of disturbance kinds and construction from plain dicts (scenario files, JSON).

``build_disturbance({"kind": "pulse", "start": 10, "duration": 5, "force": [5, 0, 0, 0, 0]})``;
``build_disturbance(c.describe()) == c`` for every component ``c``.
"""
from __future__ import annotations

from dataclasses import fields
from importlib import import_module


def _component(path: str) -> type:
    module, name = path.split(":")
    return getattr(import_module(f"{__package__}.{module}"), name)


COMPONENTS: tuple[type, ...] = tuple(_component(path) for path in (
    "disturbances:PaperDisturbance",
    "disturbances:Pulse",
    "current:GaussMarkovCurrent",
))
"""The registered components, ``module:Class`` (adding one: its module plus one line here)."""

EFFECTS = ("force", "current")


def check_component(cls: type) -> type:
    """Check a component class against the contract (``docs/architecture.md``, "Adding an environment component").

    Parameters
    ----------
    cls : type
        A frozen dataclass with ``KIND``, ``CODE``, ``EFFECT``, ``TIME_ONLY``, ``TERM``,
        ``describe`` and ``pack_row``.

    Returns
    -------
    type
        ``cls``.

    Raises
    ------
    ValueError
        One line naming the class and the missing or wrong piece.
    """
    import sys

    from numba.core.dispatcher import Dispatcher

    where = f"{cls.__module__}.{cls.__name__}"
    missing = [n for n in ("KIND", "CODE", "EFFECT", "TIME_ONLY", "TERM", "describe", "pack_row") if not hasattr(cls, n)]
    if missing:
        raise ValueError(f"{where} does not define {', '.join(missing)}")
    if not (isinstance(cls.KIND, str) and cls.KIND.isidentifier()):
        raise ValueError(f"{where}: KIND must be an identifier (got {cls.KIND!r})")
    if isinstance(cls.CODE, bool) or not isinstance(cls.CODE, float) or not cls.CODE > 0:
        raise ValueError(f"{where}: CODE must be a float > 0 (got {cls.CODE!r})")
    if cls.EFFECT not in EFFECTS:
        raise ValueError(f"{where}: EFFECT must be one of {', '.join(EFFECTS)} (got {cls.EFFECT!r})")
    term = getattr(sys.modules[cls.__module__], cls.TERM, None)
    if not isinstance(term, Dispatcher):
        raise ValueError(f"{where}: TERM must name a compiled function of its module (got {cls.TERM!r})")
    return cls


def _registry() -> dict[str, type]:
    out: dict[str, type] = {}
    codes: dict[float, str] = {}
    for cls in COMPONENTS:
        check_component(cls)
        if cls.KIND in out or cls.CODE in codes:
            raise ValueError(f"{cls.__name__}: KIND {cls.KIND!r} or CODE {cls.CODE} is taken")
        out[cls.KIND] = cls
        codes[cls.CODE] = cls.KIND
    return out


DISTURBANCES: dict[str, type] = _registry()
"""``kind`` -> component class."""


def build_disturbance(spec: dict):
    """Build a component from ``spec`` = ``{"kind": ..., **fields}``.

    Parameters
    ----------
    spec : dict
        ``kind`` is one of :data:`DISTURBANCES`; the other keys are that class's fields.  The
        key ``stream`` (written by ``DisturbanceTables.describe``) is ignored.

    Returns
    -------
    PaperDisturbance, Pulse or GaussMarkovCurrent
        The validated component.

    Raises
    ------
    ValueError
        Unknown kind, unknown or missing fields, or an invalid value.
    """
    spec = dict(spec)
    kind = spec.pop("kind", None)
    spec.pop("stream", None)
    if kind not in DISTURBANCES:
        raise ValueError(f"disturbance kind must be one of {sorted(DISTURBANCES)}, got {kind!r}")
    cls = DISTURBANCES[kind]
    names = {f.name for f in fields(cls)}
    unknown = sorted(set(spec) - names)
    if unknown:
        raise ValueError(f"unknown field(s) {unknown} for disturbance {kind!r}; allowed: {sorted(names)}")
    try:
        return cls(**spec)
    except TypeError as exc:  # missing required field
        raise ValueError(f"disturbance {kind!r}: {exc}") from None

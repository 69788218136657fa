"""Vehicle presets: model numbers stored as data, each with its unit and source.

Presets live in ``auvtrack/data/vehicles/*.toml``; each number is a table with ``value``,
``unit`` and ``source`` so that ``run.json`` and the docs can cite where every parameter came
from.  Registering a preset means adding its file: :func:`available` lists the files.  Shipped:

* ``paper`` -- the torpedo AUV of the paper's Section 4 (ERRATA 5; partly assumed);
* ``remus100`` -- the REMUS 100 (Prestero 2001) reduced to the diagonal 5-DOF form, damping
  linearised at a speed U0: a *reduced* preset, computed by :mod:`auvtrack.vehicle.reduction`
  from the 6-DOF ``remus100_prestero`` data (``get_preset("remus100", u0=...)``; reduction in
  ``docs/vehicles.md``).

A reduced preset also knows its actuators' *reach* at U0: the tau its fins and propeller produce
at their limits in straight running at U0 (``reach``, with its source), computed by the 6-DOF
model it is reduced from; the plant contributes that computation (:func:`register_reach`), and a
preset stored as numbers (``paper``) has none.  The gain design of
:mod:`auvtrack.control.design` uses it.

Other design models come from *preset sources* that plants register (:func:`register_source`):
the 6-DOF truths contribute the reduction of a Fossen-type torpedo
(:mod:`auvtrack.plant.sixdof.torpedo_reduction`), so that a preset may also be a vehicle file's path
(``.toml``) or the name of a shipped Fossen-type 6-DOF file.  This package never imports a plant.

:data:`SHIPPED` names them; a test checks that each one is present and valid.  Use :func:`get_preset` to read one and :func:`pack_vehicle` to build the packed ``vp``
array of :mod:`auvtrack.vehicle.params`.
"""
from __future__ import annotations

import copy
import functools
import tomllib
from dataclasses import dataclass
from typing import Callable
from importlib import resources

import numpy as np

from .params import VP

_FIELDS = ("m", "d", "wgml", "l")
SHIPPED: tuple[str, ...] = ("paper", "remus100")


@dataclass(frozen=True)
class VehiclePreset:
    """Nominal 5-DOF vehicle: diagonal inertia, linear damping, restoring coefficient, offset.

    Attributes
    ----------
    name, description : str
        Identifier and one-line description.
    m : tuple of 5 float
        m11, m22, m33 (kg) and m44, m55 (kg m^2), rigid body plus added mass.
    d : tuple of 5 float
        Linear damping d11, d22, d33 (N s/m) and d44, d55 (N m s/rad).
    wgml : float
        rho g nabla GM_L, pitch restoring coefficient (N m).
    l : float
        Virtual-point offset ell of eq. (2) (m).
    sources : dict
        Per field: ``{"unit": ..., "source": ...}``.
    u0 : float or None
        Linearisation speed (m/s) of a reduced preset; None for a preset stored as numbers.
    reach : tuple of 3 float or None
        (tau_u (N), tau_q, tau_r (N m)): what the actuators produce at their limits in straight
        running at ``u0`` (the smaller magnitude of the two limits per axis); None when unknown.
        Its source is ``sources["reach"]``.
    """

    name: str
    description: str
    m: tuple[float, ...]
    d: tuple[float, ...]
    wgml: float
    l: float
    sources: dict
    u0: float | None = None
    reach: tuple[float, float, float] | None = None


def available() -> list[str]:
    """Names of the presets shipped with the package."""
    return list(_names())


# Package data does not change while a process runs: list and parse each file once (preparing
# a scenario reads its preset twice; parsing was most of the Python-side preparation time).
@functools.lru_cache(maxsize=1)
def _names() -> tuple[str, ...]:
    root = resources.files("auvtrack") / "data" / "vehicles"
    return tuple(sorted(p.name[:-5] for p in root.iterdir() if p.name.endswith(".toml")))


@functools.lru_cache(maxsize=None)
def _parsed(name: str) -> dict:
    return tomllib.loads((resources.files("auvtrack") / "data" / "vehicles" / f"{name}.toml").read_text())


@dataclass(frozen=True)
class PresetSource:
    """A contributed family of design presets (e.g. the reductions of torpedo vehicle files).

    Attributes
    ----------
    names : callable
        ``names() -> tuple[str, ...]``: the shipped names it offers.
    accepts : callable
        ``accepts(name) -> bool``: whether a name (or a path) is one of its presets.
    get : callable
        ``get(name, u0) -> VehiclePreset``: the preset, reduced at ``u0`` (None: its default).
    """

    names: Callable[[], tuple[str, ...]]
    accepts: Callable[[object], bool]
    get: Callable[[str, float | None], "VehiclePreset"]


SOURCES: list[PresetSource] = []
"""Registered preset sources, asked in order after the shipped files."""


def register_source(source: PresetSource) -> PresetSource:
    """Add a source of design presets (:class:`PresetSource`).

    Parameters
    ----------
    source : PresetSource
        The source.

    Returns
    -------
    PresetSource
        ``source``.
    """
    SOURCES.append(source)
    return source


REACH: list[Callable[[str, float], tuple[tuple[float, float, float], str] | None]] = []
"""Registered reach computations: ``fn(model, u0) -> (reach, source)`` or None for a model it does not know."""


def register_reach(fn: Callable[[str, float], tuple[tuple[float, float, float], str] | None]) -> None:
    """Add a computation of the actuators' reach of a 6-DOF model at a speed (see :data:`REACH`).

    Parameters
    ----------
    fn : callable
        ``fn(model, u0) -> ((tau_u, tau_q, tau_r), source)``, or None for a model it does not know.
    """
    REACH.append(fn)


def reach_of(model: str, u0: float) -> tuple[tuple[float, float, float], str] | None:
    """The reach of a 6-DOF model at ``u0`` from the first registered computation that knows it.

    Parameters
    ----------
    model : str
        A 6-DOF model (e.g. ``remus100_prestero``) or vehicle file.
    u0 : float
        Speed, m/s.

    Returns
    -------
    tuple or None
        ((tau_u (N), tau_q, tau_r (N m)), source), or None when no computation knows the model.
    """
    return next((r for r in (fn(model, u0) for fn in REACH) if r is not None), None)


def _source_of(name: object) -> PresetSource | None:
    return next((src for src in SOURCES if src.accepts(name)), None)


def contributed() -> tuple[str, ...]:
    """The preset names the registered sources ship (besides paths they accept)."""
    return tuple(n for src in SOURCES for n in src.names())


def is_reduced(name: str) -> bool:
    """True for a preset computed from a 6-DOF model at a linearisation speed (e.g. ``remus100``, a vehicle file)."""
    return _source_of(name) is not None or (name in available() and "reduction_of" in _parsed(name))


def get_preset(name: str, u0: float | None = None) -> VehiclePreset:
    """Load a vehicle preset from ``auvtrack/data/vehicles``.

    Parameters
    ----------
    name : str
        Preset name, e.g. ``"paper"``, or a name or path a registered source accepts (a shipped
        Fossen-type torpedo, a vehicle file ``.toml``).
    u0 : float, optional
        Linearisation speed (m/s) of a reduced preset (default: the file's ``u0``); refused for
        a preset stored as numbers.

    Returns
    -------
    VehiclePreset
        The preset's numbers with their sources.

    Raises
    ------
    KeyError
        If there is no such preset (the message names the available ones).
    ValueError
        ``u0`` given for a preset that is not reduced, or out of range; a vehicle file that
        breaks its rules (the message names the file and the field).
    """
    source = _source_of(name)
    if source is not None:
        return source.get(name, u0)
    if name not in available():
        raise KeyError(f"unknown vehicle preset {name!r}; choose one of {available() + list(contributed())} "
                       f"or a vehicle file (.toml)")
    raw = copy.deepcopy(_parsed(name))  # callers own what they get
    if "reduction_of" in raw:
        from .reduction import reduce_prestero  # a reduced preset: numbers from its 6-DOF data
        speed = float(raw["u0"]["value"]) if u0 is None else u0
        red = reduce_prestero(speed)
        reach = reach_of(raw["reduction_of"], speed)
        extra = {} if reach is None else {"reach": {"unit": "N, N m, N m", "source": reach[1]}}
        return VehiclePreset(
            name=raw["name"], description=raw.get("description", ""), m=red["m"], d=red["d"],
            wgml=red["wgml"], l=float(raw["l"]["value"]),
            sources={**red["sources"], "l": {"unit": raw["l"]["unit"], "source": raw["l"]["source"]}, **extra},
            u0=speed, reach=None if reach is None else reach[0])
    if u0 is not None:
        raise ValueError(f"vehicle.u0: only a reduced preset has a linearisation speed; {name!r} is stored as numbers (got {u0!r})")
    vals = {k: raw[k]["value"] for k in _FIELDS}
    return VehiclePreset(
        name=raw["name"],
        description=raw.get("description", ""),
        m=tuple(float(x) for x in vals["m"]),
        d=tuple(float(x) for x in vals["d"]),
        wgml=float(vals["wgml"]),
        l=float(vals["l"]),
        sources={k: {"unit": raw[k]["unit"], "source": raw[k]["source"]} for k in _FIELDS},
    )


def pack_vehicle(m, d, wgml: float, l: float, c_scale: float = 1.0) -> np.ndarray:
    """Pack vehicle numbers into the ``vp`` layout of :mod:`auvtrack.vehicle.params`."""
    vp = np.zeros(VP.size)
    vp[VP.m : VP.m + 5] = m
    vp[VP.d : VP.d + 5] = d
    vp[VP.wgml] = wgml
    vp[VP.ell] = l
    vp[VP.cscale] = c_scale
    return vp


def vehicle_arrays(sc) -> tuple[np.ndarray, np.ndarray, dict]:
    """Nominal and true packed 5-DOF vehicles of a scenario, and their record.

    Parameters
    ----------
    sc : Scenario
        A validated scenario: ``[vehicle]`` (preset and overrides) and ``[uncertainty]``.

    Returns
    -------
    vp_nom, vp_true : numpy.ndarray
        Packed vehicles (:mod:`auvtrack.vehicle.params`): the nominal one that controllers use, and
        the true one with the uncertainty applied (M, D, G scaled by 1 + Delta, C by 1 + Delta C).
    record : dict
        Preset, numbers, sources and the true plant's numbers, for ``run.json``.
    """
    pre = get_preset(sc.vehicle.preset, u0=getattr(sc.vehicle, "u0", None))
    v = sc.vehicle
    m = np.array(v.m if v.m is not None else pre.m, dtype=float)
    d = np.array(v.d if v.d is not None else pre.d, dtype=float)
    wgml = float(v.wgml if v.wgml is not None else pre.wgml)
    ell = float(v.l if v.l is not None else pre.l)
    u = sc.uncertainty
    vp_nom = pack_vehicle(m, d, wgml, ell, 1.0)
    vp_true = pack_vehicle(m * (1 + u.M), d * (1 + u.D), wgml * (1 + u.G), ell, 1.0 + u.C)
    record = {"preset": pre.name, "m": m.tolist(), "d": d.tolist(), "wgml": wgml, "l": ell,
              "sources": pre.sources, **({"u0": pre.u0} if pre.u0 is not None else {}),
              **({"reach": list(pre.reach)} if pre.reach is not None else {}),
              "true_plant": {"m": (m * (1 + u.M)).tolist(), "d": (d * (1 + u.D)).tolist(),
                             "wgml": wgml * (1 + u.G), "c_scale": 1.0 + u.C}}
    return vp_nom, vp_true, record

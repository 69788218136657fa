"""A Fossen-type torpedo AUV from a user's TOML file: every field checked, with unit and range.

A *vehicle file* has the form of ``auvtrack/data/vehicles/6dof/remus100_fossen.toml``: sections
``[hull]``, ``[damping]``, ``[fins]``, ``[propeller]``, ``[actuators]`` and an optional
``[design]``, each entry ``key = { value = ..., unit = "...", source = "...", note = "..." }``
(``note`` optional).  The numbers feed the Fossen (2021, Section 8.4.2) torpedo model of
:mod:`auvtrack.plant.sixdof.fossen` (6-DOF truth) and its 5-DOF reduction
(:mod:`auvtrack.plant.sixdof.torpedo_reduction`).  :data:`FIELDS` lists every allowed field with
its unit, range and meaning (docs/vehicles.md, "Your own vehicle").

Rules: every required field is present, its ``unit`` is the one of :data:`FIELDS` (no unit
conversion), its value is a finite number in range (``inf`` only for the rate limits), the
vector fields have three items; unknown sections, fields and entry keys are refused.  A bad file
raises a one-line ``ValueError`` naming the file and the field, e.g.
``my_auv.toml: fins.S_fin: must be > 0 m^2 (got -1)``.

References (in a vehicle file): [F21] Fossen, T. I. (2021), Handbook of Marine Craft
Hydrodynamics and Motion Control, 2nd ed., Wiley, Section 8.4.2; the Python Vehicle Simulator
``remus100.py`` (the model's reference implementation).
"""
from __future__ import annotations

import functools
import hashlib
import math
import os
import tomllib
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from .truth_presets import Preset6

SECTIONS = ("hull", "damping", "fins", "propeller", "actuators", "design")
ENTRY_KEYS = ("value", "unit", "source", "note")
TOP_KEYS = ("name", "description", *SECTIONS)


@dataclass(frozen=True)
class FieldSpec:
    """Unit, range and meaning of one field of a vehicle file.

    Attributes
    ----------
    unit : str
        The unit the file must state (exactly).
    lo, hi : float
        Range of the value (each component of a vector).
    lo_open, hi_open : bool
        Whether ``lo`` (``hi``) itself is excluded.
    size : int
        1 for a number, 3 for a vector.
    integer : bool
        The value must be a whole number.
    default : float or None
        Value used when the field is absent (None: the field is required).
    allow_inf : bool
        ``inf`` (no limit) is accepted.
    text : str
        One-line meaning.
    """

    unit: str
    lo: float
    hi: float
    lo_open: bool = True
    hi_open: bool = False
    size: int = 1
    integer: bool = False
    default: float | None = None
    allow_inf: bool = False
    text: str = ""

    def range_text(self) -> str:
        """The allowed range as a phrase, e.g. ``"> 0 m^2"`` or ``"in (0, 1] -"``."""
        unit = f" {self.unit}" if self.unit else ""
        if math.isinf(self.hi):
            return f"{'>' if self.lo_open else '>='} {self.lo:g}{unit}"
        if math.isinf(self.lo):
            return f"{'<' if self.hi_open else '<='} {self.hi:g}{unit}"
        a, b = ("(" if self.lo_open else "["), (")" if self.hi_open else "]")
        return f"in {a}{self.lo:g}, {self.hi:g}{b}{unit}"

    def contains(self, x: float) -> bool:
        """Whether the number ``x`` lies in the range."""
        above = x > self.lo if self.lo_open else x >= self.lo
        below = x < self.hi if self.hi_open else x <= self.hi
        return above and below


INF = math.inf
FIELDS: dict[str, FieldSpec] = {
    # hull: a prolate spheroid of semi-axes a = L/2, b = diam/2 (F21 Section 8.4.2)
    "hull.rho": FieldSpec("kg/m^3", 950.0, 1100.0, False, False, text="water density"),
    "hull.g": FieldSpec("m/s^2", 9.7, 9.9, False, False, text="acceleration of gravity"),
    "hull.L": FieldSpec("m", 0.1, 50.0, False, False, text="length (spheroid a = L/2)"),
    "hull.diam": FieldSpec("m", 0.0, 10.0, text="diameter (spheroid b = diam/2), < L"),
    "hull.mass": FieldSpec("kg", 0.0, 1e6, default=None, text="mass in air; absent: the spheroid's displaced mass (neutral)"),
    "hull.buoyancy": FieldSpec("N", 0.0, 1e7, default=None, text="buoyancy B; absent: B = W (trimmed neutral)"),
    "hull.S_ratio": FieldSpec("-", 0.0, 1.0, text="planform area S = S_ratio L diam"),
    "hull.r_g": FieldSpec("m", -50.0, 50.0, False, False, size=3, text="CG w.r.t. the CO (x, y, z; z down)"),
    "hull.r_b": FieldSpec("m", -50.0, 50.0, False, False, size=3, text="CB w.r.t. the CO"),
    "hull.Cd": FieldSpec("-", 0.0, 2.0, text="axial drag coefficient on the frontal area pi b^2"),
    "hull.r44": FieldSpec("-", 0.0, 1.0, False, False, text="added roll inertia A44 = r44 Ix"),
    "hull.oswald_e": FieldSpec("-", 0.0, 1.0, text="Oswald efficiency number of the hull as a wing"),
    "hull.Cd_2D": FieldSpec("-", 0.0, 3.0, text="2-D cross-flow drag coefficient (Hoerner)"),
    "hull.n_strips": FieldSpec("-", 1.0, 1000.0, False, False, integer=True, text="strips of the cross-flow drag sum"),
    # low-speed linear damping (F21 Section 8.4.2)
    "damping.T_surge": FieldSpec("s", 0.0, 1e4, text="surge time constant, D11 = M11/T_surge exp(-3 U_r)"),
    "damping.T_sway": FieldSpec("s", 0.0, 1e4, text="sway time constant, D22 = M22/T_sway exp(-3 U_r)"),
    "damping.T_heave": FieldSpec("s", 0.0, 1e4, text="heave time constant, D33 = M33/T_heave"),
    "damping.zeta_roll": FieldSpec("-", 0.0, 10.0, False, False, text="roll damping ratio, D44 = 2 zeta w_roll M44"),
    "damping.zeta_pitch": FieldSpec("-", 0.0, 10.0, False, False, text="pitch damping ratio, D55 = 2 zeta w_pitch M55"),
    "damping.T_yaw": FieldSpec("s", 0.0, 1e4, text="yaw time constant, D66 = M66/T_yaw"),
    # fins: rudder (2 fins) and stern planes (2 fins) at x_fin
    "fins.S_fin": FieldSpec("m^2", 0.0, INF, text="area of one fin (a pair: 2 S_fin)"),
    "fins.CL_delta_r": FieldSpec("1/rad", 0.0, 20.0, text="rudder lift coefficient"),
    "fins.CL_delta_s": FieldSpec("1/rad", 0.0, 20.0, text="stern-plane lift coefficient"),
    "fins.x_fin": FieldSpec("m", -50.0, 0.0, False, True, text="fin x-position w.r.t. the CO, aft (< 0), >= -L"),
    # propeller: linear fits of the Wageningen KT, KQ in the advance number
    "propeller.D_prop": FieldSpec("m", 0.0, 10.0, text="propeller diameter"),
    "propeller.t_prop": FieldSpec("-", 0.0, 1.0, False, True, text="thrust deduction number"),
    "propeller.wake": FieldSpec("-", 0.0, 1.5, text="advance speed Va = wake U"),
    "propeller.Ja_max": FieldSpec("-", 0.0, 10.0, text="advance number of the fit's second point"),
    "propeller.KT_0": FieldSpec("-", 0.0, 2.0, text="thrust coefficient at J = 0"),
    "propeller.KQ_0": FieldSpec("-", 0.0, 1.0, text="torque coefficient at J = 0"),
    "propeller.KT_max": FieldSpec("-", 0.0, 2.0, False, False, text="thrust coefficient at J = Ja_max"),
    "propeller.KQ_max": FieldSpec("-", 0.0, 1.0, False, False, text="torque coefficient at J = Ja_max"),
    "propeller.roll_torque_scale": FieldSpec("-", 0.0, 1.0, False, False, text="fraction of the propeller torque acting in roll"),
    # actuators: first-order lags with limits (sixdof/actuators.py)
    "actuators.delta_max": FieldSpec("rad", 0.0, math.pi / 2, text="fin angle limit"),
    "actuators.n_max": FieldSpec("rpm", 0.0, 1e5, text="propeller speed limit"),
    "actuators.T_delta": FieldSpec("s", 0.0, 100.0, text="fin time constant"),
    "actuators.T_n": FieldSpec("s", 0.0, 100.0, text="propeller time constant"),
    "actuators.delta_rate_max": FieldSpec("rad/s", 0.0, INF, allow_inf=True, text="fin rate limit (inf: none)"),
    "actuators.n_rate_max": FieldSpec("rpm/s", 0.0, INF, allow_inf=True, text="propeller rate limit (inf: none)"),
    # the reduced 5-DOF design model (vehicle.preset = this file)
    "design.l": FieldSpec("m", 0.0, 10.0, default=1.0, text="virtual-point offset ell of the 5-DOF model"),
    "design.u0": FieldSpec("m/s", 0.05, 3.0, False, False, default=1.5,
                           text="linearisation speed when no scenario gives one"),
}
DEFAULT_SOURCES = {
    "design.l": "default: 1 m, the virtual-point offset of the remus100 preset (a controller choice, not a "
                "vehicle property; set [design] l or vehicle.l)",
    "design.u0": "default: 1.5 m/s, used only without a scenario (a scenario linearises at its reference's speed)",
}


def is_vehicle_ref(name: object) -> bool:
    """Whether a preset name is a path to a vehicle file (it ends with ``.toml``)."""
    return isinstance(name, str) and name.strip().lower().endswith(".toml")


def resolve_path(ref: str, base_dir: str | os.PathLike | None = None) -> str:
    """The absolute path of a vehicle file reference.

    Parameters
    ----------
    ref : str
        A ``.toml`` path; ``~`` is expanded.
    base_dir : str or path-like, optional
        Folder a relative path is relative to (default: the current working directory).

    Returns
    -------
    str
        The absolute, normalised path (the file need not exist).
    """
    path = Path(ref.strip()).expanduser()
    if not path.is_absolute():
        path = Path(base_dir if base_dir is not None else Path.cwd()) / path
    return os.path.normpath(str(path.absolute()))


def anchor_vehicle_files(data: dict, folder: str | os.PathLike) -> dict:
    """Make relative vehicle-file paths of a scenario file's data relative to the file's folder.

    ``plant.preset`` and ``vehicle.preset`` ending in ``.toml`` are made absolute against
    ``folder``; paths given in a dict or by ``--set`` are left for the schema, which resolves them
    against the current working directory.

    Parameters
    ----------
    data : dict
        Parsed scenario (modified in place).
    folder : str or path-like
        Folder of the scenario file.

    Returns
    -------
    dict
        ``data``.
    """
    if not isinstance(data, dict):
        return data
    for section in ("plant", "vehicle"):
        table = data.get(section)
        if isinstance(table, dict) and is_vehicle_ref(table.get("preset")):
            table["preset"] = resolve_path(table["preset"], Path(folder).resolve())
    return data


def label(path: str) -> str:
    """A path as shown in messages: relative to the working directory when below it, else absolute."""
    try:
        rel = os.path.relpath(path)
    except ValueError:
        return path
    return path if rel.startswith("..") else rel


def shipped_dir() -> Path:
    """Folder of the 6-DOF data files shipped with the package."""
    return Path(str(resources.files("auvtrack") / "data" / "vehicles" / "6dof"))


def _fmt(x) -> str:
    if isinstance(x, float) and math.isfinite(x) and x == int(x) and abs(x) < 1e15:
        return str(int(x))
    return repr(x) if isinstance(x, str) else (f"{x:g}" if isinstance(x, float) else str(x))


def _number(where: str, spec: FieldSpec, x) -> float:
    if isinstance(x, bool) or not isinstance(x, (int, float)):
        raise ValueError(f"{where}: must be a number in {spec.unit or '-'} (got {_fmt(x)})")
    x = float(x)
    if math.isnan(x) or (math.isinf(x) and not (spec.allow_inf and x > 0)):
        raise ValueError(f"{where}: must be a finite number (got {_fmt(x)})")
    if not spec.contains(x):
        raise ValueError(f"{where}: must be {spec.range_text()} (got {_fmt(x)})")
    if spec.integer and x != int(x):
        raise ValueError(f"{where}: must be a whole number (got {_fmt(x)})")
    return x


def _entry(tag: str, key: str, spec: FieldSpec, e) -> float | tuple[float, ...]:
    where = f"{tag}: {key}"
    if not isinstance(e, dict):
        raise ValueError(f"{where}: must be a table {{ value = ..., unit = \"{spec.unit}\", source = \"...\" }} "
                         f"(got {_fmt(e)})")
    extra = [k for k in e if k not in ENTRY_KEYS]
    if extra:
        raise ValueError(f"{where}.{extra[0]}: unknown key (allowed: {', '.join(ENTRY_KEYS)})")
    for k in ("value", "unit", "source"):
        if k not in e:
            raise ValueError(f"{where}.{k}: required key is missing")
    for k in ("unit", "source", "note"):
        if k in e and not isinstance(e[k], str):
            raise ValueError(f"{where}.{k}: must be a string (got {_fmt(e[k])})")
    if not e["source"].strip():
        raise ValueError(f"{where}.source: must name where the number comes from (got '')")
    if e["unit"].strip() != spec.unit:
        raise ValueError(f"{where}.unit: must be {spec.unit!r} (got {e['unit']!r})")
    v = e["value"]
    if spec.size == 1:
        return _number(where, spec, v)
    if not isinstance(v, list) or len(v) != spec.size:
        raise ValueError(f"{where}: must be {spec.size} numbers in {spec.unit} (got {_fmt(v)})")
    return tuple(_number(f"{where}.{i}", spec, x) for i, x in enumerate(v))


def _cross_checks(tag: str, v: dict) -> None:
    """Relations between fields: a prolate hull, fins on the hull, a righting moment."""
    L, d = v["hull.L"], v["hull.diam"]
    if not d < L:
        raise ValueError(f"{tag}: hull.diam: must be < hull.L = {_fmt(L)} m (a prolate spheroid) (got {_fmt(d)})")
    if not v["fins.x_fin"] >= -L:
        raise ValueError(f"{tag}: fins.x_fin: must be >= -hull.L = {_fmt(-L)} m (on the hull) (got {_fmt(v['fins.x_fin'])})")
    m = v.get("hull.mass", 4.0 / 3.0 * math.pi * v["hull.rho"] * (L / 2) * (d / 2) ** 2)
    W = m * v["hull.g"]
    B = v.get("hull.buoyancy", W)
    if not W * v["hull.r_g"][2] - B * v["hull.r_b"][2] > 0.0:
        raise ValueError(f"{tag}: hull.r_g: the righting moment W z_g - B z_b must be > 0 N m (CG below the CB) "
                         f"(got {_fmt(W * v['hull.r_g'][2] - B * v['hull.r_b'][2])} N m)")


def parse_vehicle(raw: dict, tag: str, default_name: str) -> Preset6:
    """Check a parsed vehicle file and return its numbers.

    Parameters
    ----------
    raw : dict
        The parsed TOML document.
    tag : str
        File label for messages.
    default_name : str
        Name when the file has no ``name``.

    Returns
    -------
    Preset6
        ``values`` by ``"section.key"`` (defaults of optional fields filled in) and the record
        (the file's entries, plus the defaults used, each with unit and source).

    Raises
    ------
    ValueError
        ``"<tag>: <section.key>: <rule> (got <value>)"`` for the first problem found.
    """
    for key in raw:
        if key not in TOP_KEYS:
            raise ValueError(f"{tag}: {key}: unknown key (allowed: {', '.join(TOP_KEYS)})")
    for key in ("name", "description"):
        if key in raw and not isinstance(raw[key], str):
            raise ValueError(f"{tag}: {key}: must be a string (got {_fmt(raw[key])})")
    values: dict = {}
    record: dict = {}
    for section in SECTIONS:
        entries = raw.get(section, {})
        if not isinstance(entries, dict):
            raise ValueError(f"{tag}: {section}: must be a table (got {_fmt(entries)})")
        allowed = [k.split(".", 1)[1] for k in FIELDS if k.startswith(section + ".")]
        for key, e in entries.items():
            if key not in allowed:
                raise ValueError(f"{tag}: {section}.{key}: unknown field (allowed: {', '.join(allowed)})")
            values[f"{section}.{key}"] = _entry(tag, f"{section}.{key}", FIELDS[f"{section}.{key}"], e)
        record[section] = dict(entries)
    for key, spec in FIELDS.items():
        if key in values:
            continue
        section, name = key.split(".", 1)
        if key in DEFAULT_SOURCES:
            values[key] = spec.default
            record[section][name] = {"value": spec.default, "unit": spec.unit, "source": DEFAULT_SOURCES[key]}
        elif key not in ("hull.mass", "hull.buoyancy"):  # optional; fossen.derived states their defaults
            raise ValueError(f"{tag}: {key}: required field is missing ({spec.text}, {spec.unit or '-'})")
    _cross_checks(tag, values)
    record = {s: e for s, e in record.items() if e}
    name = raw.get("name", default_name) or default_name
    return Preset6(name=name, description=raw.get("description", ""), values=values, record=record)


@functools.lru_cache(maxsize=64)
def _parsed(path: str, data: bytes) -> Preset6:
    tag = label(path)
    try:
        raw = tomllib.loads(data.decode("utf-8"))
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"{tag}: TOML syntax error: {' '.join(str(exc).split())}") from None
    except UnicodeDecodeError:
        raise ValueError(f"{tag}: not a UTF-8 text file") from None
    return parse_vehicle(raw, tag, Path(path).stem)


def load_vehicle_file(path: str | os.PathLike) -> Preset6:
    """Load and check a vehicle file (cached by path and content).

    Parameters
    ----------
    path : str or path-like
        The file; a relative path is relative to the current working directory.

    Returns
    -------
    Preset6
        Its checked numbers (:func:`parse_vehicle`).

    Raises
    ------
    ValueError
        A missing or unreadable file, TOML syntax, or any field out of its rules; one line
        naming the file and the field.
    """
    full = resolve_path(os.fspath(path))
    tag = label(full)
    try:
        data = Path(full).read_bytes()
    except FileNotFoundError:
        raise ValueError(f"{tag}: file not found") from None
    except IsADirectoryError:
        raise ValueError(f"{tag}: is a directory, not a vehicle file") from None
    except OSError as exc:
        raise ValueError(f"{tag}: cannot read file ({' '.join((exc.strerror or str(exc)).split())})") from None
    return _parsed(full, data)


def file_digest(path: str | os.PathLike) -> str:
    """SHA-256 of a file's bytes (hex), for the run record."""
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()

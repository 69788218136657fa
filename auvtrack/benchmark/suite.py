"""Benchmark suites of ``auvtrack compare``: the versioned data file, its validation and its runs.

A suite (``auvtrack/data/benchmarks/<name>.toml``, format in ``docs/benchmark.md``) holds the
tasks (a reference, a duration), the tiers of conditions (scenario overrides, random draws,
start offsets, values cycled over the seeds), the number of seeds, the scoring weights and the
scenario keys every run shares.  A *run* is one controller on one task under one tier with one
seed index; :meth:`Suite.scenario` turns it into the scenario the engine runs.

Seeding: the random numbers of seed index ``i`` of task ``k`` come from
``SeedSequence([suite seed, crc32(purpose), i])``, one purpose per quantity:
``"seed/<k>"`` for the scenario seed (RBF centres, currents, sensor noise), ``"start/<k>/<axis>"``
for the start offsets (the same unit draw in every tier, scaled by the tier's half-width) and
``"draw/<k>/<key>"`` for a tier's random scenario key.  No purpose names the controller, so
every controller meets the same conditions (common random numbers); a run depends only on the
suite and its own (task, tier, index), never on the order, chunking or worker.
"""
from __future__ import annotations

import functools
import hashlib
import json
import math
import re
import zlib
from dataclasses import dataclass, field, replace
from importlib import resources
from pathlib import Path
from typing import Annotated, Any, Mapping

import numpy as np
from pydantic import AllowInfNan, BaseModel, ConfigDict, Field, Strict, ValidationError, model_validator

from ..batch.sweep_spec import Distribution
from ..scenario.errors import ScenarioError, translate

__all__ = ["SuiteError", "SuiteFile", "Suite", "Task", "Tier", "Start", "ControllerEntry", "load_suite",
           "available_suites", "CRITERIA", "METRICS", "tracking_kinds", "check_competitor", "resolve_controllers",
           "start_state", "DEFAULT_SUITE"]

DEFAULT_SUITE = "auv-track-v1"
METRICS: tuple[str, ...] = ("rmse", "itae", "max_error", "settling", "energy", "tv")
"""The benchmark's per-run metrics (definitions in :mod:`auvtrack.benchmark.compare`)."""
CRITERIA: tuple[str, ...] = ("failure",) + METRICS
"""Criteria of the scoring rule: the failure rate and the median of each metric."""
SETTLE_LABELS = ("5cm", "1cm", "1mm")
START_AXES = ("along", "lateral", "vertical", "heading", "speed")

Num = Annotated[float, Strict(), AllowInfNan(False)]
NonNeg = Annotated[Num, Field(ge=0)]
Pos = Annotated[Num, Field(gt=0)]
Text = Annotated[str, Strict()]
_NAME = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.+\-]{0,63}")


class SuiteError(ScenarioError):
    """Invalid suite file or request: ``str(err)`` is one line naming the field and the rule."""


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class Start(_Model):
    """Half-widths of the uniform start offsets (virtual point from the reference's start, path frame)."""

    along: NonNeg = Field(0.0, description="m, along the reference's initial tangent")
    lateral: NonNeg = Field(0.0, description="m, horizontal, to starboard of the tangent")
    vertical: NonNeg = Field(0.0, description="m, down")
    heading: NonNeg = Field(0.0, description="rad, added to the tangent's heading")
    speed: Annotated[Num, Field(ge=0, lt=1)] = Field(0.0, description="fraction of the reference speed")


class Task(_Model):
    """``[tasks.<name>]``: a reference flown for ``duration`` seconds, starting on it at its speed."""

    description: Text = ""
    duration: Pos
    reference: dict[str, Any]


class Tier(_Model):
    """``[tiers.<name>]``: a group of conditions applied on top of every task."""

    description: Text = ""
    requires_plant: Text | None = Field(None, description="plant model the tier needs (skipped if absent)")
    start: Start = Field(default_factory=Start)
    set: dict[str, Any] = Field(default_factory=dict)
    random: dict[str, Distribution] = Field(default_factory=dict)
    cycle: dict[str, Annotated[list[Any], Field(min_length=1)]] = Field(default_factory=dict)

    @model_validator(mode="after")
    def _keys(self) -> "Tier":
        from ..scenario.overrides import parse_overrides

        seen: set[str] = set()
        for section, keys in (("set", self.set), ("random", self.random), ("cycle", self.cycle)):
            for key in keys:
                try:
                    parse_overrides({key: 0})
                except ScenarioError:
                    raise ValueError(f"{section}: {key!r} is not a dotted scenario key") from None
                if key in seen and section != "set":
                    raise ValueError(f"{section}: {key!r} is given twice")
                seen.add(key)
        return self


class Scoring(_Model):
    """``[scoring]``: the weight of each criterion in a cell's score (>= 0, not all 0)."""

    failure: NonNeg = 3.0
    rmse: NonNeg = 1.0
    itae: NonNeg = 1.0
    max_error: NonNeg = 1.0
    settling: NonNeg = 1.0
    energy: NonNeg = 1.0
    tv: NonNeg = 1.0

    @model_validator(mode="after")
    def _some(self) -> "Scoring":
        if not any(getattr(self, c) > 0 for c in CRITERIA):
            raise ValueError("must give at least one criterion a weight > 0")
        return self

    def weights(self) -> dict[str, float]:
        """Criterion -> weight, in :data:`CRITERIA` order."""
        return {c: float(getattr(self, c)) for c in CRITERIA}


class Quick(_Model):
    """``[quick]``: the CI-sized variant (every controller, task and tier)."""

    seeds: Annotated[int, Strict(), Field(ge=1, le=1000)] = 3
    duration: Pos = 10.0
    bootstrap_resamples: Annotated[int, Strict(), Field(ge=100, le=100_000)] = 500


class MetricsSettings(_Model):
    """``[metrics]``: the settling threshold."""

    settle: Text = "5cm"

    @model_validator(mode="after")
    def _label(self) -> "MetricsSettings":
        if self.settle not in SETTLE_LABELS:
            raise ValueError(f"settle: must be one of {', '.join(SETTLE_LABELS)} (got {self.settle!r})")
        return self


class SuiteFile(_Model):
    """The keys of a suite file (``docs/benchmark.md``)."""

    name: Text
    version: Annotated[int, Strict(), Field(ge=1)]
    title: Text = ""
    seed: Annotated[int, Strict(), Field(ge=0, le=2**63 - 1)]
    seeds: Annotated[int, Strict(), Field(ge=1, le=100_000)]
    failure_halfwidth: Annotated[Num, Field(gt=0, lt=0.5)] = 0.05
    gain_preset: Text = "{kind}_tuned"
    confidence: Annotated[Num, Field(gt=0.5, lt=1)] = 0.95
    bootstrap_resamples: Annotated[int, Strict(), Field(ge=100, le=100_000)] = 2000
    base: dict[str, Any] = Field(default_factory=dict)
    metrics: MetricsSettings = Field(default_factory=MetricsSettings)
    scoring: Scoring = Field(default_factory=Scoring)
    quick: Quick = Field(default_factory=Quick)
    tasks: Annotated[dict[str, Task], Field(min_length=1)]
    tiers: Annotated[dict[str, Tier], Field(min_length=1)]

    @model_validator(mode="after")
    def _names(self) -> "SuiteFile":
        if not _NAME.fullmatch(self.name):
            raise ValueError(f"name: must be 1-64 characters from A-Z a-z 0-9 _ - . + (got {self.name!r})")
        for section, names in (("tasks", self.tasks), ("tiers", self.tiers)):
            for n in names:
                if not re.fullmatch(r"[A-Za-z][A-Za-z0-9_]{0,31}", n):
                    raise ValueError(f"{section}.{n}: a name must be a letter then letters, digits or _")
        if "{kind}" not in self.gain_preset:
            raise ValueError(f"gain_preset: must contain '{{kind}}' (got {self.gain_preset!r})")
        return self


@dataclass(frozen=True)
class ControllerEntry:
    """One competitor of a comparison.

    Attributes
    ----------
    label : str
        Its name in the tables (the kind, or a plug-in's file name without ``.py``).
    table : dict
        The scenario's ``[controller]`` table (``kind`` and ``preset`` or ``module``).
    gains : str
        Where its gains come from, for the report.
    digest : str
        SHA-256 of a plug-in file (empty for built-ins): part of the comparison's fingerprint.
    """

    label: str
    table: dict
    gains: str
    digest: str = ""

    def to_dict(self) -> dict:
        """Plain-data form (for manifests and ``results.json``)."""
        return {"label": self.label, "table": self.table, "gains": self.gains, "digest": self.digest}


def tracking_kinds() -> list[str]:
    """Built-in controllers that track a reference: those whose registration says so (``ControllerSpec.tracks``).

    Returns
    -------
    list of str
        Kinds in registration order (the open-loop kinds are left out).
    """
    from ..control import BUILTIN_NAMES, CONTROLLERS

    return [k for k in BUILTIN_NAMES if CONTROLLERS[k].tracks]


def check_competitor(entry: "ControllerEntry") -> None:
    """Refuse a competitor that cannot enter a tracking comparison: open loop, or a plug-in that does not import.

    Parameters
    ----------
    entry : ControllerEntry
        A built-in kind or a plug-in file (``controller.kind = "plugin"``).

    Raises
    ------
    SuiteError
        One line naming ``--controllers`` or ``--plugin``: an unknown kind, a controller whose
        ``TRACKS`` is False, or a plug-in file that cannot be imported or breaks the contract.
    """
    from ..control import CONTROLLERS

    kind = entry.table.get("kind")
    if kind == "plugin":
        from ..control.plugin import load

        module = str(entry.table.get("module", ""))
        try:
            _, spec = load(module)
        except ValueError as exc:
            why = " ".join(str(exc).split())
            raise SuiteError(f"--plugin: {why}" if module in why else f"--plugin: {module}: {why}") from None
        if not spec.tracks:
            raise SuiteError(f"--plugin: {module}: does not track a reference (TRACKS = False); "
                             "a comparison is of tracking controllers")
        return
    if kind not in CONTROLLERS:
        raise SuiteError(f"--controllers: unknown controller {kind!r} (allowed: {', '.join(tracking_kinds())}; "
                         "plug-in files with --plugin)")
    if not CONTROLLERS[kind].tracks:
        raise SuiteError(f"--controllers: {kind!r} does not track a reference (allowed: "
                         f"{', '.join(tracking_kinds())}; plug-in files with --plugin)")


def _builtin_entry(kind: str, pattern: str) -> ControllerEntry:
    from ..control.gain_presets import available_gain_presets, get_gain_preset

    preset = pattern.format(kind=kind)
    if preset in available_gain_presets() and get_gain_preset(preset).kind == kind:
        desc = get_gain_preset(preset).description
        return ControllerEntry(kind, {"kind": kind, "preset": preset}, f"preset {preset}: {desc}")
    return ControllerEntry(kind, {"kind": kind}, f"package defaults (no gain preset {preset!r} is installed)")


def _plugin_entry(path: str | Path, taken: set[str]) -> ControllerEntry:
    p = Path(path).expanduser().resolve()
    if p.suffix != ".py" or not p.is_file():
        raise SuiteError(f"--plugin: must be an existing .py file (got {str(path)!r})")
    base = re.sub(r"[^A-Za-z0-9_.+\-]", "_", p.stem) or "plugin"
    label, k = base, 2
    while label in taken:
        label, k = f"{base}-{k}", k + 1
    digest = hashlib.sha256(p.read_bytes()).hexdigest()
    entry = ControllerEntry(label, {"kind": "plugin", "module": str(p)}, f"plug-in {p.name}: its Params defaults",
                            digest)
    check_competitor(entry)  # it imports and follows the contract, now rather than in every run's set-up
    return entry


def resolve_controllers(names: list[str] | None = None, plugins: list[str | Path] | None = None,
                        gain_preset: str = "{kind}_tuned") -> list[ControllerEntry]:
    """The competitors: named (or all tracking) built-in controllers and plug-in files.

    Parameters
    ----------
    names : list of str, optional
        Built-in kinds that track a reference; None: :func:`tracking_kinds` (an empty list is refused).
    plugins : list of path, optional
        Plug-in controller files (``controller.kind = "plugin"``), each entering under its file name.
    gain_preset : str, optional
        Preset name pattern; a built-in uses ``gain_preset.format(kind=kind)`` if installed.

    Returns
    -------
    list of ControllerEntry
        Built-ins first (in ``names`` or registration order), then the plug-ins.

    Raises
    ------
    SuiteError
        An unknown, open-loop or repeated kind, an empty list of kinds, a plug-in file that is
        missing, does not import or does not track, or no controller at all.
    """
    if names is not None and not list(names):
        raise SuiteError("--controllers: names no controller (omit it to compare every tracking controller: "
                         f"{', '.join(tracking_kinds())})")
    kinds = tracking_kinds() if names is None else list(names)
    entries: list[ControllerEntry] = []
    for k in kinds:
        check_competitor(ControllerEntry(str(k), {"kind": k}, ""))
        if any(e.label == k for e in entries):
            raise SuiteError(f"--controllers: {k!r} is given twice")
        entries.append(_builtin_entry(k, gain_preset))
    for p in plugins or []:
        entries.append(_plugin_entry(p, {e.label for e in entries}))
    if not entries:
        raise SuiteError("--controllers: no controller to compare")
    return entries


def start_state(reference: dict, start: Start, unit: Mapping[str, float], ell: float) -> tuple[list, list]:
    """Initial ``eta``, ``nu`` of a run: near the reference's start, heading along it, at its speed.

    The virtual point (eq. 2, offset ``ell`` ahead) is placed at the reference's start plus
    ``(2 u - 1) h`` along the initial tangent, to starboard of it and down, with ``u`` the unit
    draws of ``unit`` and ``h`` the half-widths of ``start``; the heading is the tangent's plus
    its offset, the pitch the tangent's, and the body moves in surge only at the reference speed
    times ``1 + offset``.

    Parameters
    ----------
    reference : dict
        Reference spec (``kind`` and fields).
    start : Start
        Half-widths.
    unit : mapping
        A draw in [0, 1) per :data:`START_AXES` name.
    ell : float
        Virtual-point offset, m.

    Returns
    -------
    (list of 5 float, list of 5 float)
        ``initial.eta`` (m, m, m, rad, rad) and ``initial.nu`` (m/s, m/s, m/s, rad/s, rad/s).
    """
    p, v = _reference_start(json.dumps(reference, sort_keys=True))
    speed = float(np.linalg.norm(v))
    if speed <= 0.0:
        raise SuiteError(f"reference {reference.get('kind')!r}: starts at rest; a task needs a moving reference")
    psi_t = math.atan2(v[1], v[0])
    theta = -math.atan2(v[2], math.hypot(v[0], v[1]))
    off = {a: (2.0 * unit[a] - 1.0) * getattr(start, a) + 0.0 for a in START_AXES}
    tangent = v / speed
    lateral = np.array([-math.sin(psi_t), math.cos(psi_t), 0.0])
    target = p + off["along"] * tangent + off["lateral"] * lateral + np.array([0.0, 0.0, off["vertical"]])
    psi = psi_t + off["heading"]
    d = (math.cos(theta) * math.cos(psi), math.cos(theta) * math.sin(psi), -math.sin(theta))
    eta = [float(target[0] - ell * d[0]), float(target[1] - ell * d[1]), float(target[2] - ell * d[2]), theta, psi]
    return eta, [speed * (1.0 + off["speed"]), 0.0, 0.0, 0.0, 0.0]


@functools.lru_cache(maxsize=64)
def _reference_start(spec: str) -> tuple[np.ndarray, np.ndarray]:
    """Position and velocity at t = 0 of a reference given as JSON (cached: every run of a task shares it)."""
    from ..reference import build_reference

    p, v, _ = build_reference(json.loads(spec)).evaluate(0.0)
    p.setflags(write=False)
    v.setflags(write=False)
    return p, v


def _generator(seed: int, purpose: str, index: int) -> np.random.Generator:
    return np.random.default_rng(np.random.SeedSequence([seed, zlib.crc32(purpose.encode()), index]))


@dataclass(frozen=True)
class Suite:
    """A loaded, validated suite (plain data, picklable).

    Attributes
    ----------
    file : SuiteFile
        The validated file.
    source : str
        Where it came from (for messages and the report).
    quick : bool
        The ``--quick`` variant (:meth:`quick_variant`).
    text : str
        The suite file as written (shown in the report).
    """

    file: SuiteFile
    source: str = "<suite>"
    quick: bool = False
    text: str = field(default="", repr=False)
    _skipped: tuple[tuple[str, str], ...] = field(default=(), repr=False)

    # ---------------------------------------------------------------- shape
    @property
    def name(self) -> str:
        """Suite name (``auv-track-v1``)."""
        return self.file.name

    @property
    def seeds(self) -> int:
        """Seed indices per cell."""
        return self.file.quick.seeds if self.quick else self.file.seeds

    @property
    def bootstrap_resamples(self) -> int:
        """Bootstrap resamples per median."""
        return self.file.quick.bootstrap_resamples if self.quick else self.file.bootstrap_resamples

    @property
    def tasks(self) -> list[str]:
        """Task names, file order."""
        return list(self.file.tasks)

    @property
    def tiers(self) -> list[str]:
        """Tiers that can run in this build, file order."""
        skipped = {t for t, _ in self._skipped}
        return [t for t in self.file.tiers if t not in skipped]

    @property
    def skipped_tiers(self) -> dict[str, str]:
        """Tiers left out of this build, with the reason."""
        return dict(self._skipped)

    def duration(self, task: str) -> float:
        """Simulated seconds of ``task`` (shortened in the quick variant)."""
        d = self.file.tasks[task].duration
        return min(d, self.file.quick.duration) if self.quick else d

    def failure_halfwidths(self) -> dict[str, float]:
        """Worst-case Wilson half-widths of the failure rates: per cell and per (controller, tier).

        Returns
        -------
        dict
            ``cell`` (``seeds`` runs), ``tier`` (``seeds x tasks`` runs, the level the tier ranks
            and the failure figure pool) and ``zero_failures`` (the upper bound of a cell with no
            failure).
        """
        from .statistics import wilson_halfwidth_max, wilson_interval

        c = self.file.confidence
        return {"cell": wilson_halfwidth_max(self.seeds, c),
                "tier": wilson_halfwidth_max(self.seeds * len(self.tasks), c),
                "zero_failures": wilson_interval(0, self.seeds, c)[1]}

    def quick_variant(self) -> "Suite":
        """The ``--quick`` suite: every task and tier, few seeds, short runs."""
        return replace(self, quick=True)

    # ---------------------------------------------------------------- runs
    def scenario_seed(self, task: str, index: int) -> int:
        """Scenario seed of seed index ``index`` of ``task`` (shared by every tier and controller)."""
        return int(_generator(self.file.seed, f"seed/{task}", index).integers(0, 2**63 - 1))

    def unit_draws(self, task: str, index: int) -> dict[str, float]:
        """Unit draws in [0, 1) of the start offsets (shared by every tier and controller)."""
        return {a: float(_generator(self.file.seed, f"start/{task}/{a}", index).random()) for a in START_AXES}

    def tier_values(self, task: str, tier: str, index: int) -> dict[str, Any]:
        """The tier's random and cycled scenario values of one seed index (dotted key -> value)."""
        t = self.file.tiers[tier]
        vals: dict[str, Any] = {}
        for key, dist in t.random.items():
            vals[key] = dist.draw(_generator(self.file.seed, f"draw/{task}/{key}", index))
        for key, options in t.cycle.items():
            vals[key] = options[index % len(options)]
        return vals

    def conditions(self, task: str, tier: str, index: int) -> tuple[dict, dict, dict]:
        """What one seed index of a (task, tier) cell imposes, whatever the controller.

        Parameters
        ----------
        task, tier : str
            Names from the suite.
        index : int
            Seed index, ``0 <= index < seeds``.

        Returns
        -------
        (dict, dict, dict)
            The raw scenario without ``name`` and ``controller``, the overrides to apply on it,
            and the values this seed drew (start offsets and tier values), for the record.
        """
        tk, tr = self.file.tasks[task], self.file.tiers[tier]
        ell = float(self.file.base.get("vehicle.l", 1.0))
        unit = self.unit_draws(task, index)
        eta, nu = start_state(tk.reference, tr.start, unit, ell)
        raw = {"seed": self.scenario_seed(task, index), "sim": {"duration": self.duration(task)},
               "reference": dict(tk.reference), "initial": {"eta": eta, "nu": nu}}
        values = self.tier_values(task, tier, index)
        overrides = {**self.file.base, **tr.set, **values}
        drawn = {f"start.{a}": (2.0 * unit[a] - 1.0) * getattr(tr.start, a) + 0.0 for a in START_AXES} | values
        return raw, overrides, drawn

    def scenario(self, entry: ControllerEntry, task: str, tier: str, index: int,
                 conditions: tuple[dict, dict, dict] | None = None) -> tuple[dict, dict, dict]:
        """The scenario of one run: :meth:`conditions` with the controller's table.

        Parameters
        ----------
        entry : ControllerEntry
            The controller.
        task, tier : str
            Names from the suite.
        index : int
            Seed index, ``0 <= index < seeds``.
        conditions : tuple, optional
            ``self.conditions(task, tier, index)`` when already computed.

        Returns
        -------
        (dict, dict, dict)
            The raw scenario dict, the overrides to apply on it (``load_scenario(raw,
            overrides)``) and the values this seed drew.
        """
        raw, overrides, drawn = conditions or self.conditions(task, tier, index)
        raw = {"name": f"{self.name}-{entry.label}-{task}-{tier}-{index}", **raw, "controller": dict(entry.table)}
        return raw, dict(overrides), dict(drawn)

    def fingerprint(self) -> str:
        """SHA-256 of everything that defines the runs (the file's contents and the variant)."""
        doc = {"suite": self.file.model_dump(mode="json"), "quick": self.quick, "skipped": list(self._skipped)}
        return hashlib.sha256(json.dumps(doc, sort_keys=True, default=str).encode()).hexdigest()

    def settings(self) -> dict[str, Any]:
        """Every setting of the suite as plain data (for the report and ``results.json``)."""
        return {"name": self.name, "version": self.file.version, "title": self.file.title, "source": self.source,
                "quick": self.quick, "seed": self.file.seed, "seeds": self.seeds,
                "durations": {t: self.duration(t) for t in self.tasks},
                "bootstrap_resamples": self.bootstrap_resamples, "skipped_tiers": self.skipped_tiers,
                "failure_halfwidths": self.failure_halfwidths(),
                "file": self.file.model_dump(mode="json")}


def _suites_root():
    return resources.files("auvtrack") / "data" / "benchmarks"


def available_suites() -> list[str]:
    """Names of the suites shipped with the package (``auvtrack/data/benchmarks/*.toml``).

    Returns
    -------
    list of str
        Sorted.
    """
    root = _suites_root()
    return sorted(p.name[:-5] for p in root.iterdir() if p.name.endswith(".toml")) if root.is_dir() else []


def _check_runs(suite: Suite) -> None:
    """Validate every (task, tier) scenario of seed index 0 and each random range's ends."""
    from ..scenario import load_scenario

    entry = ControllerEntry("probe", {"kind": "fxtntsmc"}, "")
    for task in suite.tasks:
        for tier in suite.tiers:
            raw, ov, _ = suite.scenario(entry, task, tier, 0)
            tr = suite.file.tiers[tier]
            ov = {k: v for k, v in ov.items() if k not in tr.random}  # the random keys probed one by one
            probes = [("set", ov)]
            for key, dist in suite.file.tiers[tier].random.items():
                for end in dist.probes():
                    probes.append((f"random.{key}", {**ov, key: end}))
            for key, options in suite.file.tiers[tier].cycle.items():
                for j, v in enumerate(options):
                    probes.append((f"cycle.{key}.{j}", {**ov, key: v}))
            for where, overrides in probes:
                try:
                    load_scenario(raw, overrides)
                except ScenarioError as exc:
                    raise SuiteError(f"{suite.source}: tiers.{tier}.{where} on task {task!r}: the scenario rejects "
                                     f"it: {exc}") from None


def load_suite(name: str | Path = DEFAULT_SUITE, *, check: bool = True) -> Suite:
    """Read and validate a suite.

    Parameters
    ----------
    name : str or Path
        A shipped suite's name (:func:`available_suites`) or the path of a suite TOML file.
    check : bool, optional
        Also validate the scenario of every (task, tier) and the ends of every random range.

    Returns
    -------
    Suite
        Tiers whose ``requires_plant`` is not registered in this build are left out (listed in
        :attr:`Suite.skipped_tiers`).

    Raises
    ------
    SuiteError
        One line naming the file, the field and the rule.
    """
    from ..plant import PLANTS
    from ..scenario.loader import read_toml

    label = str(name)
    if label in available_suites():
        path, source = Path(str(_suites_root() / f"{label}.toml")), label
    elif label.endswith(".toml"):
        path, source = Path(label), label
    else:
        raise SuiteError(f"--suite: unknown suite {label!r} (shipped: {', '.join(available_suites()) or 'none'}; "
                         "or a path to a .toml file)")
    try:
        raw = read_toml(path)
        text = path.read_text(encoding="utf-8")
    except ScenarioError as exc:
        raise SuiteError(str(exc)) from None
    try:
        sf = SuiteFile.model_validate(raw)
    except ValidationError as exc:
        err = translate(exc, SuiteFile, source)
        msg = re.sub(r"\.(?:uniform|normal|loguniform)(?=[.:])", "", str(err), count=1)
        raise SuiteError(msg, err.path) from None
    skipped = tuple((t, f"plant model {tr.requires_plant!r} is not available in this build")
                    for t, tr in sf.tiers.items() if tr.requires_plant and tr.requires_plant not in PLANTS)
    suite = Suite(sf, source, False, text, skipped)
    if not suite.tiers:
        raise SuiteError(f"{source}: tiers: none can run in this build ({'; '.join(r for _, r in skipped)})")
    if check:
        _check_runs(suite)
    return suite

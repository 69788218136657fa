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
import itertools
import json
import math
import re
import string
import warnings
import zlib
from dataclasses import dataclass, field, replace
from importlib import resources
from pathlib import Path
from typing import Annotated, Any, Literal, Mapping

import numpy as np
from pydantic import (AllowInfNan, BaseModel, ConfigDict, Field, Strict, ValidationError, field_validator,
                      model_validator)

from ..batch.sweep_spec import Distribution, Normal
from ..scenario.errors import ScenarioError, translate

__all__ = ["SuiteError", "SuiteFile", "Suite", "Task", "Tier", "Start", "ControllerEntry", "load_suite",
           "available_suites", "CRITERIA", "METRICS", "tracking_kinds", "check_competitor", "resolve_controllers",
           "start_state", "DEFAULT_SUITE", "SPLITS", "Split", "Splits", "RunScore"]

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
_PRESET_TEXT = re.compile(r"[A-Za-z0-9_.+\-]*")
MAX_WEIGHT = 1e6
"""Largest scoring weight (only their ratios matter; larger ones would overflow the weighted sum)."""
MIN_WEIGHT = 1e-6
"""Smallest non-zero scoring weight."""
NORMAL_PROBE_STD = 3.0
"""A tier's normal draw is checked at its mean and at mean +- this many standard deviations."""
RUN_KEYS: dict[tuple[str, ...], str] = {
    ("name",): "the run's name",
    ("seed",): "each run's scenario seed, from the suite seed and the seed index (runs.parquet records it)",
    ("controller",): "the controller under test (--controllers, --plugin and gain_preset choose it)",
    ("reference",): "the task's reference (tasks.<name>.reference)",
    ("sim", "duration"): "the task's duration (tasks.<name>.duration)",
    ("initial", "eta"): "the start (tasks.<name>.reference and tiers.<name>.start)",
    ("initial", "nu"): "the start (tasks.<name>.reference and tiers.<name>.start)",
}
"""Scenario keys the comparison sets on every run itself: no suite key may set them, or a table above them."""
ELL_KEYS = (("vehicle",), ("vehicle", "l"), ("vehicle", "preset"))
"""Keys that set the virtual-point offset the start is placed with: fixed per tier (never drawn or cycled)."""


class SuiteError(ScenarioError):
    """Invalid suite file or request: ``str(err)`` is one line naming the field and the rule."""


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class Start(_Model):
    """Half-widths of the uniform start offsets (virtual point from the reference's start, path frame)."""

    along: NonNeg = Field(0.0, description="m, along the reference's initial tangent")
    lateral: NonNeg = Field(0.0, description="m, horizontal, to starboard of the tangent")
    vertical: NonNeg = Field(0.0, description="m, down")
    heading: Annotated[Num, Field(ge=0, le=math.pi)] = Field(0.0, description="rad, added to the tangent's heading")
    speed: Annotated[Num, Field(ge=0, lt=1)] = Field(0.0, description="fraction of the reference speed")


class Task(_Model):
    """``[tasks.<name>]``: a reference flown for ``duration`` seconds, starting on it at its speed."""

    description: Text = ""
    duration: Pos
    reference: dict[str, Any]

    @field_validator("reference")
    @classmethod
    def _reference(cls, v: dict[str, Any]) -> dict[str, Any]:
        """The reference module's own validation, and a start in motion (the start is placed along it)."""
        from ..scenario.components import check_reference

        resolved = check_reference(v)
        _, vel = _reference_start(json.dumps(resolved, sort_keys=True))
        if not float(np.linalg.norm(vel)) > 0.0:
            raise ValueError(f"starts at rest (kind {resolved.get('kind')!r}); a task needs a moving reference, "
                             "its start is placed along the initial tangent")
        return v  # as written: the runs resolve it, and the fingerprint stays that of the file


def _key_path(key: str) -> tuple[str, ...]:
    from ..scenario.overrides import parse_overrides

    return tuple(str(p) for p in parse_overrides({key: 0})[0].path)


def _overlaps(a: tuple[str, ...], b: tuple[str, ...]) -> bool:
    """True when one key path is the other or lies below it."""
    n = min(len(a), len(b))
    return a[:n] == b[:n]


def _check_run_keys(section: str, keys, fixed_only: bool = False) -> None:
    """Refuse suite keys that would overwrite what the comparison sets per run (and, drawn or cycled, ℓ)."""
    for key in keys:
        path = _key_path(key)
        for owned, what in RUN_KEYS.items():
            if _overlaps(path, owned):
                raise ValueError(f"{section}: {key!r} would overwrite {'.'.join(owned)}, which the comparison sets "
                                 f"for every run: {what}")
        if fixed_only and any(_overlaps(path, k) for k in ELL_KEYS):
            raise ValueError(f"{section}: {key!r} cannot vary between seeds: the start is placed with vehicle.l, "
                             "fixed per tier (give it in [base] or the tier's set)")


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
            _check_run_keys(section, keys, fixed_only=section != "set")
        return self


class Scoring(_Model):
    """``[scoring]``: the weight of each criterion in a cell's score (>= 0, not all 0).

    The fields are the failure rate and the benchmark's derived metrics (:data:`METRICS`, with
    their defaults); any engine metric (:data:`auvtrack.metrics.METRIC_NAMES`, e.g.
    ``xtrack_rmse``) can be added by name.  The criteria a suite ranks, tabulates and tests are
    those with a weight > 0 (:meth:`criteria`).
    """

    model_config = ConfigDict(extra="allow", frozen=True)

    failure: NonNeg = 3.0
    rmse: NonNeg = 1.0
    itae: NonNeg = 1.0
    max_error: NonNeg = 1.0
    settling: NonNeg = 1.0
    energy: NonNeg = 1.0
    tv: NonNeg = 1.0

    @model_validator(mode="after")
    def _some(self) -> "Scoring":
        from ..metrics import METRIC_NAMES

        for c, w in (self.model_extra or {}).items():
            if c not in METRIC_NAMES:
                raise ValueError(f"{c}: not a criterion (failure, one of the benchmark's metrics {', '.join(METRICS)} "
                                 "or an engine metric, docs/metrics.md)")
            if isinstance(w, bool) or not isinstance(w, (int, float)) or not math.isfinite(w) or w < 0:
                raise ValueError(f"{c}: must be a finite number >= 0 (got {w!r})")
        for c, w in self.weights().items():
            if w != 0 and not MIN_WEIGHT <= w <= MAX_WEIGHT:
                raise ValueError(f"{c}: must be 0 or in [{MIN_WEIGHT:g}, {MAX_WEIGHT:g}] (only the ratios of the "
                                 f"weights matter) (got {w:g})")
        if not any(w > 0 for w in self.weights().values()):
            raise ValueError("must give at least one criterion a weight > 0")
        return self

    def weights(self) -> dict[str, float]:
        """Criterion -> weight: ``failure``, the engine metrics in file order, then :data:`METRICS` in order."""
        extra = {c: float(w) for c, w in (self.model_extra or {}).items()}
        return {"failure": float(self.failure)} | extra | {c: float(getattr(self, c)) for c in METRICS}

    def criteria(self) -> tuple[str, ...]:
        """The criteria with a weight > 0, in :meth:`weights` order (``failure`` first when weighted)."""
        return tuple(c for c, w in self.weights().items() if w > 0)

    def metrics(self) -> tuple[str, ...]:
        """The weighted criteria other than the failure rate: the metrics whose medians are ranked."""
        return tuple(c for c in self.criteria() if c != "failure")

    def primary(self) -> str:
        """The metric with the largest weight (the first in :meth:`weights` order on a tie)."""
        w = self.weights()
        return max(self.metrics(), key=lambda c: w[c], default="rmse")


class RunScore(_Model):
    """``[run_score]``: the score of one run (:mod:`auvtrack.benchmark.scoring`), what tuning minimises."""

    cap: Annotated[Num, Field(gt=0, le=1e6)] = 10.0
    weights: dict[str, NonNeg] = Field(default_factory=dict, description="criterion -> weight")
    scales: dict[str, Pos] = Field(default_factory=dict, description="criterion -> the value that scores 1")

    @model_validator(mode="after")
    def _criteria(self) -> "RunScore":
        from ..metrics import METRIC_NAMES

        known = set(METRICS) | set(METRIC_NAMES)
        for section in ("weights", "scales"):
            for c in getattr(self, section):
                if c not in known:
                    raise ValueError(f"{section}.{c}: not a criterion (one of the benchmark's metrics "
                                     f"{', '.join(METRICS)} or an engine metric, docs/metrics.md)")
        for c, w in self.weights.items():
            if w > 0 and c not in self.scales:
                raise ValueError(f"scales.{c}: missing (the value of {c} that scores 1, in its unit)")
            if w != 0 and not MIN_WEIGHT <= w <= MAX_WEIGHT:
                raise ValueError(f"weights.{c}: must be 0 or in [{MIN_WEIGHT:g}, {MAX_WEIGHT:g}] (got {w:g})")
        return self


class Quick(_Model):
    """``[quick]``: the CI-sized variant (every controller, task and tier)."""

    seeds: Annotated[int, Strict(), Field(ge=1, le=1000)] = 3
    duration: Pos = 10.0
    bootstrap_resamples: Annotated[int, Strict(), Field(ge=100, le=100_000)] = 500


SplitName = Literal["training", "validation"]
SPLITS: tuple[str, ...] = ("training", "validation", "evaluation")
"""The purposes a seed index serves: tuning, checking a tuning for over-fitting, the comparison."""


class Split(_Model):
    """Seed indices ``[start, stop)`` of one purpose and the cells it flies (every task and tier by default)."""

    seeds: tuple[Annotated[int, Strict(), Field(ge=0, le=2**31)], Annotated[int, Strict(), Field(ge=1, le=2**31)]]
    tasks: list[Text] | None = Field(None, description="tasks of the split (default: every task)")
    tiers: list[Text] | None = Field(None, description="tiers of the split (default: every tier)")

    @model_validator(mode="after")
    def _range(self) -> "Split":
        if self.seeds[1] <= self.seeds[0]:
            raise ValueError(f"seeds: must be [start, stop) with start < stop (got {list(self.seeds)})")
        return self


class Splits(_Model):
    """Seed indices for tuning (``training``) and for checking a tuning (``validation``).

    The evaluation seeds are ``0 .. seeds - 1`` (the suite's ``seeds``); the three sets are disjoint.
    """

    training: Split | None = None
    validation: Split | None = None


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
    splits: Splits = Field(default_factory=Splits)
    run_score: RunScore = Field(default_factory=RunScore)
    feasibility: Annotated[bool, Strict()] = Field(False, description="assess every cell's feasibility at load")

    @model_validator(mode="after")
    def _names(self) -> "SuiteFile":
        if not _NAME.fullmatch(self.name):
            raise ValueError(f"name: must be 1-64 characters from A-Z a-z 0-9 _ - . + (got {self.name!r})")
        for section, names in (("tasks", self.tasks), ("tiers", self.tiers)):
            for n in names:
                if not re.fullmatch(r"[A-Za-z][A-Za-z0-9_]{0,31}", n):
                    raise ValueError(f"{section}.{n}: a name must be a letter then letters, digits or _")
        _check_gain_preset(self.gain_preset)
        for key in self.base:
            try:
                _key_path(key)
            except ScenarioError:
                raise ValueError(f"base: {key!r} is not a dotted scenario key") from None
        _check_run_keys("base", self.base)
        self._check_splits()
        return self

    def _check_splits(self) -> None:
        """Each split names known tasks and tiers; training, validation and evaluation seeds are disjoint."""
        ranges = {"evaluation": (0, self.seeds)}
        for name in ("training", "validation"):
            sp = getattr(self.splits, name)
            if sp is None:
                continue
            for section, names, known in (("tasks", sp.tasks, self.tasks), ("tiers", sp.tiers, self.tiers)):
                for n in names or ():
                    if n not in known:
                        raise ValueError(f"splits.{name}.{section}: unknown {section[:-1]} {n!r} "
                                         f"(the suite has {', '.join(known)})")
            for other, (a, b) in ranges.items():
                if sp.seeds[0] < b and a < sp.seeds[1]:
                    raise ValueError(f"splits.{name}.seeds: [{sp.seeds[0]}, {sp.seeds[1]}) overlaps the {other} "
                                     f"seeds [{a}, {b}): the sets must be disjoint")
            ranges[name] = sp.seeds


def _check_gain_preset(pattern: str) -> None:
    """A gain-preset name pattern: name characters and the field ``{kind}``, nothing else."""
    rule = (f"gain_preset: must be a preset name with {{kind}} in it: letters, digits, _ . + - and the field "
            f"{{kind}}, no other {{}} field or format (got {pattern!r})")
    try:
        parts = list(string.Formatter().parse(pattern))
    except ValueError:
        raise ValueError(rule) from None
    fields = [f for _, f, _, _ in parts if f is not None]
    if not fields or any(f != "kind" or spec or conv for _, f, spec, conv in parts if f is not None):
        raise ValueError(rule)
    if not all(_PRESET_TEXT.fullmatch(text) for text, _, _, _ in parts):
        raise ValueError(rule)


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
        SHA-256 of a plug-in file or of the policy file a learned law flies (empty for the other
        built-ins): part of the comparison's fingerprint.
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
    policy = _default_policy_file(kind)
    if policy is not None:
        digest = hashlib.sha256(policy.read_bytes()).hexdigest()
        return ControllerEntry(kind, {"kind": kind}, f"policy file {policy.name} (sha256 {digest[:16]})", digest)
    return ControllerEntry(kind, {"kind": kind}, f"package defaults (no gain preset {preset!r} is installed)")


def _default_policy_file(kind: str) -> Path | None:
    """The file a learned law (a controller with a ``file`` parameter) flies by default, if it exists."""
    from ..control import CONTROLLERS
    from ..control.policy import policy_path

    field = CONTROLLERS[kind].params.model_fields.get("file")
    if field is None or not isinstance(field.default, str):
        return None
    path = policy_path(field.default)
    return path if path.is_file() else None


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


def _tier_ell(sf: SuiteFile, tier: str) -> float:
    """``vehicle.l`` of [base] with the tier's set (the preset's when neither gives it)."""
    keys = {k: v for k, v in {**sf.base, **sf.tiers[tier].set}.items()
            if any(_overlaps(_key_path(k), e) for e in ELL_KEYS)}
    return _vehicle_l(json.dumps(keys, sort_keys=True))


@functools.lru_cache(maxsize=64)
def _vehicle_l(vehicle_overrides: str) -> float:
    """``vehicle.l`` of the scenario these vehicle overrides (JSON) give (the preset's when unset)."""
    from ..scenario import load_scenario

    return float(load_scenario({}, json.loads(vehicle_overrides)).vehicle.l)


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
    _ells: tuple[tuple[str, float], ...] = field(default=(), repr=False)

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

    def split_seeds(self, split: str) -> range:
        """The seed indices of ``split`` (one of :data:`SPLITS`; evaluation: those of this variant).

        Raises
        ------
        SuiteError
            ``split`` unknown, or not declared in the suite file.
        """
        if split == "evaluation":
            return range(self.seeds)
        if split not in SPLITS:
            raise SuiteError(f"split: must be one of {', '.join(SPLITS)} (got {split!r})")
        sp = getattr(self.file.splits, split)
        if sp is None:
            raise SuiteError(f"{self.source}: splits.{split}: not declared (a [splits.{split}] table with seeds = "
                             f"[start, stop) outside the evaluation seeds 0 .. {self.file.seeds - 1})")
        return range(*sp.seeds)

    def split_cells(self, split: str) -> list[tuple[str, str]]:
        """The (task, tier) cells ``split`` flies, file order (evaluation: every cell)."""
        sp = None if split == "evaluation" else getattr(self.file.splits, split, None)
        self.split_seeds(split)  # refuses an unknown or undeclared split
        tasks = [t for t in self.tasks if sp is None or sp.tasks is None or t in sp.tasks]
        tiers = [t for t in self.tiers if sp is None or sp.tiers is None or t in sp.tiers]
        return [(k, r) for k in tasks for r in tiers]

    def split_of(self, index: int) -> str | None:
        """The split a seed index belongs to (None: none declared holds it)."""
        if 0 <= index < self.file.seeds:
            return "evaluation"
        for name in ("training", "validation"):
            sp = getattr(self.file.splits, name)
            if sp is not None and sp.seeds[0] <= index < sp.seeds[1]:
                return name
        return None

    def run_score(self, values: Mapping[str, Any], task: str) -> float:
        """The score of one run of ``task`` under the suite's ``[run_score]`` (:mod:`~auvtrack.benchmark.scoring`).

        Parameters
        ----------
        values : mapping
            The run's ``status``, ``t_stop`` and criteria (a row of the runs table after
            :func:`~auvtrack.benchmark.leaderboard.derive_metrics`).
        task : str
            Its task (for the duration: this variant's).

        Returns
        -------
        float
            Lower is better; every failed run above every completed one.

        Raises
        ------
        SuiteError
            The suite gives no criterion a weight.
        """
        from .scoring import run_score

        rs = self.file.run_score
        if not any(w > 0 for w in rs.weights.values()):
            raise SuiteError(f"{self.source}: run_score.weights: no criterion has a weight > 0 (the per-run score "
                             "that tuning minimises; docs/benchmark.md)")
        return run_score(values, rs.weights, rs.scales, cap=rs.cap, duration=self.duration(task))

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

    def ell(self, tier: str) -> float:
        """Virtual-point offset (m) the starts of ``tier`` are placed with: ``vehicle.l`` of [base] and its set.

        Parameters
        ----------
        tier : str
            A tier of the suite.

        Returns
        -------
        float
            The effective ``vehicle.l`` (the preset's unless given).
        """
        known = dict(self._ells)
        return known[tier] if tier in known else _tier_ell(self.file, tier)

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
        ell = self.ell(tier)
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
        suite = self.file.model_dump(mode="json")
        suite.pop("splits")  # tuning seeds: they define no run of the comparison
        suite.pop("feasibility")  # a check at load: it defines no run either
        doc = {"suite": suite, "quick": self.quick, "skipped": list(self._skipped)}
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


def _reason(exc: Exception) -> str:
    """A scenario error without the ``<dict>: `` source and the override hint (the suite's keys are not overrides)."""
    text = re.sub(r"^<dict>: ", "", " ".join(str(exc).split()))
    text = re.sub(r"--set (limits\.\w+)=N or a \[limits\] table", r'"\1" in [base]', text)
    return re.sub(r" \(set by override [^)]*\)", "", text)


def _blame(suite: Suite, task: str, tier: str, where: str, exc: Exception) -> SuiteError:
    """One line naming the file and the suite field behind a refused probe scenario.

    The task's own keys (its duration and reference) and the start are named as such; anything
    else is the tier's ``where`` (``set``, ``random.<key>``, ``cycle.<key>.<i>``), which holds
    the [base] keys too.
    """
    path = getattr(exc, "path", "") or ""
    if path == "sim.duration" or path.startswith("reference"):
        field = f"tasks.{task}.{'duration' if path == 'sim.duration' else 'reference'}"
        return SuiteError(f"{suite.source}: {field}: under tier {tier!r} the scenario refuses it: {_reason(exc)}")
    if path.startswith("initial."):
        where = "start"
    return SuiteError(f"{suite.source}: tiers.{tier}.{where} on task {task!r}: the scenario refuses it: "
                      f"{_reason(exc)}")


def _check_starts(suite: Suite, task: str, tier: str) -> None:
    """Every start the tier can draw is a valid initial state: the offsets at their half-widths, all signs."""
    from ..scenario.errors import translate as _translate
    from ..scenario.schema import InitialSection

    tk, start = suite.file.tasks[task], suite.file.tiers[tier].start
    axes = [a for a in START_AXES if getattr(start, a) > 0]
    for ends in itertools.product((0.0, 1.0), repeat=len(axes)):
        unit = {a: 0.5 for a in START_AXES} | dict(zip(axes, ends))
        eta, nu = start_state(tk.reference, start, unit, suite.ell(tier))
        try:
            InitialSection.model_validate({"eta": eta, "nu": nu})
        except ValidationError as exc:
            err = _translate(exc, InitialSection)
            raise SuiteError(f"{suite.source}: tiers.{tier}.start: on task {task!r} the start offsets can put "
                             f"initial.{err}") from None


def _prepared_probe(suite: Suite, entries: list[ControllerEntry], task: str, tier: str, where: str,
                    overrides: dict):
    """The probe's run prepared for the first competitor that accepts it (schema, run plan, set-up).

    A schema error does not depend on the controller (the suite cannot set ``controller``); a
    run plan or set-up refusal by every competitor means every run of the cell would fail.
    """
    from ..scenario import load_scenario
    from ..simulation.pipeline import prepare

    first: Exception | None = None
    for entry in entries:
        raw, _, _ = suite.scenario(entry, task, tier, 0)
        try:
            sc = load_scenario(raw, overrides)
        except ScenarioError as exc:
            raise _blame(suite, task, tier, where, exc) from None
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                return prepare(sc)
        except (ValueError, ImportError, TypeError) as exc:
            first = first or exc
    assert first is not None
    raise _blame(suite, task, tier, where, first) from None


def _probe_values(dist) -> list[tuple[str, float]]:
    """(what, value) pairs at which a tier's random key is checked."""
    out = [("the range's end" if not isinstance(dist, Normal) else "the mean", float(v)) for v in dist.probes()]
    if isinstance(dist, Normal):
        out += [(f"mean {sign} {NORMAL_PROBE_STD:g} std", dist.mean + k * NORMAL_PROBE_STD * dist.std)
                for sign, k in (("-", -1.0), ("+", 1.0))]
    return out


def _check_runs(suite: Suite) -> None:
    """Check that every (task, tier) cell can run, as ``auvtrack check`` would check its scenarios.

    Per cell: every start the tier can draw (:func:`_check_starts`); the scenario of seed index 0
    with the tier's fixed values through loading, the run plan and the set-up of the default
    competitors (one of them must accept it); each cycled value the same way; each random key at
    the ends of its range (a normal at its mean and mean +- :data:`NORMAL_PROBE_STD` std) through
    loading and the run plan.  Messages name the file, the task or tier field and the task.
    """
    from ..scenario import load_scenario
    from ..scenario.plan import plan_run

    entries = resolve_controllers(None, gain_preset=suite.file.gain_preset)
    for task in suite.tasks:
        for tier in suite.tiers:
            tr = suite.file.tiers[tier]
            _check_starts(suite, task, tier)
            _, ov, _ = suite.conditions(task, tier, 0)
            fixed = {k: v for k, v in ov.items() if k not in tr.random and k not in tr.cycle}
            fixed |= {k: options[0] for k, options in tr.cycle.items()}  # a cycled key always has a value
            prep = _prepared_probe(suite, entries, task, tier, "set", fixed)
            for key, options in tr.cycle.items():
                for j, v in enumerate(options):
                    _prepared_probe(suite, entries, task, tier, f"cycle.{key}.{j}", {**fixed, key: v})
            raw, _, _ = suite.scenario(entries[0], task, tier, 0)
            for key, dist in tr.random.items():
                for what, v in _probe_values(dist):
                    try:
                        plan_run(load_scenario(raw, {**fixed, key: v}), len(prep.channels))
                    except ScenarioError as exc:
                        raise SuiteError(f"{suite.source}: tiers.{tier}.random.{key}: on task {task!r} {what} "
                                         f"{v:g} is refused: {_reason(exc)}") from None


def _worst_draws(tier: Tier) -> list[dict[str, float]]:
    """Every corner of a tier's random ranges (a normal at mean +- :data:`NORMAL_PROBE_STD` std)."""
    keys = list(tier.random)
    ends = [[v for what, v in _probe_values(tier.random[k]) if what != "the mean"] or
            [v for _, v in _probe_values(tier.random[k])] for k in keys]
    return [dict(zip(keys, combo)) for combo in itertools.product(*ends)] if keys else [{}]


def _check_feasibility(suite: Suite) -> None:
    """Refuse a (task, tier) cell whose plant cannot fly the task's reference (:mod:`auvtrack.feasibility`).

    Each cell is assessed with every cycled value and every corner of its random ranges (the
    current at its worst); a plant without a steady-state model is not assessed.  The message
    names the cell and the first infeasible check.
    """
    from ..feasibility.assess import assess

    entry = resolve_controllers(None, gain_preset=suite.file.gain_preset)[0]
    for task in suite.tasks:
        for tier in suite.tiers:
            tr = suite.file.tiers[tier]
            raw, ov, _ = suite.scenario(entry, task, tier, 0)
            fixed = {k: v for k, v in ov.items() if k not in tr.random and k not in tr.cycle}
            cycles = [dict(zip(tr.cycle, combo)) for combo in itertools.product(*tr.cycle.values())]
            for cyc in cycles:
                for draw in _worst_draws(tr):
                    with warnings.catch_warnings():
                        warnings.simplefilter("ignore")
                        verdict = assess(raw, {**fixed, **cyc, **draw})
                    if verdict.verdict == "infeasible":
                        bad = next(c for c in verdict.checks if c.status == "infeasible")
                        where = ", ".join(f"{k} = {v}" for k, v in {**cyc, **draw}.items())
                        raise SuiteError(f"{suite.source}: task {task!r} under tier {tier!r} is infeasible"
                                         f"{' (' + where + ')' if where else ''}: {bad.describe()}")


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
    from ..scenario.loader import parse_toml_text
    from ..scenario.reading import read_bounded

    label = str(name)
    if label in available_suites():
        path, source = Path(str(_suites_root() / f"{label}.toml")), label
    elif label.endswith(".toml"):
        path, source = Path(label), label
    else:
        raise SuiteError(f"--suite: unknown suite {label!r} (shipped: {', '.join(available_suites()) or 'none'}; "
                         "or a path to a .toml file)")
    try:
        data = read_bounded(path, source)
        try:
            text = data.decode("utf-8")
        except UnicodeDecodeError:
            raise ScenarioError(f"{source}: not a UTF-8 text file") from None
        raw = parse_toml_text(text, source)
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
    try:
        ells = tuple((t, _tier_ell(sf, t)) for t in sf.tiers if t not in dict(skipped))
    except ScenarioError as exc:
        raise SuiteError(f"{source}: base or a tier's set: its vehicle keys are refused: {_reason(exc)}") from None
    suite = Suite(sf, source, False, text, skipped, ells)
    if not suite.tiers:
        raise SuiteError(f"{source}: tiers: none can run in this build ({'; '.join(r for _, r in skipped)})")
    if check:
        _check_runs(suite)
        if sf.feasibility:
            _check_feasibility(suite)
    return suite

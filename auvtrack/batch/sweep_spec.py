"""Study files of ``auvtrack sweep``: the validated model, its sample plan and one-line errors.

A study file (TOML, format in ``docs/sweeps.md``) names a base scenario, ``--set``-style
overrides, grids over scenario keys and random draws.  Sample ``i`` is grid point
``i // samples`` (the last grid key varies fastest) and replicate ``i % samples``.  Every random
number of sample ``i`` comes from ``SeedSequence([study seed, crc32(purpose), i])`` (one purpose
per varied key, ``"seed"`` for the scenario seed), so a sample depends only on the study and
its own index, never on chunking, worker or order.  With ``common_seeds = true`` the replicate
index replaces ``i`` (common random numbers across grid points).
"""
from __future__ import annotations

import hashlib
import json
import math
import re
import zlib
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any, Literal, Union

import numpy as np
from pydantic import (AllowInfNan, BaseModel, ConfigDict, Field, Strict, ValidationError, field_validator,
                      model_validator)

from ..scenario.errors import ScenarioError, format_value, one_line, translate
from ..scenario.names import check_name

__all__ = ["StudyError", "StudyFile", "StudyLimits", "SweepSpec", "load_study", "PAPER_SCENARIO", "MAX_SAMPLES"]

PAPER_SCENARIO = "paper"
MAX_SAMPLES = 100_000_000
MAX_CHUNK = 1_000_000
MAX_GRID_VALUES = 1_000_000
MAX_CHUNK_FILES = 1_000_000

Num = Annotated[float, Strict(), AllowInfNan(False)]
Scalar = Union[Annotated[bool, Strict()], Annotated[int, Strict()], Num, Annotated[str, Strict()]]


class StudyError(ScenarioError):
    """Invalid study file: ``str(err)`` is one line naming the file, the field and the rule."""


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class Uniform(_Model):
    """``dist = "uniform"``: uniform on [low, high)."""

    dist: Literal["uniform"]
    low: Num
    high: Num

    @model_validator(mode="after")
    def _order(self) -> "Uniform":
        if not self.high > self.low:
            raise ValueError(f"high: must be > low = {self.low:g} (got {self.high:g})")
        return self

    def draw(self, g: np.random.Generator) -> float:
        """One draw."""
        return float(g.uniform(self.low, self.high))

    def probes(self) -> tuple[float, ...]:
        """Values checked against the scenario when the study is loaded (the range ends)."""
        return self.low, self.high


class Normal(_Model):
    """``dist = "normal"``: Gaussian with mean and standard deviation std > 0."""

    dist: Literal["normal"]
    mean: Num
    std: Annotated[Num, Field(gt=0)]

    def draw(self, g: np.random.Generator) -> float:
        """One draw."""
        return float(g.normal(self.mean, self.std))

    def probes(self) -> tuple[float, ...]:
        """Values checked against the scenario when the study is loaded (the mean)."""
        return (self.mean,)


class LogUniform(_Model):
    """``dist = "loguniform"``: log(x) uniform on [log low, log high), 0 < low < high."""

    dist: Literal["loguniform"]
    low: Annotated[Num, Field(gt=0)]
    high: Num

    @model_validator(mode="after")
    def _order(self) -> "LogUniform":
        if not self.high > self.low:
            raise ValueError(f"high: must be > low = {self.low:g} (got {self.high:g})")
        return self

    def draw(self, g: np.random.Generator) -> float:
        """One draw."""
        return float(math.exp(g.uniform(math.log(self.low), math.log(self.high))))

    def probes(self) -> tuple[float, ...]:
        """Values checked against the scenario when the study is loaded (the range ends)."""
        return self.low, self.high


Distribution = Annotated[Union[Uniform, Normal, LogUniform], Field(discriminator="dist")]


class StudyLimits(_Model):
    """``[limits]`` of a study file: the largest plan accepted, checked before anything is set up.

    Each grid value is validated with a full set-up when the study loads, and every sample is a
    run and a row, so the defaults keep loading to seconds and a sweep to days; raise them
    deliberately (each has a hard ceiling of its own).
    """

    max_samples: Annotated[int, Strict(), Field(ge=1, le=MAX_SAMPLES)] = Field(
        1_000_000, description="samples: grid points x samples")
    max_grid_values: Annotated[int, Strict(), Field(ge=1, le=MAX_GRID_VALUES)] = Field(
        1_000, description="values of one grid key (each checked with a full set-up at load)")
    max_chunks: Annotated[int, Strict(), Field(ge=1, le=MAX_CHUNK_FILES)] = Field(
        100_000, description="chunks (Dask tasks, chunk files): samples / chunk_size")


def _over_limit(field: str, what: str, key: str, limit: int, ceiling: int, hint: str = "") -> ValueError:
    return ValueError(f"{field}: {what}, more than limits.{key} = {limit} ({hint}raise it deliberately in a "
                      f"[limits] table of the study file, up to {ceiling})")


class StudyFile(_Model):
    """The keys of a study file (see ``docs/sweeps.md``)."""

    name: Annotated[str, Strict()] = "sweep"
    scenario: Annotated[str, Strict()] = Field(PAPER_SCENARIO, description="a packaged scenario's name or a TOML path")
    set: list[Annotated[str, Strict()]] = Field(default_factory=list)
    seed: Annotated[int, Strict(), Field(ge=0)] = 0
    samples: Annotated[int, Strict(), Field(ge=1, le=MAX_SAMPLES)] = 1
    chunk_size: Annotated[int, Strict(), Field(ge=1, le=MAX_CHUNK)] = 50
    seed_key: Annotated[str, Strict()] = "seed"
    common_seeds: Annotated[bool, Strict()] = False
    grid: dict[str, Annotated[list[Any], Field(min_length=1)]] = Field(default_factory=dict)
    random: dict[str, Distribution] = Field(default_factory=dict)
    limits: StudyLimits = Field(default_factory=StudyLimits)

    @field_validator("name")
    @classmethod
    def _name(cls, v: str) -> str:
        return check_name(v)  # it becomes the folder sweeps/<name>: the rule of scenario names

    @model_validator(mode="after")
    def _plan(self) -> "StudyFile":
        lim = self.limits
        for key, vals in self.grid.items():
            if len(vals) > lim.max_grid_values:
                raise _over_limit(f"grid.{key}", f"{len(vals)} values", "max_grid_values", lim.max_grid_values,
                                  MAX_GRID_VALUES, "each is checked with a full set-up before the sweep starts; ")
        n = self.n_points * self.samples
        if n > lim.max_samples:
            field = "grid" if self.n_points > lim.max_samples else "samples"
            raise _over_limit(field, f"{self.n_points} grid points x {self.samples} samples = {n} samples",
                              "max_samples", lim.max_samples, MAX_SAMPLES)
        chunks = -(-n // self.chunk_size)
        if chunks > lim.max_chunks:
            raise _over_limit("chunk_size", f"{n} samples in chunks of {self.chunk_size} make {chunks} chunks",
                              "max_chunks", lim.max_chunks, MAX_CHUNK_FILES, "raise chunk_size, or ")
        return self

    @model_validator(mode="after")
    def _keys(self) -> "StudyFile":
        from ..scenario.overrides import parse_overrides

        seen: set[str] = set()
        for section, keys in (("grid", self.grid), ("random", self.random)):
            for key in keys:
                try:
                    parse_overrides({key: 0})
                except ScenarioError:
                    raise ValueError(f"{section}: {key!r} is not a dotted scenario key "
                                     f"(e.g. uncertainty.C, disturbance.0.amplitude)") from None
                if key in seen:
                    raise ValueError(f"{section}: {key!r} is varied twice (in grid and random)")
                if key == self.seed_key:
                    raise ValueError(f"{section}: {key!r} is the seed_key, which receives each sample's seed")
                seen.add(key)
        return self

    @property
    def n_points(self) -> int:
        """Number of grid points (1 without a grid)."""
        return math.prod(len(v) for v in self.grid.values())


def _column_value(v: Any) -> Any:
    """A grid value as stored in the results table: scalars as they are, arrays and tables as JSON."""
    return v if isinstance(v, (bool, int, float, str)) else json.dumps(v, sort_keys=True)


@dataclass(frozen=True)
class SweepSpec:
    """A loaded, validated study: everything a worker needs (plain data, picklable).

    Attributes
    ----------
    study : StudyFile
        The validated file.
    base : dict
        Raw base scenario with the study's ``set`` overrides applied.
    source : str
        Label of the study file for messages.
    """

    study: StudyFile
    base: dict
    source: str = "<study>"

    @property
    def n_samples(self) -> int:
        """Total number of samples."""
        return self.study.n_points * self.study.samples

    @property
    def n_chunks(self) -> int:
        """Number of chunks of ``chunk_size`` samples."""
        return -(-self.n_samples // self.study.chunk_size)

    def chunk_range(self, chunk: int) -> range:
        """Sample indices of chunk ``chunk``."""
        cs = self.study.chunk_size
        return range(chunk * cs, min((chunk + 1) * cs, self.n_samples))

    @property
    def varied(self) -> tuple[str, ...]:
        """Varied keys: grid keys (file order) then random keys."""
        return tuple(self.study.grid) + tuple(self.study.random)

    def _stream(self, index: int) -> int:
        return index % self.study.samples if self.study.common_seeds else index

    def _generator(self, purpose: str, index: int) -> np.random.Generator:
        ss = np.random.SeedSequence([self.study.seed, zlib.crc32(purpose.encode()), self._stream(index)])
        return np.random.default_rng(ss)

    def sample_seed(self, index: int) -> int:
        """Scenario seed of sample ``index`` (a non-negative 63-bit integer)."""
        return int(self._generator("seed", index).integers(0, 2**63 - 1))

    def sample(self, index: int) -> tuple[int, int, dict[str, Any]]:
        """(grid point, replicate, {key: value}) of sample ``index``; values as applied."""
        if not 0 <= index < self.n_samples:
            raise IndexError(f"sample index {index} out of range [0, {self.n_samples})")
        point, rep = divmod(index, self.study.samples)
        values: dict[str, Any] = {}
        rem = point
        sizes = [len(v) for v in self.study.grid.values()]
        digits = []
        for size in reversed(sizes):
            rem, d = divmod(rem, size)
            digits.append(d)
        for (key, vals), d in zip(self.study.grid.items(), reversed(digits)):
            values[key] = vals[d]
        for key, dist in self.study.random.items():
            values[key] = dist.draw(self._generator(f"draw/{key}", index))
        return point, rep, values

    def overrides(self, index: int) -> tuple[int, dict[str, Any]]:
        """(seed, overrides mapping) of sample ``index`` applied on top of :attr:`base`."""
        _, _, values = self.sample(index)
        seed = self.sample_seed(index)
        ov = dict(values)
        if self.study.seed_key:
            ov[self.study.seed_key] = seed
        return seed, ov

    def column_values(self, index: int) -> dict[str, Any]:
        """The varied values of sample ``index`` as stored in the results table."""
        return {k: _column_value(v) for k, v in self.sample(index)[2].items()}

    def fingerprint(self) -> str:
        """SHA-256 of everything that defines the samples (file contents, base scenario)."""
        doc = {"study": self.study.model_dump(mode="json"), "base": self.base}
        return hashlib.sha256(json.dumps(doc, sort_keys=True, default=str).encode()).hexdigest()


def _fail(source: str, field: str, text: str) -> StudyError:
    return StudyError(f"{source}: {field}: {text}" if field else f"{source}: {text}", field)


def _base_scenario(study: StudyFile, folder: Path, source: str) -> dict:
    from ..scenario.catalog import is_scenario_name, scenario_path
    from ..scenario.loader import _default_at, read_toml
    from ..scenario.overrides import apply_overrides, parse_overrides
    from ..user_modules import anchor_module

    try:  # a packaged scenario's name (no '/', '.'), else a path relative to the study file
        path = scenario_path(study.scenario) if is_scenario_name(study.scenario) else (folder / study.scenario)
        raw = anchor_module(read_toml(path), Path(path).parent)  # a plug-in path: relative to its file
    except (ScenarioError, ValueError) as exc:
        raise _fail(source, "scenario", f"must be a packaged scenario's name or a readable scenario TOML file "
                                        f"({exc})") from None
    try:
        return apply_overrides(raw, parse_overrides(study.set), _default_at)
    except ScenarioError as exc:
        raise _fail(source, "set", str(exc)) from None


def _problem(spec: SweepSpec, overrides: dict) -> ValueError | None:
    """Validate one sample as ``auvtrack check`` would (load, plan, controller set-up, a plug-in's probe run);
    the error or None."""
    import warnings

    from ..scenario import load_scenario
    from ..simulation.pipeline import prepare
    from ..simulation.probe import probe

    try:
        sc = load_scenario(spec.base, overrides)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            probe(prepare(sc))
    except ValueError as exc:  # ScenarioError of the schema or the run plan, a controller refusing its set-up
        return exc
    return None


def _error_path(exc: ValueError) -> str:
    """Dotted scenario path an error names (``ScenarioError.path``, else its leading ``a.b: ``)."""
    path = getattr(exc, "path", "")
    if path:
        return path
    m = re.match(r"^(?:<[^>]*>: )?([A-Za-z_][\w]*(?:\.\w+)*): ", str(exc))
    return m.group(1) if m else ""


def _probe(spec: SweepSpec, field: str, overrides: dict) -> None:
    exc = _problem(spec, overrides)
    if exc is not None:
        raise _fail(spec.source, field, f"the scenario rejects it: {one_line(str(exc))}") from None


def check_against_scenario(spec: SweepSpec) -> None:
    """Validate the base scenario, every grid value and each random range as ``auvtrack check`` would.

    Each probe is loaded, planned (``[limits]``) and set up by its controller, so a grid value
    that ``auvtrack run`` would refuse (``sim.duration = 1e9``) refuses the study up front.

    Raises
    ------
    StudyError
        Naming the study field (e.g. ``grid.uncertainty.C.2``) and the scenario's rule.
    """
    study = spec.study
    _probe(spec, "set" if study.set else "scenario", {})
    first = {k: v[0] for k, v in study.grid.items()}
    exc = _problem(spec, first)
    if exc is not None:  # the first grid point: blame the grid key the error names
        path = _error_path(exc)
        named = [k for k in study.grid if path == k or path.startswith(k + ".") or k.startswith(path + ".")]
        key = named[0] if named else next(iter(study.grid))
        raise _fail(spec.source, f"grid.{key}.0", f"the scenario rejects it: {one_line(str(exc))}")
    for key, vals in study.grid.items():
        for j, v in enumerate(vals):
            _probe(spec, f"grid.{key}.{j}", {**first, key: v})
    for key, dist in study.random.items():
        for name, v in zip(("low", "high") if len(dist.probes()) == 2 else ("mean",), dist.probes()):
            _probe(spec, f"random.{key}.{name}", {**first, key: v})
    if study.seed_key:
        _probe(spec, "seed_key", {**first, study.seed_key: spec.sample_seed(0)})


def load_study(path: str | Path, *, check: bool = True) -> SweepSpec:
    """Read and validate a study file.

    Parameters
    ----------
    path : str or Path
        The study TOML file; a relative ``scenario`` path is resolved against its folder.
    check : bool, optional
        Also validate the base scenario, grid values and random ranges against the scenario
        schema (:func:`check_against_scenario`).

    Returns
    -------
    SweepSpec

    Raises
    ------
    StudyError
        One line naming the file, the field and the allowed range.
    """
    from ..scenario.loader import read_toml

    source = str(path)
    try:
        raw = read_toml(path)
    except ScenarioError as exc:
        raise StudyError(str(exc)) from None
    try:
        study = StudyFile.model_validate(raw)
    except ValidationError as exc:
        err = translate(exc, StudyFile, source)
        text = re.sub(r"\.(?:uniform|normal|loguniform)(?=[.:])", "", str(err), count=1)  # union tag
        raise StudyError(text, err.path) from None
    spec = SweepSpec(study, _base_scenario(study, Path(path).resolve().parent, source), source)
    if check:
        check_against_scenario(spec)
    return spec


def describe_value(v: Any) -> str:
    """Short rendering of a value for messages."""
    return one_line(format_value(v))

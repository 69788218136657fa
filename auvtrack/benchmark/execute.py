"""Execution of ``auvtrack compare``: every run of a suite, locally or on Dask, resumable and verified.

The runs (:func:`plan_runs`: tier, task, seed index, controller, in that order) are cut into
chunks of ``chunk_size``; :class:`CompareJob` hands them to the chunk executor shared with
sweeps (:mod:`auvtrack.batch.executor`).  A chunk is planned, prepared and run through the batch
runner (:func:`auvtrack.batch.runner.run_batch`: metrics reduced in the kernel, no trajectory)
-- locally in this process over threads, or as a Dask task (:func:`run_planned`, importable on
a worker; the suite and the controllers travel as plain data, never compiled functions) when a
scheduler is given.  Each finished chunk is written atomically as
``chunks/chunk-NNNNNN.parquet`` with the comparison's fingerprint and its content hash, so an
interrupted comparison resumes (``resume=True``) with every run exactly once, chunks that fail
verification are recomputed, and a run's row depends only on the suite, the controller and its
(task, tier, seed index).  ``compare.json`` holds the fingerprint (suite, controllers, chunk
size, back end, package sources): a folder of another comparison, or of another version of the
code, is refused.  The plan's size is checked against ``max_runs`` (``--max-runs``) before
anything is planned.
"""
from __future__ import annotations

import json
import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Sequence

from ..batch.chunk_files import chunk_path
from ..batch.executor import ChunkJob, check_workers, execute_chunks
from ..control.plugin import PluginFailure

__all__ = ["RunSpec", "plan_size", "check_plan", "check_plugin_setups", "plan_runs", "run_planned", "run_chunk", "warm_runs", "execute", "ExecOutcome",
           "CompareJob", "CompareError", "chunk_path", "MANIFEST", "RUNS_FILE", "FIXED_COLUMNS", "DEFAULT_MAX_RUNS",
           "MAX_RUNS"]

MANIFEST = "compare.json"
RUNS_FILE = "runs.parquet"
FIXED_COLUMNS = ("run", "controller", "task", "tier", "seed_index", "seed", "status", "cause", "detail",
                 "fail_time", "t_stop", "steps", "draws")
DEFAULT_MAX_RUNS = 100_000
"""Default bound on the runs of one comparison (``--max-runs``): several times the default suite's."""
MAX_RUNS = 1_000_000
"""Hard ceiling of ``--max-runs`` (the runs table and its statistics are held in memory)."""


class CompareError(ValueError):
    """A comparison that cannot start (wrong output folder, bad option): one line."""


@dataclass(frozen=True)
class RunSpec:
    """One run of a comparison (plain data).

    Attributes
    ----------
    run : int
        Position in the plan.
    controller, task, tier : str
        Controller label, task and tier names.
    index : int
        Seed index.
    raw, overrides : dict
        ``load_scenario(raw, overrides)`` is the run's scenario.
    drawn : dict
        The values this seed drew (recorded as JSON in the ``draws`` column).
    """

    run: int
    controller: str
    task: str
    tier: str
    index: int
    raw: dict
    overrides: dict
    drawn: dict


def plan_size(suite, entries: Sequence) -> int:
    """Number of runs of ``suite`` for the controllers ``entries`` (arithmetic only, nothing is planned).

    Parameters
    ----------
    suite : auvtrack.benchmark.suite.Suite
        The suite (or its quick variant).
    entries : sequence of ControllerEntry
        The competitors.

    Returns
    -------
    int
        tiers x tasks x seeds x controllers.
    """
    return len(suite.tiers) * len(suite.tasks) * suite.seeds * len(entries)


def check_plan(suite, entries: Sequence, max_runs: int = DEFAULT_MAX_RUNS) -> int:
    """Refuse a comparison of more than ``max_runs`` runs, before anything is planned or set up.

    Parameters
    ----------
    suite : auvtrack.benchmark.suite.Suite
        The suite.
    entries : sequence of ControllerEntry
        The competitors.
    max_runs : int, optional
        The bound (``--max-runs``), in ``[1, MAX_RUNS]``.

    Returns
    -------
    int
        The number of runs.

    Raises
    ------
    CompareError
        One line naming the suite's ``seeds`` (the factor a suite sizes) and ``--max-runs``.
    """
    if isinstance(max_runs, bool) or not isinstance(max_runs, int) or not 1 <= max_runs <= MAX_RUNS:
        raise CompareError(f"--max-runs: must be an integer in [1, {MAX_RUNS}] (got {max_runs!r})")
    n = plan_size(suite, entries)
    if n > max_runs:
        raise CompareError(f"{suite.source}: seeds: {suite.seeds} seeds x {len(suite.tasks)} tasks x "
                           f"{len(suite.tiers)} tiers x {len(entries)} controllers = {n} runs, more than "
                           f"--max-runs = {max_runs} (raise it deliberately with --max-runs N, up to {MAX_RUNS})")
    return n


def plan_runs(suite, entries: Sequence, runs: range | None = None) -> list[RunSpec]:
    """The runs ``runs`` (default: every run) of ``suite`` for the controllers ``entries``, in plan order.

    Run ``r`` is tier-major, then task, seed index and controller: ``r = ((tier * tasks + task)
    * seeds + index) * controllers + controller``, so any range of runs is planned on its own
    (a chunk on a Dask worker) and gives the runs the whole plan would.

    Parameters
    ----------
    suite : auvtrack.benchmark.suite.Suite
        The suite (or its quick variant).
    entries : sequence of ControllerEntry
        The competitors.
    runs : range, optional
        Run positions, within ``range(plan_size(suite, entries))``.

    Returns
    -------
    list of RunSpec
        In ``runs`` order.
    """
    n = plan_size(suite, entries)
    runs = range(n) if runs is None else runs
    tiers, tasks, seeds, n_c = suite.tiers, suite.tasks, suite.seeds, len(entries)
    specs: list[RunSpec] = []
    cell, cond = None, None
    for r in runs:
        if not 0 <= r < n:
            raise IndexError(f"run {r} out of range [0, {n})")
        q, c = divmod(r, n_c)
        q, i = divmod(q, seeds)
        tier, task = tiers[q // len(tasks)], tasks[q % len(tasks)]
        if cell != (tier, task, i):
            cell, cond = (tier, task, i), suite.conditions(task, tier, i)  # the same for every controller
        raw, ov, drawn = suite.scenario(entries[c], task, tier, i, cond)
        specs.append(RunSpec(r, entries[c].label, task, tier, i, raw, ov, drawn))
    return specs


def _schema():
    import pyarrow as pa

    from ..metrics import METRIC_NAMES

    ints = {"run", "seed_index", "seed", "steps"}
    floats = {"fail_time", "t_stop"}
    fields = [pa.field(c, pa.int64() if c in ints else pa.float64() if c in floats else pa.string())
              for c in FIXED_COLUMNS]
    return pa.schema(fields + [pa.field(m, pa.float64()) for m in METRIC_NAMES])


def _prepare(spec: RunSpec, plant_cache: dict | None = None):
    """A Prepared run, or the one-line reason the controller's set-up refused it.

    ``plant_cache``: :func:`auvtrack.simulation.pipeline.prepare`'s (runs sharing their conditions).

    A plug-in's set-up is user code: any exception it raises is its refusal of the run (with the
    exception's type), never a traceback in the middle of a comparison.
    """
    import warnings

    from ..scenario import ScenarioError, load_scenario
    from ..simulation.pipeline import prepare

    refusals = Exception if spec.raw.get("controller", {}).get("kind") == "plugin" else (
        ScenarioError, ValueError, ImportError, TypeError)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return prepare(load_scenario(spec.raw, spec.overrides), plant_cache=plant_cache)
    except refusals as exc:
        if isinstance(exc, PluginFailure):
            return exc.cause
        text = " ".join(str(exc).split()) or type(exc).__name__
        return text if isinstance(exc, ValueError) else f"{type(exc).__name__}: {text}"


def check_plugin_setups(suite, entries: Sequence) -> None:
    """Refuse a plug-in whose set-up breaks, or whose law faults in its probe run, on the comparison's first run.

    The contract's way to refuse a run is a ``ValueError`` (a gain condition); such a run counts
    as a set-up failure.  Any other exception on the first (tier, task, seed 0) is a broken
    plug-in, and the comparison stops before anything runs.  That run's first seconds are then
    flown with the law bounds-checked (:func:`auvtrack.simulation.probe.probe`, as ``check`` and
    ``run`` do): a law that raises there (an index out of bounds) or never returns is refused.

    Parameters
    ----------
    suite : auvtrack.benchmark.suite.Suite
        The suite.
    entries : sequence of ControllerEntry
        The competitors (only plug-ins are probed).

    Raises
    ------
    CompareError
        One line naming ``--plugin``, the file and the exception (for a probe's fault: the file's
        line, the error and the time).
    """
    import warnings

    from ..scenario import load_scenario
    from ..simulation.pipeline import prepare
    from ..simulation.probe import ProbeFault, probe

    for e in entries:
        if e.table.get("kind") != "plugin":
            continue
        spec = plan_runs(suite, [e], range(1))[0]
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                prep = prepare(load_scenario(spec.raw, spec.overrides))
            probe(prep)
        except ProbeFault as exc:
            where = str(exc).removeprefix("controller.module: ")
            raise CompareError(f"--plugin: {where}, on task {spec.task}, tier {spec.tier}") from None
        except PluginFailure as exc:
            raise CompareError(f"--plugin: {e.table.get('module')}: its set-up fails on task {spec.task}, tier "
                               f"{spec.tier}: {exc.cause}") from None
        except ValueError:
            pass  # a refusal of this run (ScenarioError is one): recorded as a set-up failure
        except Exception as exc:  # noqa: BLE001 - the plug-in's own code
            raise CompareError(f"--plugin: {e.table.get('module')}: its set-up fails on task {spec.task}, tier "
                               f"{spec.tier}: {type(exc).__name__}: {' '.join(str(exc).split())}") from None


def _backend_kw(backend: str | None) -> dict:
    """``run_batch`` keywords for ``backend`` (None: the batch runner's own default back end)."""
    return {} if backend is None else {"backend": backend}


def _base_row(spec: RunSpec) -> dict[str, Any]:
    return {"run": spec.run, "controller": spec.controller, "task": spec.task, "tier": spec.tier,
            "seed_index": spec.index, "seed": int(spec.raw["seed"]), "draws": json.dumps(spec.drawn, sort_keys=True)}


def _not_run(spec: RunSpec, cause: str, detail: str) -> dict[str, Any]:
    """The row of a run that did not fly: failed, zero steps, every metric NaN."""
    from ..metrics import METRIC_NAMES

    row = _base_row(spec)
    row.update(status="failed", cause=cause, detail=detail, fail_time=0.0, t_stop=0.0, steps=0)
    row.update({m: math.nan for m in METRIC_NAMES})
    return row


def _table(rows: list[dict[str, Any]]):
    import pyarrow as pa

    schema = _schema()
    return pa.Table.from_pydict({f.name: [r[f.name] for r in rows] for f in schema}, schema=schema)


def run_chunk(specs: Sequence[RunSpec], *, workers: int | None = 1, backend: str | None = None,
              plant_cache: dict | None = None):
    """Prepare and run ``specs`` (metrics only) and return one row per run as an Arrow table.

    A run whose set-up is refused (a controller rejecting its gains or the start) is a failure
    with cause ``setup`` and the reason in ``detail``: it counts, it is not dropped.

    Parameters
    ----------
    specs : sequence of RunSpec
        The chunk's runs.
    workers : int or None, optional
        Threads of :func:`auvtrack.batch.runner.run_batch` (None: every core; 1 on a Dask
        worker, which is single-threaded).
    backend : str, optional
        A back end of :func:`auvtrack.batch.runner.run_batch` (one of its ``BACKENDS``); default:
        the batch runner's default.
    plant_cache : dict, optional
        Plant set-ups to reuse and fill (:func:`auvtrack.simulation.pipeline.prepare`): a
        tuning's candidates fly the same runs with other gains.

    Returns
    -------
    pyarrow.Table
        Columns :data:`FIXED_COLUMNS` and every metric of
        :data:`auvtrack.metrics.METRIC_NAMES`, in ``specs`` order.
    """
    from ..batch.runner import run_batch
    from ..report import failure_cause

    prepared = [_prepare(s, plant_cache) for s in specs]
    runnable = [p for p in prepared if not isinstance(p, str)]
    summaries = iter(run_batch(runnable, workers=workers, **_backend_kw(backend)))
    rows = []
    for spec, prep in zip(specs, prepared):
        if isinstance(prep, str):
            rows.append(_not_run(spec, "setup", prep))
            continue
        s = next(summaries)
        f = s.failure or {}
        row = _base_row(spec)
        row.update(status=s.status, cause=failure_cause(s) or "", detail=str(f.get("detail", "")),
                   fail_time=float(f.get("time", math.nan)), t_stop=s.t_stop, steps=s.steps)
        row.update(s.metrics)
        rows.append(row)
    return _table(rows)


def run_planned(suite, entries: Sequence, runs: range, *, workers: int | None = 1, backend: str | None = None):
    """Plan and run the runs ``runs`` of a comparison: the Dask task of one chunk.

    Parameters
    ----------
    suite : auvtrack.benchmark.suite.Suite
        The suite (plain data).
    entries : sequence of ControllerEntry
        The competitors.
    runs : range
        Run positions (:func:`plan_runs`).
    workers : int or None, optional
        Threads of the batch runner (1 on a Dask worker).
    backend : str, optional
        Back end of the batch runner.

    Returns
    -------
    pyarrow.Table
        :func:`run_chunk` of the planned runs.
    """
    return run_chunk(plan_runs(suite, entries, runs), workers=workers, backend=backend)


def _warm_specs(suite, entries: Sequence) -> list[RunSpec]:
    """One run per (controller, tier, plant preset), the first of each in plan order.

    The preset can only differ between seed indices through a tier's ``cycle`` (random draws are
    numbers), so the seed indices below the longest cycle of the first task hold every key.
    """
    n_c, seeds, n_tasks = len(entries), suite.seeds, len(suite.tasks)
    runs = []
    for t, tier in enumerate(suite.tiers):
        cycles = suite.file.tiers[tier].cycle.values()
        for i in range(min(seeds, max((len(v) for v in cycles), default=1))):
            first = (t * n_tasks * seeds + i) * n_c
            runs.extend(range(first, first + n_c))
    seen: dict[tuple, RunSpec] = {}
    for s in plan_runs(suite, entries, runs):
        seen.setdefault((s.controller, s.tier, s.overrides.get("plant.preset")), s)
    return list(seen.values())


def warm_runs(specs: Sequence[RunSpec], workers: int | None = None, backend: str | None = None, *,
              progress: bool = True, notice: Callable[[str], None] | None = None) -> float:
    """Compile or load everything the runs ``specs`` need before the timed runs start.

    One run per (controller, tier, plant preset) is prepared (set-up helpers compile on first
    use), its kernel compiled or loaded, and then flown for 0.5 s: a kernel compiles one
    specialisation per type signature of its bundles, and the tiers' bundles differ, so this
    loads every signature the runs will call.  With the ``simd`` back end each is flown in a full
    block of lanes, so that the lane kernels too compile here.

    Parameters
    ----------
    specs : sequence of RunSpec
        The runs about to be flown (one per key is enough, e.g. :func:`plan_runs` of a chunk).
    workers : int or None, optional
        Threads of the batch runner for the short flights.
    backend : str, optional
        Back end of the batch runner (``simd`` also compiles the lane kernels).
    progress : bool, optional
        A progress bar over the kernels compiled.
    notice : callable, optional
        Receives the "compiling kernels (first run only, about N s)" line when a kernel is not
        cached (default: standard error).

    Returns
    -------
    float
        Wall time of the warm-up in seconds.
    """
    from ..batch.runner import run_batch
    from ..simulation.compiling import ensure_compiled

    t0 = time.perf_counter()
    seen: dict[tuple, Any] = {}
    for s in specs:
        key = (s.controller, s.tier, s.overrides.get("plant.preset"))
        if key not in seen:
            sim = {**s.raw.get("sim", {}), "duration": min(0.5, float(s.raw.get("sim", {}).get("duration", 0.5)))}
            short = RunSpec(s.run, s.controller, s.task, s.tier, s.index, {**s.raw, "sim": sim}, s.overrides,
                            s.drawn)
            p = _prepare(short)
            if not isinstance(p, str):
                seen[key] = p
    ensure_compiled(list(seen.values()), progress=progress, notice=notice)
    if seen:
        warm = list(seen.values())
        if backend == "simd":  # a block of lanes per signature: the lane kernels compile here, not in the timed runs
            from ..engine.loop import LANES

            warm = [p for p in warm for _ in range(LANES)]
        run_batch(warm, workers=workers, **_backend_kw(backend))
    return time.perf_counter() - t0


def _silent(text: str) -> None:
    """A notice nobody asked for (``--quiet``)."""


class CompareJob(ChunkJob):
    """A comparison as a job of the chunk executor: its runs in chunks of ``chunk_size``.

    Parameters
    ----------
    suite : Suite
        The suite (or its quick variant).
    entries : sequence of ControllerEntry
        The competitors.
    chunk_size : int
        Runs per chunk.
    backend : str or None
        Back end of the batch runner (a named one is part of the fingerprint).
    """

    kind = "comparison"
    manifest_name = MANIFEST
    results_name = RUNS_FILE
    id_column = "run"
    unit = "run"
    error = CompareError

    def __init__(self, suite, entries: Sequence, chunk_size: int, backend: str | None) -> None:
        self.suite, self.entries, self.chunk_size, self.backend = suite, list(entries), chunk_size, backend
        self.runs = plan_size(suite, self.entries)

    @property
    def label(self) -> str:
        """The suite's name (and "(quick)")."""
        return self.suite.name + (" (quick)" if self.suite.quick else "")

    @property
    def n_chunks(self) -> int:
        """Chunks of the plan."""
        return -(-self.runs // self.chunk_size)

    @property
    def n_rows(self) -> int:
        """Runs of the plan."""
        return self.runs

    def chunk_ids(self, chunk: int) -> range:
        """Run positions of chunk ``chunk``."""
        return range(chunk * self.chunk_size, min((chunk + 1) * self.chunk_size, self.runs))

    def definition(self) -> dict:
        """Suite fingerprint, controllers, chunk size and a named back end."""
        doc = {"suite": self.suite.fingerprint(), "controllers": [e.to_dict() for e in self.entries],
               "chunk_size": self.chunk_size}
        if self.backend is not None:
            doc["backend"] = self.backend
        return doc

    def schema(self):
        """The columns of ``runs.parquet`` before the benchmark's derived metrics."""
        return _schema()

    def manifest(self) -> dict:
        """Suite, variant, controllers and sizes."""
        return {"suite_fingerprint": self.suite.fingerprint(), "suite": self.suite.name, "quick": self.suite.quick,
                "controllers": [e.to_dict() for e in self.entries], "runs": self.runs,
                "chunk_size": self.chunk_size, "backend": self.backend}

    def describe(self, manifest: dict) -> str:
        """Suite, variant and controllers of another comparison's manifest."""
        labels = [c.get("label", "?") for c in manifest.get("controllers", []) if isinstance(c, dict)]
        return (f"suite {manifest.get('suite', '?')}{' (quick)' if manifest.get('quick') else ''}, controllers "
                f"{', '.join(labels) or '?'}, chunk size {manifest.get('chunk_size', '?')}, back end "
                f"{manifest.get('backend') or 'default'}")

    def format1_fingerprint(self) -> str:
        """SHA-256 of suite, controllers, chunk size, sources and named back end: what format-1 manifests record."""
        import hashlib

        from ..jit import source_hash

        doc = {**self.definition(), "source": source_hash()}
        return hashlib.sha256(json.dumps(doc, sort_keys=True).encode()).hexdigest()

    def warm_local(self, workers: int | None, progress: bool = True) -> float:
        """:func:`warm_runs` of one run per (controller, tier, plant preset); without ``progress``, silently."""
        return warm_runs(_warm_specs(self.suite, self.entries), workers, self.backend, progress=progress,
                         notice=None if progress else _silent)

    def run_local(self, ids: range, workers: int | None):
        """The runs ``ids`` over ``workers`` threads of the batch runner."""
        return run_planned(self.suite, self.entries, ids, workers=workers, backend=self.backend)

    def dask_call(self, ids: range) -> tuple:
        """:func:`run_planned` of the runs, one thread on the worker."""
        return run_planned, (self.suite, self.entries, ids), {"backend": self.backend}

    def lost_rows(self, ids: range, detail: str):
        """Failed rows with cause ``worker_died``."""
        return _table([_not_run(s, "worker_died", detail) for s in plan_runs(self.suite, self.entries, ids)])


@dataclass(frozen=True)
class ExecOutcome:
    """What :func:`execute` did.

    Attributes
    ----------
    out : Path
        Output folder.
    complete : bool
        Every chunk is on disk (False after an interruption or ``max_chunks``).
    runs : int
        Runs in the plan.
    chunks_run, chunks_skipped : int
        Chunks computed now, chunks found on disk and verified.
    seconds : float
        Wall time of the runs computed now (excluding kernel compilation).
    compile_seconds : float
        Wall time spent compiling or loading kernels before the first chunk.
    chunks_redone : tuple of int
        Chunks found on disk that failed verification (named on one line each, recomputed).
    """

    out: Path
    complete: bool
    runs: int
    chunks_run: int
    chunks_skipped: int
    seconds: float
    compile_seconds: float
    chunks_redone: tuple[int, ...] = ()


def execute(suite, entries: Sequence, out: str | Path, *, resume: bool = False, scheduler: str | None = None,
            client: Any = None, workers: int | None = None, backend: str | None = None, chunk_size: int = 48,
            max_chunks: int | None = None, max_runs: int = DEFAULT_MAX_RUNS, progress: bool = True,
            on_chunk: Callable[[int], None] | None = None,
            notify: Callable[[str], None] | None = None) -> ExecOutcome:
    """Run (or resume) every run of a comparison and write ``chunks/`` and, when complete, ``runs.parquet``.

    Parameters
    ----------
    suite : Suite
        The suite (or its quick variant).
    entries : sequence of ControllerEntry
        The competitors.
    out : str or Path
        Output folder.
    resume : bool, optional
        Keep the chunks on disk that pass verification (this comparison's fingerprint, this chunk,
        its content hash); recompute the others, each named on one line, and the missing ones.
    scheduler : str, optional
        Address of a Dask scheduler (``tcp://host:port``); runs go there instead of local threads.
        It is probed with a bounded timeout first.
    client : distributed.Client, optional
        An existing Dask client (overrides ``scheduler``; left open).
    workers : int, optional
        Local threads (default: every core, :func:`auvtrack.batch.runner.default_workers`).
    backend : str, optional
        Back end of :func:`auvtrack.batch.runner.run_batch` for every chunk, local or on Dask
        (default: the batch runner's default).  A named back end is part of the fingerprint.
    chunk_size : int, optional
        Runs per chunk (per Parquet file, per Dask task).
    max_chunks : int, optional
        Stop after this many chunks (testing the resume path).
    max_runs : int, optional
        Refuse a plan of more runs (``--max-runs``, at most :data:`MAX_RUNS`).
    progress : bool, optional
        A tqdm bar over the runs.
    on_chunk : callable, optional
        ``on_chunk(chunks_written_now)`` after each chunk is written.
    notify : callable, optional
        Receives the one-line notices (a chunk that failed verification); default standard error.

    Returns
    -------
    ExecOutcome
        Whether every chunk is on disk (``runs.parquet`` is then written), chunks run, kept and
        redone, timing.

    Raises
    ------
    CompareError
        A plan over ``max_runs``, a plug-in whose set-up breaks on the first run, an output folder
        of another comparison or holding other files, existing chunks without ``resume``, a
        ``--scheduler`` where no Dask scheduler answers.
    auvtrack.batch.runner.BatchInterrupted
        Ctrl-C during a local chunk (the chunks written so far stay, for ``resume``).
    """
    if isinstance(chunk_size, bool) or not isinstance(chunk_size, int) or chunk_size < 1:
        raise CompareError(f"chunk_size: must be an integer >= 1 (got {chunk_size!r})")
    check_workers(workers, CompareError)
    if backend is not None:
        from ..batch.runner import BACKENDS

        if backend not in BACKENDS:
            raise CompareError(f"--backend: must be one of {', '.join(BACKENDS)} (got {backend!r})")
    check_plan(suite, entries, max_runs)
    check_plugin_setups(suite, entries)
    job = CompareJob(suite, entries, chunk_size, backend)
    hook = None if on_chunk is None else (lambda written, _client: on_chunk(written))
    res = execute_chunks(job, out, resume=resume, client=client, scheduler=scheduler, workers=workers,
                         max_chunks=max_chunks, progress=progress, on_chunk=hook, notify=notify)
    return ExecOutcome(res.out, res.complete, job.runs, res.chunks_run, res.chunks_kept, res.seconds,
                       res.warm_seconds, res.chunks_redone)


def read_runs(out: str | Path):
    """The runs of a finished comparison as a pandas DataFrame (one row per run, plan order).

    Parameters
    ----------
    out : str or Path
        The comparison's output folder.

    Returns
    -------
    pandas.DataFrame
        ``runs.parquet``.
    """
    import pandas as pd

    return pd.read_parquet(Path(out) / RUNS_FILE)

"""Execution of ``auvtrack compare``: every run of a suite, locally or on Dask, resumable.

The runs (:func:`plan_runs`: tier, task, seed index, controller, in that order) are cut into
chunks of ``chunk_size``.  A chunk is prepared and run through the batch runner
(:func:`auvtrack.batch.runner.run_batch`: metrics reduced in the kernel, no trajectory) --
locally in this process over threads, or as a Dask task (:func:`run_chunk`, importable on a
worker; the runs travel as plain data, never compiled functions) when a scheduler is given.  Each
finished chunk is written atomically as ``chunks/chunk-NNNNNN.parquet``, so like a sweep
(``docs/sweeps.md``) an interrupted comparison resumes (``resume=True``) with every run exactly
once, and a run's row depends only on the suite, the controller and its (task, tier, seed index).
``compare.json`` holds the fingerprint (suite, controllers, package sources): a folder of another
comparison, or of another version of the code, is refused.
"""
from __future__ import annotations

import json
import math
import time
import uuid
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Sequence

from .._atomic import atomic_file, atomic_write
from ..batch.dask_wait import ClusterLost

__all__ = ["RunSpec", "plan_runs", "run_chunk", "execute", "ExecOutcome", "CompareError", "chunk_path",
           "MANIFEST", "RUNS_FILE", "FIXED_COLUMNS"]

MANIFEST = "compare.json"
CHUNK_DIR = "chunks"
RUNS_FILE = "runs.parquet"
FIXED_COLUMNS = ("run", "controller", "task", "tier", "seed_index", "seed", "status", "cause", "detail",
                 "fail_time", "t_stop", "steps", "draws")


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


def plan_runs(suite, entries: Sequence) -> list[RunSpec]:
    """Every run of ``suite`` for the controllers ``entries``, in plan order.

    Parameters
    ----------
    suite : auvtrack.benchmark.suite.Suite
        The suite (or its quick variant).
    entries : sequence of ControllerEntry
        The competitors.

    Returns
    -------
    list of RunSpec
        Tier-major, then task, seed index and controller.
    """
    runs: list[RunSpec] = []
    for tier in suite.tiers:
        for task in suite.tasks:
            for i in range(suite.seeds):
                cond = suite.conditions(task, tier, i)  # the same for every controller
                for e in entries:
                    raw, ov, drawn = suite.scenario(e, task, tier, i, cond)
                    runs.append(RunSpec(len(runs), e.label, task, tier, i, raw, ov, drawn))
    return runs


def chunk_path(out: Path, chunk: int) -> Path:
    """File of chunk ``chunk`` under ``out``."""
    return Path(out) / CHUNK_DIR / f"chunk-{chunk:06d}.parquet"


def _schema():
    import pyarrow as pa

    from ..metrics import METRIC_NAMES

    ints = {"run", "seed_index", "seed", "steps"}
    floats = {"fail_time", "t_stop"}
    fields = [pa.field(c, pa.int64() if c in ints else pa.float64() if c in floats else pa.string())
              for c in FIXED_COLUMNS]
    return pa.schema(fields + [pa.field(m, pa.float64()) for m in METRIC_NAMES])


def _prepare(spec: RunSpec):
    """A Prepared run, or the one-line reason the controller's set-up refused it."""
    import warnings

    from ..scenario import ScenarioError, load_scenario
    from ..simulation.pipeline import prepare

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return prepare(load_scenario(spec.raw, spec.overrides))
    except (ScenarioError, ValueError, ImportError, TypeError) as exc:
        return " ".join(str(exc).split()) or type(exc).__name__


def _backend_kw(backend: str | None) -> dict:
    """``run_batch`` keywords for ``backend`` (None: the batch runner's own default back end)."""
    return {} if backend is None else {"backend": backend}


def run_chunk(specs: Sequence[RunSpec], *, workers: int | None = 1, backend: str | None = None):
    """Prepare and run ``specs`` (metrics only) and return one row per run as an Arrow table.

    A run whose set-up is refused (a controller rejecting its gains or the start, a plug-in that
    does not import) is a failure with cause ``setup`` and the reason in ``detail``: it counts,
    it is not dropped.

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

    Returns
    -------
    pyarrow.Table
        Columns :data:`FIXED_COLUMNS` and every metric of
        :data:`auvtrack.metrics.METRIC_NAMES`, in ``specs`` order.
    """
    import pyarrow as pa

    from ..metrics import METRIC_NAMES
    from ..report import failure_cause
    from ..batch.runner import run_batch

    schema = _schema()
    prepared = [_prepare(s) for s in specs]
    runnable = [p for p in prepared if not isinstance(p, str)]
    summaries = iter(run_batch(runnable, workers=workers, **_backend_kw(backend)))
    cols: dict[str, list] = {f.name: [] for f in schema}
    for spec, prep in zip(specs, prepared):
        row: dict[str, Any] = {"run": spec.run, "controller": spec.controller, "task": spec.task, "tier": spec.tier,
                               "seed_index": spec.index, "seed": int(spec.raw["seed"]),
                               "draws": json.dumps(spec.drawn, sort_keys=True)}
        if isinstance(prep, str):
            row.update(status="failed", cause="setup", detail=prep, fail_time=0.0, t_stop=0.0, steps=0)
            row.update({m: math.nan for m in METRIC_NAMES})
        else:
            s = next(summaries)
            f = s.failure or {}
            row.update(status=s.status, cause=failure_cause(s) or "", detail=str(f.get("detail", "")),
                       fail_time=float(f.get("time", math.nan)), t_stop=s.t_stop, steps=s.steps)
            row.update(s.metrics)
        for name in cols:
            cols[name].append(row[name])
    return pa.Table.from_pydict(cols, schema=schema)


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
        Chunks computed now, chunks found on disk.
    seconds : float
        Wall time of the runs computed now (excluding kernel compilation).
    compile_seconds : float
        Wall time spent compiling or loading kernels before the first chunk.
    """

    out: Path
    complete: bool
    runs: int
    chunks_run: int
    chunks_skipped: int
    seconds: float
    compile_seconds: float


def _write_atomic_table(table, path: Path) -> None:
    import pyarrow.parquet as pq

    with atomic_file(path) as fh:  # unique, exclusively created temporary name, then rename
        pq.write_table(table, fh)


def _prepare_out(out: Path, manifest: dict, n_chunks: int, resume: bool) -> set[int]:
    """Create or check the output folder; return the chunks already done."""
    (out / CHUNK_DIR).mkdir(parents=True, exist_ok=True)
    man = out / MANIFEST
    done = {c for c in range(n_chunks) if chunk_path(out, c).exists()}
    if man.exists():
        try:
            old = json.loads(man.read_text())
        except (OSError, ValueError):
            old = {}
        if old.get("fingerprint") != manifest["fingerprint"]:
            why = ("another version of the auvtrack sources" if old.get("suite_fingerprint") ==
                   manifest["suite_fingerprint"] and old.get("controllers") == manifest["controllers"]
                   else "another comparison (suite, variant or controllers)")
            raise CompareError(f"--out: {out} holds {why}; choose another folder")
        if done and not resume:
            raise CompareError(f"--out: {out} already holds {len(done)} of {n_chunks} chunks of this comparison; "
                               "pass --resume to finish it or choose another folder")
    elif done:
        raise CompareError(f"--out: {out} holds chunk files but no {MANIFEST}; choose another folder")
    atomic_write(man, json.dumps(manifest, indent=2))
    for stale in (out / CHUNK_DIR).glob(".chunk-*.tmp"):  # left by an interrupted write
        stale.unlink(missing_ok=True)
    return done


def manifest_for(suite, entries: Sequence, chunk_size: int, n_runs: int, backend: str | None = None) -> dict:
    """The ``compare.json`` of a comparison (its fingerprint covers suite, controllers and sources)."""
    import hashlib

    from .. import __version__
    from ..jit import source_hash

    controllers = [e.to_dict() for e in entries]
    src = source_hash()
    doc = {"suite": suite.fingerprint(), "controllers": controllers, "chunk_size": chunk_size, "source": src}
    if backend is not None:
        doc["backend"] = backend
    fp = hashlib.sha256(json.dumps(doc, sort_keys=True).encode()).hexdigest()
    return {"fingerprint": fp, "suite_fingerprint": suite.fingerprint(), "suite": suite.name,
            "quick": suite.quick, "controllers": controllers, "runs": n_runs, "chunk_size": chunk_size,
            "auvtrack_version": __version__, "source_hash": src}


def _warm(specs: Sequence[RunSpec], workers: int | None = None, backend: str | None = None) -> float:
    """Compile or load everything the runs need before the timed runs start.

    One run per (controller, tier, plant preset) is prepared (set-up helpers compile on first
    use), its kernel compiled or loaded, and then flown for 0.5 s: a kernel compiles one
    specialisation per type signature of its bundles, and the tiers' bundles differ, so this
    loads every signature the runs will call.  With the ``simd`` back end each is flown in a full
    block of lanes, so that the lane kernels too compile here.
    """
    from ..simulation.compiling import ensure_compiled
    from ..batch.runner import run_batch

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
    ensure_compiled(list(seen.values()), progress=True)
    if seen:
        warm = list(seen.values())
        if backend == "simd":  # a block of lanes per signature: the lane kernels compile here, not in the timed runs
            from ..engine.loop import LANES

            warm = [p for p in warm for _ in range(LANES)]
        run_batch(warm, workers=workers, **_backend_kw(backend))
    return time.perf_counter() - t0


def execute(suite, entries: Sequence, out: str | Path, *, resume: bool = False, scheduler: str | None = None,
            client: Any = None, workers: int | None = None, backend: str | None = None, chunk_size: int = 48,
            max_chunks: int | None = None,
            progress: bool = True, on_chunk: Callable[[int], None] | None = None) -> ExecOutcome:
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
        Keep the chunks already on disk and run the rest.
    scheduler : str, optional
        Address of a Dask scheduler (``tcp://host:port``); runs go there instead of local threads.
    client : distributed.Client, optional
        An existing Dask client (overrides ``scheduler``; left open).
    workers : int, optional
        Local threads (default: every core).
    backend : str, optional
        Back end of :func:`auvtrack.batch.runner.run_batch` for every chunk, local or on Dask
        (default: the batch runner's default).  A named back end is part of the fingerprint.
    chunk_size : int, optional
        Runs per chunk (per Parquet file, per Dask task).
    max_chunks : int, optional
        Stop after this many chunks (testing the resume path).
    progress : bool, optional
        A tqdm bar over the runs.
    on_chunk : callable, optional
        ``on_chunk(chunks_written_now)`` after each chunk is written.

    Returns
    -------
    ExecOutcome
        Whether every chunk is on disk (``runs.parquet`` is then written), chunks run and resumed, timing.

    Raises
    ------
    CompareError
        An output folder of another comparison, or existing chunks without ``resume``.
    auvtrack.batch.runner.BatchInterrupted
        Ctrl-C during a local chunk (the chunks written so far stay, for ``resume``).
    """
    if chunk_size < 1:
        raise CompareError(f"chunk_size: must be >= 1 (got {chunk_size})")
    if workers is not None and workers < 1:
        raise CompareError(f"--workers: must be >= 1 (got {workers})")
    if backend is not None:
        from ..batch.runner import BACKENDS

        if backend not in BACKENDS:
            raise CompareError(f"--backend: must be one of {', '.join(BACKENDS)} (got {backend!r})")
    out = Path(out)
    specs = plan_runs(suite, entries)
    chunks = [specs[i:i + chunk_size] for i in range(0, len(specs), chunk_size)]
    done = _prepare_out(out, manifest_for(suite, entries, chunk_size, len(specs), backend), len(chunks), resume)
    todo = [c for c in range(len(chunks)) if c not in done]
    written, seconds, compile_s = 0, 0.0, 0.0
    if todo:
        from tqdm.auto import tqdm

        local = client is None and scheduler is None
        if local:
            compile_s = _warm(specs, workers, backend)
        n_done = sum(len(chunks[c]) for c in done)
        bar = tqdm(total=len(specs), initial=n_done, unit="run", desc=suite.name + (" (quick)" if suite.quick else ""),
                   disable=not progress, smoothing=0.05)
        try:
            if local:
                t0 = time.perf_counter()
                for c in todo:
                    table = run_chunk(chunks[c], workers=workers, backend=backend)
                    _write_atomic_table(table, chunk_path(out, c))
                    written += 1
                    bar.update(table.num_rows)
                    if on_chunk is not None:
                        on_chunk(written)
                    if max_chunks is not None and written >= max_chunks:
                        break
                seconds = time.perf_counter() - t0
            else:
                try:
                    written, seconds = _on_dask(out, chunks, todo, client, scheduler, bar, max_chunks, on_chunk,
                                                backend)
                except ClusterLost as exc:
                    kept = sum(1 for c in range(len(chunks)) if chunk_path(out, c).exists())
                    raise CompareError(f"{exc}; {kept} of {len(chunks)} chunks are kept in {out}: "
                                       "finish with --resume once the cluster has workers") from None
        finally:
            bar.close()
    complete = all(chunk_path(out, c).exists() for c in range(len(chunks)))
    if complete:
        combine(out, len(chunks))
    return ExecOutcome(out, complete, len(specs), written, len(done), seconds, compile_s)


def _on_dask(out: Path, chunks, todo, client, scheduler, bar, max_chunks, on_chunk,
             backend: str | None = None) -> tuple[int, float]:
    from dask.distributed import Client

    from ..batch.dask_wait import completed
    from ..batch.sweep_worker import WarmupPlugin

    own = client is None
    if own:
        client = Client(scheduler)
    written = 0
    try:
        client.register_plugin(WarmupPlugin(), name=WarmupPlugin.name)
        token = uuid.uuid4().hex[:10]
        t0 = time.perf_counter()
        futures = [client.submit(run_chunk, chunks[c], backend=backend, key=f"auvtrack-compare-{token}-{c}", retries=1) for c in todo]
        chunk_of = {f.key: c for f, c in zip(futures, todo)}
        try:
            for fut in completed(futures, client, what="running the comparison's chunks"):
                table = fut.result()
                path = chunk_path(out, chunk_of[fut.key])
                if not path.exists():
                    _write_atomic_table(table, path)
                fut.release()
                written += 1
                bar.update(table.num_rows)
                if on_chunk is not None:
                    on_chunk(written)
                if max_chunks is not None and written >= max_chunks:
                    break
        finally:
            pending = [f for f in futures if not f.done()]
            if pending:
                client.cancel(pending)
        return written, time.perf_counter() - t0
    finally:
        if own:
            client.close()


def combine(out: Path, n_chunks: int) -> Path:
    """Concatenate every chunk, in order, into ``out/runs.parquet`` (atomic)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    schema = _schema()
    tables = [pq.read_table(chunk_path(out, c), schema=schema) for c in range(n_chunks)]
    path = Path(out) / RUNS_FILE
    _write_atomic_table(pa.concat_tables(tables), path)
    return path


def read_runs(out: str | Path):
    """The runs of a finished comparison as a pandas DataFrame (one row per run, plan order)."""
    import pandas as pd

    return pd.read_parquet(Path(out) / RUNS_FILE)

"""The chunk executor of ``auvtrack sweep`` and ``auvtrack compare``: resumable, verified, local or on Dask.

A *job* (:class:`ChunkJob`: a sweep, a comparison) is a list of rows cut into chunks; it says
what defines its rows (its fingerprint), how a chunk is computed (here, over threads and the
batch runner's back ends, or as a Dask task), the Arrow schema of its rows, what the row of a
sample lost with its worker looks like and how the chunks are combined.  :func:`execute_chunks`
does the rest, the same way for every job:

* **The output folder.**  ``<manifest>`` (``study.json``, ``compare.json``) records the
  fingerprint; ``chunks/chunk-NNNNNN.parquet`` one file per finished chunk, written atomically
  with the fingerprint, its index and a hash of its content in its Parquet metadata
  (:mod:`auvtrack.batch.chunk_files`).  A folder of another sweep or comparison (or of another
  version of the sources) is refused; so is an existing folder that holds anything else (the
  user's own files), and one that holds chunks of this job without ``resume``.
* **Resume verifies and repairs.**  With ``resume``, every chunk file is read back and checked
  (:func:`~auvtrack.batch.chunk_files.check_chunk`): a truncated, empty, foreign or duplicated
  chunk, one of another run (another suite seed, say), one whose content does not match its hash,
  or one written before chunks carried their fingerprint is named on one line and recomputed.
  The combined table is written only when every chunk is verified or freshly computed, so two
  sweeps or comparisons never mix.
* **Bounded waits.**  Dask waits go through :mod:`auvtrack.batch.dask_wait` (a cluster without
  workers ends with a diagnostic and the chunks kept); a ``--scheduler`` address is probed with
  a timeout first (:mod:`auvtrack.batch.scheduler`).
* **One worker setting.**  Local threads default to
  :func:`auvtrack.batch.runner.default_workers`; at most :data:`MAX_WORKERS`.
"""
from __future__ import annotations

import hashlib
import json
import re
import sys
import time
import uuid
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

from .._atomic import atomic_file, atomic_write
from .chunk_files import CHUNK_DIR, check_chunk, chunk_path, write_chunk
from .dask_wait import ClusterLost

__all__ = ["ChunkJob", "ChunkOutcome", "execute_chunks", "check_workers", "MAX_WORKERS", "FORMAT"]

MAX_WORKERS = 256
"""Largest number of local threads or worker processes accepted (``--workers``)."""
FORMAT = 2
"""Layout of the output folder: chunk files carry fingerprint, index and content hash."""
_CHUNK_NAME = re.compile(r"chunk-(\d{6,})\.parquet")


def check_workers(workers: int | None, error: type[Exception] = ValueError) -> None:
    """Refuse a worker count outside ``[1, MAX_WORKERS]`` (None: the default, one per core).

    Parameters
    ----------
    workers : int or None
        The requested count.
    error : type, optional
        The exception class to raise (a one-line error of the caller).

    Raises
    ------
    Exception
        ``error("--workers: must be in [1, 256] (got ...)")``.
    """
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int)
                                or not 1 <= workers <= MAX_WORKERS):
        raise error(f"--workers: must be an integer in [1, {MAX_WORKERS}] (got {workers!r})")


class ChunkJob:
    """What a sweep or a comparison supplies to :func:`execute_chunks` (subclass it).

    Class attributes name the job in messages (``kind``: "sweep", "comparison"), its files
    (``manifest_name``, ``results_name``), the column numbering its rows (``id_column``), the
    unit of its progress bar (``unit``), a hint added to the detail of a row lost with its worker
    (``lost_hint``) and its one-line exception (``error``).
    """

    kind = "job"
    manifest_name = "manifest.json"
    results_name = "results.parquet"
    id_column = "id"
    unit = "row"
    lost_hint = ""
    error: type[Exception] = ValueError

    # ---------------------------------------------------------------- what the job defines
    @property
    def label(self) -> str:
        """Name shown on the progress bar."""
        return self.kind

    @property
    def n_chunks(self) -> int:
        """Number of chunks."""
        raise NotImplementedError

    @property
    def n_rows(self) -> int:
        """Number of rows of the whole job."""
        raise NotImplementedError

    def chunk_ids(self, chunk: int) -> range:
        """Row ids (values of :attr:`id_column`) of chunk ``chunk``, in order."""
        raise NotImplementedError

    def definition(self) -> dict:
        """Plain data that defines every row (the fingerprint hashes it with the package sources)."""
        raise NotImplementedError

    def schema(self):
        """Arrow schema of every chunk."""
        raise NotImplementedError

    def manifest(self) -> dict:
        """Keys of the manifest besides the fingerprint (names, sizes, versions), for people reading it."""
        return {}

    def describe(self, manifest: dict) -> str:
        """A few words naming the job a manifest records (for the message refusing another job's folder)."""
        return str(manifest.get("name", "?"))

    def format1_fingerprint(self) -> str | None:
        """The fingerprint a format-1 manifest (chunks without metadata) records for this job, if it has one.

        Such a folder is accepted with ``resume``; its chunks carry no fingerprint, so each is
        recomputed.
        """
        return None

    # ---------------------------------------------------------------- how a chunk is computed
    def warm_local(self, workers: int | None, progress: bool = True) -> float:
        """Compile or load what the local runs need before they are timed; the seconds it took.

        ``progress``: the "compiling kernels" notice and a bar; without it nothing is printed.
        """
        return 0.0

    def run_local(self, ids: range, workers: int | None):
        """The rows of ``ids`` computed in this process (``workers`` threads of the batch runner)."""
        raise NotImplementedError

    def dask_call(self, ids: range) -> tuple[Callable, tuple, dict]:
        """``(function, args, kwargs)`` of the Dask task computing the rows of ``ids`` (importable, plain data)."""
        raise NotImplementedError

    def lost_rows(self, ids: range, detail: str):
        """Rows of ``ids`` whose worker process died each time they ran (status failed, cause worker_died)."""
        raise NotImplementedError

    def combine(self, out: Path) -> Path:
        """Stream every chunk, in order, into ``out/<results_name>`` (atomic; memory flat in the number of chunks)."""
        import pyarrow.parquet as pq

        schema = self.schema()
        path = out / self.results_name
        with atomic_file(path) as fh, pq.ParquetWriter(fh, schema) as writer:
            for c in range(self.n_chunks):
                writer.write_table(pq.read_table(chunk_path(out, c), schema=schema))
        return path

    # ---------------------------------------------------------------- derived
    def definition_hash(self) -> str:
        """SHA-256 of :meth:`definition`."""
        return hashlib.sha256(json.dumps(self.definition(), sort_keys=True, default=str).encode()).hexdigest()

    def fingerprint(self) -> str:
        """SHA-256 of the definition, the package sources and the folder format: what every chunk carries."""
        from ..jit import source_hash

        doc = {"definition": self.definition_hash(), "source": source_hash(), "format": FORMAT}
        return hashlib.sha256(json.dumps(doc, sort_keys=True).encode()).hexdigest()


@dataclass(frozen=True)
class ChunkOutcome:
    """What :func:`execute_chunks` did.

    Attributes
    ----------
    out : Path
        Output folder.
    complete : bool
        Every chunk is verified or computed, and the combined table is written.
    chunks_run : int
        Chunks computed now.
    chunks_kept : int
        Chunks found on disk and verified (``resume``).
    chunks_redone : tuple of int
        Chunks found on disk that failed verification (recomputed, or left to a later ``resume``).
    seconds : float
        Wall time of the chunks computed now (excluding cluster start-up and warm-up).
    warm_seconds : float
        Wall time of the local warm-up (compiling or loading kernels) before the first chunk.
    """

    out: Path
    complete: bool
    chunks_run: int
    chunks_kept: int
    chunks_redone: tuple[int, ...]
    seconds: float
    warm_seconds: float


def _say(text: str) -> None:
    print(f"auvtrack: {text}", file=sys.stderr, flush=True)


def _read_manifest(path: Path) -> dict | None:
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return doc if isinstance(doc, dict) and isinstance(doc.get("fingerprint"), str) else None


def _present_chunks(out: Path, n_chunks: int) -> list[int]:
    folder = out / CHUNK_DIR
    if not folder.is_dir():
        return []
    found = []
    for p in folder.iterdir():
        m = _CHUNK_NAME.fullmatch(p.name)
        if m and int(m.group(1)) < n_chunks and p.name == chunk_path(out, int(m.group(1))).name:
            found.append(int(m.group(1)))
    return sorted(found)


def _check_folder(job: ChunkJob, out: Path, fp: str, resume: bool) -> list[int]:
    """Refuse a folder that is not this job's (or not resumable without ``resume``); the chunk files present."""
    err = job.error
    if out.is_symlink():
        raise err(f"--out: {out}: is a symbolic link, not a folder")
    if out.exists() and not out.is_dir():
        raise err(f"--out: {out}: is a file, not a folder")
    if not out.exists():
        return []
    present = _present_chunks(out, job.n_chunks)
    man = out / job.manifest_name
    if man.exists() or man.is_symlink():
        old = _read_manifest(man)
        if old is None:
            raise err(f"--out: {man}: is not the {job.manifest_name} of an auvtrack {job.kind}; choose another folder")
        if "format" not in old and old["fingerprint"] == job.format1_fingerprint():
            old = {**old, "fingerprint": fp}  # this job in format 1: resumable, every chunk recomputed
        if old["fingerprint"] != fp:
            if old.get("definition") == job.definition_hash():
                why = "another version of the auvtrack sources"
            elif "definition" not in old:
                why = f"another {job.kind}, or one written by an older auvtrack ({job.describe(old)})"
            else:
                why = f"another {job.kind} ({job.describe(old)})"
            raise err(f"--out: {out} holds {why}; choose another folder")
        if present and not resume:
            raise err(f"--out: {out} already holds {len(present)} of {job.n_chunks} chunks of this {job.kind}; "
                      "pass --resume to finish it (chunks that fail verification are recomputed) "
                      "or choose another folder")
        return present
    foreign = sorted(p.name for p in out.iterdir()
                     if not (p.name == CHUNK_DIR and p.is_dir() and not p.is_symlink() and not any(p.iterdir())))
    if foreign:
        shown = ", ".join(foreign[:3]) + (", ..." if len(foreign) > 3 else "")
        raise err(f"--out: {out} already holds files that are not an auvtrack {job.kind} ({shown}); "
                  "choose a new or empty folder")
    return []


def _verified(job: ChunkJob, out: Path, fp: str, present: list[int], notify: Callable[[str], None]) -> tuple[set, list]:
    """(chunks that pass verification, chunks that do not), each bad one named on one line."""
    schema = job.schema()
    good, bad = set(), []
    for c in present:
        path = chunk_path(out, c)
        why = check_chunk(path, fp, c, schema, job.id_column, job.chunk_ids(c))
        if why is None:
            good.add(c)
        else:
            bad.append(c)
            notify(f"{path}: {why}; recomputing chunk {c}")
    return good, bad


def _manifest(job: ChunkJob, fp: str) -> dict:
    from .. import __version__
    from ..jit import source_hash

    return {"fingerprint": fp, "definition": job.definition_hash(), "format": FORMAT, "kind": job.kind,
            **job.manifest(), "n_chunks": job.n_chunks, "auvtrack_version": __version__,
            "source_hash": source_hash()}


def execute_chunks(job: ChunkJob, out: str | Path, *, resume: bool = False, client: Any = None,
                   scheduler: str | None = None, start_cluster: Callable[[], tuple[Any, Any]] | None = None,
                   workers: int | None = None, max_chunks: int | None = None,
                   progress: bool = True, on_chunk: Callable[[int, Any], None] | None = None,
                   notify: Callable[[str], None] | None = None) -> ChunkOutcome:
    """Compute (or finish) every chunk of ``job`` under ``out`` and, when all are there, combine them.

    Where the chunks run: on ``client`` if given (left open); else on the scheduler at
    ``scheduler`` (connected with a bounded timeout, closed at the end); else on the cluster
    ``start_cluster()`` returns as ``(client, cluster)`` (closed at the end); else here, over
    ``workers`` threads of the batch runner (:meth:`ChunkJob.run_local`).

    Parameters
    ----------
    job : ChunkJob
        The sweep or comparison.
    out : str or Path
        Output folder.
    resume : bool, optional
        Keep the chunks on disk that pass verification; recompute the others and the missing ones.
    client : distributed.Client, optional
        An existing Dask client.
    scheduler : str, optional
        Address of a Dask scheduler (``tcp://host:port``).
    start_cluster : callable, optional
        Starts a cluster of the job's own: returns ``(client, cluster)``.
    workers : int, optional
        Local threads (default :func:`auvtrack.batch.runner.default_workers`).
    max_chunks : int, optional
        Stop after this many chunks have been written (the rest stay to ``resume``).
    progress : bool, optional
        A tqdm bar over the rows.
    on_chunk : callable, optional
        ``on_chunk(chunks_written_now, client_or_None)`` after each chunk file is written.
    notify : callable, optional
        Receives each one-line notice (a chunk that failed verification); default: standard error.

    Returns
    -------
    ChunkOutcome
        Whether the job is complete, what was computed, kept and redone, and the timing.

    Raises
    ------
    Exception
        ``job.error`` (one line): the folder belongs to something else, holds chunks without
        ``resume``, the scheduler does not answer, or the cluster lost every worker.
    auvtrack.batch.runner.BatchInterrupted
        Ctrl-C during a local chunk (the chunks written so far stay, for ``resume``).
    """
    out = Path(out)
    if max_chunks is not None and max_chunks < 1:
        raise job.error(f"max_chunks: must be >= 1 (got {max_chunks})")
    check_workers(workers, job.error)
    notify = notify or _say
    fp = job.fingerprint()
    present = _check_folder(job, out, fp, resume)
    done, bad = _verified(job, out, fp, present, notify) if present else (set(), [])
    todo = [c for c in range(job.n_chunks) if c not in done]
    run = _Run(job, out, fp, todo, max_chunks, on_chunk)
    own_client = own_cluster = None
    if todo and client is None and scheduler:
        from .scheduler import SchedulerError, connect_scheduler

        try:
            client = own_client = connect_scheduler(scheduler)
        except SchedulerError as exc:
            raise job.error(str(exc)) from None
    elif todo and client is None and start_cluster is not None:
        client, own_cluster = start_cluster()
        own_client = client
    try:
        (out / CHUNK_DIR).mkdir(parents=True, exist_ok=True)
        atomic_write(out / job.manifest_name, json.dumps(_manifest(job, fp), indent=2))
        for stale in (out / CHUNK_DIR).glob(".chunk-*.tmp"):  # left by an interrupted write
            stale.unlink(missing_ok=True)
        if todo:
            run.setup(progress, sum(len(job.chunk_ids(c)) for c in done), client)
            try:
                if client is None:
                    run.local(workers)
                else:
                    run.on_dask(client)
            except ClusterLost as exc:
                kept = len(done) + run.written
                raise job.error(f"{exc}; {kept} of {job.n_chunks} chunks are kept in {out}: "
                                "finish with --resume once the cluster has workers") from None
            finally:
                run.close_bar()
    finally:
        if own_client is not None:
            own_client.close()
        if own_cluster is not None:
            own_cluster.close()
    complete = len(done) + len(run.finished) == job.n_chunks
    if complete:
        job.combine(out)
    return ChunkOutcome(out, complete, run.written, len(done), tuple(bad), run.seconds, run.warm_seconds)


class _Run:
    """The chunks still to compute, their progress bar and the files written."""

    def __init__(self, job: ChunkJob, out: Path, fp: str, todo: list[int], max_chunks: int | None,
                 on_chunk: Callable[[int, Any], None] | None) -> None:
        self.job, self.out, self.fp, self.todo = job, out, fp, todo
        self.max_chunks, self.on_chunk = max_chunks, on_chunk
        self.finished: set[int] = set()
        self.written = 0
        self.seconds = self.warm_seconds = 0.0
        self.bar: Any = None
        self.client: Any = None

    def setup(self, progress: bool, initial: int, client: Any) -> None:
        """Remember the bar's settings and the client handed to ``on_chunk``."""
        self.client = client
        self.progress, self.initial = progress, initial

    def _open_bar(self) -> None:
        from tqdm.auto import tqdm

        self.bar = tqdm(total=self.job.n_rows, initial=self.initial, unit=self.job.unit, desc=self.job.label,
                        disable=not self.progress, smoothing=0.05)

    def close_bar(self) -> None:
        if self.bar is not None:
            self.bar.close()

    def store(self, chunk: int, table) -> bool:
        """Write one chunk; True when ``max_chunks`` says to stop."""
        write_chunk(table, chunk_path(self.out, chunk), self.fp, chunk)
        self.finished.add(chunk)
        self.written += 1
        self.bar.update(table.num_rows)
        if self.on_chunk is not None:
            self.on_chunk(self.written, self.client)
        return self.max_chunks is not None and self.written >= self.max_chunks

    def local(self, workers: int | None) -> None:
        self.warm_seconds = self.job.warm_local(workers, self.progress)
        self._open_bar()
        t0 = time.perf_counter()
        try:
            for c in self.todo:
                if self.store(c, self.job.run_local(self.job.chunk_ids(c), workers)):
                    break
        finally:
            self.seconds = time.perf_counter() - t0

    def on_dask(self, client) -> None:
        from .dask_wait import completed
        from .sweep_worker import WarmupPlugin

        client.register_plugin(WarmupPlugin(), name=WarmupPlugin.name)
        token = f"{self.fp[:12]}-{uuid.uuid4().hex[:8]}"  # fresh keys: never reuse cancelled tasks
        self._open_bar()
        t0 = time.perf_counter()
        futures = []
        for c in self.todo:
            fn, args, kwargs = self.job.dask_call(self.job.chunk_ids(c))
            futures.append(client.submit(fn, *args, **kwargs, key=f"auvtrack-{self.job.kind}-{token}-{c}", retries=1))
        chunk_of = {f.key: c for f, c in zip(futures, self.todo)}
        try:
            for fut in completed(futures, client, what=f"running the {self.job.kind}'s chunks"):
                c = chunk_of[fut.key]
                table = self._table(c, fut, client, token)
                fut.release()
                if self.store(c, table):
                    break
        finally:
            self.seconds = time.perf_counter() - t0
            pending = [f for f in futures if not f.done()]
            if pending:
                client.cancel(pending)

    def _table(self, chunk: int, fut, client, token: str, attempts: int = 2):
        """The table of a finished chunk task; when its worker died, its rows are run one at a time.

        A worker that dies fails every task queued on it, so a row is blamed only when it kills a
        worker ``attempts`` times running on its own: it is then recorded by the job's
        :meth:`ChunkJob.lost_rows`, and one memory-hungry sample costs its own row, never the job.
        """
        import pyarrow as pa
        from distributed import KilledWorker

        from .dask_wait import result

        try:
            return result(fut, client, what=f"running chunk {chunk}")
        except KilledWorker:
            pass
        tables = []
        for i in self.job.chunk_ids(chunk):
            one = range(i, i + 1)
            reason = ""
            for attempt in range(attempts):
                fn, args, kwargs = self.job.dask_call(one)
                single = client.submit(fn, *args, **kwargs, key=f"auvtrack-one-{token}-{i}-{attempt}", retries=0)
                try:
                    tables.append(result(single, client, what=f"running {self.job.id_column} {i} alone"))
                    break
                except KilledWorker as exc:
                    reason = " ".join(str(exc).split())[:200]
                finally:
                    single.release()
            else:
                tables.append(self.job.lost_rows(one, f"the worker process died running this {self.job.id_column} "
                                                      f"alone, {attempts} times{self.job.lost_hint}: {reason}"))
        return pa.concat_tables(tables)

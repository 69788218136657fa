"""The chunk executor with a job of its own (pure arithmetic, no simulation): folders, resume, repair, limits.

The job's row ``i`` is ``(i, i**2, "row i")``: any mixing, loss or duplication shows in the
combined table, which must equal the one of an uninterrupted run.
"""
from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from auvtrack.batch.chunk_files import chunk_path
from auvtrack.batch.executor import MAX_WORKERS, ChunkJob, check_workers, execute_chunks

SCHEMA = pa.schema([pa.field("i", pa.int64()), pa.field("square", pa.int64()), pa.field("text", pa.string())])
CALLS: list[range] = []


class JobError(ValueError):
    pass


def rows(ids: range, offset: int = 0) -> pa.Table:
    """The job's rows (module level: importable by a Dask worker)."""
    return pa.Table.from_pydict({"i": list(ids), "square": [i * i + offset for i in ids],
                                 "text": [f"row {i}" for i in ids]}, schema=SCHEMA)


class Squares(ChunkJob):
    kind = "squares"
    manifest_name = "squares.json"
    results_name = "all.parquet"
    id_column = "i"
    unit = "row"
    error = JobError

    def __init__(self, n: int = 23, size: int = 5, offset: int = 0) -> None:
        self.n, self.size, self.offset = n, size, offset

    @property
    def n_chunks(self) -> int:
        return -(-self.n // self.size)

    @property
    def n_rows(self) -> int:
        return self.n

    def chunk_ids(self, chunk: int) -> range:
        return range(chunk * self.size, min((chunk + 1) * self.size, self.n))

    def definition(self) -> dict:
        return {"n": self.n, "size": self.size, "offset": self.offset}

    def schema(self):
        return SCHEMA

    def manifest(self) -> dict:
        return {"name": f"squares+{self.offset}"}

    def run_local(self, ids: range, workers):
        CALLS.append(ids)
        return rows(ids, self.offset)

    def dask_call(self, ids: range):
        return rows, (ids, self.offset), {}

    def lost_rows(self, ids: range, detail: str):
        return rows(ids, -1)


def run(out: Path, job: ChunkJob | None = None, **kw):
    notes: list[str] = []
    res = execute_chunks(job or Squares(), out, progress=False, notify=notes.append, **kw)
    return res, notes


@pytest.fixture(scope="module")
def reference(tmp_path_factory) -> pa.Table:
    out = tmp_path_factory.mktemp("ref") / "out"
    res, notes = run(out)
    assert res.complete and res.chunks_run == 5 and notes == []
    return pq.read_table(out / "all.parquet")


def test_a_complete_run_has_every_row_once(reference):
    assert reference.column("i").to_pylist() == list(range(23))
    assert reference.column("square").to_pylist() == [i * i for i in range(23)]


def test_resume_verifies_every_chunk_and_recomputes_the_bad_ones(tmp_path, reference):
    out = tmp_path / "out"
    first, _ = run(out, max_chunks=5)
    assert first.complete
    (out / "all.parquet").unlink()
    foreign = tmp_path / "foreign"
    run(foreign, Squares(offset=7))  # another job (another "suite seed"): same rows, other values
    c = [chunk_path(out, k) for k in range(5)]
    c[0].write_bytes(c[0].read_bytes()[: c[0].stat().st_size // 2])  # truncated
    c[1].write_bytes(b"")  # empty
    shutil.copy(c[3], c[2])  # duplicated: chunk 3's file as chunk 2
    shutil.copy(chunk_path(foreign, 3), c[3])  # foreign: the same chunk of another job
    CALLS.clear()
    res, notes = run(out, resume=True)
    assert res.complete and res.chunks_kept == 1 and res.chunks_run == 4 and res.chunks_redone == (0, 1, 2, 3)
    assert CALLS == [range(0, 5), range(5, 10), range(10, 15), range(15, 20)]  # only the bad chunks ran again
    assert len(notes) == 4 and all("\n" not in n for n in notes)
    assert "chunk-000000.parquet: is not a readable Parquet file" in notes[0] and "recomputing chunk 0" in notes[0]
    assert "chunk-000001.parquet: is empty" in notes[1]
    assert "chunk-000002.parquet: is a copy of chunk 3" in notes[2]
    assert "chunk-000003.parquet: belongs to another run" in notes[3]
    assert pq.read_table(out / "all.parquet").equals(reference)
    again, notes = run(out, resume=True)  # nothing left to do
    assert again.complete and again.chunks_run == 0 and again.chunks_kept == 5 and notes == []


def test_an_interrupted_run_resumes_to_the_same_table(tmp_path, reference):
    out = tmp_path / "out"
    part, _ = run(out, max_chunks=2)
    assert not part.complete and part.chunks_run == 2 and not (out / "all.parquet").exists()
    with pytest.raises(JobError, match="already holds 2 of 5 chunks .* pass --resume"):
        run(out)
    res, notes = run(out, resume=True)
    assert res.complete and res.chunks_kept == 2 and res.chunks_run == 3 and notes == []
    assert pq.read_table(out / "all.parquet").equals(reference)


def test_a_folder_of_another_job_is_refused_even_with_resume(tmp_path):
    out = tmp_path / "out"
    run(out, max_chunks=1)
    with pytest.raises(JobError, match=r"holds another squares \(squares\+0\); choose another folder"):
        run(out, Squares(offset=1), resume=True)
    manifest = json.loads((out / "squares.json").read_text())
    assert manifest["format"] == 2 and manifest["name"] == "squares+0" and manifest["n_chunks"] == 5


def test_a_folder_of_user_files_is_refused_and_left_alone(tmp_path):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "notes.txt").write_text("my notes")
    for resume in (False, True):
        with pytest.raises(JobError, match=r"already holds files that are not an auvtrack squares \(notes.txt\)"):
            run(out, resume=resume)
    assert sorted(p.name for p in out.iterdir()) == ["notes.txt"]
    (out / "chunks").mkdir()
    (out / "chunks" / "chunk-000000.parquet").write_bytes(b"x")  # chunk files without a manifest: not ours either
    with pytest.raises(JobError, match="not an auvtrack squares"):
        run(out, resume=True)
    empty = tmp_path / "empty"
    empty.mkdir()
    assert run(empty)[0].complete  # an empty folder is fine


def test_a_file_a_symlink_or_a_foreign_manifest_is_refused(tmp_path):
    (tmp_path / "f").write_text("x")
    with pytest.raises(JobError, match="is a file"):
        run(tmp_path / "f")
    (tmp_path / "real").mkdir()
    os.symlink(tmp_path / "real", tmp_path / "link")
    with pytest.raises(JobError, match="is a symbolic link"):
        run(tmp_path / "link")
    (tmp_path / "m").mkdir()
    (tmp_path / "m" / "squares.json").write_text("{not json")
    with pytest.raises(JobError, match="is not the squares.json of an auvtrack squares"):
        run(tmp_path / "m", resume=True)


def test_a_format1_folder_is_resumed_with_every_chunk_recomputed(tmp_path, reference):
    class Old(Squares):
        def format1_fingerprint(self) -> str:
            return "old-fingerprint"

    out = tmp_path / "out"
    (out / "chunks").mkdir(parents=True)
    (out / "squares.json").write_text(json.dumps({"fingerprint": "old-fingerprint"}))
    for c in range(5):  # chunks as format 1 wrote them: the right rows, no metadata
        pq.write_table(rows(Old().chunk_ids(c)), chunk_path(out, c))
    with pytest.raises(JobError, match="pass --resume"):
        run(out, Old())
    res, notes = run(out, Old(), resume=True)
    assert res.complete and res.chunks_run == 5 and res.chunks_redone == (0, 1, 2, 3, 4)
    assert all("carries no fingerprint" in n for n in notes) and len(notes) == 5
    assert pq.read_table(out / "all.parquet").equals(reference)


@pytest.mark.parametrize("workers", [0, -1, MAX_WORKERS + 1, 100_000, 2.5, True])
def test_worker_counts_outside_the_range_are_refused(tmp_path, workers):
    with pytest.raises(JobError, match=rf"--workers: must be an integer in \[1, {MAX_WORKERS}\]"):
        run(tmp_path / "out", workers=workers)
    assert not (tmp_path / "out").exists()
    check_workers(None)
    check_workers(MAX_WORKERS)


def test_dask_gives_the_local_table_and_writes_verified_chunks(tmp_path, reference):
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=1, threads_per_worker=2, processes=False, dashboard_address=":0") as cluster, \
            Client(cluster) as client:
        seen = []
        res, notes = run(tmp_path / "out", client=client, on_chunk=lambda n, c: seen.append((n, c is client)))
    assert res.complete and res.chunks_run == 5 and notes == []
    assert seen == [(k, True) for k in range(1, 6)]
    assert pq.read_table(tmp_path / "out" / "all.parquet").equals(reference)
    # its chunks are the local run's: the same fingerprint and content hash
    local = tmp_path / "local"
    run(local)
    for c in range(5):
        a, b = pq.read_metadata(chunk_path(local, c)).metadata, pq.read_metadata(chunk_path(tmp_path / "out", c)).metadata
        assert a[b"auvtrack.sha256"] == b[b"auvtrack.sha256"]

"""Chunk files: the content hash survives a Parquet round trip and changes with any value; every tampering is named.

Pure Arrow and Parquet: no simulation.
"""
from __future__ import annotations

import math
import shutil

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from auvtrack.batch.chunk_files import check_chunk, chunk_path, table_digest, write_chunk

SCHEMA = pa.schema([pa.field("sample", pa.int64()), pa.field("status", pa.string()), pa.field("ok", pa.bool_()),
                    pa.field("rmse", pa.float64())])
FP = "f" * 64

floats = st.floats(allow_nan=True, allow_infinity=True, width=64)
rows = st.lists(st.tuples(st.text(max_size=8), st.booleans(), floats), min_size=1, max_size=30)


def make(rows_: list, start: int = 0) -> pa.Table:
    return pa.Table.from_pydict({"sample": list(range(start, start + len(rows_))), "status": [r[0] for r in rows_],
                                 "ok": [r[1] for r in rows_], "rmse": [r[2] for r in rows_]}, schema=SCHEMA)


def roundtrip(table: pa.Table, tmp_path, name: str = "t.parquet") -> pa.Table:
    path = tmp_path / name
    pq.write_table(table, path, row_group_size=7)  # several row groups: other buffers, same values
    return pq.read_table(path)


@settings(max_examples=60, deadline=None)
@given(rows)
def test_the_digest_is_the_same_after_a_parquet_round_trip(tmp_path_factory, rs):
    t = make(rs)
    back = roundtrip(t, tmp_path_factory.mktemp("rt"))
    assert table_digest(back, FP, 3) == table_digest(t, FP, 3)
    # and split in memory differently
    assert table_digest(pa.concat_tables([t.slice(0, 1), t.slice(1)]), FP, 3) == table_digest(t, FP, 3)


@settings(max_examples=60, deadline=None)
@given(rows, st.data())
def test_the_digest_changes_with_any_value(rs, data):
    t = make(rs)
    i = data.draw(st.integers(0, len(rs) - 1))
    col = data.draw(st.sampled_from(["status", "ok", "rmse", "sample"]))
    values = t.column(col).to_pylist()
    old = values[i]
    if col == "status":
        values[i] = old + "x"
    elif col == "ok":
        values[i] = not old
    elif col == "sample":
        values[i] = old + 1
    else:
        new = data.draw(floats)
        if np.float64(new).tobytes() == np.float64(old).tobytes():
            new = 1.0 if old != 1.0 else 2.0
        values[i] = new
    changed = t.set_column(t.schema.get_field_index(col), SCHEMA.field(col), pa.array(values, SCHEMA.field(col).type))
    assert table_digest(changed, FP, 0) != table_digest(t, FP, 0)


def test_the_digest_binds_fingerprint_chunk_and_row_boundaries():
    t = make([("ok", True, 1.0), ("ok", True, 2.0)])
    d = table_digest(t, FP, 0)
    assert d != table_digest(t, "e" * 64, 0) and d != table_digest(t, FP, 1)
    assert d != table_digest(t.slice(0, 1), FP, 0)
    a = make([("ab", True, 0.0), ("c", True, 0.0)])
    b = make([("a", True, 0.0), ("bc", True, 0.0)])  # the same characters, other strings
    assert table_digest(a, FP, 0) != table_digest(b, FP, 0)
    z = make([("ok", True, 0.0)])
    nz = make([("ok", True, -0.0)])
    assert table_digest(z, FP, 0) != table_digest(nz, FP, 0)  # bit for bit


@pytest.fixture
def folder(tmp_path):
    (tmp_path / "chunks").mkdir()
    for c in range(3):
        write_chunk(make([("ok", True, float(c)), ("failed", False, math.nan)], start=2 * c), chunk_path(tmp_path, c),
                    FP, c)
    return tmp_path


def check(folder, c: int, fp: str = FP):
    return check_chunk(chunk_path(folder, c), fp, c, SCHEMA, "sample", range(2 * c, 2 * c + 2))


def test_written_chunks_pass(folder):
    assert [check(folder, c) for c in range(3)] == [None, None, None]
    meta = pq.read_metadata(chunk_path(folder, 1)).metadata
    assert meta[b"auvtrack.fingerprint"] == FP.encode() and meta[b"auvtrack.chunk"] == b"1"
    assert meta[b"auvtrack.rows"] == b"2" and len(meta[b"auvtrack.sha256"]) == 64


def test_every_kind_of_tampering_is_named(folder):
    p = chunk_path(folder, 0)
    p.write_bytes(p.read_bytes()[:-40])  # truncated
    assert "not a readable Parquet file" in check(folder, 0)
    p.write_bytes(b"")
    assert check(folder, 0) == "is empty"
    shutil.copy(chunk_path(folder, 2), p)  # another chunk's copy
    assert check(folder, 0) == "is a copy of chunk 2"
    assert "belongs to another run" in check(folder, 1, fp="e" * 64)  # another sweep or comparison
    pq.write_table(make([("ok", True, 1.0), ("failed", False, math.nan)], start=2), chunk_path(folder, 1))
    assert "carries no fingerprint" in check(folder, 1)  # written without the metadata
    # values edited, the metadata kept
    t = pq.read_table(chunk_path(folder, 2))
    edited = t.set_column(3, SCHEMA.field("rmse"), pa.array([9.0, math.nan]))
    pq.write_table(edited.replace_schema_metadata(t.schema.metadata), chunk_path(folder, 2))
    assert check(folder, 2) == "does not match its content hash (edited or corrupted)"


def test_a_chunk_holding_other_rows_or_columns_is_refused(folder):
    good = pq.read_table(chunk_path(folder, 1))
    meta = good.schema.metadata
    other_ids = good.set_column(0, SCHEMA.field("sample"), pa.array([7, 8]))
    pq.write_table(other_ids.replace_schema_metadata(meta), chunk_path(folder, 1))
    assert check(folder, 1) == "holds other samples than 2..3"
    pq.write_table(good.slice(0, 1).replace_schema_metadata(meta), chunk_path(folder, 1))
    assert check(folder, 1) == "holds 1 rows, not 2"
    pq.write_table(good.drop_columns(["ok"]).replace_schema_metadata(meta), chunk_path(folder, 1))
    assert check(folder, 1) == "has other columns than this run's"

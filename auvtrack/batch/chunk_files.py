"""Chunk files of sweeps and comparisons: Parquet tables that carry their provenance and a content hash.

A chunk file ``chunks/chunk-NNNNNN.parquet`` holds the rows of one chunk and, in its Parquet
key-value metadata (``auvtrack.*`` keys):

* ``fingerprint``: the fingerprint of the sweep or comparison that computed it (everything that
  defines its rows, and the package sources);
* ``chunk`` and ``rows``: which chunk it is and how many rows it holds;
* ``sha256``: :func:`table_digest` of its table, fingerprint and chunk index.

:func:`check_chunk` reads a file back and says why it cannot be trusted (unreadable, truncated,
empty, of another sweep or comparison, another chunk's copy, other rows, content that does not
match its hash), or returns None.  The hash covers the values, not the bytes of the file: it is
the same before and after a Parquet round trip (tested), and any change of a value, a row or a
column changes it.
"""
from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Sequence

from .._atomic import atomic_file

__all__ = ["CHUNK_DIR", "chunk_path", "table_digest", "write_chunk", "check_chunk", "META_PREFIX"]

CHUNK_DIR = "chunks"
META_PREFIX = "auvtrack."
_KEYS = ("fingerprint", "chunk", "rows", "sha256")


def chunk_path(out: str | Path, chunk: int) -> Path:
    """File of chunk ``chunk`` under the output folder ``out``.

    Parameters
    ----------
    out : str or Path
        The sweep's or comparison's output folder.
    chunk : int
        Chunk index.

    Returns
    -------
    Path
        ``out/chunks/chunk-NNNNNN.parquet``.
    """
    return Path(out) / CHUNK_DIR / f"chunk-{chunk:06d}.parquet"


def _column_bytes(column) -> list[bytes]:
    """A canonical byte form of one column: its validity and its values, independent of memory layout."""
    import numpy as np
    import pyarrow as pa

    arr = column.combine_chunks() if isinstance(column, pa.ChunkedArray) else column
    parts = [np.packbits(arr.is_valid().to_numpy(zero_copy_only=False)).tobytes()]
    t = arr.type
    if pa.types.is_string(t) or pa.types.is_large_string(t) or pa.types.is_binary(t):
        for v in arr.to_pylist():
            b = b"" if v is None else (v.encode("utf-8") if isinstance(v, str) else bytes(v))
            parts.append(len(b).to_bytes(8, "little") + b)
    elif pa.types.is_boolean(t) or pa.types.is_integer(t) or pa.types.is_floating(t):
        filled = arr.fill_null(False if pa.types.is_boolean(t) else 0)
        parts.append(np.ascontiguousarray(filled.to_numpy(zero_copy_only=False)).tobytes())
    else:  # any other type: its values as JSON
        parts.append(json.dumps(arr.to_pylist(), sort_keys=True, default=str).encode("utf-8"))
    return parts


def table_digest(table, fingerprint: str, chunk: int) -> str:
    """SHA-256 of a chunk's values, columns, fingerprint and index.

    Parameters
    ----------
    table : pyarrow.Table
        The chunk's rows.
    fingerprint : str
        Fingerprint of the sweep or comparison.
    chunk : int
        Chunk index.

    Returns
    -------
    str
        64 hexadecimal digits.  Floats enter bit for bit (``-0.0`` differs from ``0.0``, a NaN
        from another NaN payload); the result does not depend on how the table is split in
        memory, so it survives a Parquet round trip.
    """
    h = hashlib.sha256()
    head = {"fingerprint": fingerprint, "chunk": int(chunk), "rows": table.num_rows,
            "columns": [[f.name, str(f.type)] for f in table.schema]}
    h.update(json.dumps(head, sort_keys=True).encode("utf-8"))
    for column in table.columns:
        for part in _column_bytes(column):
            h.update(len(part).to_bytes(8, "little"))
            h.update(part)
    return h.hexdigest()


def write_chunk(table, path: Path, fingerprint: str, chunk: int) -> None:
    """Write a chunk atomically with its fingerprint, index, row count and content hash.

    Parameters
    ----------
    table : pyarrow.Table
        The chunk's rows.
    path : Path
        Its file (:func:`chunk_path`).
    fingerprint : str
        Fingerprint of the sweep or comparison.
    chunk : int
        Chunk index.
    """
    import pyarrow.parquet as pq

    meta = {"fingerprint": fingerprint, "chunk": str(chunk), "rows": str(table.num_rows),
            "sha256": table_digest(table, fingerprint, chunk)}
    tagged = table.replace_schema_metadata({f"{META_PREFIX}{k}": v for k, v in meta.items()})
    with atomic_file(path) as fh:  # unique, exclusively created temporary name, then rename
        pq.write_table(tagged, fh)


def _metadata(path: Path) -> dict[str, str] | str:
    """The ``auvtrack.*`` metadata of a chunk file, or why it cannot be read."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    try:
        if path.stat().st_size == 0:
            return "is empty"
        raw = pq.read_metadata(path).metadata or {}
    except (OSError, pa.ArrowException, ValueError) as exc:
        return f"is not a readable Parquet file (truncated?): {' '.join(str(exc).split())[:120]}"
    meta = {k.decode()[len(META_PREFIX):]: v.decode() for k, v in raw.items() if k.decode().startswith(META_PREFIX)}
    if not all(k in meta for k in _KEYS):
        return "carries no fingerprint (written by an older auvtrack or by hand)"
    return meta


def check_chunk(path: Path, fingerprint: str, chunk: int, schema, id_column: str, ids: Sequence[int]) -> str | None:
    """Why the chunk file ``path`` cannot be trusted as chunk ``chunk`` of this sweep or comparison, or None.

    Parameters
    ----------
    path : Path
        The file.
    fingerprint : str
        Fingerprint of the sweep or comparison being resumed.
    chunk : int
        The chunk this file should hold.
    schema : pyarrow.Schema
        The columns every chunk has.
    id_column : str
        The column numbering the rows (``sample``, ``run``).
    ids : sequence of int
        The values ``id_column`` must hold, in order.

    Returns
    -------
    str or None
        A short reason ("belongs to another comparison", "holds chunk 3", ...), or None when the
        file is this chunk, complete and unaltered.
    """
    import pyarrow as pa
    import pyarrow.parquet as pq

    meta = _metadata(path)
    if isinstance(meta, str):
        return meta
    if meta["fingerprint"] != fingerprint:
        return f"belongs to another run of the command (fingerprint {meta['fingerprint'][:12]}, not {fingerprint[:12]})"
    if meta["chunk"] != str(chunk):
        return f"is a copy of chunk {meta['chunk']}"
    try:
        table = pq.read_table(path)
    except (OSError, pa.ArrowException, ValueError) as exc:
        return f"is not a readable Parquet file (truncated?): {' '.join(str(exc).split())[:120]}"
    if not table.schema.equals(schema, check_metadata=False):
        return "has other columns than this run's"
    expected = list(ids)
    if meta["rows"] != str(table.num_rows) or table.num_rows != len(expected):
        return f"holds {table.num_rows} rows, not {len(expected)}"
    if table.column(id_column).to_pylist() != expected:
        return f"holds other {id_column}s than {expected[0]}..{expected[-1]}" if expected else f"holds other {id_column}s"
    if table_digest(table, fingerprint, chunk) != meta["sha256"]:
        return "does not match its content hash (edited or corrupted)"
    return None

"""Grasp sets and results as Arrow tables: the Parquet schema, and streaming in fixed-size chunks.

Parquet files hold the same schema as the JSON Lines files of :mod:`qualgrasp.certify.io`:

* grasps: ``id`` (string), ``contacts`` (list of struct ``p``, ``n`` (lists of float64),
  ``model`` (string), and one float64 field per model parameter: ``mu``, ``torsion``,
  ``width``, nullable), ``center`` (list of float64, nullable), ``length`` (float64, nullable).
  Other layouts are read too (:mod:`qualgrasp.certify.columns`);
* results: the columns of :data:`qualgrasp.certify.results.COLUMNS`, with ``certificate`` a
  struct ``{force, form}`` of certificate structs.

The format of a file is chosen by its extension: ``.parquet`` / ``.pq`` for Parquet, anything
else (``.jsonl``, ``.json``, ``.ndjson``) for JSON Lines. Both are read in chunks of a fixed number
of grasps, so memory stays bounded whatever the file's size, and a chunk's boundaries do not
depend on how the file was written (needed to resume an interrupted run).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Iterator, Sequence

import pyarrow as pa
import pyarrow.parquet as pq

from .errors import GraspFileError
from .results import RESULT_SCHEMA
from .validation import param_names

__all__ = ["CONTACT", "GRASP_SCHEMA", "is_parquet", "Chunk", "iter_chunks", "count_grasps",
           "grasps_table", "rows_to_table", "table_to_rows", "chunk_values", "parse_line"]

CONTACT = pa.struct([("p", pa.list_(pa.float64())), ("n", pa.list_(pa.float64())), ("model", pa.string())]
                    + [(name, pa.float64()) for name in param_names()])
"""A contact as an Arrow struct: ``p``, ``n``, ``model`` and every registered model parameter."""
GRASP_SCHEMA = pa.schema([
    ("id", pa.string()), ("contacts", pa.list_(CONTACT)), ("center", pa.list_(pa.float64())),
    ("length", pa.float64()),
])


def is_parquet(path: str | Path) -> bool:
    """True for ``.parquet`` / ``.pq`` files (Parquet), False for JSON Lines."""
    return Path(path).suffix.lower() in (".parquet", ".pq")


@dataclass(frozen=True)
class Chunk:
    """``index``-th chunk of a grasp set: its rows with their line numbers (1-based; JSON Lines
    count blank lines too, Parquet counts rows, as a ``range``). ``rows`` is a list of
    ``(line, text)`` for JSON Lines and an Arrow table for Parquet."""

    index: int
    lines: Sequence[int]
    rows: Any

    def __len__(self) -> int:
        return len(self.lines)

    def __reduce__(self):
        # Arrow tables pickle (protocol 4, as process pools use) about 5x slower than the IPC
        # stream format; chunks travel to workers this way.
        if isinstance(self.rows, pa.Table):
            return _chunk_from_ipc, (self.index, self.lines, _ipc_bytes(self.rows))
        return Chunk, (self.index, self.lines, self.rows)


def _ipc_bytes(table: pa.Table) -> pa.Buffer:
    sink = pa.BufferOutputStream()
    with pa.ipc.new_stream(sink, table.schema) as writer:
        writer.write_table(table)
    return sink.getvalue()


def _chunk_from_ipc(index: int, lines: Sequence[int], data) -> Chunk:
    return Chunk(index, lines, pa.ipc.open_stream(data).read_all())


def _open_error(path: Path, err: Exception) -> GraspFileError:
    return GraspFileError(f"cannot read {path}: {getattr(err, 'strerror', None) or err}")


def iter_chunks(path: str | Path, size: int) -> Iterator[Chunk]:
    """Yield the grasp set at ``path`` in chunks of ``size`` grasps (the last may be shorter)."""
    path = Path(path)
    if is_parquet(path):
        try:
            # Without pre-buffering, pyarrow (26) keeps every decoded page of the file alive while
            # iterating batches; buffered reads keep memory bounded by the chunk size.
            reader = pq.ParquetFile(path, pre_buffer=False, buffer_size=1 << 20)
        except (OSError, pa.ArrowException) as err:
            raise _open_error(path, err) from None
        buffered, start, index = [], 0, 0
        pending = 0
        for batch in reader.iter_batches(batch_size=size):
            buffered.append(batch)
            pending += batch.num_rows
            while pending >= size:
                table = pa.Table.from_batches(buffered).combine_chunks()
                yield Chunk(index, range(start + 1, start + size + 1), table.slice(0, size))
                rest = table.slice(size)
                buffered, pending = rest.to_batches(), rest.num_rows
                start, index = start + size, index + 1
        if pending:
            table = pa.Table.from_batches(buffered, schema=reader.schema_arrow)
            yield Chunk(index, range(start + 1, start + pending + 1), table)
        return
    try:
        # undecodable bytes become lone surrogates (and the line an error row, see
        # chunk_values), so that one bad line neither stops the run nor shifts line numbers
        fh = path.open("r", encoding="utf-8", errors="surrogateescape")
    except OSError as err:
        raise _open_error(path, err) from None
    with fh:
        rows, index = [], 0
        for number, text in enumerate(fh, start=1):
            if text.strip():
                rows.append((number, text))
                if len(rows) == size:
                    yield Chunk(index, [n for n, _ in rows], rows)
                    rows, index = [], index + 1
        if rows:
            yield Chunk(index, [n for n, _ in rows], rows)


def clean_value(d: Any) -> Any:
    """Drop null fields (Parquet's missing values) so that defaults apply as in JSON."""
    if not isinstance(d, dict):
        return d
    out = {k: v for k, v in d.items() if v is not None}
    if isinstance(out.get("contacts"), list):
        out["contacts"] = [clean_value(c) for c in out["contacts"]]
    return out


def table_values(table: pa.Table) -> list:
    """Grasp values (dicts, JSON-like) of the rows of an Arrow grasp table."""
    return [clean_value(d) for d in table.to_pylist()]


def parse_line(text: str) -> Any:
    """The JSON value of one line, or a :class:`GraspFileError` saying why there is none (not
    UTF-8, malformed, nested too deeply, an integer too long to convert)."""
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        return GraspFileError("the line is not valid UTF-8")
    try:
        return json.loads(text)
    except json.JSONDecodeError as err:
        return GraspFileError(f"malformed JSON ({err.msg} at column {err.colno})")
    except RecursionError:
        return GraspFileError("malformed JSON (nested too deeply)")
    except ValueError as err:  # e.g. an integer with more digits than Python converts
        return GraspFileError(f"malformed JSON ({str(err)[:80]})")


def chunk_values(chunk: Chunk) -> list:
    """Parsed grasp values of a chunk: dicts, or a :class:`GraspFileError` for a malformed line."""
    if isinstance(chunk.rows, pa.Table):
        return table_values(chunk.rows)
    return [parse_line(text) for _, text in chunk.rows]


def count_grasps(path: str | Path) -> int | None:
    """Number of grasps in the file (Parquet metadata, or a scan of JSON Lines), None if unreadable."""
    path = Path(path)
    try:
        if is_parquet(path):
            return pq.ParquetFile(path).metadata.num_rows
        with path.open("rb") as fh:
            return sum(1 for line in fh if line.strip())
    except (OSError, pa.ArrowException):
        return None


def grasps_table(dicts: list[dict]) -> pa.Table:
    """Arrow table (grasp schema) of grasp dictionaries in the JSON schema; ids become strings."""
    rows = []
    keys = ("p", "n", "model") + param_names()
    for d in dicts:
        contacts = [{k: c.get(k) for k in keys} for c in d["contacts"]]
        gid = d.get("id")
        rows.append({"id": None if gid is None else str(gid), "contacts": contacts,
                     "center": d.get("center"), "length": d.get("length")})
    return pa.Table.from_pylist(rows, schema=GRASP_SCHEMA)


def rows_to_table(rows: list[dict]) -> pa.Table:
    """Arrow table (results schema) of results rows; ids become strings."""
    fixed = []
    for r in rows:
        r = dict(r)
        if r.get("id") is not None and not isinstance(r["id"], str):
            r["id"] = json.dumps(r["id"]) if not isinstance(r["id"], (int, float)) else str(r["id"])
        fixed.append(r)
    return pa.Table.from_pylist(fixed, schema=RESULT_SCHEMA)


def table_to_rows(table: pa.Table) -> list[dict]:
    """Results rows (dictionaries) of an Arrow results table; empty certificate fields dropped."""
    rows = table.to_pylist()
    for r in rows:
        cert = r.get("certificate")
        if isinstance(cert, dict):  # any other value is left as it is, for the re-check to refuse
            for key in ("force", "form"):
                if isinstance(cert.get(key), dict):
                    cert[key] = {k: v for k, v in cert[key].items() if v is not None}
    return rows

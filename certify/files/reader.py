"""Grasp sets and results as Arrow tables: the Parquet schema, and streaming in fixed-size chunks.

Parquet files hold the same schema as the JSON Lines files of :mod:`qualgrasp.certify.files.writers`:

* grasps: ``id`` (string), ``contacts`` (list of struct ``p``, ``n`` (lists of float64),
  ``model`` (string), and one float64 field per model parameter: ``mu``, ``torsion``,
  ``width``, nullable), ``center`` (list of float64, nullable), ``length`` (float64, nullable).
  Other layouts are read too (:mod:`qualgrasp.certify.files.columns`);
* results: the columns of :data:`qualgrasp.certify.files.results.COLUMNS`, with ``certificate`` a
  struct ``{force, form}`` of certificate structs.

An input file's format is recognised by its content (Parquet's magic number, else JSON Lines,
unless its first lines show binary data or one JSON document, which is refused with a one-line
reason (:func:`input_format`); only regular files are read); a results file's by its extension
(``.parquet`` / ``.pq`` for Parquet, anything else for JSON Lines). Both are read in chunks of a
fixed number of grasps, so memory stays bounded whatever the file's size, and a chunk's
boundaries do not depend on how the file was written (needed to resume an interrupted run).
JSON Lines may end lines with ``\\n``, ``\\r\\n`` or ``\\r`` and start with a UTF-8 byte-order
mark; a line that is too long (:data:`MAX_LINE_BYTES`), not UTF-8 or not JSON is an error row.
"""

from __future__ import annotations

import json
import os
import stat
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Iterator, Sequence

import pyarrow as pa
import pyarrow.parquet as pq

from ..errors import GraspFileError
from .outputs import file_kind
from .results import RESULT_SCHEMA
from ..core.validation import param_names

__all__ = ["CONTACT", "GRASP_SCHEMA", "contact_type", "grasp_schema", "MAX_LINE_BYTES", "READ_ERROR", "SNIFF_BYTES", "is_parquet", "input_format",
           "column_problem", "json_lines", "Chunk",
           "iter_chunks", "count_grasps", "parse_line", "grasps_table", "rows_to_table", "table_to_rows",
           "carried_array", "json_text", "JSON_TEXT", "unified_schema", "conform", "chunk_values", "table_values",
           "read_results"]

def contact_type() -> pa.StructType:
    """A contact as an Arrow struct: ``p``, ``n``, ``model`` and every model parameter registered
    now (a model registered after import adds its parameters)."""
    return pa.struct([("p", pa.list_(pa.float64())), ("n", pa.list_(pa.float64())), ("model", pa.string())]
                     + [(name, pa.float64()) for name in param_names()])


def grasp_schema() -> pa.Schema:
    """The Arrow schema of a grasp table: ``id``, ``contacts`` (:func:`contact_type`), ``center``,
    ``length``."""
    return pa.schema([("id", pa.string()), ("contacts", pa.list_(contact_type())),
                      ("center", pa.list_(pa.float64())), ("length", pa.float64())])


CONTACT = contact_type()
"""The contact struct of the built-in models (:func:`contact_type` for the registered ones)."""
GRASP_SCHEMA = grasp_schema()
"""The grasp schema of the built-in models (:func:`grasp_schema` for the registered ones)."""


def is_parquet(path: str | Path) -> bool:
    """True for ``.parquet`` / ``.pq`` names: the format a results file is written in (input
    files are recognised by their content, :func:`input_format`)."""
    return Path(path).suffix.lower() in (".parquet", ".pq")


#: Longest line of a JSON Lines file, in bytes; a longer line is an error row, never read whole.
MAX_LINE_BYTES = 16 << 20
#: Column of an Arrow chunk marking rows that could not be read (a corrupt Parquet page).
READ_ERROR = "_qualgrasp_read_error"

_MAGIC = ((b"\x1f\x8b", "gzip-compressed data: decompress it first (gunzip)"),
          (b"\x89PNG", "a PNG image"), (b"\xff\xd8\xff", "a JPEG image"), (b"%PDF", "a PDF document"),
          (b"PK\x03\x04", "a zip archive: extract it first"), (b"\xff\xfe", "UTF-16 text: save it as UTF-8"),
          (b"\xfe\xff", "UTF-16 text: save it as UTF-8"), (b"BZh", "bzip2-compressed data: decompress it first"),
          (b"\xfd7zXZ", "xz-compressed data: decompress it first"))


def _not_grasps(path: Path, what: str) -> GraspFileError:
    return GraspFileError(f"{path} is neither JSON Lines nor Parquet: {what}")


#: Bytes read from the start of a file to recognise its format.
SNIFF_BYTES = 1 << 20


def input_format(path: str | Path) -> str:
    """``'parquet'`` or ``'jsonl'``, from the file's content (not its name).

    JSON Lines is decided on the lines of the first :data:`SNIFF_BYTES` as a whole: a file whose
    lines are mostly JSON objects is JSON Lines, and each bad line (a NUL byte, a JSON array) is
    an error row of its own; a file that is not mostly JSON objects is refused, with the reason,
    when it holds binary data (NUL bytes) or one JSON document or array, and is otherwise read
    line by line, each line that is not a grasp an error row (a CSV file, a log, a file damaged
    throughout).

    Raises
    ------
    GraspFileError
        The file cannot be read, is not a regular file (a FIFO or a device is never read), or
        holds something else: compressed or binary data, an image, UTF-16 text, one JSON document
        spread over many lines (a JSON array of grasps, pretty-printed JSON), or a Parquet file
        with two columns of one name or a column named :data:`READ_ERROR`; the message says
        which and how to fix it.
    """
    path = Path(path)
    try:
        st = os.stat(path)
        if not stat.S_ISREG(st.st_mode):
            raise GraspFileError(f"cannot read {path}: it is {file_kind(st.st_mode)}, not a regular file")
        with path.open("rb") as fh:
            head = fh.read(SNIFF_BYTES)
    except FileNotFoundError:
        raise GraspFileError(f"cannot read {path}: no such file") from None
    except OSError as err:
        raise _open_error(path, err) from None
    if head.startswith(b"PAR1"):
        _check_parquet(path)
        return "parquet"
    for magic, what in _MAGIC:
        if head.startswith(magic):
            raise _not_grasps(path, what)
    reason = _not_lines(head, complete=len(head) < SNIFF_BYTES)
    if reason:
        raise _not_grasps(path, reason)
    return "jsonl"


def _not_lines(head: bytes, complete: bool) -> str | None:
    """Why the start of a file is not JSON Lines, or None when it is. A file of which more than
    half of the complete non-blank lines are JSON objects is JSON Lines, whatever its other lines
    hold (each is an error row). Otherwise it is refused when it holds a NUL byte (binary data) or
    its first line opens a JSON document spread over lines or a JSON array of grasps, and read as
    JSON Lines with bad lines when not (a CSV file or a log: one error row per line, as a damaged
    JSON Lines file, every line of which may be bad, is read). A file whose first line is longer
    than the sample is judged by that line's start."""
    text = head[3:] if head.startswith(b"\xef\xbb\xbf") else head
    lines = text.replace(b"\r\n", b"\n").replace(b"\r", b"\n").split(b"\n")
    if not complete:
        lines = lines[:-1]  # the last one may be cut short
    lines = [line.strip() for line in lines if line.strip()]
    if not lines:
        return None if complete or text.lstrip()[:1] in (b"{", b"") else "the first line is not a JSON object"
    objects = sum(isinstance(parse_line(line), dict) for line in lines)
    if 2 * objects > len(lines):
        return None
    first = lines[0]
    if b"\x00" in text:
        return "binary data (NUL bytes)"
    if first in (b"[", b"{") or first.endswith((b",", b"[", b"{")):
        return "one JSON document spread over many lines (a JSON array or pretty-printed JSON); write one grasp per line"
    if first.startswith(b"[") and b'"contacts"' in first:
        return "a JSON array of grasps; write one grasp per line"
    return None  # JSON Lines with bad lines: each is an error row


def _check_parquet(path: Path) -> None:
    """Refuse a Parquet file whose columns the reader cannot keep apart: two columns of one name,
    or a column named like the reader's marker :data:`READ_ERROR`."""
    try:
        names = pq.read_schema(path).names
    except (OSError, pa.ArrowException) as err:
        raise _open_error(path, err) from None
    problem = column_problem(names)
    if problem:
        raise GraspFileError(f"{path}: {problem}")


def column_problem(names: Sequence[str]) -> str | None:
    """What makes columns ``names`` unreadable as one table, or None: a name given twice, or the
    reader's marker :data:`READ_ERROR`.

    Examples
    --------
    >>> column_problem(["id", "contacts", "contacts"])
    'the column contacts appears 2 times: give each column its own name'
    """
    seen: dict[str, int] = {}
    for name in names:
        seen[name] = seen.get(name, 0) + 1
    for name, count in seen.items():
        if count > 1:
            return f"the column {name} appears {count} times: give each column its own name"
    if READ_ERROR in seen:
        return f"the column {READ_ERROR} is reserved by qualgrasp (it marks unreadable rows): rename it"
    return None


def json_lines(path: str | Path, what: str = "line file") -> Iterator[tuple[int, Any]]:
    """``(line number, value)`` of every non-blank line of a JSON Lines file, read by the rules
    of grasp sets (:func:`input_format` first, then line by line: numbers count from 1 and
    include blank lines; a line that cannot be read gives a :class:`GraspFileError` saying why,
    :func:`parse_line`). Every line file of the toolkit is read this way.

    Raises
    ------
    GraspFileError
        The whole file is refused (:func:`input_format`), or it is Parquet (``what`` names the
        kind of file expected, for the message).

    Examples
    --------
    >>> import pathlib, tempfile
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "r.jsonl"
    >>> _ = path.write_bytes(b'{"id": 1}\\n\\n{"id": 2, "x": \\xff}\\n{"id": 3}\\n')
    >>> [(n, v if isinstance(v, dict) else str(v)) for n, v in json_lines(path)]
    [(1, {'id': 1}), (3, 'not valid UTF-8 (byte 0xff at column 16)'), (4, {'id': 3})]
    """
    path = Path(path)
    if input_format(path) != "jsonl":
        raise GraspFileError(f"{path} is a Parquet file; a {what} is JSON Lines (one JSON object per line)")
    try:
        fh = path.open("rb")
    except OSError as err:
        raise _open_error(path, err) from None
    with fh:
        for number, raw in _raw_lines(fh):
            if raw is not None and not raw.strip():
                continue
            yield number, parse_line(raw)


def _raw_lines(fh, limit: int = MAX_LINE_BYTES) -> Iterator[tuple[int, bytes | None]]:
    """``(line number, bytes)`` of every line of a binary file (line ends ``\\n``, ``\\r\\n`` or
    ``\\r`` removed; a UTF-8 byte-order mark at the start removed); ``None`` for a line longer
    than ``limit``, which is skipped without being held in memory."""
    number, carry = 0, b""
    first = True
    while True:
        block = fh.read(1 << 20)
        if not block:
            break
        data = carry + block
        if first:
            data = data[3:] if data.startswith(b"\xef\xbb\xbf") else data
            first = False
        # a \r at the very end may be the first half of \r\n: keep it for the next block
        cut = len(data) - 1 if data.endswith(b"\r") else len(data)
        start, n = 0, cut
        while True:
            i = data.find(b"\n", start, n)
            j = data.find(b"\r", start, n)
            if i < 0 and j < 0:
                break
            end = j if (j >= 0 and (i < 0 or j < i)) else i
            number += 1
            line = data[start:end]
            yield number, (None if len(line) > limit else line)
            start = end + (2 if data[end:end + 2] == b"\r\n" else 1)
        carry = data[start:]
        if len(carry) > limit + 1:  # a line longer than the limit: skip to its end
            number += 1
            yield number, None
            carry = _skip_line(fh)
            if carry is None:
                return
    if carry.endswith(b"\r"):  # the file's last line end
        carry = carry[:-1]
        number += 1
        yield number, (carry if len(carry) <= limit else None)
    elif carry:
        number += 1
        yield number, (carry if len(carry) <= limit else None)


def _skip_line(fh) -> bytes | None:
    """Read past the end of the current line; the bytes after it, or None at the end of the file."""
    while True:
        block = fh.read(1 << 20)
        if not block:
            return None
        i, j = block.find(b"\n"), block.find(b"\r")
        ends = [k for k in (i, j) if k >= 0]
        if ends:
            end = min(ends)
            return block[end + (2 if block[end:end + 2] == b"\r\n" else 1):]


@dataclass(frozen=True)
class Chunk:
    """``index``-th chunk of a grasp set: its rows with their line numbers (1-based; JSON Lines
    count blank lines too, Parquet counts rows, as a ``range``). ``rows`` is a list of
    ``(line, bytes)`` for JSON Lines (``None`` for a line too long to read) and an Arrow table for
    Parquet."""

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
    """Yield the grasp set at ``path`` in chunks of ``size`` grasps (the last may be shorter); the
    format is recognised by content (:func:`input_format`).

    Parquet row groups that cannot be decoded (corrupt pages) become rows marked with the
    :data:`READ_ERROR` column, so that every row still gets its line and the run goes on.
    """
    path = Path(path)
    if size < 1:
        raise GraspFileError(f"chunk size must be at least 1, got {size}")
    if input_format(path) == "parquet":
        yield from _parquet_chunks(path, size)
        return
    try:
        fh = path.open("rb")
    except OSError as err:
        raise _open_error(path, err) from None
    with fh:
        rows, index = [], 0
        for number, raw in _raw_lines(fh):
            if raw is not None and not raw.strip():
                continue
            rows.append((number, raw))
            if len(rows) == size:
                yield Chunk(index, [n for n, _ in rows], rows)
                rows, index = [], index + 1
        if rows:
            yield Chunk(index, [n for n, _ in rows], rows)


def _parquet_batches(path: Path, size: int) -> Iterator[pa.RecordBatch]:
    """The file's rows as record batches of the file's schema plus :data:`READ_ERROR`; a row
    group that fails to decode gives its remaining rows as null rows with the error."""
    try:
        # Without pre-buffering, pyarrow (26) keeps every decoded page of the file alive while
        # iterating batches; buffered reads keep memory bounded by the chunk size.
        reader = pq.ParquetFile(path, pre_buffer=False, buffer_size=1 << 20)
    except (OSError, pa.ArrowException) as err:
        raise _open_error(path, err) from None
    schema = reader.schema_arrow.append(pa.field(READ_ERROR, pa.string()))
    meta = reader.metadata
    for rg in range(meta.num_row_groups):
        total, done = meta.row_group(rg).num_rows, 0
        try:
            for batch in reader.iter_batches(batch_size=size, row_groups=[rg]):
                done += batch.num_rows
                yield pa.RecordBatch.from_arrays(batch.columns + [pa.nulls(batch.num_rows, pa.string())],
                                                 schema=schema)
        except (OSError, pa.ArrowException, ValueError) as err:
            rest = total - done
            message = f"unreadable Parquet data (row group {rg}): {str(err).splitlines()[0] if str(err) else err}"
            arrays = [pa.nulls(rest, f.type) for f in reader.schema_arrow] + [pa.array([message] * rest, pa.string())]
            yield pa.RecordBatch.from_arrays(arrays, schema=schema)


def _parquet_chunks(path: Path, size: int) -> Iterator[Chunk]:
    buffered, start, index = [], 0, 0
    pending = 0
    schema = None
    for batch in _parquet_batches(path, size):
        schema = batch.schema
        buffered.append(batch)
        pending += batch.num_rows
        while pending >= size:
            table = pa.Table.from_batches(buffered).combine_chunks()
            yield Chunk(index, range(start + 1, start + size + 1), table.slice(0, size))
            rest = table.slice(size)
            buffered, pending = rest.to_batches(), rest.num_rows
            start, index = start + size, index + 1
    if pending:
        table = pa.Table.from_batches(buffered, schema=schema)
        yield Chunk(index, range(start + 1, start + pending + 1), table)


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


def parse_line(raw: bytes | None) -> Any:
    """A JSON Lines line's value, or a :class:`GraspFileError` saying why it cannot be read
    (too long, not UTF-8, malformed JSON, nested deeper than Python's parser allows)."""
    if raw is None:
        return GraspFileError(f"line longer than {MAX_LINE_BYTES} bytes")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as err:
        return GraspFileError(f"not valid UTF-8 (byte 0x{raw[err.start]:02x} at column {err.start + 1})")
    try:
        return json.loads(text)
    except json.JSONDecodeError as err:
        return GraspFileError(f"malformed JSON ({err.msg} at column {err.colno})")
    except RecursionError:
        return GraspFileError("JSON nested deeper than the parser allows (about 1,000 levels)")
    except ValueError as err:  # e.g. an integer of more than 4,300 digits
        return GraspFileError(f"malformed JSON ({err})")


def chunk_values(chunk: Chunk) -> list:
    """Parsed values of a chunk: dicts (or other JSON values), or a :class:`GraspFileError` for a
    line that cannot be read."""
    if isinstance(chunk.rows, pa.Table):
        return table_values(chunk.rows)
    return [parse_line(raw) for _, raw in chunk.rows]


def count_grasps(path: str | Path) -> int | None:
    """Number of grasps in the file (Parquet metadata, or a scan of JSON Lines), None if it cannot
    be read as a grasp set."""
    path = Path(path)
    try:
        if input_format(path) == "parquet":
            return pq.ParquetFile(path).metadata.num_rows
        with path.open("rb") as fh:
            return sum(1 for _, raw in _raw_lines(fh) if raw is None or raw.strip())
    except (OSError, pa.ArrowException, GraspFileError):
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
    return pa.Table.from_pylist(rows, schema=grasp_schema())


def rows_to_table(rows: list[dict]) -> pa.Table:
    """Arrow table of results rows: the results schema, then the fields carried from the input
    (those beyond the results columns, in the order first met), each as the Arrow type its values
    have, or as JSON text when they have no common type (:func:`carried_array`); ids become
    strings.

    Examples
    --------
    >>> from qualgrasp.certify.files.results import error_row
    >>> t = rows_to_table([{**error_row("bad", id=1, line=1), "note": "a"},
    ...                    {**error_row("bad", id=2, line=2), "note": [1, 2]}])
    >>> t.column_names[-1], t.column("note").to_pylist()
    ('note', ['"a"', '[1, 2]'])
    """
    fixed = []
    for r in rows:
        r = dict(r)
        if r.get("id") is not None and not isinstance(r["id"], str):
            r["id"] = json.dumps(r["id"]) if not isinstance(r["id"], (int, float)) else str(r["id"])
        fixed.append(r)
    table = pa.Table.from_pylist(fixed, schema=RESULT_SCHEMA)
    names = set(RESULT_SCHEMA.names)
    for key in dict.fromkeys(k for r in fixed for k in r if k not in names):
        array = carried_array([r.get(key) for r in fixed])
        table = table.append_column(pa.field(key, array.type, metadata=JSON_TEXT if array.type == pa.large_string()
                                             else None), array)
    return table


#: Field metadata of a carried column written as JSON text (:func:`carried_array`).
JSON_TEXT = {b"qualgrasp": b"json"}


def carried_array(values: list) -> pa.Array:
    """An Arrow array of one carried field's JSON values: the type Arrow infers for them, or,
    when they have none in common (a string in one row, a list in another), their JSON text
    (``large_string``, whose field :func:`rows_to_table` marks with :data:`JSON_TEXT`; null stays
    null), so that no value is lost or changed."""
    try:
        array = pa.array(values)
    except (pa.ArrowInvalid, pa.ArrowTypeError, pa.ArrowNotImplementedError, OverflowError):
        return json_text(values)
    if array.type == pa.large_string():  # that type means JSON text here
        return json_text(values)
    return array


def unified_schema(schemas: list[pa.Schema]) -> pa.Schema:
    """One schema for results tables written in parts (a Parquet output): every column of any
    part, in the order first met, each of the type its parts' types promote to; a carried column
    whose types do not promote (a string in one part, a list in another) becomes JSON text
    (:data:`JSON_TEXT`).

    Examples
    --------
    >>> a = pa.schema([("x", pa.null()), ("y", pa.int64())])
    >>> b = pa.schema([("x", pa.string()), ("y", pa.list_(pa.int64()))])
    >>> s = unified_schema([a, b])
    >>> s.field("x").type, s.field("y").type, s.field("y").metadata
    (DataType(string), DataType(large_string), {b'qualgrasp': b'json'})
    """
    fields = {}
    for schema in schemas:
        for f in schema:
            fields.setdefault(f.name, []).append(f)
    out = []
    for name, found in fields.items():
        if any(f.metadata == JSON_TEXT for f in found):
            out.append(pa.field(name, pa.large_string(), metadata=JSON_TEXT))
            continue
        try:
            out.append(pa.unify_schemas([pa.schema([f]) for f in found], promote_options="permissive").field(name))
        except (pa.ArrowInvalid, pa.ArrowTypeError, pa.ArrowNotImplementedError):
            out.append(pa.field(name, pa.large_string(), metadata=JSON_TEXT))
    return pa.schema(out)


def conform(table: pa.Table, schema: pa.Schema) -> pa.Table:
    """``table`` in ``schema`` (:func:`unified_schema` of its part and the others): its columns
    cast, those it lacks null, those the schema holds as JSON text written as JSON text."""
    columns = []
    for f in schema:
        if f.name not in table.column_names:
            columns.append(pa.nulls(table.num_rows, f.type))
        elif f.metadata == JSON_TEXT and table.schema.field(f.name).metadata != JSON_TEXT:
            columns.append(json_text(table.column(f.name).to_pylist()))
        else:
            columns.append(table.column(f.name).cast(f.type))
    return pa.Table.from_arrays(columns, schema=schema)


def json_text(values: list) -> pa.Array:
    """JSON text of each value (null stays null), as ``large_string``."""
    return pa.array([None if v is None else json.dumps(v, allow_nan=False) for v in values], pa.large_string())


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


def read_results(path: str | Path, chunk_size: int = 4096) -> Iterator[dict]:
    """Yield the rows of a results file as dictionaries.

    Raises
    ------
    GraspFileError
        The file is refused as a whole, or a line cannot be read (the message names it).
    """
    for chunk in iter_chunks(path, chunk_size):
        if isinstance(chunk.rows, list):
            for line, value in zip(chunk.lines, chunk_values(chunk)):
                if isinstance(value, Exception):
                    raise GraspFileError(f"{path} line {line}: {value}")
                yield value
        else:
            yield from table_to_rows(chunk.rows)

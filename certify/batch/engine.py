"""Resumable, parallel certification of large grasp sets.

The input is read in chunks of a fixed number of grasps (:func:`qualgrasp.certify.files.reader.iter_chunks`;
by default :func:`chunk_size_for` the input and the workers, or on resume the interrupted run's).
Each chunk is certified by a worker (local processes by default, or a dask.distributed cluster)
and its results are written to ``RESULTS.parts/part-NNNNNN.EXT`` under a temporary name, renamed
atomically when complete, with ``part-NNNNNN.EXT.sum`` stating its rows, bytes and CRC-32 (local
workers write their own parts; dask workers encode their parts and send the bytes back to the
client, which writes them, so a remote cluster needs no shared filesystem and the client's work
per row stays a copy). Parts of a Parquet output are Arrow IPC
files (``.arrow``, LZ4): cheap to write and to read back, so the Parquet encoding is done once.
The main process appends the parts in chunk order to a temporary results file in the parts folder
as they complete, renamed to ``RESULTS`` at the end; then the parts folder is removed. A Parquet
output is written in one schema, that of all its parts (the columns carried from JSON rows may
differ between chunks): its parts are appended as they complete while they share the first one's,
and all are written again at the end, in the schema of them all, when one does not or its values
do not convert to the first one's types (the file is the same either way; the workers' parts then
overlap with its encoding instead of waiting, and a write that fails does so mid-run, keeping the
parts finished by then).

Local workers (and the ``qualgrasp certify`` and ``verify`` commands) keep the memory they free for
the next chunk (:func:`tune_allocator`, glibc only).

A run killed at any moment leaves only complete parts (plus temporaries, discarded).
``resume=True`` keeps the complete parts whose sums match (a part truncated by a crash or a disk
error is computed again) and certifies only the missing chunks, so every input grasp appears
exactly once, with the same result as in an uninterrupted run (the computation of a chunk is
deterministic). ``RESULTS.parts/manifest.json`` records the input and the options, and marks the
folder as this output's (:data:`MADE_BY`); a resume with a different input, chunk size or options
is refused, and a ``RESULTS.parts`` that no run for this output made is never reused nor removed.

Nothing is lost (:mod:`qualgrasp.certify.files.outputs`): the output is checked before any work (never
an input, a FIFO or a device), one run at a time writes it (a second is refused), and a write that
fails (full disk, file-size limit, read-only folder) ends the run with a one-line
:class:`CertifyError` that keeps every finished part for ``--resume``.
"""

from __future__ import annotations

import ctypes
import json
import os
import re
import shutil
import sys
import time
import zlib
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, Callable, Sequence

import pyarrow as pa
import pyarrow.parquet as pq

from .chunk import Options, certify_chunk_results, status_counts
from ..errors import CertifyError, GraspFileError
from ..files.outputs import check_output, lock_output, write_error
from ..files.results import RESULT_SCHEMA, RESULT_WRITE_OPTIONS, carried_clash
from ..files.reader import (JSON_TEXT, Chunk, conform, count_grasps, input_format, is_parquet, iter_chunks,
                            rows_to_table, table_to_rows, unified_schema)
from ..core.validation import TOP_LEVEL

__all__ = ["RunSummary", "run", "CHUNK_SIZE", "chunk_size_for", "tune_allocator", "check_paths", "certify_chunk",
           "encoded_chunk", "encode_part", "parts_folder", "MADE_BY"]


@dataclass
class RunSummary:
    """Counts of a certification run, its wall time (s) and peak resident memory (MB) of this
    process and of the largest local worker process (None where the platform does not say);
    ``resumed_rows`` of the ``rows`` were kept from an interrupted run, not certified in this one."""

    rows: int = 0
    statuses: dict[str, int] = field(default_factory=dict)
    unverified: int = 0
    chunks: int = 0
    resumed_chunks: int = 0
    resumed_rows: int = 0
    seconds: float = 0.0
    peak_mb: float | None = None
    peak_worker_mb: float | None = None

    @property
    def errors(self) -> int:
        return self.statuses.get("error", 0)

    def add(self, counts: dict[str, int], unverified: int) -> None:
        for status, n in counts.items():
            self.statuses[status] = self.statuses.get(status, 0) + n
            self.rows += n
        self.unverified += unverified


# Parts are compressed and read back on one thread each: the run's processes keep the cores busy
# already, and Arrow's compression threads cost CPU (0.7 s against 0.55 s of compression per
# million planar rows with quality) that the other processes would have used.
_IPC = pa.ipc.IpcWriteOptions(compression="lz4", use_threads=False)
_IPC_READ = pa.ipc.IpcReadOptions(use_threads=False)


def _part_name(index: int, results: Path) -> str:
    """File name of chunk ``index``'s part: Arrow IPC for a Parquet output, else JSON Lines."""
    return f"part-{index:06d}" + (".arrow" if is_parquet(results) else results.suffix)


def _read_part(path: Path) -> pa.Table:
    with pa.memory_map(str(path)) as source:
        return pa.ipc.open_file(source, options=_IPC_READ).read_all()


def _part_schema(path: Path) -> pa.Schema:
    with pa.memory_map(str(path)) as source:
        return pa.ipc.open_file(source).schema


def _checksum(path: Path) -> tuple[int, int]:
    """``(size in bytes, CRC-32)`` of a file, read in blocks."""
    crc, size = 0, 0
    with path.open("rb") as fh:
        while block := fh.read(1 << 20):
            crc = zlib.crc32(block, crc)
            size += len(block)
    return size, crc


def _sum_path(part: Path) -> Path:
    return part.with_name(part.name + ".sum")


def encode_part(results, suffix: str) -> tuple[bytes, int]:
    """The bytes of a part holding ``results`` (an Arrow table or a list of rows), and its row
    count: Arrow IPC for ``.arrow``, else JSON Lines."""
    if suffix == ".arrow":
        table = results if isinstance(results, pa.Table) else rows_to_table(results)
        sink = pa.BufferOutputStream()
        with pa.ipc.new_file(sink, table.schema, options=_IPC) as writer:
            writer.write_table(table)
        return sink.getvalue().to_pybytes(), table.num_rows
    rows = table_to_rows(results) if isinstance(results, pa.Table) else results
    return "".join(json.dumps(row, allow_nan=False) + "\n" for row in rows).encode("utf-8"), len(rows)


def _write_part(data: bytes, rows: int, path: Path) -> None:
    """Write a part's bytes (:func:`encode_part`) atomically, with its companion ``.sum`` (rows,
    bytes, CRC-32) written first: a part counts only when its sum matches (:func:`_part_ok`), so a
    part truncated by a crash or a disk error is found and computed again."""
    tmp = path.with_name(f"{path.name}.{os.getpid()}.tmp")  # writers never share a temporary
    tmp_sum = path.with_name(f"{path.name}.sum.{os.getpid()}.tmp")
    try:
        tmp.write_bytes(data)
        size, crc = _checksum(tmp)  # read back: what the disk holds, not what was meant
        tmp_sum.write_text(json.dumps({"rows": rows, "bytes": size, "crc32": crc}))
        os.replace(tmp_sum, _sum_path(path))
        os.replace(tmp, path)  # atomic: a part exists only when complete
    except BaseException:
        for t in (tmp, tmp_sum):
            try:
                t.unlink()
            except OSError:
                pass
        raise


def _part_ok(part: Path, rows: int) -> bool:
    """True when ``part`` exists, holds ``rows`` rows and matches its sum (size and CRC-32)."""
    try:
        stated = json.loads(_sum_path(part).read_text(encoding="utf-8"))
        return (isinstance(stated, dict) and stated.get("rows") == rows
                and [stated.get("bytes"), stated.get("crc32")] == list(_checksum(part)))
    except (OSError, ValueError):
        return False


def certify_chunk(chunk: Chunk, options: Options, part: str) -> tuple[int, dict[str, int], int]:
    """Certify ``chunk`` and write its results to ``part`` atomically.

    Returns ``(chunk index, status counts, unverified count)``. This is the unit of work sent to
    local processes.
    """
    data, rows, counts, unverified = encoded_chunk(chunk, options, Path(part).suffix)
    _write_part(data, rows, Path(part))
    return chunk.index, counts, unverified


def encoded_chunk(chunk: Chunk, options: Options, suffix: str) -> tuple[bytes, int, dict[str, int], int]:
    """Certify ``chunk``: its part's bytes (:func:`encode_part`), row count, status counts and
    unverified count. This is the unit of work sent to dask workers: the client only writes the
    bytes, so encoding the rows runs on the workers, in parallel."""
    results = certify_chunk_results(chunk, options)
    return *encode_part(results, suffix), *_counts(results)


def _counts(results) -> tuple[dict[str, int], int]:
    """Status counts and unverified count of results (an Arrow table or a list of rows)."""
    if isinstance(results, pa.Table):
        return status_counts(results.column("status"), results.column("verified"))
    return status_counts([r["status"] for r in results], [r["verified"] for r in results])


def _part_counts(part: Path) -> tuple[dict[str, int], int]:
    if part.suffix == ".arrow":
        return _counts(_read_part(part))
    return _counts([json.loads(line) for line in part.read_text(encoding="utf-8").splitlines()])


MADE_BY = "qualgrasp certify"
"""The marker of a checkpoint folder's manifest (``made_by``): only folders carrying it, for the
same output, are ever reused or removed."""

_OURS = re.compile(r"(manifest\.json|part-\d{6}.*|.*\.tmp)")


def _manifest(grasps: Path, results: Path, chunk_size: int, options: Options) -> dict:
    st = grasps.stat()
    return {"made_by": MADE_BY, "input": str(grasps.resolve()), "input_size": st.st_size,
            "input_mtime_ns": st.st_mtime_ns, "output": str(results.resolve()), "chunk_size": chunk_size,
            "options": asdict(options)}


#: Most grasps in a chunk when the run does not say (:func:`chunk_size_for`).
CHUNK_SIZE = 16384


def chunk_size_for(n_grasps: int | None, workers: int) -> int:
    """The chunk size of a run of ``n_grasps`` grasps on ``workers`` processes that does not give
    one: :data:`CHUNK_SIZE`, or fewer (down to 1024) so that each worker gets four chunks.

    A chunk has fixed costs (the columnar kernels' calls, its part, a results row group), about
    10 % of a planar grasp's time at 4096 grasps a chunk; but the last chunks of a small run
    leave workers idle.

    Examples
    --------
    >>> chunk_size_for(1_000_000, 2), chunk_size_for(20_000, 2), chunk_size_for(100, 2), chunk_size_for(None, 2)
    (16384, 2500, 1024, 16384)
    """
    if not n_grasps:
        return CHUNK_SIZE
    return max(1024, min(CHUNK_SIZE, -(-n_grasps // (4 * workers))))


def parts_folder(results: str | Path) -> Path:
    """The checkpoint folder of ``results``: ``RESULTS.parts`` next to it."""
    results = Path(results)
    return results.with_name(results.name + ".parts")


def _owned(parts: Path, results: Path) -> dict | None:
    """The manifest of ``parts`` when it is a checkpoint folder of this output (a folder, not a
    link, whose manifest carries :data:`MADE_BY` and the output's path), else None."""
    if parts.is_symlink() or not parts.is_dir():
        return None
    try:
        old = json.loads((parts / "manifest.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not isinstance(old, dict) or old.get("made_by") != MADE_BY or old.get("output") != str(results.resolve()):
        return None
    return old


def _prepare(grasps: Path, results: Path, chunk_size: int, options: Options, resume: bool) -> Path:
    """The checkpoint folder of the run: kept (resume), emptied of its own files (a new run over a
    folder of an earlier run for this output) or created. A folder (or file) of that name that
    this output's runs did not make is never touched: the run is refused."""
    parts = parts_folder(results)
    manifest = _manifest(grasps, results, chunk_size, options)
    if os.path.lexists(parts):
        old = _owned(parts, results)
        if old is None:
            what = "a folder" if parts.is_dir() and not parts.is_symlink() else "a file"
            raise CertifyError(f"{'cannot resume: ' if resume else ''}{parts} exists and is {what} that "
                               "qualgrasp certify did not make for this output (no manifest naming it); "
                               "move it away or choose another output name")
        if resume:
            if old != manifest:
                raise CertifyError(f"cannot resume: {parts} was made from another input or with other "
                                   "options (chunk size, method, quality); run without --resume to start over")
            for tmp in parts.glob("*.tmp"):
                tmp.unlink()
            return parts
        strangers = sorted(p.name for p in parts.iterdir() if not _OURS.fullmatch(p.name) or not p.is_file())
        if strangers:
            raise CertifyError(f"{parts} holds files qualgrasp did not write ({', '.join(strangers[:3])}); "
                               "move them away or choose another output name")
        for p in parts.iterdir():
            if p.name != "manifest.json":
                p.unlink()
        (parts / "manifest.json").unlink()
        parts.rmdir()
    parts.mkdir()
    tmp = parts / "manifest.json.tmp"
    tmp.write_text(json.dumps(manifest, indent=1))
    os.replace(tmp, parts / "manifest.json")
    return parts


def _remove_parts(parts: Path) -> None:
    """Remove a finished run's checkpoint folder: its own files only (a file put there by someone
    else stays, and so does the folder)."""
    for p in parts.iterdir():
        if p.name != "manifest.json" and _OURS.fullmatch(p.name) and p.is_file():
            p.unlink()
    if not any(p.name != "manifest.json" for p in parts.iterdir()):
        (parts / "manifest.json").unlink()
        parts.rmdir()


class _Assembler:
    """Appends complete parts, in chunk order, to the results' temporary file (in the checkpoint
    folder) as they arrive; a Parquet output in the one schema of them all (:meth:`_stream`);
    :meth:`close` then renames it to the results and removes the parts (a run killed before that
    leaves the parts, from which a resumed run assembles again)."""

    def __init__(self, parts: Path, results: Path) -> None:
        self.parts, self.results = parts, results
        self.tmp = parts / f"results.{os.getpid()}.tmp"
        self.parquet = is_parquet(results)
        self.out = None  # opened with the first part, so that nothing is left if no run starts
        self.next, self.ready = 0, set()
        self.schema, self.streaming = None, self.parquet  # the Parquet schema written as parts come
        self.schemas: dict[int, pa.Schema] = {}  # of the parts streamed: the close needs them again

    def _open(self, schema: pa.Schema = RESULT_SCHEMA):
        """The output, opened on first use (Parquet: with the parts' schema, the results columns
        and any columns carried from the input)."""
        if self.out is None:
            self.out = (pq.ParquetWriter(self.tmp, schema, **RESULT_WRITE_OPTIONS) if self.parquet
                        else self.tmp.open("wb"))
        return self.out

    def add(self, index: int) -> None:
        self.ready.add(index)
        while self.next in self.ready:
            self.ready.remove(self.next)
            part = self.parts / _part_name(self.next, self.results)
            if self.parquet:
                self._stream(part, self.next)
            else:
                with part.open("rb") as fh:
                    shutil.copyfileobj(fh, self._open())
            self.next += 1

    def _stream(self, part: Path, index: int) -> None:
        """Append a Parquet part in the schema of the first (:func:`unified_schema` of it alone)
        while each part's schema adds nothing to it and its values convert; a part that would
        change it, or whose values do not convert, stops the appending and drops what was written
        (:meth:`_write_parquet` writes every part at the close)."""
        if not self.streaming:
            return
        table = None
        try:
            read = _read_part(part)  # one read for the schema and the rows: most parts are appended
            schema = self.schemas[index] = read.schema
            if self.schema is None:
                self.schema = unified_schema([schema])
            if unified_schema([self.schema, schema]).equals(self.schema, check_metadata=True):
                table = conform(read, self.schema)
        except (pa.ArrowInvalid, pa.ArrowTypeError, pa.ArrowNotImplementedError):
            pass  # values the first part's types cannot hold (an integer past 2**53 in a float
            # column) where the schema of all parts may (JSON text), or a part that does not read:
            # the close decides
        if table is None:
            self.streaming = False
            self.abort()
            return
        self._open(self.schema).write_table(table)

    def _write_parquet(self, n_chunks: int) -> None:
        """Every part, in order, in the schema of them all (:func:`unified_schema`: the columns
        carried from JSON rows may differ between parts, in presence or type), unless
        :meth:`_stream` has written them all in that schema already."""
        parts = [self.parts / _part_name(i, self.results) for i in range(n_chunks)]
        schemas = [self.schemas[i] if i in self.schemas else _part_schema(p) for i, p in enumerate(parts)]
        schema = unified_schema(schemas) if parts else RESULT_SCHEMA
        if self.streaming and self.out is not None and schema.equals(self.schema, check_metadata=True):
            return
        self.abort()
        schema = _holding(schema, zip(parts, schemas))
        writer = self._open(schema)
        for part in parts:
            writer.write_table(conform(_read_part(part), schema))

    def close(self, n_chunks: int) -> None:
        if self.next != n_chunks:
            raise CertifyError(f"internal error: {self.next} of {n_chunks} parts assembled")
        if self.parquet:
            self._write_parquet(n_chunks)
        out, self.out = self._open(), None
        out.close()
        check_output(self.results, "-o")  # nothing put in the output's place meanwhile
        os.replace(self.tmp, self.results)
        _remove_parts(self.parts)

    def abort(self) -> None:
        """Close and remove the temporary output (the parts stay)."""
        if self.out is not None:
            try:
                self.out.close()
            except (OSError, pa.ArrowException):  # the disk that failed the write fails the close
                pass
            self.out = None
        self.tmp.unlink(missing_ok=True)


def _holding(schema: pa.Schema, parts) -> pa.Schema:
    """``schema`` (:func:`unified_schema` of the ``(path, schema)`` pairs ``parts``) with each
    column that some part's values do not convert to exactly (an integer past 2**53 into a float
    column) as JSON text, as :func:`unified_schema` holds types that do not promote: no value is
    changed, and the run does not fail on a cast a resume would fail on again."""
    text = set()
    for path, own in parts:
        cast = [f.name for f in own if f.name not in text and schema.field(f.name).metadata != JSON_TEXT
                and f.type != schema.field(f.name).type]
        table = _read_part(path) if cast else None
        for name in cast:
            try:
                table.column(name).cast(schema.field(name).type)
            except (pa.ArrowInvalid, pa.ArrowTypeError, pa.ArrowNotImplementedError):
                text.add(name)
    return pa.schema([pa.field(f.name, pa.large_string(), metadata=JSON_TEXT) if f.name in text else f
                      for f in schema])


#: glibc ``mallopt`` settings of a run's own processes (:func:`tune_allocator`): blocks up to
#: 32 MB from the heap, not from fresh mappings, and freed memory kept up to 256 MB instead of
#: returned at once. A chunk's arrays are allocated and freed again chunk after chunk; by default
#: each large one is a new mapping whose pages fault in anew, which took half of the workers'
#: system time.
_MALLOPT = ((-3, 32 << 20), (-1, 256 << 20))  # M_MMAP_THRESHOLD, M_TRIM_THRESHOLD


def tune_allocator() -> None:
    """Apply :data:`_MALLOPT` to this process where the C library is glibc (elsewhere nothing):
    for processes of a run's own (local workers of certify and verify, the ``qualgrasp certify``
    and ``verify`` commands), not for a caller's process, whose allocator is its own business."""
    if not sys.platform.startswith("linux"):
        return
    try:
        mallopt = ctypes.CDLL("libc.so.6").mallopt
    except (OSError, AttributeError):  # musl and others: their allocator is left as it is
        return
    for option, value in _MALLOPT:
        mallopt(option, value)


class _LocalPool:
    def __init__(self, workers: int) -> None:
        self.pool = ProcessPoolExecutor(max_workers=workers, initializer=tune_allocator)
        self.capacity = 2 * workers

    def submit(self, *args):
        return self.pool.submit(certify_chunk, *args)

    @staticmethod
    def result(future) -> tuple[dict[str, int], int]:
        _, counts, unverified = future.result()
        return counts, unverified

    @staticmethod
    def wait_one(futures):
        done, _ = wait(futures, return_when=FIRST_COMPLETED)
        return done

    def close(self) -> None:
        self.pool.shutdown(cancel_futures=True)


DASK_CONNECT_SECONDS = 10
"""How long to try to reach a dask scheduler before giving up (s)."""


class _DaskPool:
    def __init__(self, address: str, workers: int) -> None:
        try:
            from distributed import Client, LocalCluster
        except ImportError:
            raise CertifyError('dask is an optional extra: pip install "qualgrasp[dask]"') from None
        if address == "local":
            self.cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                        dashboard_address=None)
            self.client = Client(self.cluster)
        else:
            self.cluster = None
            try:
                self.client = Client(address, timeout=DASK_CONNECT_SECONDS)
            except (OSError, ValueError, TypeError) as err:
                raise CertifyError(f"--dask: cannot reach a dask scheduler at {address!r} ({err})") from None
        self.capacity = 2 * max(1, len(self.client.scheduler_info()["workers"]))
        self.parts: dict[Any, Path] = {}

    def submit(self, chunk: Chunk, options: Options, part: str):
        # Workers only compute: the chunk travels by scatter (not inside the task graph) and its
        # encoded part comes back here to be written, so a remote cluster needs no shared filesystem.
        data = self.client.scatter(chunk, direct=False)
        future = self.client.submit(encoded_chunk, data, options, Path(part).suffix, pure=False)
        self.parts[future] = Path(part)
        return future

    def result(self, future) -> tuple[dict[str, int], int]:
        data, rows, counts, unverified = future.result()
        _write_part(data, rows, self.parts.pop(future))
        return counts, unverified

    @staticmethod
    def wait_one(futures):
        from distributed import wait as dwait

        return dwait(list(futures), return_when="FIRST_COMPLETED").done

    def close(self) -> None:
        self.client.close()
        if self.cluster is not None:
            self.cluster.close()


def check_paths(grasps: Path, results: Path, chunk_size: int | None = None, others: Sequence[Path] = ()) -> None:
    """Refuse a run before any work: an input that is not a grasp set, a chunk size below 1 (None:
    the run's default), and
    an output that :func:`qualgrasp.certify.files.outputs.check_output` refuses (a folder, a FIFO or
    device, the input itself or one of the ``others`` files read (a source's mesh) through any
    link, a checkpoint folder ``RESULTS.parts`` that is or holds an input, a name too long for that
    folder, a folder that cannot be created or written). The output's folder is created if needed.

    Raises
    ------
    CertifyError
        With a one-line message naming the problem (:class:`GraspFileError` for the input and the
        chunk size, :class:`qualgrasp.certify.errors.OptionError` for the output).
    """
    if chunk_size is not None and chunk_size < 1:
        raise GraspFileError(f"the chunk size must be at least 1 grasp, got {chunk_size}")
    if input_format(grasps) == "parquet":  # raises for a file that is not JSON Lines or Parquet
        clash = carried_clash([n for n in pq.read_schema(grasps).names if n not in TOP_LEVEL])
        if clash:
            raise GraspFileError(f"{grasps}: the columns {clash}")
    check_output(results, "-o", reads=[grasps, *others], companions=[parts_folder(results)])


def run(grasps: str | Path, results: str | Path, *, options: Options = Options(),
        workers: int | None = None, dask: str | None = None, resume: bool = False,
        chunk_size: int | None = None, progress: Callable[[int], None] | None = None,
        grasp_count: int | None = None) -> RunSummary:
    """Certify the grasp set ``grasps`` into ``results`` in parallel (the input's format is
    recognised by content, the output's by extension; see :func:`check_paths` for what is
    refused before any work).

    Parameters
    ----------
    workers : int, optional
        Local worker processes (default: all cores). With 1, chunks are certified in this process.
    dask : str, optional
        ``"local"`` for a dask LocalCluster of ``workers`` processes, or a scheduler address.
    resume : bool
        Keep the complete chunks of an interrupted run and certify only the rest.
    chunk_size : int, optional
        Grasps per chunk (the unit of work, of checkpointing and of memory). Default: with
        ``resume``, the interrupted run's; else :func:`chunk_size_for` the input's grasps and
        the workers (a dask cluster's as its scheduler counts them).
    progress : callable, optional
        Called with the number of grasps of each chunk as it completes (or is found complete).
    grasp_count : int, optional
        The input's grasps (:func:`~qualgrasp.certify.files.reader.count_grasps`) when the caller
        has counted them, for the default chunk size (else counted here: a scan of JSON Lines).
    """
    grasps, results = Path(grasps), Path(results)
    check_paths(grasps, results, chunk_size, options.source.inputs() if options.source is not None else ())
    with lock_output(results, "-o"):
        try:
            return _run(grasps, results, options, workers, dask, resume, chunk_size, progress, grasp_count)
        except (OSError, pa.ArrowException) as err:
            raise CertifyError(_fault(err, results)) from None
        except BrokenProcessPool:  # a worker killed (a signal, out of memory) or crashed: no Python error to give
            raise CertifyError("a worker process ended abruptly (killed by a signal or by the system, for example "
                               "out of memory)" + _kept(results)) from None


def _resumed_chunk_size(results: Path) -> int | None:
    """The chunk size of the interrupted run of ``results`` (its checkpoint folder's manifest),
    None when there is none."""
    old = _owned(parts_folder(results), results)
    size = None if old is None else old.get("chunk_size")
    return size if isinstance(size, int) and not isinstance(size, bool) and size >= 1 else None


def _fault(err: Exception, results: Path) -> str:
    """One line for a write that failed mid-run (full disk, file-size limit, read-only folder):
    what failed, and that the finished parts are kept for ``--resume``."""
    target = getattr(err, "filename", None) or results
    message = (write_error(target, err) if isinstance(err, OSError)
               else f"cannot write {results}: {str(err).splitlines()[0][:200]}")
    return message + _kept(results)


def _kept(results: Path) -> str:
    """What a run that ended mid-way keeps: its finished parts, for ``--resume``."""
    parts = parts_folder(results)
    return (f"; the finished parts are kept in {parts}: fix the cause and run again with --resume"
            if parts.is_dir() and any(parts.glob("part-*.sum")) else "")


def _run(grasps: Path, results: Path, options: Options, workers: int | None, dask: str | None,
         resume: bool, chunk_size: int | None, progress: Callable[[int], None] | None,
         grasp_count: int | None = None) -> RunSummary:
    start = time.perf_counter()
    workers = workers or os.cpu_count() or 1
    # The pool first: a scheduler that cannot be reached leaves nothing behind.
    pool = _DaskPool(dask, workers) if dask else (_LocalPool(workers) if workers > 1 else None)
    try:
        if chunk_size is None:  # the pool's workers: a remote cluster's, not this machine's cores
            chunk_size = (resume and _resumed_chunk_size(results)
                          or chunk_size_for(count_grasps(grasps) if grasp_count is None else grasp_count,
                                            pool.capacity // 2 if pool else 1))
        parts = _prepare(grasps, results, chunk_size, options, resume)
    except BaseException:
        if pool is not None:
            pool.close()
        raise
    summary = RunSummary()
    assembler = _Assembler(parts, results)
    pending: dict[Any, tuple[int, int]] = {}

    def done(index: int, size: int) -> None:
        assembler.add(index)
        if progress:
            progress(size)

    def collect(future) -> None:
        summary.add(*pool.result(future))
        done(*pending.pop(future))

    try:
        n_chunks = 0
        for chunk in iter_chunks(grasps, chunk_size):
            n_chunks += 1
            part = parts / _part_name(chunk.index, results)
            if resume and _part_ok(part, len(chunk)):
                summary.add(*_part_counts(part))
                summary.resumed_chunks += 1
                summary.resumed_rows += len(chunk)
            elif pool is None:
                _, counts, unverified = certify_chunk(chunk, options, str(part))
                summary.add(counts, unverified)
            else:
                while len(pending) >= pool.capacity:
                    for future in pool.wait_one(pending):
                        collect(future)
                pending[pool.submit(chunk, options, str(part))] = (chunk.index, len(chunk))
                continue
            done(chunk.index, len(chunk))
        while pending:
            for future in pool.wait_one(pending):
                collect(future)
        assembler.close(n_chunks)
    except BaseException:
        assembler.abort()
        raise
    finally:
        if pool is not None:
            pool.close()
    summary.chunks = n_chunks
    summary.seconds = time.perf_counter() - start
    summary.peak_mb, summary.peak_worker_mb = _peak_memory()
    return summary


def _peak_memory() -> tuple[float | None, float | None]:
    """Peak RSS in MB of this process and of its largest finished child process."""
    try:
        import resource
    except ImportError:  # not on this platform
        return None, None
    unit = 1 / 1024 if sys.platform != "darwin" else 1 / 2**20  # kB on Linux, bytes on macOS
    own = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * unit
    child = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss * unit
    return own, (child or None)

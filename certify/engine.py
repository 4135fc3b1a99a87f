"""Resumable, parallel certification of large grasp sets.

The input is read in chunks of a fixed number of grasps (:func:`qualgrasp.certify.table.iter_chunks`).
Each chunk is certified by a worker (local processes by default, or a dask.distributed cluster)
and its results are written to ``RESULTS.parts/part-NNNNNN.EXT`` under a temporary name, renamed
atomically when complete (local workers write their own parts; dask workers send their results
back to the client, which writes them, so a remote cluster needs no shared filesystem). Parts of
a Parquet output are Arrow IPC files (``.arrow``, LZ4): cheap to write and to read back, so the
Parquet encoding is done once. As parts complete, the main process appends them in chunk order to
a temporary results file, renamed to ``RESULTS`` when the last one is in; then the parts folder
is removed.

A run killed at any moment leaves only complete parts (plus temporaries, discarded).
``resume=True`` keeps the complete parts and certifies only the missing chunks, so every input
grasp appears exactly once, with the same result as in an uninterrupted run (the computation of a
chunk is deterministic). ``RESULTS.parts/manifest.json`` records the input and the options; a
resume with a different input, chunk size or options is refused.
"""

from __future__ import annotations

import json
import os
import shutil
import sys
import time
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, Callable

import pyarrow as pa
import pyarrow.parquet as pq

from .chunk import Options, certify_chunk_results, status_counts
from .errors import CertifyError, GraspFileError
from .results import RESULT_SCHEMA, RESULT_WRITE_OPTIONS
from .table import Chunk, input_format, is_parquet, iter_chunks, rows_to_table, table_to_rows

__all__ = ["RunSummary", "run", "check_paths", "certify_chunk"]


@dataclass
class RunSummary:
    """Counts of a certification run, its wall time (s) and peak resident memory (MB) of this
    process and of the largest local worker process (None where the platform does not say)."""

    rows: int = 0
    statuses: dict[str, int] = field(default_factory=dict)
    unverified: int = 0
    chunks: int = 0
    resumed_chunks: int = 0
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


_IPC = pa.ipc.IpcWriteOptions(compression="lz4")


def _part_name(index: int, results: Path) -> str:
    """File name of chunk ``index``'s part: Arrow IPC for a Parquet output, else JSON Lines."""
    return f"part-{index:06d}" + (".arrow" if is_parquet(results) else results.suffix)


def _read_part(path: Path) -> pa.Table:
    with pa.memory_map(str(path)) as source:
        return pa.ipc.open_file(source).read_all()


def _write_part(results, path: Path) -> None:
    tmp = path.with_name(f"{path.name}.{os.getpid()}.tmp")  # writers never share a temporary
    if path.suffix == ".arrow":
        table = results if isinstance(results, pa.Table) else rows_to_table(results)
        with pa.ipc.new_file(tmp, table.schema, options=_IPC) as writer:
            writer.write_table(table)
    else:
        rows = table_to_rows(results) if isinstance(results, pa.Table) else results
        with tmp.open("w", encoding="utf-8") as fh:
            for row in rows:
                fh.write(json.dumps(row, allow_nan=False) + "\n")
    os.replace(tmp, path)  # atomic: a part exists only when complete


def certify_chunk(chunk: Chunk, options: Options, part: str) -> tuple[int, dict[str, int], int]:
    """Certify ``chunk`` and write its results to ``part`` atomically.

    Returns ``(chunk index, status counts, unverified count)``. This is the unit of work sent to
    local processes.
    """
    return chunk.index, *_finish(certify_chunk_results(chunk, options), Path(part))


def _finish(results, part: Path) -> tuple[dict[str, int], int]:
    """Write a chunk's results to ``part`` atomically; its status counts and unverified count."""
    _write_part(results, part)
    if isinstance(results, pa.Table):
        return status_counts(results.column("status"), results.column("verified"))
    return status_counts([r["status"] for r in results], [r["verified"] for r in results])


def _part_counts(part: Path) -> tuple[dict[str, int], int]:
    if part.suffix == ".arrow":
        t = _read_part(part)
        return status_counts(t.column("status"), t.column("verified"))
    rows = [json.loads(line) for line in part.read_text(encoding="utf-8").splitlines()]
    return status_counts([r["status"] for r in rows], [r["verified"] for r in rows])


def _manifest(grasps: Path, results: Path, chunk_size: int, options: Options) -> dict:
    st = grasps.stat()
    return {"input": str(grasps.resolve()), "input_size": st.st_size, "input_mtime_ns": st.st_mtime_ns,
            "output": str(results.resolve()), "chunk_size": chunk_size, "options": asdict(options)}


def _prepare(grasps: Path, results: Path, chunk_size: int, options: Options, resume: bool) -> Path:
    parts = results.with_name(results.name + ".parts")
    manifest = _manifest(grasps, results, chunk_size, options)
    if resume and parts.exists():
        try:
            old = json.loads((parts / "manifest.json").read_text())
        except (OSError, json.JSONDecodeError):
            old = None
        if old != manifest:
            raise CertifyError(f"cannot resume: {parts} was made from another input or with other "
                               "options (chunk size, method, quality); run without --resume to start over")
        for tmp in parts.glob("*.tmp"):
            tmp.unlink()
        return parts
    if parts.exists():
        shutil.rmtree(parts)
    parts.mkdir(parents=True)
    tmp = parts / "manifest.json.tmp"
    tmp.write_text(json.dumps(manifest, indent=1))
    os.replace(tmp, parts / "manifest.json")
    return parts


class _Assembler:
    """Appends complete parts, in chunk order as they arrive, to the results' temporary file;
    :meth:`close` renames it to the results and removes the parts (a run killed before that
    leaves the parts, from which a resumed run assembles again)."""

    def __init__(self, parts: Path, results: Path) -> None:
        self.parts, self.results = parts, results
        self.tmp = results.with_name(results.name + ".tmp")
        self.parquet = is_parquet(results)
        self.out = None  # opened with the first part, so that nothing is left if no run starts
        self.next, self.ready = 0, set()

    def _open(self, schema: pa.Schema = RESULT_SCHEMA):
        """The output, opened on first use (Parquet: with the first part's schema, the results
        columns and any columns carried from the input)."""
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
                table = _read_part(part)
                self._open(table.schema).write_table(table)
            else:
                with part.open("rb") as fh:
                    shutil.copyfileobj(fh, self._open())
            self.next += 1

    def close(self, n_chunks: int) -> None:
        self._open().close()
        if self.next != n_chunks:
            raise CertifyError(f"internal error: {self.next} of {n_chunks} parts assembled")
        os.replace(self.tmp, self.results)
        shutil.rmtree(self.parts)

    def abort(self) -> None:
        if self.out is not None:
            self.out.close()
        self.tmp.unlink(missing_ok=True)


class _LocalPool:
    def __init__(self, workers: int) -> None:
        self.pool = ProcessPoolExecutor(max_workers=workers)
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
        # Workers only compute: the chunk travels by scatter (not inside the task graph) and the
        # results come back here to be written, so a remote cluster needs no shared filesystem.
        data = self.client.scatter(chunk, direct=False)
        future = self.client.submit(certify_chunk_results, data, options, pure=False)
        self.parts[future] = Path(part)
        return future

    def result(self, future) -> tuple[dict[str, int], int]:
        return _finish(future.result(), self.parts.pop(future))

    @staticmethod
    def wait_one(futures):
        from distributed import wait as dwait

        return dwait(list(futures), return_when="FIRST_COMPLETED").done

    def close(self) -> None:
        self.client.close()
        if self.cluster is not None:
            self.cluster.close()


def check_paths(grasps: Path, results: Path, chunk_size: int = 1) -> None:
    """Refuse a run before any work: an input that is not a grasp set, a chunk size below 1, and
    an output that is a folder, the input itself (output never overwrites what the run reads) or
    in a folder that cannot be created or written. The output's folder is created if needed.

    Raises
    ------
    GraspFileError
        With a one-line message naming the problem.
    """
    if chunk_size < 1:
        raise GraspFileError(f"the chunk size must be at least 1 grasp, got {chunk_size}")
    input_format(grasps)  # raises for a file that is not JSON Lines or Parquet
    if results.is_dir():
        raise GraspFileError(f"the output {results} is a folder; give a file name (.jsonl or .parquet)")
    if results.exists() and os.path.samefile(results, grasps):
        raise GraspFileError(f"the output {results} is the input file: choose another name (the input "
                             "is never overwritten)")
    folder = results.parent if str(results.parent) else Path(".")
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise GraspFileError(f"cannot create the output's folder {folder}: {err.strerror or err}") from None
    if not os.access(folder, os.W_OK):
        raise GraspFileError(f"cannot write into {folder}")


def run(grasps: str | Path, results: str | Path, *, options: Options = Options(),
        workers: int | None = None, dask: str | None = None, resume: bool = False,
        chunk_size: int = 4096,
        progress: Callable[[int], None] | None = None) -> RunSummary:
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
    chunk_size : int
        Grasps per chunk (the unit of work, of checkpointing and of memory).
    progress : callable, optional
        Called with the number of grasps of each chunk as it completes (or is found complete).
    """
    start = time.perf_counter()
    grasps, results = Path(grasps), Path(results)
    check_paths(grasps, results, chunk_size)
    workers = workers or os.cpu_count() or 1
    # The pool first: a scheduler that cannot be reached leaves nothing behind.
    pool = _DaskPool(dask, workers) if dask else (_LocalPool(workers) if workers > 1 else None)
    try:
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
            if part.exists():
                summary.add(*_part_counts(part))
                summary.resumed_chunks += 1
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

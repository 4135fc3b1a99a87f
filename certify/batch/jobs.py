"""Certify and re-verify whole grasp-set files (JSON Lines or Parquet, chosen by extension).

:func:`certify_file` streams the input in chunks through :mod:`qualgrasp.certify.batch.engine` (parallel,
resumable; :mod:`qualgrasp.certify.batch.chunk` is what happens to one chunk); :func:`verify_file`
re-checks a results file (all of its rows or any subset, in any order: rows are paired with their
grasps by line) against its grasps, in parallel, without any solver.
"""

from __future__ import annotations

import os
import pickle
import tempfile
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Iterator, Sequence

import numpy as np
import pyarrow as pa

from ..core.certificates import Tolerances
from .chunk import STATUSES, Options, Quality, verify_chunk
from .engine import RunSummary, chunk_size_for, run, tune_allocator
from ..errors import CertifyError
from ..files.reader import READ_ERROR, Chunk, chunk_values, count_grasps, input_format, is_parquet, iter_chunks
from ..core.validation import show
from ..solvers import Method

__all__ = ["Summary", "certify_file", "verify_file"]


def certify_file(grasps_path: str | Path, results_path: str | Path, *, method: Method = "fast",
                 progress: Callable[[int], None] | None = None, workers: int | None = 1,
                 dask: str | None = None, resume: bool = False, chunk_size: int | None = None,
                 quality: bool = True, eps_gap: float = 0.01, eps_budget: int = 200_000,
                 eps_time: float | None = 10.0, source: Any = None, grasp_count: int | None = None) -> RunSummary:
    """Certify every grasp of ``grasps_path`` into ``results_path``: one results row per grasp,
    in input order. See :func:`qualgrasp.certify.batch.engine.run` for ``workers``, ``dask``, ``resume``,
    ``chunk_size`` and ``grasp_count`` (``workers=None`` uses every core); ``quality``, ``eps_gap``, ``eps_budget``,
    ``eps_time`` and ``source`` are :class:`qualgrasp.certify.batch.chunk.Options`' (``eps_time``
    in seconds per grasp, None for no limit; ``source`` turns the input's rows into grasps, such
    as :class:`qualgrasp.certify.meshes.source.PoseSource` for poses on a mesh)."""
    options = Options(method=method, quality=quality, eps_gap=eps_gap, eps_budget=eps_budget,
                      eps_time=eps_time, source=source)
    return run(grasps_path, results_path, options=options, workers=workers, dask=dask,
               resume=resume, chunk_size=chunk_size, progress=progress, grasp_count=grasp_count)


@dataclass
class Summary:
    """Counts of a verification run; ``failures`` lists ``(id, reason)`` of the rows that fail
    (the id the results row states, the reason naming its line); ``missing`` counts the grasps
    that have no results row (a results file may hold a subset: not a failure); ``unpaired``
    counts the rows that failed before any re-check, having no grasp to be re-checked against
    (unreadable, stating no usable line or a line that is no grasp of the file, or repeating
    another row's line), and ``unpaired_errors`` those of them stating status ``error``."""

    rows: int = 0
    statuses: dict[str, int] = field(default_factory=dict)
    failures: list[tuple[object, str]] = field(default_factory=list)
    missing: int = 0
    grasps: int = 0
    unpaired: int = 0
    unpaired_errors: int = 0

    @property
    def errors(self) -> int:
        return self.statuses.get("error", 0)

    def count(self, status: str, n: int = 1) -> None:
        self.statuses[status] = self.statuses.get(status, 0) + n
        self.rows += n


#: Largest line number a results row may state (lines are 1-based row or line numbers).
MAX_LINE = 1 << 62


class _Block:
    """Results rows read from the results file: an Arrow table (Parquet) or a list of parsed
    values (JSON Lines: a dict, or an error for a line that cannot be read), with the line of
    each row in the results file (for messages about rows that name no grasp line)."""

    def __init__(self, rows: Any, where: Sequence[int]) -> None:
        self.rows, self.where = rows, where

    def __len__(self) -> int:
        return len(self.where)

    def take(self, idx: np.ndarray) -> Any:
        """The rows ``idx`` in a form :func:`verify_chunk` reads (the table itself when ``idx``
        is all of it, in order: the columnar fast path stays zero-copy)."""
        if isinstance(self.rows, pa.Table):
            if len(idx) == self.rows.num_rows and (len(idx) == 0 or (idx[0] == 0 and np.all(np.diff(idx) == 1))):
                return self.rows
            return self.rows.take(pa.array(idx, pa.int64()))
        return [self.rows[i] for i in idx]

    def lines(self) -> tuple[np.ndarray, dict[int, str]]:
        """The grasp line each row states (-1 where none can be used) and, for those rows, why:
        for a row of an unreadable Parquet row group, the reader's error."""
        out, problems = self._stated_lines()
        if isinstance(self.rows, pa.Table) and READ_ERROR in self.rows.column_names:
            unreadable = self.rows.column(READ_ERROR).combine_chunks()
            for k in np.flatnonzero(np.asarray(unreadable.is_valid(), dtype=bool)):
                out[k] = -1
                problems[int(k)] = f"results row {self.where[k]}: {unreadable[int(k)].as_py()}"
        return out, problems

    def _stated_lines(self) -> tuple[np.ndarray, dict[int, str]]:
        n = len(self)
        if isinstance(self.rows, pa.Table):
            if "line" not in self.rows.column_names:
                return np.full(n, -1, np.int64), {k: "column line missing" for k in range(n)}
            col = self.rows.column("line")
            if pa.types.is_integer(col.type):
                values = np.asarray(col.cast(pa.int64()).fill_null(-1).to_numpy(zero_copy_only=False), np.int64)
                bad = np.flatnonzero((values < 1) | (values > MAX_LINE))
                return np.where((values < 1) | (values > MAX_LINE), -1, values), {
                    int(k): _line_problem(col[int(k)].as_py()) for k in bad}
            values = col.to_pylist()
        else:
            values = [row.get("line", ...) if isinstance(row, dict) else ... for row in self.rows]
        out, problems = np.full(n, -1, np.int64), {}
        for k, value in enumerate(values):
            if isinstance(self.rows, list) and not isinstance(self.rows[k], dict):
                problems[k] = _unreadable(self.rows[k], self.where[k])
            elif value is ...:
                problems[k] = "column line missing"
            elif isinstance(value, int) and not isinstance(value, bool) and 1 <= value <= MAX_LINE:
                out[k] = value
            else:
                problems[k] = _line_problem(value)
        return out, problems

    def own_id(self, k: int) -> Any:
        if isinstance(self.rows, pa.Table):
            return self.rows.column("id")[k].as_py() if "id" in self.rows.column_names else None
        row = self.rows[k]
        return row.get("id") if isinstance(row, dict) else None

    def status(self, k: int) -> str:
        if isinstance(self.rows, pa.Table):
            value = self.rows.column("status")[k].as_py() if "status" in self.rows.column_names else None
        else:
            value = self.rows[k].get("status") if isinstance(self.rows[k], dict) else None
        return value if isinstance(value, str) and value in STATUSES else "malformed"


def _unreadable(value: Any, where: int) -> str:
    if isinstance(value, Exception):
        return f"results line {where}: {value}"
    return f"results line {where}: not a JSON object"


def _no_grasp(line: int) -> str:
    return f"line {line} is not a grasp of the grasp file (a blank line, or beyond its end)"


def _line_problem(value: Any) -> str:
    if isinstance(value, int) and not isinstance(value, bool):
        return _no_grasp(value)
    return f"line {show(value)} is not a line number"


def _result_blocks(path: Path, size: int, parsed: list) -> Iterator[_Block]:
    """The results file in blocks of ``size`` rows; ``parsed[0]`` counts the JSON Lines rows
    that are JSON objects."""
    for chunk in iter_chunks(path, size):
        if isinstance(chunk.rows, pa.Table):
            yield _Block(chunk.rows, chunk.lines)
        else:
            values = chunk_values(chunk)
            parsed[0] += sum(isinstance(v, dict) for v in values)
            yield _Block(values, chunk.lines)


class _Unordered(Exception):
    """The results rows' lines do not increase: verify by buckets instead of streaming."""


def _grasp_subset(chunk: Chunk, idx: np.ndarray) -> Chunk:
    """The grasps ``idx`` of ``chunk`` (the chunk itself when that is all of it, in order)."""
    if len(idx) == len(chunk) and (len(idx) == 0 or (idx[0] == 0 and np.all(np.diff(idx) == 1))):
        return chunk
    lines = [chunk.lines[int(i)] for i in idx]
    if isinstance(chunk.rows, pa.Table):
        return Chunk(chunk.index, lines, chunk.rows.take(pa.array(idx, pa.int64())))
    return Chunk(chunk.index, lines, [chunk.rows[int(i)] for i in idx])


class _Verifier:
    """Verification work, in this process or a pool (few chunks in flight), and its totals."""

    def __init__(self, tol: Tolerances, workers: int) -> None:
        self.tol = tol
        self.summary, self.quality = Summary(), Quality()
        self.pool = ProcessPoolExecutor(workers, initializer=tune_allocator) if workers > 1 else None
        self.workers = workers
        self.futures: list = []
        self.paired = 0

    def pair(self, chunk: Chunk, block: _Block, pos: np.ndarray, lines: np.ndarray) -> None:
        """Verify the results rows ``pos`` of ``block`` (grasp lines ``lines``, increasing, all in
        ``chunk``'s range) against their grasps of ``chunk``."""
        grasp_lines = np.asarray(chunk.lines, dtype=np.int64)
        at = np.searchsorted(grasp_lines, lines)
        found = (at < len(grasp_lines)) & (grasp_lines[np.minimum(at, len(grasp_lines) - 1)] == lines)
        for k in np.flatnonzero(~found):
            self.fail(block, int(pos[k]), _no_grasp(int(lines[k])))
        if not found.any():
            return
        sub, rows = _grasp_subset(chunk, at[found]), block.take(pos[found])
        self.paired += len(sub)
        if self.pool is None:
            self.merge(verify_chunk(sub, rows, self.tol))
            return
        self.futures.append(self.pool.submit(verify_chunk, sub, rows, self.tol))
        if len(self.futures) > 2 * self.workers:  # bounded memory: few chunks in flight
            self.merge(self.futures.pop(0).result())

    def fail(self, block: _Block, k: int, reason: str) -> None:
        """A results row that pairs with no grasp: counted, and a failure naming its own id."""
        status = block.status(k)
        self.summary.count(status)
        self.summary.unpaired += 1
        self.summary.unpaired_errors += status == "error"
        self.summary.failures.append((block.own_id(k), reason))

    def merge(self, result) -> None:
        statuses, failures, q = result
        for status, n in statuses.items():
            self.summary.count(status, n)
        self.summary.failures.extend(failures)
        self.quality.merge(q)

    def drain(self) -> None:
        for f in self.futures:
            self.merge(f.result())
        self.futures = []

    def close(self) -> None:
        if self.pool is not None:
            self.pool.shutdown(cancel_futures=True)


def _usable(v: _Verifier, block: _Block) -> tuple[np.ndarray, np.ndarray]:
    """Positions and lines of the rows of ``block`` that state a usable line (the others are
    failures)."""
    lines, problems = block.lines()
    for k, reason in problems.items():
        v.fail(block, k, reason)
    pos = np.flatnonzero(lines >= 1)
    return pos, lines[pos]


def _stream(v: _Verifier, results: Path, grasps: Path, size: int, parsed: list) -> None:
    """Verify rows whose lines increase through the file, pairing as both files stream; raises
    :class:`_Unordered` at the first line smaller than one before it."""
    chunks = iter_chunks(grasps, size)
    chunk = next(chunks, None)
    last = 0
    for block in _result_blocks(results, size, parsed):
        pos, lines = _usable(v, block)
        keep = np.ones(len(lines), dtype=bool)
        prev = np.concatenate([[last], lines[:-1]])
        if np.any(lines < prev):
            raise _Unordered
        for k in np.flatnonzero(lines == prev):
            v.fail(block, int(pos[k]), f"line {int(lines[k])} appears twice in the results")
            keep[k] = False
        pos, lines = pos[keep], lines[keep]
        last = int(lines[-1]) if len(lines) else last
        while len(lines):
            while chunk is not None and chunk.lines[-1] < lines[0]:
                chunk = next(chunks, None)
            if chunk is None:
                for k, line in zip(pos.tolist(), lines.tolist()):
                    v.fail(block, k, _no_grasp(line))
                break
            n = int(np.searchsorted(lines, chunk.lines[-1], side="right"))
            v.pair(chunk, block, pos[:n], lines[:n])
            pos, lines = pos[n:], lines[n:]


def _bucketed(v: _Verifier, results: Path, grasps: Path, size: int, parsed: list) -> None:
    """Verify rows in any order with bounded memory: the results rows are spilled to a temporary
    folder in buckets, one per grasp chunk (a line seen twice is a failure, not spilled), then
    each grasp chunk is verified against its bucket."""
    firsts, lasts = [], []
    for chunk in iter_chunks(grasps, size):
        firsts.append(chunk.lines[0])
        lasts.append(chunk.lines[-1])
    firsts, lasts = np.asarray(firsts, np.int64), np.asarray(lasts, np.int64)
    seen = np.zeros(int(lasts[-1]) + 1 if len(lasts) else 1, dtype=bool)
    with tempfile.TemporaryDirectory(prefix="qualgrasp-verify-") as spill:
        pending: dict[int, list] = {}
        held = 0

        def flush() -> None:
            for b, items in pending.items():
                with open(os.path.join(spill, f"{b}.pkl"), "ab") as fh:
                    pickle.dump(items, fh, protocol=pickle.HIGHEST_PROTOCOL)
            pending.clear()

        for block in _result_blocks(results, size, parsed):
            pos, lines = _usable(v, block)
            bucket = np.searchsorted(firsts, lines, side="right") - 1
            ok = np.zeros(len(pos), dtype=bool)
            for k, (line, b) in enumerate(zip(lines.tolist(), bucket.tolist())):
                if b < 0 or line > lasts[b]:
                    v.fail(block, int(pos[k]), _no_grasp(line))
                elif seen[line]:
                    v.fail(block, int(pos[k]), f"line {line} appears twice in the results")
                else:
                    seen[line] = ok[k] = True
            for b in np.unique(bucket[ok]):
                mine = ok & (bucket == b)
                pending.setdefault(int(b), []).append((lines[mine], _Block(block.take(pos[mine]), [
                    block.where[int(k)] for k in pos[mine]])))
            held += int(ok.sum())
            if held >= size:
                flush()
                held = 0
        for chunk in iter_chunks(grasps, size):
            items = []
            path = os.path.join(spill, f"{chunk.index}.pkl")
            if os.path.exists(path):
                with open(path, "rb") as fh:
                    while True:
                        try:
                            items.extend(pickle.load(fh))
                        except EOFError:
                            break
            items.extend(pending.pop(chunk.index, []))
            if not items:
                continue
            lines = np.concatenate([x for x, _ in items])
            block = _concat([b for _, b in items])
            order = np.argsort(lines, kind="stable")
            v.pair(chunk, block, order, lines[order])


def _concat(blocks: list[_Block]) -> _Block:
    where = [w for b in blocks for w in b.where]
    if isinstance(blocks[0].rows, pa.Table):
        return _Block(pa.concat_tables([b.rows for b in blocks]), where)
    return _Block([r for b in blocks for r in b.rows], where)


def verify_file(results_path: str | Path, grasps_path: str | Path,
                tol: Tolerances = Tolerances(), workers: int | None = 1,
                chunk_size: int | None = None) -> Summary:
    """Re-check every certificate of ``results_path`` against the grasps of ``grasps_path``.

    Each results row is paired with the grasp of the line it states (its ``line``; its ``id``
    must then be that grasp's), so a results file may hold a subset of the rows, in any order:
    ``Summary.missing`` counts the grasps without a row (not a failure). A row whose line is not
    a grasp of the file, or that repeats a line, fails. Every column a row states is re-checked
    (:func:`qualgrasp.certify.report.verify_row`); rows with status ``error`` must be exactly the
    error row of an invalid grasp. A file whose rows mix epsilon and no epsilon fails the rarer
    kind (a run computes quality for all rows or none). A malformed row is a failure with a
    message; each failure names the row's own id and its line. A results file that is neither
    JSON Lines nor Parquet raises :class:`qualgrasp.certify.errors.CertifyError`. Chunks are
    verified in ``workers`` processes (``None``: every core), of ``chunk_size`` grasps (default
    :func:`~qualgrasp.certify.batch.engine.chunk_size_for` the grasps and the workers).

    Memory stays bounded: rows whose lines increase (as certify writes them) are paired while
    both files stream; otherwise the rows are first spilled to a temporary folder in one bucket
    per chunk of grasps.
    """
    results_path, grasps_path = Path(results_path), Path(grasps_path)
    workers = workers or os.cpu_count() or 1
    parsed = [0]
    input_format(grasps_path)  # a grasp file that is not one is refused before any work
    if chunk_size is None:
        chunk_size = chunk_size_for(count_grasps(grasps_path), workers)
    try:
        v = _Verifier(tol, workers)
        try:
            _stream(v, results_path, grasps_path, chunk_size, parsed)
            v.drain()
        except _Unordered:
            v.close()
            v, parsed = _Verifier(tol, workers), [0]
            _bucketed(v, results_path, grasps_path, chunk_size, parsed)
            v.drain()
        finally:
            v.close()
    except (pa.ArrowException, OSError) as err:
        raise CertifyError(f"cannot read {results_path} or {grasps_path}: {str(err).splitlines()[0][:200]}") from None
    summary = v.summary
    n_rows = count_grasps(results_path)
    if not is_parquet(results_path) and n_rows and not parsed[0]:
        raise CertifyError(f"{results_path} is not a JSON Lines results file (no line is a JSON object)")
    summary.failures.extend(v.quality.failures())
    summary.grasps = count_grasps(grasps_path) or 0
    summary.missing = summary.grasps - v.paired
    return summary

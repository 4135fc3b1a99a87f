"""Certify and re-verify whole grasp-set files (JSON Lines or Parquet, chosen by extension).

:func:`certify_file` streams the input in chunks through :mod:`qualgrasp.certify.engine` (parallel,
resumable); :func:`certify_values` is what happens to one chunk; :func:`verify_file` re-checks a
results file against its grasps, in parallel, without any solver.
"""

from __future__ import annotations

import os
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Iterable, Iterator

import pyarrow as pa

from .certificates import Tolerances
from .engine import Options, RunSummary, _counts, run
from .errors import CertifyError, GraspFileError
from .grasp import grasp_from_dict
from .report import certify_grasp, error_row, verify_row
from .solvers import make_solver
from .table import chunk_values, count_grasps, iter_chunks, table_to_rows, table_values

__all__ = ["Summary", "certify_values", "certify_file", "verify_file"]


def certify_values(values: Iterable[Any], lines: Iterable[int], options: Options = Options(),
                   tol: Tolerances = Tolerances()) -> Iterator[dict]:
    """One results row per parsed grasp value (a dict in the grasp schema, or the error met while
    reading it), in order; bad values become ``error`` rows naming the line."""
    solver = make_solver(options.method)
    for value, number in zip(values, lines):
        gid = value.get("id") if isinstance(value, dict) else None
        if isinstance(value, Exception):
            yield error_row(f"line {number}: {value}", id=gid, line=number)
            continue
        try:
            grasp = grasp_from_dict(value)
            report = certify_grasp(grasp, solver=solver, tol=tol, quality=options.quality,
                                   eps_gap=options.eps_gap, eps_budget=options.eps_budget)
            yield report.row(line=number)
        except CertifyError as err:
            yield error_row(f"line {number}: {err}", id=gid, line=number)


def certify_file(grasps_path: str | Path, results_path: str | Path, *, method: str = "fast",
                 progress: Callable[[int], None] | None = None, workers: int | None = 1,
                 dask: str | None = None, resume: bool = False, chunk_size: int = 4096,
                 quality: bool = True, eps_gap: float = 0.01, eps_budget: int = 200_000) -> RunSummary:
    """Certify every grasp of ``grasps_path`` into ``results_path``: one results row per grasp,
    in input order. See :func:`qualgrasp.certify.engine.run` for ``workers``, ``dask``, ``resume`` and
    ``chunk_size`` (``workers=None`` uses every core)."""
    options = Options(method=method, quality=quality, eps_gap=eps_gap, eps_budget=eps_budget)
    return run(grasps_path, results_path, options=options, workers=workers, dask=dask,
               resume=resume, chunk_size=chunk_size, progress=progress)


@dataclass
class Summary:
    """Counts of a verification run; ``failures`` lists ``(id, reason)`` of the rows that fail."""

    rows: int = 0
    statuses: dict[str, int] = field(default_factory=dict)
    failures: list[tuple[object, str]] = field(default_factory=list)

    @property
    def errors(self) -> int:
        return self.statuses.get("error", 0)


def _result_rows(path: Path, size: int) -> Iterator[tuple[Callable[[], list], Any]]:
    """Results in chunks of ``size``: ``(function giving the rows as dicts or errors, Arrow table
    or None)``; rows are built only when asked for (a columnar re-check rarely needs them)."""
    import json

    def parse(text):
        try:
            return json.loads(text)
        except json.JSONDecodeError:
            return GraspFileError("not a JSON object")

    for chunk in iter_chunks(path, size):
        if isinstance(chunk.rows, list):
            rows = [parse(text) for _, text in chunk.rows]
            yield (lambda rows=rows: rows), None
        else:
            yield (lambda t=chunk.rows: table_to_rows(t)), chunk.rows


def _verify_one(value, line: int, row, tol: Tolerances) -> tuple[str, tuple | None]:
    """Re-check one results row against its parsed grasp value: ``(status, failure or None)``."""
    if not isinstance(row, dict):
        return "error", (None, f"results row for line {line}: not a JSON object")
    status = str(row.get("status"))
    gid = value.get("id") if isinstance(value, dict) else None
    if row.get("line") not in (None, line):
        return status, (row.get("id"), f"results row is for line {row.get('line')}, grasp is line {line}")
    if row.get("id") != gid and str(row.get("id")) != str(gid):
        return status, (row.get("id"), f"id does not match grasp line {line} ({gid!r})")
    try:
        grasp = grasp_from_dict(value) if isinstance(value, dict) else value
    except CertifyError as err:
        grasp = err
    if status == "error":
        if not isinstance(grasp, Exception):
            return status, (gid, "row says error but the grasp is valid")
        return status, None
    if isinstance(grasp, Exception):
        return status, (gid, f"grasp is invalid: {grasp}")
    check = verify_row(grasp, row, tol)
    return status, None if check else (gid, check.reason)


def _verify_chunk(grasp_values: list, lines: list[int], rows, tol: Tolerances):
    """Verify one chunk of aligned (parsed grasp, results row) pairs; return counts and failures."""
    statuses: dict[str, int] = {}
    failures = []
    for value, line, row in zip(grasp_values, lines, rows):
        status, failure = _verify_one(value, line, row, tol)
        statuses[status] = statuses.get(status, 0) + 1
        if failure:
            failures.append(failure)
    return statuses, failures


def _verify_tables(grasps, results, lines: list[int], tol: Tolerances):
    """Verify one chunk of aligned Arrow tables: the common certificates are proved in bulk
    (:func:`qualgrasp.certify.recheck.recheck_table`); only the other rows are turned into Python values
    and re-checked one by one."""
    from .recheck import recheck_table

    failures = []

    def slow(i):
        value = table_values(grasps.slice(i, 1))[0]
        status, failure = _verify_one(value, lines[i], table_to_rows(results.slice(i, 1))[0], tol)
        if failure:
            failures.append(failure)
        return failure is None

    recheck_table(grasps, results, lines, slow, tol)
    return _counts(results.column("status"), results.column("verified"))[0], failures


def verify_file(results_path: str | Path, grasps_path: str | Path,
                tol: Tolerances = Tolerances(), workers: int | None = 1,
                chunk_size: int = 4096) -> Summary:
    """Re-check every certificate of ``results_path`` against the grasps of ``grasps_path``.

    Rows and grasps are matched by position (a row's ``line`` and ``id`` must agree with its
    grasp's). Rows with status ``error`` have no certificate; their grasp must indeed be invalid.
    Chunks are verified in ``workers`` processes (``None``: every core).
    """
    results_path, grasps_path = Path(results_path), Path(grasps_path)
    workers = workers or os.cpu_count() or 1
    summary = Summary()
    pool = ProcessPoolExecutor(workers) if workers > 1 else None
    futures = []
    try:
        pairs = zip(iter_chunks(grasps_path, chunk_size), _result_rows(results_path, chunk_size))
        for chunk, (rows, table) in pairs:
            if table is not None and isinstance(chunk.rows, pa.Table) and table.num_rows == len(chunk):
                fn, args = _verify_tables, (chunk.rows, table, chunk.lines, tol)
            else:
                fn, args = _verify_chunk, (chunk_values(chunk), chunk.lines, rows(), tol)
            if pool is None:
                _merge(summary, fn(*args))
                continue
            futures.append(pool.submit(fn, *args))
            if len(futures) > 2 * workers:  # bounded memory: few chunks in flight
                _merge(summary, futures.pop(0).result())
        for f in futures:
            _merge(summary, f.result())
    finally:
        if pool is not None:
            pool.shutdown()
    n_grasps, n_rows = count_grasps(grasps_path), count_grasps(results_path)
    if n_rows != n_grasps:
        summary.failures.append((None, f"{n_rows} results rows for {n_grasps} grasps"))
    return summary


def _merge(summary: Summary, result) -> None:
    statuses, failures = result
    for status, n in statuses.items():
        summary.statuses[status] = summary.statuses.get(status, 0) + n
        summary.rows += n
    summary.failures.extend(failures)

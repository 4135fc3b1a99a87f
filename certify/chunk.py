"""One chunk of a grasp set, certified or re-checked, whichever its format.

A chunk (:class:`qualgrasp.certify.table.Chunk`) holds JSON Lines text or an Arrow table. Either
is read into checked columns (:mod:`qualgrasp.certify.columns`: one validation, the same rules and
messages for both). An Arrow chunk goes through the columnar path
(:func:`qualgrasp.certify.fastpath.certify_table`); every row it does not settle, like every row
of a JSON chunk, goes through the per-grasp path (:func:`certify_rows`). A bad row becomes an
``error`` row naming its line, the field and the problem: a chunk always gives exactly one
results row per input row, in order.

Re-checking (:func:`verify_chunk`) mirrors it: Arrow chunks are proved in bulk by the rigorous
floating-point kernels (:func:`qualgrasp.certify.recheck.recheck_table`), every other row by
:func:`qualgrasp.certify.report.verify_row` with exact rational arithmetic. No solver is used.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

import pyarrow as pa
import pyarrow.compute as pc

from .certificates import Tolerances
from .columns import GraspColumns, grasp_columns, value_columns
from .errors import CertifyError
from .fastpath import certify_table
from .recheck import recheck_table
from .report import certify_grasp, verify_row
from .results import error_row
from .solvers import make_solver
from .table import Chunk, chunk_values, table_to_rows

__all__ = ["Options", "certify_rows", "certify_values", "certify_chunk_results", "verify_rows",
           "verify_chunk", "status_counts"]


@dataclass(frozen=True)
class Options:
    """What is computed for every grasp (recorded in a run's manifest; part of a chunk's
    identity): the solver ``method``, whether to compute epsilon (``quality``), the spatial
    epsilon's relative gap and budget, and the per-grasp time limit of quality in seconds
    (``eps_time``, None for none; see :func:`qualgrasp.certify.certify_grasp`)."""

    method: str = "fast"
    quality: bool = True
    eps_gap: float = 0.01
    eps_budget: int = 200_000
    eps_time: float | None = 10.0


def certify_rows(cols: GraspColumns, rows: Sequence[int], lines: Sequence[int],
                 options: Options = Options(), tol: Tolerances = Tolerances()) -> list[dict]:
    """Results rows of ``rows`` of checked columns, grasp by grasp (``lines[k]`` is the line of
    ``rows[k]``); invalid rows become error rows."""
    solver = make_solver(options.method)
    out = []
    for i, line in zip(rows, lines):
        gid = cols.id_of(i)
        message = cols.message(i)
        if message is None:
            try:
                grasp = cols.grasps([i])[0]
                report = certify_grasp(grasp, solver=solver, tol=tol, quality=options.quality,
                                       eps_gap=options.eps_gap, eps_budget=options.eps_budget,
                                       eps_time=options.eps_time)
                out.append(report.row(line=line))
                continue
            except CertifyError as err:
                message = str(err)
        out.append(error_row(f"line {line}: {message}", id=gid, line=line))
    return out


def certify_values(values: Sequence[Any], lines: Sequence[int], options: Options = Options(),
                   tol: Tolerances = Tolerances()) -> list[dict]:
    """One results row per parsed grasp value (a dict in the grasp schema, or the error met
    while reading it), in order."""
    cols = value_columns(values)
    return certify_rows(cols, range(len(values)), lines, options, tol)


def certify_chunk_results(chunk: Chunk, options: Options, tol: Tolerances = Tolerances()):
    """Results of ``chunk``: an Arrow table for an Arrow chunk (columnar path), a list of rows
    for JSON Lines (per-grasp path)."""
    if not isinstance(chunk.rows, pa.Table):
        return certify_values(chunk_values(chunk), chunk.lines, options, tol)
    lines = chunk.lines
    cols = grasp_columns(chunk.rows)

    def slow(rows):
        return certify_rows(cols, rows, [lines[i] for i in rows], options, tol)

    return certify_table(cols, lines, options, tol, slow=slow)


def _verify_one(cols: GraspColumns, i: int, line: int, row: Any, tol: Tolerances) -> tuple[str, tuple | None]:
    """Re-check the results ``row`` of grasp ``i``: ``(status, failure or None)``."""
    if not isinstance(row, dict):
        return "error", (None, f"results row for line {line}: not a JSON object")
    status = str(row.get("status"))
    gid = cols.id_of(i)
    if row.get("line") not in (None, line):
        return status, (row.get("id"), f"results row is for line {row.get('line')}, grasp is line {line}")
    if row.get("id") != gid and str(row.get("id")) != str(gid):
        return status, (row.get("id"), f"id does not match grasp line {line} ({gid!r})")
    message = cols.message(i)
    if status == "error":
        if message is None:
            return status, (gid, "row says error but the grasp is valid")
        return status, None
    if message is not None:
        return status, (gid, f"grasp is invalid: {message}")
    check = verify_row(cols.grasps([i])[0], row, tol)
    return status, None if check else (gid, check.reason)


def verify_rows(cols: GraspColumns, rows: Sequence[int], lines: Sequence[int], results: Sequence[Any],
                tol: Tolerances = Tolerances()) -> tuple[dict[str, int], list]:
    """Re-check results rows (dicts) against rows of checked grasp columns, one by one: status
    counts and ``(id, reason)`` of each failure."""
    statuses: dict[str, int] = {}
    failures = []
    for i, line, row in zip(rows, lines, results):
        status, failure = _verify_one(cols, i, line, row, tol)
        statuses[status] = statuses.get(status, 0) + 1
        if failure:
            failures.append(failure)
    return statuses, failures


def verify_chunk(chunk: Chunk, results, tol: Tolerances = Tolerances()) -> tuple[dict[str, int], list]:
    """Re-check a chunk's results (a list of parsed rows, or an Arrow table aligned with an
    Arrow chunk): status counts and failures. Arrow pairs are proved in bulk where the rigorous
    float kernels can; only the other rows are turned into Python values."""
    if isinstance(chunk.rows, pa.Table) and isinstance(results, pa.Table) and results.num_rows == len(chunk):
        cols = grasp_columns(chunk.rows)
        failures: list = []

        def slow(i: int) -> bool:
            row = table_to_rows(results.slice(i, 1))[0]
            _, failure = _verify_one(cols, i, chunk.lines[i], row, tol)
            if failure:
                failures.append(failure)
            return failure is None

        recheck_table(cols, results, chunk.lines, slow, tol)
        return status_counts(results.column("status"))[0], failures
    if isinstance(results, pa.Table):
        results = table_to_rows(results)
    cols = grasp_columns(chunk.rows) if isinstance(chunk.rows, pa.Table) else value_columns(chunk_values(chunk))
    return verify_rows(cols, range(len(chunk)), chunk.lines, results, tol)


def status_counts(statuses, verified=None) -> tuple[dict[str, int], int]:
    """Rows per status, and rows (not errors) whose certificates were not verified, of Arrow
    columns or lists (``verified`` None: 0 unverified)."""
    status = pa.array(statuses, pa.string()) if isinstance(statuses, list) else statuses
    counts = {d["values"]: d["counts"] for d in pc.value_counts(status).to_pylist()}
    if verified is None:
        return counts, 0
    ok = pa.array(verified, pa.bool_()) if isinstance(verified, list) else verified
    bad = pc.and_(pc.not_equal(status, "error"), pc.invert(pc.fill_null(ok, False)))
    return counts, int(pc.sum(bad).as_py() or 0)

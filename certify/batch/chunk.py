"""One chunk of a grasp set, certified or re-checked, whichever its format.

A chunk (:class:`qualgrasp.certify.files.reader.Chunk`) holds JSON Lines text or an Arrow table. Either
is read into checked columns (:mod:`qualgrasp.certify.files.columns`: one validation, the same rules and
messages for both). Either goes through the columnar path
(:func:`qualgrasp.certify.batch.fastpath.certify_table`; :func:`certify_parsed` for parsed JSON values
and a source's grasps); every row it does not settle goes through the per-grasp path
(:func:`certify_rows`, which :func:`certify_values` applies to every row). A bad row becomes an
``error`` row naming its line, the field and the problem: a chunk always gives exactly one
results row per input row, in order. A grasp's extra top-level fields are carried through
(:func:`qualgrasp.certify.files.results.carried_name`).

Re-checking (:func:`verify_chunk`) mirrors it: Arrow chunks with the results schema are proved
in bulk by the rigorous floating-point kernels (:func:`qualgrasp.certify.batch._recheck.recheck_table`),
every other row (and every row the bulk proof leaves open) by
:func:`qualgrasp.certify.report.verify_row` with exact rational arithmetic, which checks every
column the row states. A malformed row is a failure with a message naming the column, never an
exception. No solver is used.
"""

from __future__ import annotations

import json
import math
from collections import Counter
from dataclasses import dataclass, field, replace
from typing import Any, Sequence

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc

from ..core.certificates import Tolerances
from ..files.columns import GraspColumns, extra_columns, grasp_columns, value_columns
from ..errors import CertifyError, GraspFileError
from .fastpath import certify_table
from ._recheck import recheck_table, schema_matches
from ..report import certify_grasp, verify_row
from ..warmup import compile_ahead
from ..files.results import NAMES, carried_clash, carried_name, error_row
from ..solvers import METHODS, Method, make_solver
from ..core.arguments import choice, count_in, number_in, require
from ..core.validation import show_repr
from ..files.reader import Chunk, chunk_values, column_problem, table_to_rows

__all__ = ["Options", "RowFailure", "Quality", "certify_rows", "certify_values", "certify_parsed", "certify_chunk_results", "certify_arrow",
           "verify_rows", "verify_chunk", "status_counts", "STATUSES"]


@dataclass(frozen=True)
class Options:
    """What is computed for every grasp (recorded in a run's manifest; part of a chunk's
    identity): the solver ``method``, whether to compute epsilon (``quality``), the spatial
    epsilon's relative gap and budget, and the per-grasp time limit of quality in seconds
    (``eps_time``, None for none; see :func:`qualgrasp.certify.certify_grasp`).

    ``source``, when given, turns each chunk of the input into grasps first: a frozen dataclass
    (recorded in the manifest) whose ``grasp_values(chunk)`` gives, for each row in order, a grasp
    in the JSON schema or a :class:`RowFailure`, and whose ``inputs()`` names the files it reads
    (which the output must not be), such as
    :class:`qualgrasp.certify.meshes.source.PoseSource` (poses closed on a mesh)."""

    method: Method = "fast"
    quality: bool = True
    eps_gap: float = 0.01
    eps_budget: int = 200_000
    eps_time: float | None = 10.0
    source: Any = None

    def __post_init__(self) -> None:
        choice(self.method, "method", METHODS)
        number_in(self.eps_gap, "eps_gap", 0, 1, high_open=True)
        count_in(self.eps_budget, "eps_budget", 1, what="direction")
        if self.eps_time is not None:
            number_in(self.eps_time, "eps_time", 0, math.inf, unit="seconds")
        if self.source is not None and not all(callable(getattr(self.source, m, None))
                                               for m in ("grasp_values", "inputs")):
            raise TypeError("source must have grasp_values(chunk) and inputs() methods, got "
                            f"{type(self.source).__name__}")


@dataclass(frozen=True)
class RowFailure:
    """An input row its run's source could not turn into a grasp: the ``message`` (the results
    row's ``error``, after the line), the row's ``id`` and ``fields`` carried to its results row."""

    message: str
    id: Any = None
    fields: dict = field(default_factory=dict)

    def __str__(self) -> str:
        return self.message


def certify_rows(cols: GraspColumns, rows: Sequence[int], lines: Sequence[int],
                 options: Options = Options(), tol: Tolerances = Tolerances()) -> list[dict]:
    """Results rows of ``rows`` of checked columns, grasp by grasp (``lines[k]`` is the line of
    ``rows[k]``); invalid rows become error rows."""
    solver = make_solver(options.method)
    if options.quality:  # on a cold compile cache, quality's kernels compile on another core meanwhile
        compile_ahead(cols.dim[[i for i in rows if cols.ok[i]]])
    out = []
    for i, line in zip(rows, lines):
        gid = cols.id_of(i)
        carried, message = _carried(cols.meta[i] if cols.meta else None)
        message = cols.message(i) or message
        if message is None:
            try:
                grasp = cols.grasps([i])[0]
                report = certify_grasp(grasp, solver=solver, tol=tol, quality=options.quality,
                                       eps_gap=options.eps_gap, eps_budget=options.eps_budget,
                                       eps_time=options.eps_time)
                out.append({**report.row(line=line), **carried})
                continue
            except CertifyError as err:
                message = str(err)
        out.append({**error_row(f"line {line}: {message}", id=gid, line=line), **carried})
    return out


def _carried(meta: dict | None) -> tuple[dict, str | None]:
    """A grasp's extra top-level fields under their results names, and the problem of one that
    cannot be written back as JSON (NaN, nested too deeply), if any."""
    if not meta:
        return {}, None
    clash = carried_clash(list(meta))
    if clash:
        return {}, f"cannot carry the extra fields to the results: {clash}"
    out = {}
    for key, value in meta.items():
        try:
            json.dumps(value, allow_nan=False)
        except (ValueError, TypeError, RecursionError) as err:
            reason = "nested too deeply" if isinstance(err, RecursionError) else str(err)
            return {}, f"{key}: cannot be carried to the results ({reason})"
        out[carried_name(key)] = value
    return out, None


def certify_values(values: Sequence[Any], lines: Sequence[int], options: Options = Options(),
                   tol: Tolerances = Tolerances()) -> list[dict]:
    """One results row per parsed grasp value (a dict in the grasp schema, or the error met
    while reading it), in order."""
    cols = value_columns(values)
    return certify_rows(cols, range(len(values)), lines, options, tol)


FEW = 64
"""Fewer grasps than this in a chunk (parsed from JSON Lines or a source, or an Arrow chunk) are
certified grasp by grasp (the same rows): the first run after an install then compiles fewer
kernels for a handful of grasps."""


def certify_parsed(values: Sequence[Any], lines: Sequence[int], options: Options = Options(),
                   tol: Tolerances = Tolerances()) -> list[dict]:
    """The rows :func:`certify_values` gives, by the columnar path where its rules settle a row
    (:func:`qualgrasp.certify.batch.fastpath.certify_table`: row for row the per-grasp results)
    and grasp by grasp for the others, fields carried from the input included. Fewer than
    :data:`FEW` values go grasp by grasp (the same rows): the first run after an install then
    compiles fewer kernels for a handful of grasps."""
    if len(values) < FEW:
        return certify_values(values, lines, options, tol)
    cols = value_columns(values)
    carried = [_carried(cols.meta[i] if cols.meta else None) for i in range(len(values))]
    refused = np.array([message is not None for _, message in carried], dtype=bool)
    if refused.any():  # the per-grasp path states why their fields cannot be carried
        cols = replace(cols, ok=cols.ok & ~refused)

    def slow(rows):  # the results columns only: the carried fields join every row below
        out = certify_rows(cols, rows, [lines[i] for i in rows], options, tol)
        return [{k: v for k, v in row.items() if k in NAMES} for row in out]

    rows = table_to_rows(certify_table(pa.table({}), lines, options, tol, slow=slow, columns=cols))
    for i, (row, (fields, message)) in enumerate(zip(rows, carried)):
        row["id"] = cols.id_of(i)  # as read: an Arrow table holds ids as strings
        if message is None:
            row.update(fields)
    return rows


def certify_chunk_results(chunk: Chunk, options: Options, tol: Tolerances = Tolerances()):
    """Results of ``chunk``: an Arrow table for an Arrow chunk, a list of rows for JSON Lines or
    for a run with a source; the columnar path settles what it can in every case."""
    if options.source is not None:
        return _certify_sourced(options.source.grasp_values(chunk), chunk.lines, options, tol)
    if not isinstance(chunk.rows, pa.Table):
        return certify_parsed(chunk_values(chunk), chunk.lines, options, tol)
    return _certify_arrow_rows(chunk.rows, chunk.lines, options, tol)


def _certify_sourced(values: Sequence[Any], lines: Sequence[int], options: Options, tol: Tolerances) -> list[dict]:
    """Results rows of a source's values: the grasps certified, each :class:`RowFailure` an error
    row with its fields, in order."""
    grasps = [k for k, v in enumerate(values) if not isinstance(v, RowFailure)]
    rows: list[dict | None] = [None] * len(values)
    certified = certify_parsed([values[k] for k in grasps], [lines[k] for k in grasps], options, tol)
    for k, row in zip(grasps, certified):
        rows[k] = row
    for k, v in enumerate(values):
        if isinstance(v, RowFailure):
            carried = {carried_name(key): value for key, value in v.fields.items()}
            rows[k] = {**error_row(f"line {lines[k]}: {v}", id=v.id, line=lines[k]), **carried}
    return rows


def _certify_arrow_rows(table: pa.Table, lines, options: Options, tol: Tolerances) -> pa.Table:
    cols = grasp_columns(table)

    def slow(rows):
        return certify_rows(cols, rows, [lines[i] for i in rows], options, tol)

    return certify_table(table, lines, options, tol, slow=slow, columns=cols, columnar=table.num_rows >= FEW)


def certify_arrow(data: Any, options: Options = Options(), tol: Tolerances = Tolerances()) -> pa.Table:
    """Certify grasps held in memory as Arrow data: a :class:`pyarrow.Table` or record batch, or
    any object with the Arrow PyCapsule stream interface (``__arrow_c_stream__``: pandas and
    polars data frames, DuckDB results, ...).

    Any layout :func:`qualgrasp.certify.files.columns.grasp_columns` reads is accepted (list, large or
    fixed-size lists of any float or integer width, dictionary or large strings, optional
    fields absent); extra columns are carried through.

    Parameters
    ----------
    data : pyarrow.Table, pyarrow.RecordBatch or an Arrow stream object
        One grasp per row: ``contacts`` (list of structs ``p``, ``n``, ``model``, ``mu``, ...),
        optional ``id``, ``center``, ``length``.
    options : Options
        What is computed (method, quality).
    tol : Tolerances

    Returns
    -------
    pyarrow.Table
        The results (:data:`qualgrasp.certify.files.results.RESULT_SCHEMA`, then the carried columns),
        one row per input row; ``line`` is the row number (1-based).

    Raises
    ------
    GraspFileError
        ``data`` is not Arrow tabular data.
    TypeError
        ``options`` is not an :class:`Options` or ``tol`` not a
        :class:`~qualgrasp.certify.Tolerances`.

    Examples
    --------
    >>> import pyarrow as pa
    >>> from qualgrasp.certify.batch.chunk import Options, certify_arrow
    >>> t = pa.table({"id": ["g1"], "contacts": [[
    ...     {"p": [1.0, 0.0], "n": [-1.0, 0.0], "mu": 0.5}, {"p": [-1.0, 0.0], "n": [1.0, 0.0], "mu": 0.5}]],
    ...     "note": ["mine"]})
    >>> r = certify_arrow(t, Options(quality=False))
    >>> r.column("status").to_pylist(), r.column("note").to_pylist()
    (['closure'], ['mine'])
    """
    require(options, Options, "options")
    require(tol, Tolerances, "tol")
    if isinstance(data, pa.RecordBatch):
        data = pa.Table.from_batches([data])
    if not isinstance(data, pa.Table):
        try:
            data = pa.table(data)
        except (TypeError, ValueError, pa.ArrowException) as err:
            raise GraspFileError(f"cannot read the data as an Arrow table: {err}") from None
    problem = column_problem(data.column_names) or carried_clash(extra_columns(data))
    if problem:
        raise GraspFileError(f"cannot certify the data: {problem}")
    return _certify_arrow_rows(data, range(1, data.num_rows + 1), options, tol)


STATUSES = ("closure", "no_closure", "degenerate", "error")
"""The statuses of a results row."""


def _status_of(row: Any) -> str:
    """The status a row states, for the counts (``malformed`` when it is not one of them)."""
    status = row.get("status") if isinstance(row, dict) else None
    return status if isinstance(status, str) and status in STATUSES else "malformed"


def _id_text(gid: Any) -> Any:
    """The id as a Parquet results file stores it (a string; see
    :func:`qualgrasp.certify.files.reader.rows_to_table`)."""
    if gid is None or isinstance(gid, str):
        return gid
    return str(gid) if isinstance(gid, (int, float)) and not isinstance(gid, bool) else json.dumps(gid)


def _same_id(stated: Any, gid: Any) -> bool:
    if stated == gid and type(stated) is type(gid):
        return True
    return isinstance(stated, str) and stated == _id_text(gid)


def _verify_one(cols: GraspColumns, i: int, line: int, row: Any, tol: Tolerances) -> tuple[str, tuple | None]:
    """Re-check the results ``row`` of grasp ``i``: ``(status, failure or None)``, the failure
    ``(the row's own id, reason naming its line)``; never raises on a malformed row."""
    status = _status_of(row)
    own = row.get("id") if isinstance(row, dict) else None
    try:
        failure = _failure(cols, i, line, row, tol, cols.id_of(i))
    except RecursionError:
        failure = (None, "malformed row (too deeply nested)")
    except Exception as err:  # a last resort: a malformed row is a failure, never a traceback
        failure = (None, f"malformed row ({type(err).__name__})")
    if failure is None:
        return status, None
    reason = failure[1]
    return status, (own, reason if reason.startswith(f"line {line}") else f"line {line}: {reason}")


def _failure(cols: GraspColumns, i: int, line: int, row: Any, tol: Tolerances, gid: Any):
    if not isinstance(row, dict):
        return None, f"results row for line {line}: not a JSON object"
    missing = [name for name in NAMES if name not in row]
    if missing:
        return gid, f"column{'s' if len(missing) > 1 else ''} {', '.join(missing)} missing"
    stated_line = row["line"]
    if isinstance(stated_line, bool) or not isinstance(stated_line, int) or stated_line != line:
        return gid, f"line {show_repr(stated_line)} does not match the grasp's line {line}"
    if not _same_id(row["id"], gid):
        return gid, f"id {show_repr(row['id'])} does not match the grasp's id {show_repr(gid)} (line {line})"
    # a grasp whose extra fields cannot be carried is an error row, as certify_rows writes it
    message = cols.message(i) or _carried(cols.meta[i] if cols.meta else None)[1]
    if row["status"] == "error":
        if message is None:
            return gid, "status says error but the grasp is valid"
        expected = error_row(f"line {line}: {message}", id=row["id"], line=line)
        for name in NAMES:
            if row[name] != expected[name] or type(row[name]) is not type(expected[name]):
                return gid, f"{name} of an error row must be {show_repr(expected[name])}, got {show_repr(row[name])}"
        return None
    if message is not None:
        return gid, f"status {show_repr(row['status'])} but the grasp is invalid (the row must be an error row): {message}"
    check = verify_row(cols.grasps([i])[0], row, tol)
    return None if check else (gid, check.reason)


@dataclass
class Quality:
    """Which rows (not errors) of a re-checked file state epsilon and which do not: a run
    computes quality for every row or for none, so a file mixing both has been altered. Counts
    and the first ids of each kind."""

    with_eps: int = 0
    without_eps: int = 0
    ids_with: list = field(default_factory=list)
    ids_without: list = field(default_factory=list)

    def add(self, gid: Any, has_eps: bool) -> None:
        if has_eps:
            self.with_eps += 1
            if len(self.ids_with) < 100:
                self.ids_with.append(gid)
        else:
            self.without_eps += 1
            if len(self.ids_without) < 100:
                self.ids_without.append(gid)

    def add_many(self, count: int, first_ids: list, has_eps: bool) -> None:
        """Note ``count`` rows of one kind, of which ``first_ids`` are the first ids."""
        if has_eps:
            self.with_eps += count
            self.ids_with += first_ids[: max(0, 100 - len(self.ids_with))]
        else:
            self.without_eps += count
            self.ids_without += first_ids[: max(0, 100 - len(self.ids_without))]

    def merge(self, other: "Quality") -> None:
        self.with_eps += other.with_eps
        self.without_eps += other.without_eps
        self.ids_with += other.ids_with[: max(0, 100 - len(self.ids_with))]
        self.ids_without += other.ids_without[: max(0, 100 - len(self.ids_without))]

    def failures(self) -> list:
        """Failures for the rarer kind when both occur."""
        if not (self.with_eps and self.without_eps):
            return []
        if self.without_eps <= self.with_eps:
            return [(gid, "epsilon columns null although the other rows state epsilon (quality was on)")
                    for gid in self.ids_without]
        return [(gid, "epsilon columns stated although the other rows have none (quality was off)")
                for gid in self.ids_with]


def _note_quality(quality: Quality, row: Any, gid: Any) -> None:
    if isinstance(row, dict) and row.get("status") in ("closure", "no_closure", "degenerate"):
        quality.add(gid, row.get("eps_l1_hi") is not None)


def verify_rows(cols: GraspColumns, rows: Sequence[int], lines: Sequence[int], results: Sequence[Any],
                tol: Tolerances = Tolerances(), quality: Quality | None = None) -> tuple[dict[str, int], list]:
    """Re-check results rows (dicts) against rows of checked grasp columns, one by one: status
    counts and ``(id, reason)`` of each failure (``quality``, if given, notes which rows state
    epsilon)."""
    statuses: dict[str, int] = {}
    failures = []
    for i, line, row in zip(rows, lines, results):
        status, failure = _verify_one(cols, i, line, row, tol)
        statuses[status] = statuses.get(status, 0) + 1
        if failure:
            failures.append(failure)
        if quality is not None:
            _note_quality(quality, row, row.get("id") if isinstance(row, dict) else None)
    return statuses, failures


def verify_chunk(chunk: Chunk, results, tol: Tolerances = Tolerances()) -> tuple[dict[str, int], list, Quality]:
    """Re-check a chunk's results (a list of parsed rows, or an Arrow table aligned with an
    Arrow chunk): status counts, failures and which rows state epsilon (:class:`Quality`).
    Arrow pairs with the results schema are proved in bulk where the rigorous float kernels
    can; only the other rows are turned into Python values."""
    quality = Quality()
    if (isinstance(chunk.rows, pa.Table) and isinstance(results, pa.Table) and results.num_rows == len(chunk)
            and schema_matches(results.schema)):
        cols = grasp_columns(chunk.rows)
        failures: list = []

        def slow(i: int) -> bool:
            row = table_to_rows(results.slice(i, 1))[0]
            _, failure = _verify_one(cols, i, chunk.lines[i], row, tol)
            if failure:
                failures.append(failure)
            return failure is None

        recheck_table(cols, results, chunk.lines, slow, tol)
        status = pc.is_in(results.column("status"), pa.array(["closure", "no_closure", "degenerate"]))
        rows = np.asarray(status.fill_null(False).to_numpy(zero_copy_only=False), dtype=bool)
        has_eps = np.asarray(results.column("eps_l1_hi").is_valid().to_numpy(zero_copy_only=False), dtype=bool)
        for mask, flag in ((rows & has_eps, True), (rows & ~has_eps, False)):
            idx = np.flatnonzero(mask)
            quality.add_many(len(idx), results.column("id").take(pa.array(idx[:100])).to_pylist(), flag)
        return status_counts(results.column("status"))[0], failures, quality
    if isinstance(results, pa.Table):
        results = table_to_rows(results)
    cols = grasp_columns(chunk.rows) if isinstance(chunk.rows, pa.Table) else value_columns(chunk_values(chunk))
    statuses, failures = verify_rows(cols, range(len(chunk)), chunk.lines, results, tol, quality)
    return statuses, failures, quality


def status_counts(statuses, verified=None) -> tuple[dict[str, int], int]:
    """Rows per status, and rows (not errors) whose certificates were not verified, of Arrow
    columns or lists (``verified`` None: 0 unverified)."""
    if isinstance(statuses, list):  # counted here: pyarrow imports pandas for its first array from a list
        bad = 0 if verified is None else sum(s != "error" and not v for s, v in zip(statuses, verified))
        return dict(Counter(statuses)), bad
    counts = {d["values"]: d["counts"] for d in pc.value_counts(statuses).to_pylist()}
    if verified is None:
        return counts, 0
    bad = pc.and_(pc.not_equal(statuses, "error"), pc.invert(pc.fill_null(verified, False)))
    return counts, int(pc.sum(bad).as_py() or 0)

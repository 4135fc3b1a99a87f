"""The results schema: one list of columns, from which everything else is derived.

A results file has one row per input grasp, in input order. :data:`COLUMNS` states each column
once (name, Arrow type, meaning, value in an error row); the Arrow schema of Parquet results
(:data:`RESULT_SCHEMA`), the per-grasp row (:func:`result_row`, used by
:meth:`qualgrasp.certify.Report.row`), the error row (:func:`error_row`) and the columnar builder
(:func:`result_table`, used by :mod:`qualgrasp.certify.batch.fastpath`) are all derived from it, so they
cannot drift apart.

An input's extra top-level fields (columns of a Parquet or Arrow grasp table other than ``id``,
``contacts``, ``center``, ``length``; other keys of a JSON Lines grasp) are carried through
unchanged after these columns, under :func:`carried_name` (JSON Lines input gives them to JSON
Lines results only: a Parquet results file has one schema). Fields that would share a results name
(``status`` and ``input_status``) are refused by name (:func:`carried_clash`), never dropped.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Mapping, Sequence

import pyarrow as pa

__all__ = ["Column", "CERTIFICATE", "EVIDENCE", "COLUMNS", "NAMES", "RESULT_SCHEMA", "RESULT_WRITE_OPTIONS",
           "carried_name", "carried_clash", "result_row", "error_row", "result_table"]

CERTIFICATE = pa.struct([
    ("kind", pa.string()), ("layout", pa.string()), ("values", pa.list_(pa.float64())),
    ("basis", pa.list_(pa.int32())), ("y", pa.list_(pa.float64())), ("tight", pa.list_(pa.int32())),
    ("null_space", pa.bool_()), ("reason", pa.string()),
])
"""A certificate (:class:`qualgrasp.certify.Certificate`) as an Arrow struct."""

EVIDENCE = pa.struct([
    ("kind", pa.string()), ("direction", pa.list_(pa.float64())), ("ref", pa.list_(pa.int32())),
    ("points", pa.list_(pa.float64())), ("faces", pa.list_(pa.int32())),
])
"""Evidence of one norm's epsilon bounds (:class:`qualgrasp.certify.quality.evidence.Evidence`) as an
Arrow struct."""


@dataclass(frozen=True)
class Column:
    """A results column: its ``name``, Arrow ``type``, meaning, and value in an error row."""

    name: str
    type: pa.DataType
    description: str
    error: Any = None


COLUMNS: tuple[Column, ...] = (
    Column("id", pa.string(), "the grasp's id (null when it could not be read)"),
    Column("line", pa.int64(), "the grasp's line in a JSON Lines file (1-based, blank lines "
                               "counted) or its row in a Parquet file (1-based)"),
    Column("dim", pa.int8(), "2 (planar) or 3 (spatial)"),
    Column("status", pa.string(), "force closure under the declared contact models: closure, "
                                  "no_closure, degenerate; error when the grasp is invalid", "error"),
    Column("form_closure", pa.bool_(), "form closure (every contact frictionless): true, false, "
                                       "or null when degenerate"),
    Column("force_closure", pa.bool_(), "force closure: true, false, or null when degenerate"),
    Column("margin", pa.float64(), "min-weight margin t* of force closure, 0 when not in closure"),
    Column("form_status", pa.string(), "status of form closure", "error"),
    Column("form_margin", pa.float64(), "min-weight margin of form closure"),
    Column("certificate", pa.struct([("force", CERTIFICATE), ("form", CERTIFICATE)]),
           "the two certificates ({force, form}), re-checkable without a solver"),
    Column("verified", pa.bool_(), "both certificates re-checked", False),
    Column("error", pa.string(), "null, or a message naming the line, the field and the problem"),
    Column("center", pa.list_(pa.float64()), "reference point of torques used"),
    Column("length", pa.float64(), "length dividing torques used"),
    Column("n_contacts", pa.int32(), "number of contacts"),
    Column("eps_l1_lo", pa.float64(), "lower bound of the L1 Ferrari-Canny epsilon (0 when not "
                                      "in force closure; null without quality)"),
    Column("eps_l1_hi", pa.float64(), "upper bound of the L1 epsilon (equal to lo in the plane)"),
    Column("eps_linf_lo", pa.float64(), "lower bound of the L-infinity epsilon"),
    Column("eps_linf_hi", pa.float64(), "upper bound of the L-infinity epsilon"),
    Column("eps_limited", pa.bool_(), "the per-grasp time limit of quality stopped the epsilon "
                                      "computation (the bounds are those reached); null without quality"),
    Column("eps_evidence", pa.struct([("l1", EVIDENCE), ("linf", EVIDENCE)]),
           "evidence of the epsilon bounds ({l1, linf}), re-checkable without a solver; null "
           "without quality or when not in force closure"),
)

NAMES = tuple(c.name for c in COLUMNS)
RESULT_SCHEMA = pa.schema([(c.name, c.type) for c in COLUMNS])

# Dictionary-encode only the columns of names and of small indices: dictionary pages of float
# columns cost more than half the time of writing results, and make the file larger; the indices
# of the epsilon evidence (faces, sums' generator choices) take a few bits each in a dictionary,
# which made a million planar rows with quality 36 % smaller (269 -> 172 MB) and 45 % faster to
# read, for the same time to write.
RESULT_WRITE_OPTIONS = {"use_dictionary": [
    "status", "form_status", "certificate.force.kind", "certificate.force.layout",
    "certificate.form.kind", "certificate.form.layout", "eps_evidence.l1.kind",
    "eps_evidence.linf.kind"]
    + [f"certificate.{c}.{name}.list.element" for c in ("force", "form") for name in ("basis", "tight")]
    + [f"eps_evidence.{norm}.{name}.list.element" for norm in ("l1", "linf") for name in ("ref", "faces")]}


def carried_name(name: str) -> str:
    """The results column of an input's extra top-level field ``name``: the same name, or
    ``input_<name>`` when that is a results column (repeated until free)."""
    while name in NAMES:
        name = f"input_{name}"
    return name


def carried_clash(names: Sequence[str]) -> str | None:
    """Why extra fields ``names`` cannot all be carried (two of them would have the same results
    name under :func:`carried_name`, as ``status`` and ``input_status`` do), or None.

    Examples
    --------
    >>> carried_clash(["note", "status"]) is None
    True
    >>> carried_clash(["status", "input_status"])
    'status and input_status would both be carried as input_status: rename one'
    """
    seen: dict[str, str] = {}
    for name in names:
        carried = carried_name(name)
        if carried in seen:
            return f"{seen[carried]} and {name} would both be carried as {carried}: rename one"
        seen[carried] = name
    return None


def result_row(**values: Any) -> dict[str, Any]:
    """A results row (a dict in column order) from one value per column; every column must be
    given, and nothing else."""
    missing = [n for n in NAMES if n not in values]
    extra = [n for n in values if n not in NAMES]
    if missing or extra:
        raise ValueError(f"results row: missing {missing}, unknown {extra}")
    return {n: values[n] for n in NAMES}


def error_row(message: str, *, id: Any = None, line: int | None = None) -> dict[str, Any]:
    """Results row for an input that could not be certified: each column's error value."""
    row = {c.name: c.error for c in COLUMNS}
    row.update(id=id, line=line, error=message)
    return row


def result_table(columns: Mapping[str, Any], n: int) -> pa.Table:
    """Results table of ``n`` rows from Arrow arrays by column name; columns not given are null."""
    extra = [name for name in columns if name not in NAMES]
    if extra:
        raise ValueError(f"results table: unknown columns {extra}")
    arrays = [columns[c.name] if columns.get(c.name) is not None else pa.nulls(n, c.type) for c in COLUMNS]
    return pa.Table.from_arrays(arrays, schema=RESULT_SCHEMA)

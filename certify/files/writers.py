"""Writing grasp sets and results, JSON Lines or Parquet by file extension (read by
:mod:`qualgrasp.certify.files.reader`).

Grasp line: ``{"id": "g1", "contacts": [{"p": [x, y], "n": [nx, ny], "model": "point", "mu": 0.5}],
"center": [cx, cy], "length": 1.0}`` (see :func:`qualgrasp.certify.core.grasp.grasp_from_dict`); Parquet holds
the same fields (:data:`qualgrasp.certify.files.reader.GRASP_SCHEMA`). In JSON Lines, blank lines are skipped and
line numbers count from 1 and include them; in Parquet the line number is the row number.
Files are written by the rules of :mod:`qualgrasp.certify.files.outputs` (nothing lost).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Iterable

import pyarrow.parquet as pq

from ..core.grasp import Grasp, grasp_to_dict
from .outputs import atomic_output, write_lines
from .results import RESULT_WRITE_OPTIONS
from .reader import grasps_table, is_parquet, rows_to_table

__all__ = ["write_grasps", "write_rows"]


def write_grasps(path: str | Path, grasps: Iterable[Grasp], *, reads: Iterable[str | Path] = (),
                 flag: str = "-o") -> int:
    """Write grasps in the grasp-set schema (Parquet for a ``.parquet`` / ``.pq`` name, else JSON
    Lines) through :func:`qualgrasp.certify.files.outputs.atomic_output` (never one of ``reads``, a
    FIFO or a device; one writer at a time; the old file kept whole if the write fails); return
    how many were written.

    Raises
    ------
    OptionError
        The output is refused or cannot be written (message naming ``flag``).
    """
    return _write(path, [grasp_to_dict(g) for g in grasps], grasps_table, reads=reads, flag=flag)


def write_rows(path: str | Path, rows: Iterable[dict[str, Any]], *, reads: Iterable[str | Path] = (),
               flag: str = "-o") -> int:
    """Write results rows as :func:`write_grasps` writes grasps; return how many were written."""
    return _write(path, list(rows), rows_to_table, RESULT_WRITE_OPTIONS, reads=reads, flag=flag)


def _write(path: str | Path, rows: list[dict], to_table, options: dict | None = None, *,
           reads: Iterable[str | Path] = (), flag: str = "-o") -> int:
    if not is_parquet(path):
        return write_lines(path, rows, flag, reads=reads)
    table = to_table(rows)
    with atomic_output(path, flag, reads=reads) as tmp:
        pq.write_table(table, tmp, **(options or {}))
    return len(rows)

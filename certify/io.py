"""Reading and writing grasp sets and results, JSON Lines or Parquet by file extension.

Grasp line: ``{"id": "g1", "contacts": [{"p": [x, y], "n": [nx, ny], "model": "point", "mu": 0.5}],
"center": [cx, cy], "length": 1.0}`` (see :func:`qualgrasp.certify.grasp.grasp_from_dict`); Parquet holds
the same fields (:data:`qualgrasp.certify.table.GRASP_SCHEMA`). In JSON Lines, blank lines are skipped and
line numbers count from 1 and include them; in Parquet the line number is the row number.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Iterable, Iterator

import pyarrow.parquet as pq

from .grasp import Grasp, grasp_to_dict
from .results import RESULT_WRITE_OPTIONS
from .table import grasps_table, is_parquet, iter_chunks, rows_to_table, table_to_rows

__all__ = ["write_grasps", "read_results", "write_rows"]


def write_grasps(path: str | Path, grasps: Iterable[Grasp]) -> int:
    """Write grasps in the grasp-set schema; return how many were written."""
    return _write(path, [grasp_to_dict(g) for g in grasps], grasps_table)


def read_results(path: str | Path, chunk_size: int = 4096) -> Iterator[dict]:
    """Yield the rows of a results file as dictionaries."""
    for chunk in iter_chunks(path, chunk_size):
        if isinstance(chunk.rows, list):
            yield from (json.loads(text) for _, text in chunk.rows)
        else:
            yield from table_to_rows(chunk.rows)


def write_rows(path: str | Path, rows: Iterable[dict[str, Any]]) -> int:
    """Write results rows; return how many were written."""
    return _write(path, list(rows), rows_to_table, RESULT_WRITE_OPTIONS)


def _write(path: str | Path, rows: list[dict], to_table, options: dict | None = None) -> int:
    if is_parquet(path):
        pq.write_table(to_table(rows), path, **(options or {}))
    else:
        with Path(path).open("w", encoding="utf-8") as fh:
            for row in rows:
                fh.write(json.dumps(row, allow_nan=False) + "\n")
    return len(rows)

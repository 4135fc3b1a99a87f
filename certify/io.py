"""Grasp-set and results files in JSON Lines: one JSON object per line.

Grasp line: ``{"id": "g1", "contacts": [{"p": [x, y], "n": [nx, ny], "model": "point", "mu": 0.5}],
"center": [cx, cy], "length": 1.0}`` (see :func:`certify.grasp.grasp_from_dict`). Blank lines are
skipped; line numbers count from 1 and include them.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Iterable, Iterator

from .errors import CertifyError, GraspFileError
from .grasp import Grasp, grasp_from_dict

__all__ = ["read_grasps", "read_rows", "write_rows", "write_grasps"]


def read_rows(path: str | Path) -> Iterator[tuple[int, Any | GraspFileError]]:
    """Yield ``(line number, parsed JSON value or GraspFileError)`` for each non-blank line."""
    path = Path(path)
    try:
        fh = path.open("r", encoding="utf-8")
    except OSError as err:
        raise GraspFileError(f"cannot read {path}: {err.strerror}") from None
    with fh:
        for number, text in enumerate(fh, start=1):
            if not text.strip():
                continue
            try:
                yield number, json.loads(text)
            except json.JSONDecodeError as err:
                yield number, GraspFileError(f"line {number}: malformed JSON ({err.msg} at column {err.colno})")


def read_grasps(path: str | Path) -> Iterator[tuple[int, Any, Grasp | CertifyError]]:
    """Yield ``(line number, id or None, Grasp or the error that line raised)``."""
    for number, value in read_rows(path):
        if isinstance(value, GraspFileError):
            yield number, None, value
            continue
        gid = value.get("id") if isinstance(value, dict) else None
        try:
            yield number, gid, grasp_from_dict(value)
        except CertifyError as err:
            yield number, gid, type(err)(f"line {number}: {err}")


def write_rows(path: str | Path, rows: Iterable[dict[str, Any]]) -> int:
    """Write ``rows`` as JSON Lines; return how many were written."""
    count = 0
    with Path(path).open("w", encoding="utf-8") as fh:
        for row in rows:
            fh.write(json.dumps(row, allow_nan=False) + "\n")
            count += 1
    return count


def write_grasps(path: str | Path, grasps: Iterable[Grasp]) -> int:
    """Write grasps in the grasp-set schema."""
    from .grasp import grasp_to_dict

    return write_rows(path, (grasp_to_dict(g) for g in grasps))

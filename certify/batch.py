"""Certify and re-verify whole grasp-set files."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Iterator

from .certificates import Tolerances
from .errors import CertifyError, GraspFileError
from .io import read_grasps, read_rows, write_rows
from .report import certify_grasp, error_row, verify_row
from .solvers import make_solver

__all__ = ["Summary", "certify_file", "verify_file", "certify_rows"]


@dataclass
class Summary:
    """Counts of a certification or verification run."""

    rows: int = 0
    statuses: dict[str, int] = field(default_factory=dict)
    unverified: int = 0
    failures: list[tuple[object, str]] = field(default_factory=list)

    @property
    def errors(self) -> int:
        return self.statuses.get("error", 0)

    def add(self, status: str) -> None:
        self.rows += 1
        self.statuses[status] = self.statuses.get(status, 0) + 1


def certify_rows(grasps_path: str | Path, *, method: str = "fast",
                 tol: Tolerances = Tolerances(), **quality) -> Iterator[dict]:
    """Yield one results row per grasp line of ``grasps_path`` (errors become ``error`` rows).

    ``quality`` holds the epsilon options of :func:`certify.report.certify_grasp` (``quality``,
    ``eps_gap``, ``eps_budget``)."""
    solver = make_solver(method)
    for number, gid, grasp in read_grasps(grasps_path):
        if isinstance(grasp, CertifyError):
            yield error_row(str(grasp), id=gid, line=number)
            continue
        try:
            yield certify_grasp(grasp, solver=solver, tol=tol, **quality).row(line=number)
        except CertifyError as err:
            yield error_row(f"line {number}: {err}", id=gid, line=number)


def certify_file(grasps_path: str | Path, results_path: str | Path, *, method: str = "fast",
                 tol: Tolerances = Tolerances(),
                 progress: Callable[[dict], None] | None = None, **quality) -> Summary:
    """Certify every grasp of a JSON Lines grasp set and write one results row per grasp
    (``quality``: epsilon options, see :func:`certify_rows`)."""
    summary = Summary()

    def rows():
        for row in certify_rows(grasps_path, method=method, tol=tol, **quality):
            summary.add(row["status"])
            summary.unverified += row["status"] != "error" and not row["verified"]
            if progress:
                progress(row)
            yield row

    write_rows(results_path, rows())
    return summary


def verify_file(results_path: str | Path, grasps_path: str | Path,
                tol: Tolerances = Tolerances()) -> Summary:
    """Re-check every certificate of ``results_path`` against the grasps of ``grasps_path``.

    Rows are matched to grasp lines by line number (falling back to order when a row has none) and
    their ids must agree. Rows with status ``error`` have no certificate and are only counted.
    Every row that fails is listed in ``summary.failures`` as ``(id, reason)``.
    """
    grasps = {number: (gid, g) for number, gid, g in read_grasps(grasps_path)}
    order = sorted(grasps)
    summary = Summary()
    for i, (number, row) in enumerate(read_rows(results_path)):
        if isinstance(row, GraspFileError) or not isinstance(row, dict):
            summary.add("error")
            summary.failures.append((None, f"results line {number}: not a JSON object"))
            continue
        status = str(row.get("status"))
        summary.add(status)
        line = row.get("line") if isinstance(row.get("line"), int) else (order[i] if i < len(order) else None)
        if line not in grasps:
            summary.failures.append((row.get("id"), f"no grasp on line {line} of {grasps_path}"))
            continue
        gid, grasp = grasps[line]
        if row.get("id") != gid:
            summary.failures.append((row.get("id"), f"id does not match grasp line {line} ({gid!r})"))
        elif status == "error":
            if not isinstance(grasp, CertifyError):
                summary.failures.append((gid, "row says error but the grasp is valid"))
        elif isinstance(grasp, CertifyError):
            summary.failures.append((gid, f"grasp is invalid: {grasp}"))
        else:
            check = verify_row(grasp, row, tol)
            if not check:
                summary.failures.append((gid, check.reason))
    return summary

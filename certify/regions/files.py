"""Region-set files: certify every region tuple of a file, and re-check the results.

Region sets (JSON Lines, one tuple per line)::

    {"id": "r1", "regions": [{"a": [x, y], "b": [x, y], "n": [nx, ny], "model": "point", "mu": 0.5},
                             {"points": [[x, y], ...], "normals": [[nx, ny], ...], "model": "frictionless"}],
     "normal_tol": 0.0, "center": [cx, cy], "length": 1.0}

:func:`certify_region_file` writes one results row per tuple line, in order: ``id``, ``line``,
``status`` (``robust``, ``not_robust``, ``undecided``, ``error``), ``route``, ``certificate``,
``witness`` (null, or ``{"grasp": <certify's grasp format>, "certificate": <its Farkas
certificate>}``), ``reason``, ``work``, ``margin``, ``verified`` and ``error`` (null, or a message
naming the line and the field). A bad line becomes an error row and the run goes on.
:func:`verify_region_file` re-checks a results file against its region set.
"""

from __future__ import annotations

import json
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Iterator

from ..errors import CertifyError, GraspError, OptionError
from ..files.outputs import atomic_output
from ._branch import DEFAULT_BUDGET
from .decide import DEFAULT_TOL, certify_regions, verify_regions
from .data import tuple_from_dict
from ..files.reader import input_format, json_lines
from ..core.validation import id_problem, show

__all__ = ["RegionSummary", "certify_region_file", "verify_region_file", "read_region_lines", "error_row"]


def error_row(message: str, *, id: Any = None, line: int | None = None) -> dict[str, Any]:
    """The results row of a region tuple that could not be read or certified."""
    return {"id": id, "line": line, "status": "error", "route": None, "certificate": None, "witness": None,
            "reason": None, "work": 0, "margin": None, "verified": False, "error": message}


def read_region_lines(path: str | Path) -> Iterator[tuple[int, Any]]:
    """``(line number, tuple or (id, message))`` for every non-blank line of a region set, read
    by the toolkit's one line reader (:func:`qualgrasp.certify.files.reader.json_lines`: regular files
    only, the same limits and messages as grasp sets; line numbers count from 1 and include
    blank lines); a line that cannot be read gives its id (where one can be read) and an error
    message naming the line and the field instead of a tuple.

    Raises
    ------
    GraspFileError
        The file as a whole is refused (not a regular file, not JSON Lines), with a one-line
        message.
    """
    for number, value in json_lines(path, "region set"):
        if isinstance(value, Exception):
            yield number, (None, f"line {number}: {value}")
            continue
        gid = value.get("id") if isinstance(value, dict) else None
        problem = id_problem(gid)
        if problem:
            yield number, (None, f"line {number}: {problem}")
            continue
        try:
            yield number, tuple_from_dict(value)
        except GraspError as err:
            yield number, (gid, f"line {number}: {err}")
        except RecursionError:
            yield number, (gid, f"line {number}: nested too deeply")


@dataclass
class RegionSummary:
    """Counts of a region-set run: ``rows``, ``statuses`` (rows per status), ``unverified``
    (rows whose evidence failed its own re-check), ``failures`` (``(id, reason)`` of a
    verification run), ``seconds``; and, of a verification run, ``unpaired``, the rows that
    failed with no tuple to be re-checked against (unreadable, or stating another line than
    their tuple's), ``unpaired_errors`` those of them stating status ``error``."""

    rows: int = 0
    statuses: dict[str, int] = field(default_factory=dict)
    unverified: int = 0
    failures: list[tuple[Any, str]] = field(default_factory=list)
    seconds: float = 0.0
    unpaired: int = 0
    unpaired_errors: int = 0

    @property
    def errors(self) -> int:
        """Error rows."""
        return self.statuses.get("error", 0)


def certify_region_file(in_path: str | Path, out_path: str | Path, *, budget: int = DEFAULT_BUDGET,
                        tol: float = DEFAULT_TOL, progress: Callable[[int], None] | None = None) -> RegionSummary:
    """Certify every region tuple of a region set into a results file (module docstring).

    Parameters
    ----------
    in_path : path
        Region set, JSON Lines.
    out_path : path
        Results file (JSON Lines), written through a temporary file renamed at the end, one run
        at a time (:func:`qualgrasp.certify.files.outputs.atomic_output`); never the input, a FIFO or a
        device.
    budget, tol
        As for :func:`certify_regions`.
    progress : callable, optional
        Called with 1 after each line.

    Returns
    -------
    RegionSummary

    Raises
    ------
    GraspFileError
        The input as a whole cannot be read (:func:`read_region_lines`).
    OptionError
        The output is refused (the input, a FIFO or device, a folder), another run is writing
        it, it cannot be written (full disk, ...), or ``budget`` is below 1.

    Examples
    --------
    >>> import json, pathlib, tempfile
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> lines = [{"id": "r1", "regions": [{"a": [1, -0.3], "b": [1, 0.3], "n": [-1, 0], "mu": 0.5},
    ...                                   {"a": [-1, -0.3], "b": [-1, 0.3], "n": [1, 0], "mu": 0.5}]},
    ...          {"id": "bad", "regions": [{"a": [1, "x"], "b": [1, 0], "n": [-1, 0]}]}]
    >>> _ = (folder / "r.jsonl").write_text("\\n".join(json.dumps(d) for d in lines) + "\\n")
    >>> s = certify_region_file(folder / "r.jsonl", folder / "out.jsonl")
    >>> s.statuses, s.unverified
    ({'robust': 1, 'error': 1}, 0)
    >>> json.loads((folder / "out.jsonl").read_text().splitlines()[1])["error"]
    'line 2: regions[0].a: expected 2 finite numbers, got [1, "x"]'
    """
    in_path, out_path = Path(in_path), Path(out_path)
    if budget < 1:
        raise OptionError(f"--budget must be at least 1 work unit, got {budget}")
    input_format(in_path)  # the whole file is refused before any work
    t0 = time.perf_counter()
    summary = RegionSummary()
    with atomic_output(out_path, "-o", reads=[in_path]) as tmp, tmp.open("w", encoding="utf-8") as fh:
        _certify_lines(in_path, fh, summary, budget, tol, progress)
    summary.seconds = time.perf_counter() - t0
    return summary


def _certify_lines(in_path: Path, fh, summary: RegionSummary, budget: int, tol: float,
                   progress: Callable[[int], None] | None) -> None:
    """Certify every line of a region set, writing its results row to ``fh`` as it comes."""
    for number, item in read_region_lines(in_path):
        if isinstance(item, tuple):
            row = error_row(item[1], id=item[0], line=number)
        else:
            try:
                verdict = certify_regions(item, budget=budget, tol=tol)
            except CertifyError as err:  # a solver failure: recorded, the run goes on
                row = error_row(f"line {number}: {err}", id=item.id, line=number)
            else:
                ok = bool(verify_regions(item, verdict))
                row = verdict.row(verified=ok, line=number, id=item.id)
                summary.unverified += not ok
        summary.rows += 1
        summary.statuses[row["status"]] = summary.statuses.get(row["status"], 0) + 1
        fh.write(json.dumps(row, allow_nan=False) + "\n")
        if progress is not None:
            progress(1)


def verify_region_file(results: str | Path, regions: str | Path) -> RegionSummary:
    """Re-check every row of a results file against its region set, without a solver.

    Rows and tuples are matched in order (a row's ``line`` and ``id`` must agree with its
    tuple's); an error row's line must indeed be unreadable. ``failures`` lists ``(id, reason)``
    of the rows that fail.

    Parameters
    ----------
    results : path
        Results written by :func:`certify_region_file`.
    regions : path
        The region set they came from.

    Returns
    -------
    RegionSummary

    Raises
    ------
    GraspFileError
        A file cannot be read.

    Examples
    --------
    >>> import json, pathlib, tempfile
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> line = {"id": "r1", "regions": [{"a": [1, -0.7], "b": [1, 0.7], "n": [-1, 0], "mu": 0.5},
    ...                                 {"a": [-1, -0.7], "b": [-1, 0.7], "n": [1, 0], "mu": 0.5}]}
    >>> _ = (folder / "r.jsonl").write_text(json.dumps(line) + "\\n")
    >>> certify_region_file(folder / "r.jsonl", folder / "out.jsonl").statuses
    {'not_robust': 1}
    >>> verify_region_file(folder / "out.jsonl", folder / "r.jsonl").failures
    []
    """
    results, regions = Path(results), Path(regions)
    summary = RegionSummary()
    rows = []
    for number, value in json_lines(results, "results file"):
        if isinstance(value, Exception):
            value = {"status": None, "_bad": f"results line {number}: {value}"}
        rows.append(value)
    tuples = list(read_region_lines(regions))
    if len(rows) != len(tuples):
        summary.failures.append((None, f"{len(rows)} results rows for {len(tuples)} region tuples"))
    for (number, item), row in zip(tuples, rows):
        summary.rows += 1
        status = row.get("status") if isinstance(row, dict) else None
        summary.statuses[str(status)] = summary.statuses.get(str(status), 0) + 1
        unreadable = not isinstance(row, dict) or "_bad" in row
        if unreadable or row.get("line") != number:  # no tuple to re-check it against
            summary.unpaired += 1
            summary.unpaired_errors += status == "error"
            summary.failures.append(
                (None, row.get("_bad", "not a JSON object") if isinstance(row, dict)
                 else f"results row for line {number}: not a JSON object") if unreadable
                else (row.get("id"), f"results row is for line {row.get('line')}, tuple is line {number}"))
            continue
        if isinstance(item, tuple):
            if status != "error":
                summary.failures.append((row.get("id"), f"line {number} is not a valid tuple ({item[1]}) but its "
                                                        f"row says {status!r}"))
            continue
        if row.get("id") != item.id:
            summary.failures.append((row.get("id"), f"id does not match tuple line {number} ({show(item.id)})"))
            continue
        if status == "error":
            summary.failures.append((item.id, f"line {number} is a valid tuple but its row is an error"))
            continue
        check = verify_regions(item, row)
        if not check:
            summary.failures.append((item.id, check.reason))
    return summary

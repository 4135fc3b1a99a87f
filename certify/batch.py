"""Certify and re-verify whole grasp-set files (JSON Lines or Parquet, chosen by extension).

:func:`certify_file` streams the input in chunks through :mod:`qualgrasp.certify.engine` (parallel,
resumable; :mod:`qualgrasp.certify.chunk` is what happens to one chunk); :func:`verify_file`
re-checks a results file against its grasps, in parallel, without any solver.
"""

from __future__ import annotations

import os
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Iterator

import pyarrow as pa

from .certificates import Tolerances
from .chunk import Options, Quality, verify_chunk
from .engine import RunSummary, run
from .errors import CertifyError
from .table import chunk_values, count_grasps, is_parquet, iter_chunks

__all__ = ["Summary", "certify_file", "verify_file"]


def certify_file(grasps_path: str | Path, results_path: str | Path, *, method: str = "fast",
                 progress: Callable[[int], None] | None = None, workers: int | None = 1,
                 dask: str | None = None, resume: bool = False, chunk_size: int = 4096,
                 quality: bool = True, eps_gap: float = 0.01, eps_budget: int = 200_000,
                 eps_time: float | None = 10.0) -> RunSummary:
    """Certify every grasp of ``grasps_path`` into ``results_path``: one results row per grasp,
    in input order. See :func:`qualgrasp.certify.engine.run` for ``workers``, ``dask``, ``resume`` and
    ``chunk_size`` (``workers=None`` uses every core); ``quality``, ``eps_gap``, ``eps_budget``
    and ``eps_time`` are :class:`qualgrasp.certify.chunk.Options`' (``eps_time`` in seconds per
    grasp, None for no limit)."""
    options = Options(method=method, quality=quality, eps_gap=eps_gap, eps_budget=eps_budget,
                      eps_time=eps_time)
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


def _result_rows(path: Path, size: int, parsed: list) -> Iterator[Any]:
    """Results in chunks of ``size``: a list of parsed rows (dicts, or None for a line that is
    not JSON) for JSON Lines, an Arrow table for Parquet. ``parsed[0]`` counts the JSON Lines
    rows that are JSON objects."""
    for chunk in iter_chunks(path, size):
        if isinstance(chunk.rows, pa.Table):
            yield chunk.rows
        else:
            values = [value if not isinstance(value, Exception) else None for value in chunk_values(chunk)]
            parsed[0] += sum(isinstance(v, dict) for v in values)
            yield values


def verify_file(results_path: str | Path, grasps_path: str | Path,
                tol: Tolerances = Tolerances(), workers: int | None = 1,
                chunk_size: int = 4096) -> Summary:
    """Re-check every certificate of ``results_path`` against the grasps of ``grasps_path``.

    Rows and grasps are matched by position (a row's ``line`` and ``id`` must agree with its
    grasp's). Every column a row states is re-checked (:func:`qualgrasp.certify.report.verify_row`);
    rows with status ``error`` must be exactly the error row of an invalid grasp. A file whose
    rows mix epsilon and no epsilon fails the rarer kind (a run computes quality for all rows or
    none). A malformed row is a failure with a message; a results file that is neither JSON
    Lines nor Parquet raises :class:`qualgrasp.certify.errors.CertifyError`. Chunks are verified
    in ``workers`` processes (``None``: every core).
    """
    results_path, grasps_path = Path(results_path), Path(grasps_path)
    workers = workers or os.cpu_count() or 1
    summary = Summary()
    quality = Quality()
    parsed = [0]
    pool = ProcessPoolExecutor(workers) if workers > 1 else None
    futures = []
    try:
        pairs = zip(iter_chunks(grasps_path, chunk_size), _result_rows(results_path, chunk_size, parsed))
        for chunk, results in pairs:
            if pool is None:
                _merge(summary, quality, verify_chunk(chunk, results, tol))
                continue
            futures.append(pool.submit(verify_chunk, chunk, results, tol))
            if len(futures) > 2 * workers:  # bounded memory: few chunks in flight
                _merge(summary, quality, futures.pop(0).result())
        for f in futures:
            _merge(summary, quality, f.result())
    except (pa.ArrowException, OSError) as err:
        raise CertifyError(f"cannot read {results_path} or {grasps_path}: {str(err).splitlines()[0][:200]}") from None
    finally:
        if pool is not None:
            pool.shutdown()
    n_grasps, n_rows = count_grasps(grasps_path), count_grasps(results_path)
    if not is_parquet(results_path) and n_rows and not parsed[0]:
        raise CertifyError(f"{results_path} is not a JSON Lines results file (no line is a JSON object)")
    summary.failures.extend(quality.failures())
    if n_rows != n_grasps:
        summary.failures.append((None, f"{n_rows} results rows for {n_grasps} grasps"))
    return summary


def _merge(summary: Summary, quality: Quality, result) -> None:
    statuses, failures, q = result
    for status, n in statuses.items():
        summary.statuses[status] = summary.statuses.get(status, 0) + n
        summary.rows += n
    summary.failures.extend(failures)
    quality.merge(q)

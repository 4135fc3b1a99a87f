"""``qualgrasp bench --jobs``: the offline job end to end, one table from one run.

Each **job row** is the command ``qualgrasp certify GRASPS.parquet -o RESULTS.parquet --workers 2``
run as a user runs it, in a process of its own (Parquet in and out, two worker processes, chunked,
every certificate re-checked; its kernels compiled by a run on 200 of the grasps first), on random
grasps written to Parquet outside the timing: planar grasps of three point contacts with quality
(both epsilons with their evidence) and without, a degenerate planar set (``qualgrasp sample
--degenerate mixed``) and its generic counterpart (same model and contact count), and spatial grasps
of three point contacts with and without quality. Sizes: 1,000,000 planar and 100,000 spatial rows;
with ``quick`` 20,000 and 2,000. ``kinds`` (``--job``) runs only the jobs whose label holds
one of its words (:func:`select_jobs`).

Each job row is set against two baselines timed in the same run, on a prefix of the same grasps, in
this process: the build's own **per-grasp route** (:func:`qualgrasp.certify.report.certify_grasp`,
the same results row: both closures, both certificates re-checked and, for the quality rows, both
epsilons) and **cvxpy + CLARABEL rebuilt per grasp** (the reference formulation built anew for each
grasp, as naive cvxpy code does; force and form closure, no epsilon: on the quality rows this
baseline does less than the job). A grasp on which CLARABEL fails (rank-deficient sets) is timed and
counted as failed. Every route is judged by the same rule: CPU seconds per grasp (the job's summed
over the command and its workers, start-up and file work included), and the ratio is the baseline's
CPU time per grasp over the job's. The job's wall time and rate on the two workers are printed
beside it.

The **start-up rows**: ``qualgrasp --help`` and ``--version`` (median of five runs) against the
interpreter's own start-up (``python -c pass``), and the first ``qualgrasp certify`` of one line (a
planar grasp in closure, so that quality has an epsilon to compute) with a fresh compile cache
(compiling the kernels it needs), with and without quality, against the same command once the cache
is warm.
"""

from __future__ import annotations

import collections
import json
import math
import os
import re
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Sequence

import pyarrow.parquet as pq
from rich.console import Console
from rich.table import Table

from ..certify.batch import random_grasp_table
from ..certify.core import force_closure, form_closure
from ..certify.errors import OptionError, SolverError
from ..certify.files.columns import grasp_columns
from ..certify.report import certify_grasp
from ..certify.solvers import make_solver
from .bench import DEGENERATE_KIND

__all__ = ["JOB_KINDS", "SIZES", "QUICK_SIZES", "WORKERS", "JobRow", "StartRow", "select_jobs", "run_jobs_bench",
           "print_jobs_bench"]

_GENERIC = {k: v for k, v in DEGENERATE_KIND.items() if k != "degenerate"}
#: label -> (keyword arguments of :func:`~qualgrasp.certify.batch.random_grasp_table`, quality)
JOB_KINDS = {
    "planar, 3 point contacts, quality": (dict(dim=2, n_contacts=3, model="point"), True),
    "planar, 3 point contacts, --no-quality": (dict(dim=2, n_contacts=3, model="point"), False),
    "degenerate planar (mixed), 4 point contacts, --no-quality": (DEGENERATE_KIND, False),
    "generic planar, 4 point contacts, --no-quality": (_GENERIC, False),
    "spatial, 3 point contacts, quality": (dict(dim=3, n_contacts=3, model="point", spread=0.3), True),
    "spatial, 3 point contacts, --no-quality": (dict(dim=3, n_contacts=3, model="point", spread=0.3), False),
}
#: Rows per job, planar and spatial; :data:`QUICK_SIZES` with ``quick``.
SIZES = {2: 1_000_000, 3: 100_000}
QUICK_SIZES = {2: 20_000, 3: 2_000}
#: Worker processes of every job (``--workers``).
WORKERS = 2


@dataclass(frozen=True)
class JobRow:
    """A job and its baselines: ``wall`` and ``cpu`` seconds of the job (all its processes);
    per-grasp CPU seconds of the per-grasp route and of cvxpy rebuilt per grasp, each on its first
    ``*_n`` grasps (``cvxpy_failed`` of them where CLARABEL failed); the job's status counts and
    unverified rows."""

    kind: str
    rows: int
    wall: float
    cpu: float
    per_grasp: float
    per_grasp_n: int
    cvxpy: float
    cvxpy_n: int
    cvxpy_failed: int
    statuses: dict
    unverified: int

    @property
    def cpu_per_grasp(self) -> float:
        return self.cpu / self.rows


@dataclass(frozen=True)
class StartRow:
    """A start-up measurement: ``seconds`` (wall, median) against ``baseline`` seconds."""

    what: str
    seconds: float
    baseline_what: str
    baseline: float


def _cpu_per_item(fn: Callable, items) -> float:
    """CPU seconds per item of ``fn`` over ``items`` (the first call outside the timing)."""
    fn(items[0])
    start = time.process_time()
    for item in items:
        fn(item)
    return (time.process_time() - start) / len(items)


def _qualgrasp() -> str | None:
    """The ``qualgrasp`` command of this interpreter's environment."""
    return shutil.which("qualgrasp", path=os.pathsep.join([str(Path(sys.executable).parent),
                                                           os.environ.get("PATH", "")]))


def _certify(exe: str, grasps: Path, results: Path, quality: bool) -> tuple[float, float]:
    """Wall and CPU seconds (the command and every process it waited for) of ``qualgrasp certify``."""
    cmd = [exe, "certify", str(grasps), "-o", str(results), "--workers", str(WORKERS), "-q"]
    cmd += [] if quality else ["--no-quality"]
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    done = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - start
    if done.returncode != 0:  # a row refused or unverified (exit 1) is a result; anything else is not
        last = (done.stderr or done.stdout).strip().splitlines()[-1:] or ["no output"]
        if done.returncode != 1:
            raise OptionError(f"qualgrasp certify {grasps.name} ended with exit code {done.returncode}: {last[0]}")
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime + after.ru_stime) - (kids.ru_utime + kids.ru_stime)


def _job(label: str, kwargs: dict, quality: bool, rows: int, seed: int, reference_n: int,
         folder: Path, exe: str) -> JobRow:
    table = random_grasp_table(seed, rows, **kwargs)
    grasps_path, results_path = folder / "grasps.parquet", folder / "results.parquet"
    pq.write_table(table, grasps_path)
    pq.write_table(table.slice(0, 200), folder / "warm-in.parquet")
    _certify(exe, folder / "warm-in.parquet", folder / "warm.parquet", quality)  # compiled before the timing
    wall, cpu = _certify(exe, grasps_path, results_path, quality)
    done = pq.read_table(results_path, columns=["status", "verified"])
    statuses = collections.Counter(done.column("status").to_pylist())
    unverified = done.num_rows - sum(done.column("verified").to_pylist())
    few = grasp_columns(table.slice(0, max(reference_n, 1))).grasps(range(min(max(reference_n, 1), rows)))
    per_grasp = _cpu_per_item(lambda g: certify_grasp(g, quality=quality).row(), few)
    rebuilt = make_solver("reference-rebuilt")
    cvxpy_few = few[: max(reference_n // 3, 1)]
    failed = set()

    def both(g):  # a solver failure is that route's answer for the grasp: counted, and timed
        try:
            force_closure(g, solver=rebuilt), form_closure(g, solver=rebuilt)
        except SolverError:
            failed.add(g.id)

    cvxpy = _cpu_per_item(both, cvxpy_few)
    for path in (grasps_path, results_path, folder / "warm-in.parquet", folder / "warm.parquet"):
        path.unlink(missing_ok=True)
    return JobRow(label, done.num_rows, wall, cpu, per_grasp, len(few), cvxpy, len(cvxpy_few), len(failed),
                  dict(statuses), unverified)


def _median_wall(cmd: list[str], env: dict | None = None, times: int = 5) -> float:
    walls = []
    for _ in range(times):
        start = time.perf_counter()
        subprocess.run(cmd, env=env, check=True, capture_output=True)
        walls.append(time.perf_counter() - start)
    return statistics.median(walls)


def _start_rows(folder: Path, exe: str) -> list[StartRow]:
    bare = _median_wall([sys.executable, "-c", "pass"])
    rows = [StartRow(f"qualgrasp {flag}", _median_wall([exe, flag]), "python -c pass", bare)
            for flag in ("--help", "--version")]
    one = folder / "one.jsonl"  # three point contacts 120 degrees apart, normals through the centre: closure
    contacts = [{"p": [math.cos(a), math.sin(a)], "n": [-math.cos(a), -math.sin(a)], "model": "point", "mu": 0.5}
                for a in (0.0, 2 * math.pi / 3, 4 * math.pi / 3)]
    one.write_text(json.dumps({"id": "one", "contacts": contacts}) + "\n")
    for quality in (True, False):
        env = {**os.environ, "XDG_CACHE_HOME": str(folder / f"cache-{quality}")}
        env.pop("NUMBA_CACHE_DIR", None)
        cmd = [exe, "certify", str(one), "-o", str(folder / f"out-{quality}.jsonl"), "-q"]
        cmd += [] if quality else ["--no-quality"]
        cold = _median_wall(cmd, env, times=1)
        for path in folder.glob(f"out-{quality}.jsonl*"):
            path.unlink()
        warm = _median_wall(cmd, env, times=1)
        what = "with quality" if quality else "--no-quality"
        rows.append(StartRow(f"first certify of one line, fresh cache, {what}", cold,
                             "the same, cache warm", warm))
    return rows


def select_jobs(words: Sequence[str] = ()) -> list[str]:
    """The labels of :data:`JOB_KINDS` holding one of ``words`` (case-insensitive), in the table's
    order; every label when ``words`` is empty. A word holds one or more whole words of a label,
    in their order: ``quality`` is in the jobs with quality, not in those with ``--no-quality``
    (``no-quality``).

    Raises
    ------
    OptionError
        When a word is empty or in no label (naming the labels).

    Examples
    --------
    >>> select_jobs(["degenerate"])
    ['degenerate planar (mixed), 4 point contacts, --no-quality']
    >>> len(select_jobs(["quality"])), len(select_jobs(["no-quality"]))
    (2, 4)
    """
    labels = list(JOB_KINDS)
    for word in words:
        if not _tokens(word):
            raise OptionError(f"--job {word!r} holds no word: give one of the labels' words")
        if not any(_holds(label, word) for label in labels):
            raise OptionError(f"--job {word!r} is in no job's label: " + "; ".join(labels))
    return [label for label in labels if not words or any(_holds(label, w) for w in words)]


def _tokens(text: str) -> list[str]:
    return [t.strip("-") for t in re.findall(r"[\w-]+", text.lower()) if t.strip("-")]


def _holds(label: str, word: str) -> bool:
    """Whether the words of ``word`` are consecutive words of ``label``."""
    have, want = _tokens(label), _tokens(word)
    return any(have[i:i + len(want)] == want for i in range(len(have) - len(want) + 1))


def run_jobs_bench(*, quick: bool = False, seed: int = 0, reference_n: int = 300, sizes: dict | None = None,
                   startup: bool = True, kinds: Sequence[str] = (),
                   progress: Callable[[str], None] | None = None) -> tuple[list[JobRow], list[StartRow]]:
    """Run the jobs of :data:`JOB_KINDS` that ``kinds`` selects (:func:`select_jobs`: all when
    empty) and their baselines, then (with ``startup``) the start-up rows (module docstring), in a
    temporary folder removed at the end. ``sizes``: rows per job by dimension, instead of
    :data:`SIZES` (:data:`QUICK_SIZES` with ``quick``)."""
    sizes = sizes or (QUICK_SIZES if quick else SIZES)
    labels = select_jobs(kinds)
    exe = _qualgrasp()
    if exe is None:
        raise OptionError("bench --jobs runs the qualgrasp command: it is not installed beside this Python")
    jobs = []
    with tempfile.TemporaryDirectory(prefix="qualgrasp-bench-") as tmp:
        folder = Path(tmp)
        for label in labels:
            kwargs, quality = JOB_KINDS[label]
            if progress:
                progress(label)
            jobs.append(_job(label, kwargs, quality, sizes[kwargs["dim"]], seed, reference_n, folder, exe))
        if progress and startup:
            progress("start-up")
        starts = _start_rows(folder, exe) if startup else []
    return jobs, starts


def print_jobs_bench(jobs: list[JobRow], starts: list[StartRow]) -> None:
    """Print the two tables of :func:`run_jobs_bench` with rich."""
    table = Table(title=f"offline job: qualgrasp certify, Parquet in and out, --workers {WORKERS}; "
                        "baselines in this process on the same grasps; x = baseline CPU / job CPU per grasp")
    for col in ("job", "rows", "wall s", "grasps/s", "CPU us/grasp", "per-grasp route us (n)", "x",
                "cvxpy rebuilt us (n, failed)", "x", "unverified"):
        table.add_column(col, justify="left" if col == "job" else "right")
    for r in jobs:
        us = 1e6 * r.cpu_per_grasp
        table.add_row(r.kind, f"{r.rows:,}", f"{r.wall:.1f}", f"{r.rows / r.wall:,.0f}", f"{us:,.1f}",
                      f"{1e6 * r.per_grasp:,.1f} ({r.per_grasp_n})", f"{r.per_grasp / r.cpu_per_grasp:.1f}",
                      f"{1e6 * r.cvxpy:,.0f} ({r.cvxpy_n}, {r.cvxpy_failed})", f"{r.cvxpy / r.cpu_per_grasp:.0f}",
                      str(r.unverified))
    console = Console(width=max(160, Console().width))
    console.print(table)
    console.print("cvxpy rebuilt: force and form closure only (no epsilon), also on the quality rows.")
    if starts:
        start = Table(title="start-up and first call (wall seconds; x = seconds / baseline)")
        for col in ("what", "s", "baseline", "baseline s", "x"):
            start.add_column(col, justify="left" if col in ("what", "baseline") else "right")
        for r in starts:
            start.add_row(r.what, f"{r.seconds:.2f}", r.baseline_what, f"{r.baseline:.2f}",
                          f"{r.seconds / r.baseline:.1f}")
        console.print(start)

"""The certify commands: ``qualgrasp certify``, ``verify``, ``certify-regions`` and ``sample``.

Each command is a thin wrapper over a public function (:func:`qualgrasp.certify.batch.certify_file`,
:func:`qualgrasp.certify.batch.verify_file`, :func:`qualgrasp.certify.regions.certify_region_file`,
:func:`qualgrasp.certify.regions.verify_region_file`,
:func:`qualgrasp.certify.batch.samples.write_random_grasp_file`); its checks and its one-line refusals are
:mod:`qualgrasp.certify.cli.options`'.
"""

from __future__ import annotations

import math
from pathlib import Path

import typer
from rich.console import Console
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn
from rich.table import Table

from .. import models
from ..batch.engine import tune_allocator
from ..batch.jobs import certify_file, verify_file
from ..errors import CertifyError
from ..regions.files import DEFAULT_BUDGET, certify_region_file, verify_region_file
from ..batch.samples import DEGENERATE, parameter_ranges, write_random_grasp_file
from ..files.reader import count_grasps
from ..core.validation import MAX_CONTACTS
from .options import MAX_WORKERS, fail, printable

__all__ = ["register"]

console = Console(stderr=True)

#: The solver routes a run may use (``qualgrasp bench`` times the others).
METHODS = ("fast", "reference")


def certify_command(
    grasps: Path = typer.Argument(..., help="Grasp set: .jsonl (JSON Lines) or .parquet."),
    output: Path = typer.Option(..., "-o", "--output",
                                help="Results file: Parquet if named .parquet or .pq, else JSON Lines."),
    method: str = typer.Option("fast", help="'fast' (enumeration/clarabel) or 'reference' (cvxpy)."),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="No progress bar or summary."),
    quality: bool = typer.Option(True, help="Compute the epsilon columns (eps_l1_lo ... eps_linf_hi)."),
    eps_gap: float = typer.Option(0.01, help="Spatial epsilon: stop when hi - lo <= gap * hi."),
    eps_budget: int = typer.Option(200_000, help="Spatial epsilon: most work per grasp and norm, in directions examined."),
    eps_time: float = typer.Option(10.0, help="Time limit of quality per grasp, in seconds (0: none); when hit, "
                                              "the row keeps its closure verdict, states the epsilon bounds reached "
                                              "and eps_limited (results then depend on the machine)."),
    workers: int = typer.Option(0, help="Local worker processes (0: all cores)."),
    dask: str = typer.Option(None, "--dask", help="'local' for a dask LocalCluster, or a scheduler address."),
    resume: bool = typer.Option(False, "--resume", help="Continue an interrupted run, keeping its complete chunks."),
    chunk_size: int = typer.Option(None, help="Grasps per chunk (unit of work and checkpoint; default 16384, "
                                   "fewer for a small input so that each worker gets four chunks; with "
                                   "--resume, the interrupted run's)."),
    mesh: Path = typer.Option(None, "--mesh", help="Read GRASPS as gripper poses (JSON Lines or Parquet, as for "
                              "'qualgrasp contacts') and close each on this mesh (OBJ, STL, PLY, GLB, OFF) "
                              "first: contacts and certificates in one run, one results row per pose."),
    gripper: str = typer.Option(None, help="With --mesh: built-in gripper or gripper file "
                                "(default franka_panda)."),
    convention: str = typer.Option(None, help="With --mesh: pose convention (default qualgrasp)."),
    units: str = typer.Option(None, help="With --mesh: unit the mesh is drawn in (default m)."),
    mu: float = typer.Option(None, help="With --mesh: friction coefficient (default: the gripper file's)."),
    model: str = typer.Option(None, help="With --mesh: contact model of the patches, soft, patch or point "
                                                  "(default soft)."),
    mass: float = typer.Option(None, help="With --mesh: mass of the object, kg (default: density 1000 kg/m^3)."),
    points: bool = typer.Option(None, "--points/--no-points", help="With --mesh: write each patch's points "
                                "(default: written)."),
    hold: float = typer.Option(None, help="With --mesh: certify whether each grasp holds the object's weight with "
                                          "a grip force of at most this many newtons (the hold_* and grip_* "
                                          "columns, as 'qualgrasp contacts --hold' writes them)."),
    gravity: str = typer.Option(None, help="With --mesh --hold: 'all' (every direction, the default) or one "
                                           "direction x,y,z (object frame)."),
    level: int = typer.Option(None, help="With --mesh --hold and --gravity all: icosphere level of the direction "
                                         "polytope, 0 to 4 (default 1)."),
) -> None:
    """Certify form and force closure of every grasp, one results line per grasp line.

    With --mesh, GRASPS holds gripper poses: each is closed on the mesh as 'qualgrasp contacts'
    does and its contacts certified in the same run (a pose without contacts is an error row with
    its reason). Exit code 1 when some rows are errors or failed their own re-check, 2 when the run
    could not start (unreadable input, bad option, output naming an input or a folder, resume
    refused).
    """
    if method not in METHODS:
        fail(f"--method must be one of {', '.join(METHODS)}, got {method!r}")
    if not (math.isfinite(eps_gap) and 0 < eps_gap < 1):
        fail(f"--eps-gap must be a fraction between 0 and 1 (relative gap hi - lo <= gap * hi), got {eps_gap}")
    if eps_budget < 1:
        fail(f"--eps-budget must be at least 1 direction cell, got {eps_budget}")
    _check_workers(workers)
    if not (eps_time >= 0 and math.isfinite(eps_time)):  # NaN fails both
        fail(f"--eps-time must be a finite number of seconds >= 0 (0: no time limit), got {eps_time}")
    if chunk_size is not None and chunk_size < 1:
        fail(f"--chunk-size must be at least 1 grasp, got {chunk_size}")
    mesh_options = {k: v for k, v in dict(gripper=gripper, convention=convention, units=units, mu=mu, model=model,
                                          mass=mass, points=points, hold=hold, gravity=gravity,
                                          level=level).items() if v is not None}
    if hold is None and (gravity is not None or level is not None):
        fail(f"--{'gravity' if gravity is not None else 'level'} needs --hold")
    if mesh is None and mesh_options:
        fail(f"--{next(iter(mesh_options))} needs --mesh")
    source = None
    if mesh is not None:
        from ..meshes.source import PoseSource, check_pose_file  # trimesh: only for a run on a mesh

        try:
            check_pose_file(grasps)
            source = PoseSource.of(mesh, **mesh_options)
        except CertifyError as err:
            fail(str(err))
    total = count_grasps(grasps)
    tune_allocator()  # this process is the command's own
    with Progress(TextColumn("certify"), BarColumn(), MofNCompleteColumn(), TimeRemainingColumn(),
                  console=console, disable=quiet) as bar:
        task = bar.add_task("certify", total=total)
        try:
            summary = certify_file(grasps, output, method=method,
                                   progress=lambda n: bar.advance(task, n), quality=quality,
                                   eps_gap=eps_gap, eps_budget=eps_budget,
                                   eps_time=eps_time if eps_time > 0 else None, workers=workers or None,
                                   dask=dask, resume=resume, chunk_size=chunk_size, source=source,
                                   grasp_count=total)
        except CertifyError as err:
            fail(str(err))
    if not quiet:
        table = _status_table(f"{summary.rows} {'poses' if source else 'grasps'} -> {output}", summary)
        if summary.resumed_chunks:
            table.add_row("chunks kept from the interrupted run", str(summary.resumed_chunks))
        console.print(table)
        done = summary.rows - summary.resumed_rows  # the kept rows took no time in this run
        rate = done / summary.seconds if summary.seconds > 0 else 0.0
        memory = "" if summary.peak_mb is None else f"; peak memory {summary.peak_mb:.0f} MB" + (
            "" if summary.peak_worker_mb is None else f" (largest worker {summary.peak_worker_mb:.0f} MB)")
        kept = f" ({done:,} rows certified in this run)" if summary.resumed_rows else ""
        console.print(f"{summary.seconds:.1f} s, {rate:,.0f} grasps/s{kept}{memory}")
    if summary.errors or summary.unverified:
        raise typer.Exit(1)


def verify_command(
    results: Path = typer.Argument(..., help="Results file written by 'qualgrasp certify' or 'certify-regions'."),
    grasps: Path | None = typer.Option(None, "--grasps", help="The grasp set the results came from."),
    regions: Path | None = typer.Option(None, "--regions", help="The region set the results came from "
                                        "(results of 'qualgrasp certify-regions')."),
    workers: int = typer.Option(0, help="Worker processes (0: all cores; grasp sets only)."),
) -> None:
    """Re-check every certificate without a solver; print the id of each one that fails.

    Give exactly one of --grasps (results of 'qualgrasp certify') and --regions (results of
    'qualgrasp certify-regions'). Exit code 1 when a row fails, 2 when the run cannot start.
    """
    if (grasps is None) == (regions is None):
        fail("give exactly one of --grasps and --regions")
    _check_workers(workers)
    try:
        if regions is not None:
            summary = verify_region_file(results, regions)
        else:
            tune_allocator()  # this process is the command's own
            summary = verify_file(results, grasps, workers=workers or None)
    except CertifyError as err:
        fail(str(err))
    for gid, reason in summary.failures:
        typer.echo(printable(f"{gid}\t{reason}"))
    console.print(_verify_line(summary, regions is not None), soft_wrap=True)
    if summary.failures:
        raise typer.Exit(1)


def _check_workers(workers: int) -> None:
    """Refuse a ``--workers`` count below 0 or above :data:`~qualgrasp.certify.cli.options.MAX_WORKERS`."""
    if not 0 <= workers <= MAX_WORKERS:
        fail(f"--workers must be 0 (all cores) or a number of processes up to {MAX_WORKERS}, got {workers}")


def _verify_line(summary, regions: bool = False) -> str:
    """What a verification proved, in one line: the rows re-checked against their grasps (region
    tuples) (certified rows and error rows), those that failed, the rows without a grasp (tuple)
    to re-check against (failed, not re-checked) and the grasps without a row (a subset: no
    failure)."""
    rechecked = summary.rows - summary.unpaired
    errors = summary.errors - summary.unpaired_errors
    what = "region tuples" if regions else "grasps"
    line = (f"{rechecked - errors} certified rows and {errors} error rows re-checked against their {what}, "
            f"{len(summary.failures)} failed")
    if summary.unpaired:
        why = ("unreadable, or stating another line than its tuple's" if regions else
               "unreadable, stating no line of the grasp file, or repeating another row's line")
        line += f"; {summary.unpaired} of the failed rows were re-checked against no {what[:-1]} ({why})"
    if getattr(summary, "missing", 0):  # grasp sets only: a results file may hold a subset
        line += f"; {summary.missing} of the {summary.grasps} grasps have no results row (a subset: not a failure)"
    return line


def certify_regions_command(
    regions: Path = typer.Argument(..., help="Region set: JSON Lines, one region tuple per line."),
    output: Path = typer.Option(..., "-o", "--output", help="Results file (JSON Lines); never the input."),
    budget: int = typer.Option(DEFAULT_BUDGET, help="Branch-and-bound work units per tuple (curved regions, "
                               "normal_tol > 0); straight regions with normal_tol 0 are decided exactly."),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="No progress bar or summary."),
) -> None:
    """Certify region tuples: is every choice of one contact per region in force closure?

    One results row per tuple line: status robust, not_robust (with a witness grasp and its
    Farkas certificate), undecided or error, the certificate, and whether it re-checked. Exit
    code 1 when some rows are errors or failed their own re-check, 2 when the run cannot start.
    """
    if budget < 1:
        fail(f"--budget must be at least 1 work unit per tuple, got {budget}")
    total = count_grasps(regions)  # for the progress bar only: the reader says what is wrong
    with Progress(TextColumn("regions"), BarColumn(), MofNCompleteColumn(), TimeRemainingColumn(),
                  console=console, disable=quiet) as bar:
        task = bar.add_task("regions", total=total)
        try:
            summary = certify_region_file(regions, output, budget=budget, progress=lambda n: bar.advance(task, n))
        except CertifyError as err:
            fail(str(err))
    if not quiet:
        table = _status_table(f"{summary.rows} region tuples -> {output}", summary)
        console.print(table)
        console.print(f"{summary.seconds:.1f} s")
    if summary.errors or summary.unverified:
        raise typer.Exit(1)
def sample_command(
    output: Path = typer.Argument(..., help="Grasp set to write: Parquet if named .parquet or .pq, else JSON Lines."),
    n: int = typer.Option(100_000, "--n", help="Number of grasps."),
    dim: int = typer.Option(2, help="2 (planar) or 3 (spatial)."),
    contacts: int = typer.Option(3, help="Contacts per grasp."),
    model: str = typer.Option("point", help="Contact model: " + ", ".join(models.names()) + "."),
    seed: int = typer.Option(0, help="Random seed."),
    degenerate: str = typer.Option(None, "--degenerate", metavar="KIND", help=(
        "Planar grasps with degenerate wrenches instead of a blob: "
        + "; ".join(f"{k}: {v}" for k, v in DEGENERATE.items()) + ".")),
) -> None:
    """Write a random grasp set, for trying the toolkit and for benchmarks at scale.

    Contacts are placed around a random blob; about a third of the grasps are in closure. With
    --degenerate KIND, the contacts are placed so that the wrenches are degenerate (normals
    through one point, repeated or collinear contacts), as round or square objects give."""
    if n < 0:
        fail(f"--n must be a number of grasps (>= 0), got {n}")
    if seed < 0:
        fail(f"--seed must be a non-negative integer, got {seed}")
    if dim not in (2, 3):
        fail(f"--dim must be 2 (planar) or 3 (spatial), got {dim}")
    if not 1 <= contacts <= MAX_CONTACTS:
        fail(f"--contacts must be between 1 and {MAX_CONTACTS}, got {contacts}")
    if model not in models.names():
        fail(f"--model must be one of {', '.join(models.names())}, got {model!r}")
    try:
        parameter_ranges(model)
    except ValueError as err:
        fail(f"--model {model}: {err}")
    if dim not in models.get(model).dims:
        fail(f"--model {model} exists in {' and '.join(map(str, models.get(model).dims))} dimensions only, "
              f"not with --dim {dim}")
    if degenerate is not None:
        if degenerate not in DEGENERATE:
            fail(f"--degenerate must be one of {', '.join(DEGENERATE)}, got {degenerate!r}")
        if dim != 2:
            fail(f"--degenerate makes planar grasps only (--dim 2), got --dim {dim}")
        if contacts < 2:
            fail(f"--degenerate needs at least 2 contacts, got --contacts {contacts}")
    try:
        count = write_random_grasp_file(output, n, seed=seed, dim=dim, n_contacts=contacts, model=model,
                                        degenerate=degenerate)
    except CertifyError as err:
        fail(str(err))
    console.print(f"wrote {count} grasps to {output}")


def _status_table(title: str, summary) -> Table:
    """Rows per status and the unverified rows of a run's summary."""
    table = Table(title=title)
    table.add_column("status")
    table.add_column("rows", justify="right")
    for status, count in sorted(summary.statuses.items()):
        table.add_row(status, str(count))
    table.add_row("unverified", str(summary.unverified))
    return table


def register(app: typer.Typer) -> None:
    """Add the certify commands to the ``qualgrasp`` application."""
    app.command("certify")(certify_command)
    app.command("verify")(verify_command)
    app.command("certify-regions")(certify_regions_command)
    app.command("sample")(sample_command)

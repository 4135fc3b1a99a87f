"""Command-line layer of :mod:`qualgrasp.certify`: ``qualgrasp certify``, ``verify`` and ``bench``.

Each command is a thin wrapper over a public function (:func:`qualgrasp.certify.batch.certify_file`,
:func:`qualgrasp.certify.batch.verify_file`, :func:`qualgrasp.certify.bench.run_bench`).
"""

from __future__ import annotations

from pathlib import Path

import typer
from rich.console import Console
from rich.markup import escape
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn
from rich.table import Table

from . import models
from .batch import certify_file, verify_file
from .bench import (print_bench, print_contacts_bench, print_quality_bench, run_bench,
                    run_contacts_bench, run_quality_bench)
from .errors import CertifyError
from .samples import write_random_grasp_file
from .table import count_grasps

__all__ = ["register"]

console = Console(stderr=True)


def certify_command(
    grasps: Path = typer.Argument(..., help="Grasp set: .jsonl (JSON Lines) or .parquet."),
    output: Path = typer.Option(..., "-o", "--output", help="Results file: .jsonl or .parquet."),
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
    chunk_size: int = typer.Option(4096, help="Grasps per chunk (unit of work and checkpoint)."),
) -> None:
    """Certify form and force closure of every grasp, one results line per grasp line.

    Exit code 1 when some rows are errors or failed their own re-check, 2 when the run could not
    start (unreadable input, resume refused).
    """

    total = count_grasps(grasps)
    with Progress(TextColumn("certify"), BarColumn(), MofNCompleteColumn(), TimeRemainingColumn(),
                  console=console, disable=quiet) as bar:
        task = bar.add_task("certify", total=total)
        try:
            summary = certify_file(grasps, output, method=method,
                                   progress=lambda n: bar.advance(task, n), quality=quality,
                                   eps_gap=eps_gap, eps_budget=eps_budget,
                                   eps_time=eps_time if eps_time > 0 else None, workers=workers or None,
                                   dask=dask, resume=resume, chunk_size=chunk_size)
        except CertifyError as err:
            console.print(f"[red]error:[/red] {escape(_printable(str(err)))}", soft_wrap=True)
            raise typer.Exit(2)
    if not quiet:
        table = Table(title=f"{summary.rows} grasps -> {output}")
        table.add_column("status")
        table.add_column("rows", justify="right")
        for status, count in sorted(summary.statuses.items()):
            table.add_row(status, str(count))
        table.add_row("unverified", str(summary.unverified))
        if summary.resumed_chunks:
            table.add_row("chunks kept from the interrupted run", str(summary.resumed_chunks))
        console.print(table)
        rate = summary.rows / summary.seconds if summary.seconds > 0 else 0.0
        memory = "" if summary.peak_mb is None else f"; peak memory {summary.peak_mb:.0f} MB" + (
            "" if summary.peak_worker_mb is None else f" (largest worker {summary.peak_worker_mb:.0f} MB)")
        console.print(f"{summary.seconds:.1f} s, {rate:,.0f} grasps/s{memory}")
    if summary.errors or summary.unverified:
        raise typer.Exit(1)


def verify_command(
    results: Path = typer.Argument(..., help="Results file written by 'qualgrasp certify'."),
    grasps: Path = typer.Option(..., "--grasps", help="The grasp set the results came from."),
    workers: int = typer.Option(0, help="Worker processes (0: all cores)."),
) -> None:
    """Re-check every certificate without a solver; print the id of each one that fails."""
    try:
        summary = verify_file(results, grasps, workers=workers or None)
    except CertifyError as err:
        console.print(f"[red]error:[/red] {escape(_printable(str(err)))}", soft_wrap=True)
        raise typer.Exit(2)
    for gid, reason in summary.failures:
        typer.echo(_printable(f"{gid}\t{reason}"))
    checked = summary.rows - summary.errors
    console.print(f"{checked} certified rows re-checked, {summary.errors} error rows skipped, "
                  f"{len(summary.failures)} failed")
    if summary.failures:
        raise typer.Exit(1)


def _printable(text: str) -> str:
    """``text`` with lone surrogates (from invalid UTF-8 or JSON escapes) escaped, on one line."""
    return text.encode("utf-8", "backslashreplace").decode("utf-8").replace("\n", "\\n")


def bench_command(
    n: int = typer.Option(20000, "--n", help="Grasps per kind."),
    seed: int = typer.Option(0, help="Random seed of the grasps."),
    reference_n: int = typer.Option(300, "--reference-n", help="Grasps per kind for slow routes."),
    quality: bool = typer.Option(False, "--quality", help="Benchmark epsilon instead: gaps, times, 8-edge error."),
    contacts: bool = typer.Option(False, "--contacts", help="Time closure and quality of one grasp per contact count "
                                                            "(3 to 1000 point contacts, planar and spatial)."),
) -> None:
    """Time every certification route on the same random grasps, with ratios to the batch path.

    Routes: the batch path, the per-grasp fast route, clarabel, linprog, cvxpy with Parameters
    and cvxpy rebuilt per grasp; prints grasps per second and each route's ratio.

    With --quality: epsilon bound gaps and time per grasp, and the error of the 8-edge cone
    linearisation other toolkits use, on --n random grasps in closure per kind.

    With --contacts: seconds per grasp of closure and of quality (both epsilons with their
    evidence, no time limit) for one grasp in closure with 3, 10, 50, 200 and 1000 point
    contacts, planar and spatial (about a minute).
    """

    if contacts:
        print_contacts_bench(run_contacts_bench(seed=seed))
    elif quality:
        print_quality_bench(run_quality_bench(n=n, seed=seed))
    else:
        print_bench(run_bench(n=n, seed=seed, reference_n=reference_n))


def sample_command(
    output: Path = typer.Argument(..., help="Grasp set to write: .parquet or .jsonl."),
    n: int = typer.Option(100_000, "--n", help="Number of grasps."),
    dim: int = typer.Option(2, help="2 (planar) or 3 (spatial)."),
    contacts: int = typer.Option(3, help="Contacts per grasp."),
    model: str = typer.Option("point", help="Contact model: " + ", ".join(models.names()) + "."),
    seed: int = typer.Option(0, help="Random seed."),
) -> None:
    """Write a random grasp set, for trying the toolkit and for benchmarks at scale.

    Contacts are placed around a random blob; about a third of the grasps are in closure."""

    count = write_random_grasp_file(output, n, seed=seed, dim=dim, n_contacts=contacts, model=model)
    console.print(f"wrote {count} grasps to {output}")


def register(app: typer.Typer) -> None:
    """Add the certify commands to the ``qualgrasp`` application."""
    app.command("certify")(certify_command)
    app.command("verify")(verify_command)
    app.command("bench")(bench_command)
    app.command("sample")(sample_command)

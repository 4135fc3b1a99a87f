"""Command-line layer of :mod:`certify`: ``qualgrasp certify``, ``verify`` and ``bench``.

Each command is a thin wrapper over a public function (:func:`certify.batch.certify_file`,
:func:`certify.batch.verify_file`, :func:`certify.bench.run_bench`).
"""

from __future__ import annotations

from pathlib import Path

import typer
from rich.console import Console
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn
from rich.table import Table

from .batch import certify_file, verify_file
from .errors import CertifyError

__all__ = ["register"]

console = Console(stderr=True)


def _count_lines(path: Path) -> int | None:
    try:
        with path.open("rb") as fh:
            return sum(1 for line in fh if line.strip())
    except OSError:
        return None


def certify_command(
    grasps: Path = typer.Argument(..., help="Grasp set, JSON Lines (one grasp per line)."),
    output: Path = typer.Option(..., "-o", "--output", help="Results file, JSON Lines."),
    method: str = typer.Option("fast", help="'fast' (enumeration/clarabel) or 'reference' (cvxpy)."),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="No progress bar or summary."),
    quality: bool = typer.Option(True, help="Compute the epsilon columns (eps_l1_lo ... eps_linf_hi)."),
    eps_gap: float = typer.Option(0.01, help="Spatial epsilon: stop when hi - lo <= gap * hi."),
    eps_budget: float = typer.Option(5.0, help="Spatial epsilon: seconds per grasp and norm at most."),
) -> None:
    """Certify form and force closure of every grasp, one results line per grasp line.

    Exit code 1 when some rows are errors or failed their own re-check.
    """
    total = _count_lines(grasps)
    with Progress(TextColumn("certify"), BarColumn(), MofNCompleteColumn(), TimeRemainingColumn(),
                  console=console, disable=quiet) as bar:
        task = bar.add_task("certify", total=total)
        try:
            summary = certify_file(grasps, output, method=method,
                                   progress=lambda row: bar.advance(task), quality=quality,
                                   eps_gap=eps_gap, eps_budget=eps_budget)
        except CertifyError as err:
            console.print(f"[red]error:[/red] {err}")
            raise typer.Exit(2)
    if not quiet:
        table = Table(title=f"{summary.rows} grasps -> {output}")
        table.add_column("status")
        table.add_column("rows", justify="right")
        for status, count in sorted(summary.statuses.items()):
            table.add_row(status, str(count))
        table.add_row("unverified", str(summary.unverified))
        console.print(table)
    if summary.errors or summary.unverified:
        raise typer.Exit(1)


def verify_command(
    results: Path = typer.Argument(..., help="Results file written by 'qualgrasp certify'."),
    grasps: Path = typer.Option(..., "--grasps", help="The grasp set the results came from."),
) -> None:
    """Re-check every certificate without a solver; print the id of each one that fails."""
    try:
        summary = verify_file(results, grasps)
    except CertifyError as err:
        console.print(f"[red]error:[/red] {err}")
        raise typer.Exit(2)
    for gid, reason in summary.failures:
        typer.echo(f"{gid}\t{reason}")
    checked = summary.rows - summary.errors
    console.print(f"{checked} certified rows re-checked, {summary.errors} error rows skipped, "
                  f"{len(summary.failures)} failed")
    if summary.failures:
        raise typer.Exit(1)


def bench_command(
    n: int = typer.Option(2000, "--n", help="Grasps per kind."),
    seed: int = typer.Option(0, help="Random seed of the grasps."),
    reference_n: int = typer.Option(300, "--reference-n", help="Grasps per kind for slow routes."),
) -> None:
    """Time the reference (cvxpy) and fast routes on the same random grasps; print a table."""
    from .bench import print_bench, run_bench

    print_bench(run_bench(n=n, seed=seed, reference_n=reference_n))


def register(app: typer.Typer) -> None:
    """Add the certify commands to the ``qualgrasp`` application."""
    app.command("certify")(certify_command)
    app.command("verify")(verify_command)
    app.command("bench")(bench_command)

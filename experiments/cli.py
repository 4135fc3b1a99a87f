"""The ``qualgrasp`` command: one application, subcommands from every half of the toolkit."""

from __future__ import annotations

import json
from pathlib import Path

import typer
from rich.console import Console
from rich.table import Table

import certify.cli
import qualitative.cli

app = typer.Typer(add_completion=False, no_args_is_help=True,
                  help="Qualitative grasp synthesis and convex certification of closure grasps.")
certify.cli.register(app)
qualitative.cli.register(app)
console = Console()


@app.command("demo")
def demo_command(out: Path = typer.Option(Path("qualgrasp-demo"), "--out", help="Output folder.")) -> None:
    """Run the main job on the built-in objects and say what was written where.

    Currently: certifies the built-in textbook grasps (square, pinwheel, disc, antipodal planar and
    spatial, cube) and re-verifies every certificate.
    """
    from .demo import run_demo

    result = run_demo(out)
    table = Table(title="textbook grasps")
    for col in ("id", "force closure", "form closure", "margin", "verified"):
        table.add_column(col)
    with result.results.open() as fh:
        for line in fh:
            row = json.loads(line)
            table.add_row(str(row["id"]), row["status"], row["form_status"],
                          f"{row['margin']:.4g}", str(row["verified"]))
    console.print(table)
    console.print(f"wrote {result.grasps} (grasp set) and {result.results} (results); "
                  f"{len(result.verified.failures)} certificates failed re-verification")
    if result.verified.failures or result.certified.errors:
        raise typer.Exit(1)


def main() -> None:
    app()


if __name__ == "__main__":
    main()

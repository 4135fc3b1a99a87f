"""The ``qualgrasp`` command: one application holding the subcommands of every half.

Each half registers its own commands (:func:`qualgrasp.certify.cli.register`,
:func:`qualgrasp.qualitative.cli.register`, :func:`qualgrasp.experiments.cli.register`); every
command is a thin layer over a public function of its half.
"""

from __future__ import annotations

import typer

from qualgrasp import __version__
from qualgrasp.certify import cli as certify_cli
from qualgrasp.certify.meshes import cli as meshes_cli
from qualgrasp.experiments import cli as experiments_cli
from qualgrasp.experiments.physics import cli as physics_cli
from qualgrasp.qualitative import cli as qualitative_cli

__all__ = ["app", "main"]

app = typer.Typer(add_completion=False, no_args_is_help=True,
                  help="Qualitative grasp synthesis and convex certification of closure grasps.")


def _print_version(value: bool) -> None:
    if value:
        typer.echo(f"qualgrasp {__version__}")
        raise typer.Exit()


@app.callback()
def _options(version: bool = typer.Option(False, "--version", callback=_print_version, is_eager=True,
                                          help="Print the version and exit.")) -> None:
    # options of the application itself, before any command
    pass


certify_cli.register(app)
meshes_cli.register(app)
qualitative_cli.register(app)
experiments_cli.register(app)
physics_cli.register(app)


def main() -> None:
    """Entry point of the ``qualgrasp`` console script."""
    app()


if __name__ == "__main__":
    main()

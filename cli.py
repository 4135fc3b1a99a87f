"""The ``qualgrasp`` command: one application holding the subcommands of every half.

Each half registers its own commands (:func:`qualgrasp.certify.cli.register`,
:func:`qualgrasp.qualitative.cli.register`, :func:`qualgrasp.experiments.cli.register`); every
command is a thin layer over a public function of its half.
"""

from __future__ import annotations

import typer

from qualgrasp.certify import cli as certify_cli
from qualgrasp.experiments import cli as experiments_cli
from qualgrasp.qualitative import cli as qualitative_cli

__all__ = ["app", "main"]

app = typer.Typer(add_completion=False, no_args_is_help=True,
                  help="Qualitative grasp synthesis and convex certification of closure grasps.")
certify_cli.register(app)
qualitative_cli.register(app)
experiments_cli.register(app)


def main() -> None:
    """Entry point of the ``qualgrasp`` console script."""
    app()


if __name__ == "__main__":
    main()

"""Command-line layer of :mod:`qualitative`: each command is a thin wrapper over a public function."""

from __future__ import annotations

import typer

__all__ = ["register"]


def register(app: typer.Typer) -> None:
    """Add the qualitative commands to the ``qualgrasp`` application."""

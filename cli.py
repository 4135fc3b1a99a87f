"""The ``qualgrasp`` command: one application holding the subcommands of every half.

Each half registers its own commands (:func:`qualgrasp.certify.cli.register`,
:func:`qualgrasp.certify.meshes.cli.register`, :func:`qualgrasp.qualitative.cli.register`,
:func:`qualgrasp.experiments.cli.register`, :func:`qualgrasp.experiments.physics.cli.register`);
every command is a thin layer over a public function of its half.

A half's module is imported only when one of its commands runs (or prints its own help), so that
``qualgrasp --help`` and ``qualgrasp --version`` answer without loading numba, scipy, cvxpy,
matplotlib or pyarrow. :data:`COMMANDS` lists every command with the module registering it and the
one-line summary ``qualgrasp --help`` shows; a test holds each summary to the command's own
docstring.
"""

from __future__ import annotations

import importlib
import inspect
from importlib import metadata

import typer
from typer.core import TyperCommand, TyperGroup

__all__ = ["COMMANDS", "AHEAD", "app", "main"]

_CERTIFY = "qualgrasp.certify.cli"
_MESHES = "qualgrasp.certify.meshes.cli"
_QUALITATIVE = "qualgrasp.qualitative.cli"
_EXPERIMENTS = "qualgrasp.experiments.cli"
_PHYSICS = "qualgrasp.experiments.physics.cli"

#: Every subcommand, in the order ``qualgrasp --help`` lists them: the module whose ``register``
#: adds it, and its summary (the first paragraph of its docstring).
COMMANDS: dict[str, tuple[str, str]] = {
    "certify": (_CERTIFY, "Certify form and force closure of every grasp, one results line per grasp line."),
    "verify": (_CERTIFY, "Re-check every certificate without a solver; print the id of each one that fails."),
    "certify-regions": (_CERTIFY, "Certify region tuples: is every choice of one contact per region in force "
                                  "closure?"),
    "sample": (_CERTIFY, "Write a random grasp set, for trying the toolkit and for benchmarks at scale."),
    "contacts": (_MESHES, "Close the gripper at every pose on the mesh and write the contacts as a certify "
                          "grasp set."),
    "sample-poses": (_MESHES, "Sample antipodal parallel-jaw poses on a mesh (qualgrasp convention), free of "
                              "collisions while approaching, ready for 'qualgrasp contacts'."),
    "st0": (_QUALITATIVE, "Evaluate an ST0 formula on a recorded trace: one line per instant, "
                          "index<TAB>true/false."),
    "outline": (_QUALITATIVE, "Print the qualitative outline (canonical curvature-type string) of the object in "
                              "an image."),
    "regions": (_QUALITATIVE, "Print the feasible grasp regions (paper, definitions 1 and 2) of the object in an "
                              "image."),
    "synthesize": (_QUALITATIVE, "Synthesise grasps of the object in an image and write them in certify's grasp "
                                 "format."),
    "independent-regions": (_QUALITATIVE, "How far may each finger of every grasp slide along the object's "
                                          "outline, the grasp certified in force closure wherever on its stretch "
                                          "each finger lands?"),
    "demo": (_EXPERIMENTS, "Run the main job on the built-in objects and say what was written where."),
    "figures": (_EXPERIMENTS, "Draw the paper's figures 3 to 8 and figure 9 (certified regions) from the "
                              "toolkit's own computations and say where they went."),
    "compare": (_EXPERIMENTS, "Compare qualitative grasps with the quantitative baseline: quality, time, "
                              "robustness."),
    "silhouettes": (_EXPERIMENTS, "Write the bundled real silhouettes (cell outlines from geomstats and mosquito "
                                  "wings from ktch, shipped with qualgrasp; scikit-image's horse) as 512 x 512 PNG "
                                  "images."),
    "bench": (_EXPERIMENTS, "Time every certification route on the same random grasps, with ratios to the batch "
                            "path."),
    "validate": (_PHYSICS, "Do certified grasps hold in a physics engine? Planar and spatial trials against "
                           "certified verdicts."),
}


def registered_commands(module: str) -> dict[str, TyperCommand]:
    """The click commands that ``module``'s ``register`` adds, by name (imports the module), each
    help text reflowed (:func:`reflow`)."""
    commands = typer.Typer()
    importlib.import_module(module).register(commands)
    out = dict(typer.main.get_group(commands).commands)
    for command in out.values():
        command.help = reflow(command.help or "")
    return out


def reflow(text: str) -> str:
    r"""``text`` (a docstring) with each paragraph's source line breaks joined: ``--help`` prints
    a paragraph's lines as they are, and rich wraps them again to the terminal. A paragraph
    whose later lines are items or indented (``- ``, ``* ``, ``| ``, a space) keeps its lines.

    Examples
    --------
    >>> reflow("Summary.\n\nOne paragraph\nin two lines.\n\n- an item\n- another")
    'Summary.\n\nOne paragraph in two lines.\n\n- an item\n- another'
    """
    paragraphs = inspect.cleandoc(text).split("\n\n")

    def keep(p: str) -> bool:
        return any(line[:1] == " " or line[:2] in ("- ", "* ", "| ") for line in p.split("\n")[1:])

    return "\n\n".join(p if keep(p) else " ".join(line.strip() for line in p.split("\n")) for p in paragraphs)


#: Commands that start work before their module loads: the function (its module and name) called
#: with the command's arguments. On a cold compile cache ``certify`` has other processes compile
#: quality's kernels meanwhile, on the cores its imports leave idle
#: (:func:`qualgrasp.certify.warmup.compile_ahead_for_command`).
AHEAD: dict[str, tuple[str, str]] = {"certify": ("qualgrasp.certify.warmup", "compile_ahead_for_command")}


class _LazyGroup(TyperGroup):
    """The application's group: lists :data:`COMMANDS` from their summaries, loads one on use."""

    def list_commands(self, ctx: typer.Context) -> list[str]:
        return list(COMMANDS)

    def get_command(self, ctx: typer.Context, cmd_name: str) -> TyperCommand | None:
        # what the group's help lists: the summary only, the command's module left unloaded
        if cmd_name not in COMMANDS:
            return None
        return TyperCommand(cmd_name, help=COMMANDS[cmd_name][1])

    def load_command(self, ctx: typer.Context, cmd_name: str) -> TyperCommand | None:
        """The command itself, with its options (imports the module registering it)."""
        if cmd_name not in COMMANDS:
            return None
        return registered_commands(COMMANDS[cmd_name][0])[cmd_name]

    def resolve_command(self, ctx: typer.Context, args: list[str]):
        name = args[0] if args else None
        if name not in COMMANDS:
            return super().resolve_command(ctx, args)
        if name in AHEAD:
            module, function = AHEAD[name]
            getattr(importlib.import_module(module), function)(args[1:])
        return name, self.load_command(ctx, name), args[1:]


app = typer.Typer(add_completion=False, no_args_is_help=True, cls=_LazyGroup,
                  help="Qualitative grasp synthesis and convex certification of closure grasps.")


def _print_version(value: bool) -> None:
    if value:
        typer.echo(f"qualgrasp {metadata.version('qualgrasp')}")
        raise typer.Exit()


@app.callback()
def _options(version: bool = typer.Option(False, "--version", callback=_print_version, is_eager=True,
                                          help="Print the version and exit.")) -> None:
    # options of the application itself, before any command
    pass


def main() -> None:
    """Entry point of the ``qualgrasp`` console script."""
    app()


if __name__ == "__main__":
    main()

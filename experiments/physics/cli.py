"""Command-line layer of :mod:`qualgrasp.experiments.physics`: ``qualgrasp validate``, a thin
wrapper over :func:`qualgrasp.experiments.physics.study.validate` (planar) and, with ``--spatial``,
:func:`qualgrasp.experiments.physics.spatial_study.validate_spatial` (meshes in MuJoCo)."""

from __future__ import annotations

import importlib.util
from dataclasses import replace
from pathlib import Path

import typer
from rich.console import Console
from rich.markup import escape
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn
from rich.table import Table

from ...certify.cli.options import MAX_WORKERS, OptionError, count_in, output_folder
from ..design import BUILTINS
from ..silhouettes import available_silhouettes, available_wings
from ..silhouettes import silhouettes as bundled
from .spatial_study import validate_spatial
from .study import VALIDATIONS, validate

__all__ = ["register"]

console = Console()

_IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".tif", ".tiff", ".bmp")


def _fail(message: str) -> None:
    """Print a one-line error (no markup interpreted in it) and exit with code 2."""
    console.print("[red]error:[/red]", escape(message), soft_wrap=True)
    raise typer.Exit(2)


def register(app: typer.Typer) -> None:
    """Add ``validate`` to the ``qualgrasp`` application."""
    app.command("validate")(validate_command)


def validate_command(
        folder: Path | None = typer.Argument(None, help="Folder of object images (PNG, JPEG, TIFF, BMP), one "
                                                        "object per image (executed on the contour they show)."),
        out: Path = typer.Option(Path("qualgrasp-validate"), "--out", help="Output folder."),
        builtins: bool = typer.Option(False, "--builtins", help="Add the built-in objects polygon, nut, disc "
                                                                "and figure3."),
        silhouettes: int = typer.Option(0, "--silhouettes", help="Add this many bundled cell silhouettes and the "
                                                                 "horse."),
        wings: int = typer.Option(0, "--wings", help="Add this many bundled mosquito wing silhouettes."),
        setting: str = typer.Option("full", "--setting", help="Size of the work: quick or full."),
        quick: bool = typer.Option(False, "--quick", help="Same as --setting quick (few grasps and trials)."),
        workers: int = typer.Option(2, "--workers", help="Processes."),
        spatial: bool = typer.Option(False, "--spatial", help="Also (alone without images) the spatial study: "
                                                              "grasps on the object meshes of installed packages "
                                                              "(made-up meshes fill up to 20), certified to hold "
                                                              "their weight, executed in MuJoCo."),
) -> None:
    """Do certified grasps hold in a physics engine? Planar and spatial trials against certified verdicts.

    Planar trials (pymunk) of the qualitative, baseline and random grasps of every object, nominal and with placement errors inside and outside their
    certified regions; the simulator's error on closed-form cases. With --spatial, parallel-jaw
    grasps on meshes in MuJoCo against their certified least grip force. Exit code 2 on a refused
    option or output folder, or when pymunk (mujoco for --spatial) is not installed."""
    planar = folder is not None or builtins or silhouettes or wings or not spatial
    if planar and importlib.util.find_spec("pymunk") is None:
        _fail('the physical validation needs pymunk: pip install "qualgrasp[physics]"')
    if spatial and importlib.util.find_spec("mujoco") is None:
        _fail('the spatial validation needs mujoco: pip install "qualgrasp[physics]"')
    setting = "quick" if quick else setting
    if setting not in VALIDATIONS:
        _fail(f"--setting must be one of {', '.join(VALIDATIONS)}, got {setting!r}")
    if folder is not None and not folder.is_dir():
        _fail(f"FOLDER: {folder} is not a folder")
    try:
        count_in(silhouettes, "--silhouettes", 0, available_silhouettes() - 1, what="(the bundled cell outlines)")
        count_in(wings, "--wings", 0, available_wings(), what="(the bundled wing outlines)")
        count_in(workers, "--workers", 1, MAX_WORKERS, what="processes")
        output_folder(out, "--out", reads=[folder] if folder else [])
    except OptionError as err:
        _fail(str(err))
    images: list = sorted(p for p in folder.iterdir() if p.suffix.lower() in _IMAGE_SUFFIXES) if folder else []
    images += list(BUILTINS) if builtins else []
    images += bundled(silhouettes, with_horse=bool(silhouettes), wings=wings) if silhouettes or wings else []
    if not images and not spatial:
        _fail("no images: give a FOLDER of images, --builtins, --silhouettes N or --wings N")
    if spatial:
        _spatial(out, setting)
    if not images:
        return
    settings = replace(VALIDATIONS[setting], workers=workers)
    with Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(),
                  console=console) as bar:
        task = bar.add_task("validate", total=len(images) + 1)
        result = validate(images, out, settings=settings,
                          progress=lambda message: bar.update(task, advance=1, description=message))
    _print(result)


def _spatial(out: Path, setting: str) -> None:
    """Run and print the spatial study (the same --setting)."""
    with Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(),
                  console=console) as bar:
        task = bar.add_task("validate --spatial", total=None)
        result = validate_spatial(out, settings=setting,
                                  progress=lambda message: bar.update(task, advance=1, description=message))
    table = Table(title="the spatial simulator on closed-form cases (relative error; exact 0: the value measured)",
                  box=None, padding=(0, 1, 0, 0), pad_edge=False)
    for col in ("case", "closed form", *result["closed"]):
        table.add_column(col, no_wrap=True)
    for group in zip(*result["closed"].values()):
        c = group[0]
        table.add_row(c.case, c.formula, *(f"{g.error:+.4f}" if g.exact else f"{g.measured:.3g} {g.unit}"
                                           for g in group))
    console.print(table)
    s = result["summary"]
    for outcome, what in (("held", "held under gravity"), ("held_shake", "held after the shake")):
        o = s["overall"][outcome]
        console.print(f"certified to hold at F against {what}: {o['trials']} trials on {len(s['per_mesh'])} meshes, "
                      f"precision {_fmt(o['precision'])}, recall {_fmt(o['recall'])}", soft_wrap=True)
    sp = s["spearman"]
    console.print(f"Spearman of the certified least grip force with the least that holds in physics: "
                  f"{_fmt(sp['rho'], '+.2f')} ({sp['n']} poses)", soft_wrap=True)
    for path in result["files"]:
        console.print(f"wrote {path}", soft_wrap=True)
    console.print(f"{len(result['trials'])} spatial trials in {result['seconds']:.0f} s", soft_wrap=True)


def _fmt(value, spec=".3f") -> str:
    return "-" if value is None else format(value, spec)


def _print(result) -> None:
    table = Table(title="the simulator on closed-form cases (relative error; exact 0: the value measured)",
                  box=None, padding=(0, 1, 0, 0), pad_edge=False)
    for col in ("case", "closed form", *result.closed):
        table.add_column(col, no_wrap=True)
    cases = list(zip(*result.closed.values()))
    for group in cases:
        c = group[0]
        table.add_row(c.case, c.formula, *(f"{g.error:+.3f}" if g.exact else f"{g.measured:.2g}" for g in group))
    console.print(table)
    table = Table(title="certified verdict against the physical outcome (nominal placement)", box=None,
                  padding=(0, 1, 0, 0), pad_edge=False)
    for col in ("grasps", "verdict", "n", "certified", "held", "precision", "recall"):
        table.add_column(col, no_wrap=True)
    for (verdict, source), c in result.summary["confusion"].items():
        table.add_row(source, "planned" if verdict == "certified" else "true object", str(c["grasps"]),
                      str(c["certified"]), str(c["held"]), _fmt(c["precision"]), _fmt(c["recall"]))
    console.print(table)
    s = result.summary["spearman"].get("all", {})
    console.print(f"Spearman with the largest resisted disturbance (certified grasps that held): epsilon "
                  f"{_fmt((s.get('eps') or (None,))[0], '+.2f')}, tolerance "
                  f"{_fmt((s.get('tolerance') or (None,))[0], '+.2f')}", soft_wrap=True)
    for kind, p in result.summary["placements"].items():
        console.print(f"placements {kind} the certified regions: {p['held']} / {p['placements']} held "
                      f"({_fmt(p['rate'])})", soft_wrap=True)
    for r in result.summary["exceptions"]:
        console.print(f"  not held inside: {escape(r['object'])} {escape(r['grasp'])} at {r['error']:.2f} x "
                      f"tolerance: {escape(r['explanation'] or '')}", soft_wrap=True)
    for name, reason in result.skipped:
        console.print(f"skipped {escape(name)}: {escape(reason)}", soft_wrap=True)
    for path in result.files:
        console.print(f"wrote {path}", soft_wrap=True)
    console.print(f"{len(result.rows)} trials in {result.seconds:.0f} s", soft_wrap=True)

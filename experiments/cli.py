"""Command-line layer of :mod:`qualgrasp.experiments`: ``demo``, ``figures``, ``compare``,
``silhouettes`` and ``bench``; each command is a thin wrapper over a public function."""

from __future__ import annotations

import re
from dataclasses import replace
from pathlib import Path

import typer
from rich.console import Console
from rich.markup import escape
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn
from rich.table import Table

from ..certify.batch.engine import tune_allocator
from ..certify.cli.options import MAX_WORKERS, OptionError, count_in, fail, output_folder
from ..certify.errors import CertifyError
from . import figures
from .bench_jobs import print_jobs_bench, run_jobs_bench
from .bench import (print_bench, print_contacts_bench, print_quality_bench, print_single_bench, run_bench,
                    run_contacts_bench, run_quality_bench, run_single_bench)
from .demo import demo_steps, run_demo
from .dexnet import load_dexnet
from .silhouettes import available_silhouettes, available_wings, write_silhouettes
from .silhouettes import silhouettes as bundled
from .study import BUILTINS, SETTINGS, compare, workload
from .style import check_formats

__all__ = ["register"]

console = Console()


def _folder(out: Path, reads: list[Path] = ()) -> Path:
    try:
        return output_folder(out, "--out", reads=reads)
    except OptionError as err:
        fail(str(err), console)


def register(app: typer.Typer) -> None:
    """Add the experiments' commands to the ``qualgrasp`` application."""
    app.command("demo")(demo_command)
    app.command("figures")(figures_command)
    app.command("compare")(compare_command)
    app.command("silhouettes")(silhouettes_command)
    app.command("bench")(bench_command)


def demo_command(out: Path = typer.Option(Path("qualgrasp-demo"), "--out", help="Output folder.")) -> None:
    """Run the main job on the built-in objects and say what was written where.

    The paper's figures 3 to 9; FormGrasp and ForceGrasp on the built-in camera images, certified
    and every certificate re-checked; the comparison study (quick setting); a Markdown report.
    Exit code 1 when a certificate failed its re-check, 2 when the output folder is unusable.
    """
    _folder(out)
    with Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(),
                  console=console) as bar:
        task = bar.add_task("demo", total=demo_steps())
        try:
            result = run_demo(out, progress=lambda message: bar.update(task, advance=1, description=message))
        except CertifyError as err:  # an output the run may not write (a file in the way, a full disk)
            fail(str(err), console)
    table = Table(title="synthesis on the built-in objects, certified and re-checked")
    for col in ("object", "outline", "route", "grasps", "certified", "median eps"):
        table.add_column(col, no_wrap=True)
    for r in result.synthesis:
        eps = "-" if r.median_eps_l1 is None else f"{r.median_eps_l1:.3f}"
        table.add_row(r.name, r.string, f"{r.procedure} {r.fingers}", str(r.grasps), str(r.certified), eps)
    console.print(table)
    table = Table(title="qualitative versus baseline (quick study)")
    for col in ("route", "grasps", "eps best", "best/base", "robust"):
        table.add_column(col, no_wrap=True)
    for r in result.study.routes:
        table.add_row(r.route, str(r.grasps), *("-" if v is None else f"{v:.3f}"
                                                for v in (r.eps_best, r.ratio_best, r.robustness)))
    console.print(table)
    console.print(f"figures: {len(result.figures)} files in {out / 'figures'}", soft_wrap=True)
    console.print(f"grasps: {result.grasps} -> {result.results} ({result.certified.rows} rows, "
                  f"{len(result.verified.failures)} certificates failed the re-check)", soft_wrap=True)
    console.print(f"study: {len(result.study.files)} tables and plots in {out / 'study'}", soft_wrap=True)
    console.print(f"report: {result.report}  ({result.seconds:.0f} s)", soft_wrap=True)
    if not result.ok:
        raise typer.Exit(1)


def figures_command(out: Path = typer.Option(Path("qualgrasp-figures"), "--out", help="Output folder."),
                    formats: str = typer.Option("pdf,png", "--formats",
                                                help="Comma-separated file formats, e.g. pdf,png,svg.")) -> None:
    """Draw the paper's figures 3 to 8 and figure 9 (certified regions) from the toolkit's own
    computations and say where they went."""

    try:
        kinds = check_formats([f.strip() for f in formats.split(",") if f.strip()])
    except ValueError as exc:
        raise typer.BadParameter(str(exc), param_hint="--formats") from exc
    _folder(out)
    try:
        paths = figures.make_figures(out, formats=kinds, progress=lambda message: console.print(message))
    except CertifyError as err:
        fail(str(err), console)
    for path in paths:
        console.print(f"wrote {path}", soft_wrap=True)  # paths stay whole, for copy and paste
    console.print(f"{len(paths)} files in {out}", soft_wrap=True)


_IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".tif", ".tiff", ".bmp")


def compare_command(
        folder: Path | None = typer.Argument(None, help="Folder of object images (PNG, JPEG, TIFF, BMP), "
                                                        "one object per image."),
        out: Path = typer.Option(Path("qualgrasp-compare"), "--out", help="Output folder."),
        builtins: bool = typer.Option(False, "--builtins", help="Add the built-in objects polygon, nut, "
                                                                "disc and figure3."),
        silhouettes: int = typer.Option(0, "--silhouettes", help="Add this many bundled cell silhouettes "
                                                                 "and the horse, rendered in memory."),
        wings: int = typer.Option(0, "--wings", help="Add this many bundled mosquito wing silhouettes (ktch, "
                                                     "Apache-2.0); the study's 61 real objects are --silhouettes 24 "
                                                     "--wings 36."),
        setting: str = typer.Option("quick", "--setting", help="Size of the work: quick or full."),
        workers: int = typer.Option(2, "--workers", help="Processes."),
        trials: int | None = typer.Option(None, "--trials", help="Robustness trials per object, kind and "
                                                                 "size (default: the setting's)."),
) -> None:
    """Compare qualitative grasps with the quantitative baseline: quality, time, robustness."""


    if setting not in SETTINGS:
        raise typer.BadParameter(f"use one of {', '.join(SETTINGS)}", param_hint="--setting")
    if folder is not None and not folder.is_dir():
        raise typer.BadParameter(f"{folder} is not a folder", param_hint="FOLDER")
    available = available_silhouettes()
    try:
        count_in(silhouettes, "--silhouettes", 0, available - 1, what="(the bundled cell outlines)")
        count_in(wings, "--wings", 0, available_wings(), what="(the bundled wing outlines)")
        count_in(workers, "--workers", 1, MAX_WORKERS, what="processes")
        if trials is not None:
            count_in(trials, "--trials", 1, 1000)
    except OptionError as err:
        fail(str(err), console)
    _folder(out, [folder] if folder else [])
    images: list = sorted(p for p in folder.iterdir() if p.suffix.lower() in _IMAGE_SUFFIXES) if folder else []
    images += list(BUILTINS) if builtins else []
    images += bundled(silhouettes, with_horse=bool(silhouettes), wings=wings) if silhouettes or wings else []
    if not images:
        raise typer.BadParameter("no images: give a FOLDER of images, --builtins, --silhouettes N or --wings N")
    settings = replace(SETTINGS[setting], workers=workers,
                       **({} if trials is None else {"trials": trials}))
    with Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(),
                  console=console) as bar:
        task = bar.add_task("compare", total=workload(len(images), settings))
        try:
            result = compare(images, out, settings=settings, progress=_study_ticks(bar, task, settings))
        except CertifyError as err:
            fail(str(err), console)
    table = Table(title=f"{len(result.objects)} objects, {result.seconds:.0f} s; eps: certified L1 of the "
                        "grasps counted, robust: fraction still certified under vision errors; slide: "
                        "median of how far every finger of the best grasp may slide either way "
                        "(certified, fraction of the size); below res, weak edge: certified grasps not "
                        "counted, below the image's resolution or with a contact on a weak edge", box=None,
                  padding=(0, 1, 0, 0), pad_edge=False)
    for col in ("route", "grasps", "cert", "eps med", "eps best", "best/base", "s/obj", "robust",
                "paired", "slide", "below res", "weak edge"):
        table.add_column(col, no_wrap=True)

    def fmt(value, spec=".3f"):
        return "-" if value is None else format(value, spec)

    for r in result.routes:
        table.add_row(r.route, str(r.grasps), fmt(r.certified_fraction), fmt(r.eps_median), fmt(r.eps_best),
                      fmt(r.ratio_best), fmt(r.seconds_median), fmt(r.robustness), fmt(r.robustness_paired),
                      fmt(r.slide_median), str(dict(r.not_counted).get("below_resolution", 0)),
                      str(dict(r.not_counted).get("weak_edge", 0)))
    console.print(table)
    for name, reason in result.skipped:
        console.print(f"skipped {escape(name)}: {escape(reason)}", soft_wrap=True)
    for path in result.files:
        console.print(f"wrote {path}", soft_wrap=True)


def _study_ticks(bar: Progress, task, settings, before: int = 0):
    """A progress callback for :func:`qualgrasp.experiments.study.compare` that keeps the bar's
    total true: the study announces its objects and trials as ``'<phase> k/N'``, after leaving out
    the images it cannot read, so the total becomes ``before`` (earlier steps) plus
    :func:`qualgrasp.experiments.study.workload` of the objects actually compared, and the count
    ends at it."""
    def tick(message: str) -> None:
        phase = re.fullmatch(r"objects \d+/(\d+)", message)
        if phase:
            bar.update(task, total=before + workload(int(phase.group(1)), settings))
        bar.update(task, advance=1, description=message)
    return tick


def silhouettes_command(out: Path = typer.Option(Path("qualgrasp-silhouettes"), "--out", help="Output folder."),
                        n: int = typer.Option(24, "--n", help="Number of cell outlines."),
                        horse: bool = typer.Option(True, "--horse/--no-horse",
                                                   help="Also write scikit-image's horse."),
                        wings: int = typer.Option(0, "--wings", help="Number of mosquito wing outlines.")) -> None:
    """Write the bundled real silhouettes (cell outlines from geomstats and mosquito wings from ktch,
    shipped with qualgrasp; scikit-image's horse) as 512 x 512 PNG images."""

    try:
        count_in(n, "--n", 0, available_silhouettes() - 1, what="(the bundled cell outlines)")
        count_in(wings, "--wings", 0, available_wings(), what="(the bundled wing outlines)")
    except OptionError as err:
        fail(str(err), console)
    _folder(out)
    try:
        paths = write_silhouettes(out, n, with_horse=horse, wings=wings)
    except (OSError, ValueError, CertifyError) as exc:
        fail(str(exc), console)
    console.print(f"wrote {len(paths)} images into {out}", soft_wrap=True)


def bench_command(
    n: int | None = typer.Option(None, "--n", help="Grasps per kind (default 20000; 2000 with --single).",
                          show_default=False),
    seed: int = typer.Option(0, help="Random seed of the grasps."),
    reference_n: int = typer.Option(300, "--reference-n", help="Grasps per kind for slow routes."),
    quality: bool = typer.Option(False, "--quality", help="Benchmark epsilon instead: gaps, times, 8-edge error."),
    contacts: bool = typer.Option(False, "--contacts", help="Time closure and quality of one grasp per contact count "
                                                            "(3 to 1000 point contacts, planar and spatial)."),
    single: bool = typer.Option(False, "--single", help="Time one spatial grasp per call: force_closure against "
                                                        "Dex-Net's force_closure_qp on the same grasps."),
    jobs: bool = typer.Option(False, "--jobs", help="Time the offline job end to end: qualgrasp certify, Parquet in "
                                                    "and out, 2 workers, against per-grasp baselines; start-up "
                                                    "and first-call compile time."),
    quick: bool = typer.Option(False, "--quick", help="With --jobs: 20,000 planar and 2,000 spatial rows per job "
                                                      "instead of 1,000,000 and 100,000."),
    job: list[str] = typer.Option([], "--job", help="With --jobs: only the jobs whose label holds this word "
                                                    "(repeatable; e.g. degenerate, spatial, no-quality)."),
    dexnet: Path | None = typer.Option(None, "--dexnet", show_default=False,
                                       help="With --single: the graspnetAPI 1.2.11 sdist (.tar.gz, its folder or "
                                            "its quality.py) to load Dex-Net from; without it Dex-Net's row is "
                                            "skipped."),
) -> None:
    """Time every certification route on the same random grasps, with ratios to the batch path.

    Routes: the batch path, the per-grasp fast route, clarabel, linprog, cvxpy with Parameters
    and cvxpy rebuilt per grasp; prints grasps per second and each route's ratio. Also the batch
    path with quality (planar, 3 and 10 point contacts) and on a degenerate planar set. All in
    one process whose memory allocator is set as the workers of qualgrasp certify set theirs.

    With --quality: epsilon bound gaps and time per grasp, and the error of the 8-edge cone
    linearisation other toolkits use, on --n random grasps in closure per kind.

    With --contacts: seconds per grasp of closure and of quality (both epsilons with their
    evidence, no time limit) for one grasp in closure with 3, 10, 50, 200 and 1000 point
    contacts, planar and spatial (about a minute).

    With --single: per-call median and 95th percentile of force_closure on --n random spatial
    grasps of three point contacts, as a planning loop calls it, and of Dex-Net's force_closure_qp
    (8-edge cones, no certificate; loaded from --dexnet, which needs cvxopt) on the same grasps,
    in turns of 50 grasps, with the ratio of the medians.

    With --jobs: the offline job end to end, one table from one run: qualgrasp certify on Parquet
    in and out with 2 workers (planar with and without quality, a degenerate planar set and its
    generic counterpart, spatial with and without quality; 1,000,000 planar and 100,000 spatial
    rows, 20,000 and 2,000 with --quick), each against the per-grasp route and cvxpy rebuilt per
    grasp on the same grasps (CPU per grasp); then CLI start-up and the first certify of one line
    with a fresh compile cache. --job selects jobs by a word of their label.
    """
    n = (2000 if single else 20000) if n is None else n
    if n < 1 or reference_n < 0:
        fail(f"--n must be at least 1 and --reference-n at least 0, got {n} and {reference_n}")
    if single and (quality or contacts):
        fail("--single times one grasp per call; it does not go with --quality or --contacts")
    if dexnet is not None and not single:
        fail("--dexnet goes with --single")
    if jobs and (single or quality or contacts):
        fail("--jobs times the whole job; it does not go with --single, --quality or --contacts")
    if quick and not jobs:
        fail("--quick goes with --jobs")
    if job and not jobs:
        fail("--job goes with --jobs")

    if jobs:
        try:
            with Console(stderr=True).status("") as status:
                measured = run_jobs_bench(quick=quick, seed=seed, reference_n=reference_n, kinds=job,
                                          progress=lambda what: status.update(f"bench --jobs: {what}"))
        except OptionError as err:
            fail(str(err))
        print_jobs_bench(*measured)
    elif single:
        try:
            loaded = None if dexnet is None else load_dexnet(dexnet)
        except OptionError as err:
            fail(str(err))
        print_single_bench(run_single_bench(n=n, seed=seed, dexnet=loaded))
    elif contacts:
        print_contacts_bench(run_contacts_bench(seed=seed))
    elif quality:
        print_quality_bench(run_quality_bench(n=n, seed=seed))
    else:
        tune_allocator()  # the batch rows time a worker's path: in a process tuned as workers are
        print_bench(run_bench(n=n, seed=seed, reference_n=reference_n))

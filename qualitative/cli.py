"""Command-line layer of :mod:`qualgrasp.qualitative`: each command is a thin wrapper over a public function."""

from __future__ import annotations

import json
import math
from pathlib import Path

import typer

from ..certify.cli.options import FIGURE_SUFFIXES, number_in, optional_number_in, output_file
from ..certify.files import atomic_output
from ..certify.errors import CertifyError
from ..certify.files import write_grasps
from ..certify.models import MAX_MU
from ..certify.regions.boundary import SEARCH_BUDGET
from .synthesis import procedures
from .errors import FormulaError, QualitativeError, TraceError
from .plots.grasp import synthesis_figure
from .synthesis.independent import independent_file
from .vision.outline import SCALE_MAX, SCALE_MIN, outline_contour, outline_to_dict
from .vision.scales import outline_scales, planning_scale
from .plots.outline import outline_figure
from .synthesis.regions import ALPHA_MAX, FINGER_WIDTH, MARGIN, planning_regions, regions_to_dict
from .reasoning.st0 import evaluate_file
from .synthesis.pipeline import NOT_COUNTED, synthesize
from .vision.contour import extract_contour, read_image

__all__ = ["register", "TOL_MIN", "TOL_MAX"]

#: Range of independent-regions' --tol, pixels: the bisection takes log2(size / tol) steps, each
#: a region certificate, so the finest tolerance bounds the work.
TOL_MIN, TOL_MAX = 1e-6, 1e6


def _fail(message: str) -> None:
    """Print a one-line error and exit with code 2."""
    typer.echo(f"error: {message}", err=True)
    raise typer.Exit(2)


def _threshold(threshold: float | None) -> None:
    if threshold is not None and not math.isfinite(threshold):
        _fail(f"--threshold must be a finite grey level, got {threshold}")


# Segmentation options, the same for every command that reads an object from an image.
LARGEST = typer.Option(False, "--largest", help="With several objects, use the largest whole one.")
THRESHOLD = typer.Option(None, "--threshold", help="Grey level separating object and background, in the "
                         "image's units (default: Otsu's).")
SEGMENTATION = typer.Option("otsu", "--segmentation", help="How the object is told from the background: "
                            "otsu (default: one global grey-level threshold), multiotsu (three grey classes: "
                            "an object with its soft shadow), adaptive (against the local mean: uneven "
                            "lighting) or grabcut (GrabCut from a rectangle around the default "
                            "segmentation's object: a textured background).")
MASK = typer.Option(None, "--mask", help="The object's mask: an image of the same size whose non-zero pixels "
                    "are the object (instead of --segmentation).")
RECT = typer.Option(None, "--rect", help="GrabCut's starting rectangle in pixels, X,Y,W,H (top-left x and y, "
                    "width, height); default: the default segmentation's object box grown by 10 %, or the "
                    "image less 5 % on every side when every object touches the border.")


def _segmentation(threshold: float | None, largest: bool, method: str, mask: Path | None,
                  rect: str | None) -> dict:
    """The segmentation keywords of the qualitative functions from the command's options, checked."""
    _threshold(threshold)  # the combinations are checked where they are used (vision.segment)
    box = None
    if rect is not None:
        try:
            box = tuple(int(v) for v in rect.split(","))
        except ValueError:
            box = ()
        if len(box) != 4:
            _fail(f"--rect must be four whole numbers X,Y,W,H (pixels), got {rect!r}")
    return {"threshold": threshold, "largest": largest, "method": method, "mask": mask, "rect": box}


def _finger_width(finger_width: float) -> None:
    number_in(finger_width, "--finger-width", 1e-3, 1, unit="(fraction of the object's size)")


def _scale_words(used: float, given: float | None, finger_width: float) -> str:
    """``scale 0.00707 (the finger's: pad 0.08 of the object's size)``, or ``scale 0.01 (--scale)``."""
    if given is not None:
        return f"scale {used:.4g} (--scale)"
    return f"scale {used:.4g} (the finger's: pad {finger_width:g} of the object's size)"


def _save(figure, path: Path, dpi: int, reads: list[Path]) -> None:
    """Save a figure through :func:`qualgrasp.certify.files.outputs.atomic_output` (never an input,
    one writer at a time), or exit 2 saying why it could not be written (a full disk, ...)."""
    try:
        with atomic_output(path, "--plot", reads=reads) as tmp:
            figure.savefig(tmp, dpi=dpi, format=path.suffix[1:].lower())
    except CertifyError as err:
        _fail(str(err))


def register(app: typer.Typer) -> None:
    """Add the qualitative commands to the ``qualgrasp`` application."""
    app.command("st0")(st0_command)
    app.command("outline")(outline_command)
    app.command("regions")(regions_command)
    app.command("synthesize")(synthesize_command)
    app.command("independent-regions")(independent_regions_command)


def st0_command(
    formula: str = typer.Argument(..., help="ST0 formula, e.g. 'G(EC(F2,O) -> O EC(F1,O))'."),
    trace: Path = typer.Option(..., "--trace", help='Recorded trace: JSON list of {"X,Y": "REL"} frames.'),
) -> None:
    """Evaluate an ST0 formula on a recorded trace: one line per instant, index<TAB>true/false.

    Exit code 2 when the formula does not parse or the trace file is malformed.
    """

    try:
        values = evaluate_file(formula, trace)
    except (FormulaError, TraceError) as err:
        _fail(str(err))
    for i, value in enumerate(values):
        typer.echo(f"{i}\t{'true' if value else 'false'}")


def outline_command(
    image: Path = typer.Argument(..., help="Image file (PNG, JPEG, anything OpenCV reads)."),
    scale: float | None = typer.Option(None, "--scale", help="Smoothing scale: the Gaussian's standard "
                                       "deviation as a fraction of the object's perimeter, in (0, 0.032] "
                                       "(default the finger's, from --finger-width: the pad width over four "
                                       "perimeters, never below 0.004)."),
    finger_width: float = typer.Option(FINGER_WIDTH, "--finger-width", help="Finger pad width, fraction of "
                                       "the object's size: sets the default --scale, the scale at which the "
                                       "pad feels the outline (as for regions and synthesize)."),
    scales: bool = typer.Option(False, "--scales", help="Print the scale hierarchy instead: one line per "
                                "range of scales (fractions of the perimeter) and its string."),
    as_json: bool = typer.Option(False, "--json", help="Print a JSON object with keys string, scale and "
                                 "segments (with --scales: a JSON list of objects lo, hi, string, corners, "
                                 "convex)."),
    largest: bool = LARGEST,
    threshold: float | None = THRESHOLD,
    segmentation: str = SEGMENTATION,
    mask: Path | None = MASK,
    rect: str | None = RECT,
) -> None:
    """Print the qualitative outline (canonical curvature-type string) of the object in an image.

    By default at the finger's scale, where a pad of --finger-width (0.08 of the object's size)
    feels the outline, W / (4 * perimeter), as regions and synthesize read it; with --scale S, at
    that smoothing scale. The scale used is printed on standard error. With --scales, the hierarchy
    from 0.004 to 0.032: one line per interval, lo..hi<TAB>string. Coordinates in the JSON are
    pixels of the input image, x = column, y = row. Exit code 2 when the image cannot be read or
    does not hold exactly one whole object, or on a bad --scale or --finger-width.
    """

    seg = _segmentation(threshold, largest, segmentation, mask, rect)
    if scale is not None and scales:
        _fail("--scale and --scales exclude each other")
    if scale is not None and not (math.isfinite(scale) and 0 < scale <= SCALE_MAX):
        _fail(f"--scale must be a fraction of the object's perimeter in (0, {SCALE_MAX:g}], got {scale:g}")
    try:
        _finger_width(finger_width)
        if scales:
            hierarchy = outline_scales(image, **seg)
        else:
            contour = extract_contour(image, **seg)
            fine = outline_contour(contour)
            at = planning_scale(fine, finger_width) if scale is None else scale
            outline = fine if at == fine.scale else outline_contour(contour, scale=at)
    except (QualitativeError, ValueError) as err:
        _fail(str(err))
    if not scales:
        typer.echo(f"outline at {_scale_words(outline.scale, scale, finger_width)}: {outline.string}", err=True)
    if scales and as_json:
        typer.echo(json.dumps([{"lo": i.lo, "hi": i.hi, "string": i.string, "corners": i.corners,
                                "convex": i.convex} for i in hierarchy]))
    elif scales:
        for i in hierarchy:
            typer.echo(f"{i.lo:.4g}..{i.hi:.4g}\t{i.string}")
    else:
        typer.echo(json.dumps(outline_to_dict(outline)) if as_json else outline.string)


def regions_command(
    image: Path = typer.Argument(..., help="Image file (PNG, JPEG, anything OpenCV reads)."),
    alpha: float = typer.Option(0.5, "--alpha", help="Bounding-circle diameter threshold of curves, "
                                "as a fraction of the object's size (its enclosing circle's diameter)."),
    finger_width: float = typer.Option(FINGER_WIDTH, "--finger-width",
                                       help="Finger pad width, fraction of the object's size; also sets the "
                                       "default --scale (the finger's)."),
    margin: float = typer.Option(MARGIN, "--margin",
                                 help="Distance kept from element ends, fraction of the object's size."),
    scale: float | None = typer.Option(None, "--scale", help="Outline scale (Gaussian sigma as a fraction of "
                                       "the perimeter, in (0, 0.032]); default the finger's, as for outline "
                                       "and synthesize."),
    as_json: bool = typer.Option(False, "--json", help="Print a JSON object with key regions."),
    plot: Path | None = typer.Option(None, "--plot", help="Save a figure of the outline and regions (PNG)."),
    largest: bool = LARGEST,
    threshold: float | None = THRESHOLD,
    segmentation: str = SEGMENTATION,
    mask: Path | None = MASK,
    rect: str | None = RECT,
) -> None:
    """Print the feasible grasp regions (paper, definitions 1 and 2) of the object in an image.

    On the outline at the finger's scale by default (the regions synthesize plans on; --scale to
    choose another), whose scale and string are printed first. One line per region: type,
    arc-length interval along the contour (pixels), number of points and smallest bounding-circle
    diameter. With --json: points and inward unit normals as lists of [x, y] in pixels of the
    input image (x = column, y = row), and the outline's scale. Exit code 2 on unusable input.
    """

    seg = _segmentation(threshold, largest, segmentation, mask, rect)
    if scale is not None and not (math.isfinite(scale) and 0 < scale <= SCALE_MAX):
        _fail(f"--scale must be a fraction of the object's perimeter in (0, {SCALE_MAX:g}], got {scale:g}")
    try:
        number_in(alpha, "--alpha", 0, ALPHA_MAX, unit="(fraction of the object's size)")
        _finger_width(finger_width)
        number_in(margin, "--margin", 0, 0.5, unit="(fraction of the object's size)", high_open=True)
        if plot is not None:
            output_file(plot, "--plot", suffixes=FIGURE_SUFFIXES, reads=[image, *([mask] if mask else [])])
        contour = extract_contour(image, **seg)
        outline, regions = planning_regions(contour, scale=scale, alpha=alpha, finger_width=finger_width,
                                            margin=margin)
    except (QualitativeError, ValueError) as err:
        _fail(str(err))
    if plot is not None:
        _save(outline_figure(outline, regions, read_image(image)), plot, 120, [image, *([mask] if mask else [])])
    if as_json:
        typer.echo(json.dumps(regions_to_dict(outline, regions, alpha, finger_width, margin)))
        return
    typer.echo(f"outline {outline.string}  at {_scale_words(outline.scale, scale, finger_width)}  "
               f"size {outline.size:.1f} px  {len(regions)} feasible region(s)")
    for r in regions:
        rho = "inf" if r.rho == float("inf") else f"{r.rho:.1f}"
        typer.echo(f"{r.type}\tarc {r.arc[0]:.1f}..{r.arc[1]:.1f} px\t{len(r.points)} points\trho {rho} px")


def synthesize_command(
    image: Path = typer.Argument(..., help="Image file (PNG, JPEG, anything OpenCV reads)."),
    fingers: int | None = typer.Option(None, "--fingers", help="4: FormGrasp (frictionless form closure); "
                                       "2 or 3: ForceGrasp (force closure with friction)."),
    output: Path = typer.Option(..., "-o", "--output", help="Grasp set to write: .jsonl (or .parquet, "
                                "which keeps only certify's fields)."),
    mu: float | None = typer.Option(None, "--mu", help="Friction coefficient of ForceGrasp (default 0.5)."),
    theta_min: float | None = typer.Option(None, "--theta-min", help="Friction cone half-angle in degrees, "
                                           "instead of --mu (mu = tan(theta_min))."),
    alpha: float | None = typer.Option(None, "--alpha", help="Bounding-circle diameter threshold of curves, "
                                       "as a fraction of the object's size (its enclosing circle's diameter); "
                                       "default 0.5, relaxed to the finger's width (0.08) when nothing is "
                                       "found. Given, it is the only one tried."),
    plot: Path | None = typer.Option(None, "--plot", help="Save a figure of the best grasps (PNG): "
                                     "contacts, normals, friction cones, zones of freedom."),
    largest: bool = LARGEST,
    threshold: float | None = THRESHOLD,
    segmentation: str = SEGMENTATION,
    mask: Path | None = MASK,
    rect: str | None = RECT,
    procedure: str | None = typer.Option(None, "--procedure", help="A synthesis procedure by name: "
                                         + ", ".join(f"{p.name} ({p.fingers} fingers, {p.model})"
                                                     for p in procedures.procedures())
                                         + "; instead of --fingers."),
    scale: float | None = typer.Option(None, "--scale", help="Outline scale for regions and procedures "
                                       "(Gaussian sigma as a fraction of the perimeter, 0.001 to 0.032); "
                                       "default the finger's scale, with coarser scales tried when "
                                       "nothing is found."),
    no_tolerance: bool = typer.Option(False, "--no-tolerance", help="Skip the certified tolerance (independent "
                                      "contact regions) of each grasp, about 0.05 to 0.5 s per grasp."),
    finger_width: float = typer.Option(FINGER_WIDTH, "--finger-width", help="Finger pad width, fraction of the "
                                       "object's size: the feasible regions' pad and the default --scale (the "
                                       "finger's), as for outline and regions."),
) -> None:
    """Synthesise grasps of the object in an image and write them in certify's grasp format.

    Contacts are in pixels of the input image (x = column, y = row) with inward unit normals;
    center is the object's area centroid and length its radius. The file goes straight into
    'qualgrasp certify'. Prints one line per grasp (id, regions, certified margin and L1 epsilon,
    the certified slide -- how far, in pixels and as a fraction of the object's size, every finger
    may slide along the outline either way with closure still certified -- and each finger's
    certified extents before/after it, pixels; written to the grasp file as slide, slide_fraction
    and extents, with delta and delta_fraction, the search's half-width before clipping at the
    feasible regions; and whether the image resolves it: a grasp whose certified epsilon is below
    the wrench change a pixel of error can cause is flagged) and a summary. Exit code 0 (with an
    empty file) when no grasp exists, 1 when a synthesised grasp fails certification, 2 on
    unusable input or options.
    """


    if mu is not None and theta_min is not None:
        _fail("give --mu or --theta-min, not both")
    if fingers is None and procedure is None:
        _fail(f"give --fingers or --procedure ({', '.join(procedures.names())})")
    seg = _segmentation(threshold, largest, segmentation, mask, rect)
    try:
        if mu is not None:
            number_in(mu, "--mu", 0, MAX_MU, low_open=True, unit="(friction coefficient)")
        if theta_min is not None:
            number_in(theta_min, "--theta-min (theta_min, the friction cone's half-angle)", 0, 90,
                      low_open=True, high_open=True, unit="degrees")
        if alpha is not None:
            number_in(alpha, "--alpha", 0, ALPHA_MAX, unit="(fraction of the object's size)")
        _finger_width(finger_width)
        output_file(output, "-o", reads=[image, *([mask] if mask else [])])
        if plot is not None:
            output_file(plot, "--plot", suffixes=FIGURE_SUFFIXES, reads=[image, *([mask] if mask else []), output])
        result = synthesize(image, fingers, mu, None if theta_min is None else math.radians(theta_min),
                            alpha, procedure=procedure, tolerance=not no_tolerance, scale=scale,
                            finger_width=finger_width, **seg)
    except (QualitativeError, ValueError) as err:
        _fail(str(err))
    reads = [image, *([mask] if mask else [])]
    try:
        write_grasps(output, result.grasps, reads=reads)
    except CertifyError as err:
        _fail(str(err))
    if plot is not None:
        _save(synthesis_figure(result, read_image(image)), plot, 110, [*reads, output])
    friction = "frictionless" if result.mu is None else f"mu {result.mu:.4g}"
    if not result.grasps:
        typer.echo(f"no grasp found: {result.procedure.title} ({result.fingers} fingers, {friction}): "
                   f"{result.reason}; wrote an empty grasp set to {output}")
        return
    labels = {r.name: r.label for r in NOT_COUNTED}
    for grasp, report, ok, why in zip(result.grasps, result.reports, result.certified, result.not_counted):
        eps = report.epsilons["L1"].hi if report.epsilons else float("nan")
        verdict = "NOT CERTIFIED" if not ok else ", ".join(["verified"] + [labels[w] for w in why])
        tol = "" if no_tolerance else f"\t{_slide(grasp.meta)}"
        typer.echo(f"{grasp.id}\tregions {grasp.meta['regions']}\t{report.force.status}\t"
                   f"margin {report.force.margin:.4f}\teps {eps:.4f}{tol}\t{verdict}")
    s = result.summary()
    typer.echo(f"{s['grasps']} grasp(s) by {result.procedure.title} ({result.fingers} fingers, {friction}) "
               f"at outline scale {result.scale:.4g} ({result.outline.string}), alpha {result.alpha:g}"
               f"{_relaxed(result)}{'' if result.smooth else ', contacts of any normal spread'}, on "
               f"{len(result.regions)} feasible region(s) -> {output}; "
               f"{100 * s['certified_fraction']:.0f} % certified, {s['resolved']} resolved by the image; "
               f"synthesis {s['seconds']:.2f} s, certification {s['certify_seconds']:.2f} s"
               + ("" if s["median_slide_fraction"] is None else
                  f"; median certified slide {s['median_slide_fraction']:.3f} of the object's size "
                  "(every finger may slide that far either way)"))
    typer.echo(f"regions: the grasps' region indices are those of 'qualgrasp regions {image} --scale "
               f"{result.scale!r} --alpha {result.alpha!r} --finger-width {finger_width!r}' (same segmentation "
               "options)")
    for reason in NOT_COUNTED:
        if s[reason.name]:
            typer.echo(f"note: {s[reason.name]} certified grasp(s) {reason.note}")
    if s["certified"] < s["grasps"]:
        typer.echo("error: some synthesised grasps did not certify (a synthesis bug: please report it)", err=True)
        raise typer.Exit(1)


def _slide(meta: dict) -> str:
    """``slide 2.6 px (0.012), extents 2.6/7.7 4.5/20.0 px``: the certified slide and each
    finger's certified extents before/after it (``slide -`` when none was computed)."""
    if meta.get("slide") is None:
        return "slide -"
    extents = " ".join(f"{a:.1f}/{b:.1f}" for a, b in meta["extents"])
    return f"slide {meta['slide']:.1f} px ({meta['slide_fraction']:.3f}), extents {extents} px"


def _relaxed(result) -> str:
    """`` (relaxed from 0.5: curves as round as the finger)`` when the curvature threshold was relaxed."""
    if not result.alphas_tried or result.alpha == result.alphas_tried[0]:
        return ""
    return f" (relaxed from {result.alphas_tried[0]:g}: curves as round as the finger)"


def independent_regions_command(
    image: Path = typer.Argument(..., help="Image file (PNG, JPEG, anything OpenCV reads)."),
    grasps: Path = typer.Argument(..., help="Grasp set (JSON Lines, certify's format), contacts on the object."),
    output: Path = typer.Option(..., "-o", "--output", help="Results file (JSON Lines); never the grasp set."),
    asymmetric: bool = typer.Option(False, "--asymmetric", help="After the common delta, grow each finger's "
                                    "delta in turn (per-finger deltas)."),
    tol: float | None = typer.Option(None, "--tol", help="Bisection tolerance on delta, pixels, in "
                                     f"[{TOL_MIN:g}, {TOL_MAX:g}] (default 1e-3 of the object's size)."),
    normal_tol: float = typer.Option(0.0, "--normal-tol", help="Tolerance on the normals, degrees."),
    budget: int = typer.Option(SEARCH_BUDGET, help="Branch-and-bound work units per region tuple tried "
                               "(curved stretches)."),
    alpha: float | None = typer.Option(None, "--alpha", help="Feasible regions: bounding-circle diameter "
                                       "threshold of curves, fraction of the object's size (default: each "
                                       "grasp's own field alpha, else 0.5)."),
    scale: float | None = typer.Option(None, "--scale", help="Feasible regions: outline scale (Gaussian sigma as "
                                       "a fraction of the perimeter, 0.001 to 0.032; default: each grasp's own "
                                       "field scale, else the finger's, as for outline, regions and synthesize)."),
    finger_width: float = typer.Option(FINGER_WIDTH, "--finger-width", help="Feasible regions: finger pad "
                                       "width, fraction of the object's size (also sets the finger's scale)."),
    largest: bool = LARGEST,
    threshold: float | None = THRESHOLD,
    segmentation: str = SEGMENTATION,
    mask: Path | None = MASK,
    rect: str | None = RECT,
) -> None:
    """How far may each finger of every grasp slide along the object's outline, the grasp
    certified in force closure wherever on its stretch each finger lands?

    One row per grasp line: id, status (robust, not_robust, undecided, error), slide (pixels:
    every finger may slide at least this far either way), slide_fraction (of the object's size),
    extents (per finger, pixels of arc from the contact to each end of its certified region),
    delta, delta_fraction and deltas (the search's half-width of every stretch before clipping at
    the feasible regions), the certified regions (region-set format) and their certificate. A
    finger stays in the feasible region it lies on. Prints one line per grasp. Exit code 1 when
    some rows are errors, 2 when the run cannot start.
    """

    if not (math.isfinite(normal_tol) and 0 <= normal_tol <= math.degrees(0.5)):
        typer.echo(f"error: --normal-tol must be in [0, {math.degrees(0.5):.1f}] degrees", err=True)
        raise typer.Exit(2)
    seg = _segmentation(threshold, largest, segmentation, mask, rect)
    try:
        optional_number_in(tol, "--tol", TOL_MIN, TOL_MAX, unit="pixels")
        if alpha is not None:
            number_in(alpha, "--alpha", 0, ALPHA_MAX, unit="(fraction of the object's size)")
        if scale is not None:
            number_in(scale, "--scale", SCALE_MIN, SCALE_MAX, unit="(fraction of the object's perimeter)")
        _finger_width(finger_width)
        summary = independent_file(image, grasps, output, symmetric=not asymmetric, tol=tol, budget=budget,
                                   normal_tol=math.radians(normal_tol), alpha=alpha, scale=scale,
                                   finger_width=finger_width, **seg)
    except (QualitativeError, CertifyError, ValueError) as err:
        typer.echo(f"error: {err}", err=True)
        raise typer.Exit(2)
    for line in output.read_text(encoding="utf-8").splitlines():
        row = json.loads(line)
        if row["status"] == "error":
            typer.echo(f"{row['id']}\terror\t{row['error']}")
        else:
            extents = " ".join(f"{a:.2f}/{b:.2f}" for a, b in row["extents"])
            typer.echo(f"{row['id']}\t{row['status']}\tslide {row['slide']:.2f} px\t"
                       f"{100 * row['slide_fraction']:.2f} % of the size\textents {extents} px")
    typer.echo(f"{summary.rows} grasp(s) -> {output}: " + ", ".join(f"{n} {s}" for s, n in sorted(summary.statuses.items()))
               + f"; {summary.seconds:.1f} s")
    for at, string in summary.outlines.items():
        typer.echo(f"feasible regions on the outline at scale {at:.4g}: {string}")
    if summary.errors:
        raise typer.Exit(1)

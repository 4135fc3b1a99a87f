"""The paper's figures 3 to 8, and figure 9 (certified independent contact regions), drawn from
the project's own computations.

Every figure starts from a synthetic camera image of a built-in object
(:func:`qualgrasp.qualitative.objects.render`, 512 x 512 pixels) and shows what the toolkit computes from it:
the qualitative outline and its canonical string (figure 3), feasible grasp regions (figure 4),
the zones of freedom of a synthesised FormGrasp grasp contact by contact (figure 5), ForceGrasp
grasps with two and three fingers and their friction cones (figures 6 and 7), and the
positive-spanning test on normals (figure 8), and the certified independent contact regions of a
three-finger grasp beside a region tuple that is not robust, with its witness (figure 9, the
paper's figure 4 turned into a guarantee). Numbers in the titles (strings, angles, margins,
epsilons) are read from those computations and from :mod:`qualgrasp.certify`, never typed in.

Choices
-------
* Figures 5 to 8 use the irregular ``polygon`` (the paper's figure 4a), friction ``mu = 0.5`` for
  ForceGrasp. The grasp shown is the one with the largest **certified** margin
  (:func:`best_grasp`), except in figure 6, which is about Nguyen's angles: it shows the certified
  pair whose angles are largest (:func:`nguyen_example`; the best pair is nearly antipodal).
* Figure 5 needs the first two lines of action to cross near the object, as at ``E`` in the
  paper's figure 5b, or the reduced zones after two contacts lie off the picture; among the grasps
  whose certified margin is within :data:`NEAR_BEST` of the best, it takes the one whose first two
  normal lines cross closest to the object's centroid (:func:`form_example`).
* Figure 8b replaces the third contact of figure 8a's grasp by the candidate contact (a point of a
  feasible region, away from the other two fingers) that leaves the three normals farthest inside
  a half-plane, among those for which :func:`qualgrasp.certify.certify_grasp` finds no force closure
  (:func:`spanning_examples`).
* Figure 9 shows, among the three-finger grasps with certified regions, the one of largest
  certified tolerance whose whole feasible regions are not robust (:func:`regions_example`), so
  that both panels are about the same fingers.

Conventions: pixel coordinates of the image (x = column, y = row, y pointing down), so
"clockwise" is as seen on the page; axes carry no ticks (pixels mean nothing to a reader).
"""

from __future__ import annotations

import math
import textwrap
from collections import Counter
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Callable, Mapping, Sequence

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Circle, Patch, Polygon as MplPolygon, Wedge
from shapely.geometry import Polygon as ShapelyPolygon

from qualgrasp.certify import Contact, Grasp, Report, Verdict, certify_grasp, positive_span
from qualgrasp.certify.regions import CurvedRegion, RegionTuple, RegionVerdict, StraightRegion, certify_regions
from qualgrasp.qualitative.synthesis.candidates import separated
from qualgrasp.qualitative.synthesis.forcegrasp import GAP, ForceGrasp, friction_zone, positively_spans, span_margin
from qualgrasp.qualitative.synthesis.formgrasp import zone_steps
from qualgrasp.qualitative.plots.grasp import plot_contacts, plot_form_step, plot_grasp
from qualgrasp.qualitative.objects import render
from qualgrasp.qualitative.vision.outline import Outline, outline_image
from qualgrasp.qualitative.vision.grammar import NAMES
from qualgrasp.qualitative.plots.outline import curvature_handles, draw_frame, plot_outline, plot_regions
from qualgrasp.qualitative.synthesis.regions import ALPHA, feasible_regions
from qualgrasp.qualitative.synthesis.pipeline import MU, Synthesis, synthesize
from qualgrasp.qualitative.synthesis.zones import Zones

from . import style

__all__ = ["OBJECT", "MU", "NEAR_BEST", "STEMS", "Spanning", "best_grasp", "form_example", "nguyen_example",
           "spanning_examples", "zone_share", "fig3_outline", "fig4_regions", "fig5_zones", "fig6_two_fingers",
           "fig7_three_fingers", "fig8_spanning", "regions_example", "fig9_regions", "make_figures"]

OBJECT = "polygon"
NEAR_BEST = 0.05
THETA_MIN = r"$\theta_{\min}$"
FIG4_OBJECTS = (("polygon", "polygon"), ("nut", "hexagonal nut"), ("disc", "circular contour"))
STEMS = ("fig3_outline", "fig4_regions", "fig5_zones", "fig6_two_fingers", "fig7_three_fingers",
         "fig8_spanning", "fig9_regions")


# --------------------------------------------------------------------------------------------------
# What the figures show, computed


def best_grasp(synth: Synthesis) -> int:
    """Index of the grasp with the largest certified margin (the qualitative margin breaks ties).

    Raises
    ------
    ValueError
        The synthesis found no grasp, or was not certified.
    """
    if not synth.found or not synth.reports:
        raise ValueError(f"{synth.name}: {synth.procedure.title} found no certified grasp to draw")
    return max(range(len(synth.found)), key=lambda k: (synth.reports[k].force.margin, _own_margin(synth, k)))


def _own_margin(synth: Synthesis, k: int) -> float:
    g = synth.found[k]
    return g.margin if isinstance(g, ForceGrasp) else -g.depth


def _crossing(points: np.ndarray, normals: np.ndarray) -> np.ndarray | None:
    """Where the lines of action of two contacts cross (None when parallel)."""
    m = np.column_stack([normals[0], -normals[1]])
    if abs(np.linalg.det(m)) < 1e-9:
        return None
    t = np.linalg.solve(m, points[1] - points[0])
    return points[0] + t[0] * normals[0]


def form_example(synth: Synthesis) -> tuple[int, list[Zones]]:
    """The FormGrasp grasp figure 5 shows, and its zones of freedom after each contact.

    Among the grasps within :data:`NEAR_BEST` (relative) of the best certified margin, the one whose
    first two lines of action cross closest to the object's centroid (see the module notes).
    """
    best = synth.reports[best_grasp(synth)].force.margin
    near = [k for k, r in enumerate(synth.reports) if r.force.margin >= (1 - NEAR_BEST) * best]

    def distance(k: int) -> float:
        e = _crossing(synth.found[k].points[:2], synth.found[k].normals[:2])
        return math.inf if e is None else float(np.linalg.norm(e - synth.center))

    k = min(near, key=lambda i: (distance(i), -synth.reports[i].force.margin))
    return k, zone_steps(synth.found[k], synth.center, synth.length)


@dataclass(frozen=True, eq=False)
class Spanning:
    """Three contacts and the verdicts on their normals (figure 8).

    Attributes
    ----------
    points, normals : numpy.ndarray
        ``(3, 2)`` contact points and inward unit normals, pixels.
    spans : bool
        :func:`qualgrasp.qualitative.synthesis.forcegrasp.positively_spans` of the normals (angular-gap rule).
    gap : float
        Largest angular gap between the normals, radians (``spans`` iff below pi).
    certified : Verdict
        :func:`qualgrasp.certify.positive_span` of the normals (linear programme, certificate).
    report : Report
        :func:`qualgrasp.certify.certify_grasp` of the grasp with friction ``mu``.
    zone : float
        Area of the friction zone (the cones' intersection), fraction of the object's area.
    """

    points: np.ndarray
    normals: np.ndarray
    spans: bool
    gap: float
    certified: Verdict
    report: Report
    zone: float


def _spanning(synth: Synthesis, points: np.ndarray, normals: np.ndarray, gid: str) -> Spanning:
    grasp = Grasp(tuple(Contact(tuple(p), tuple(n), "point", synth.mu) for p, n in zip(points, normals)),
                  center=tuple(synth.center), length=synth.length, id=gid)
    return Spanning(points, normals, positively_spans(normals), float(np.pi - 2 * span_margin(normals)),
                    positive_span(normals), certify_grasp(grasp), zone_share(synth, points, normals))


def zone_share(synth: Synthesis, points: np.ndarray, normals: np.ndarray) -> float:
    """Area of the contacts' friction zone, fraction of the object's area (0 when empty)."""
    zone = friction_zone(points, normals, synth.theta_min, 2 * synth.outline.size)
    return float(zone.area / ShapelyPolygon(synth.outline.contour).area)


def spanning_examples(synth: Synthesis) -> tuple[Spanning, Spanning]:
    """Figure 8: the best three-finger grasp, and the same with its third contact moved so that the
    normals lie in a half-plane and the grasp is not in force closure (see the module notes)."""
    k = best_grasp(synth)
    g = synth.found[k]
    good = _spanning(synth, g.points, g.normals, synth.grasps[k].id)
    P, N = np.asarray(synth.candidates.points), np.asarray(synth.candidates.normals)
    # ForceGrasp's own spacing between fingers
    far = separated(P, GAP, synth.outline.size)[:, list(g.contacts[:2])].all(axis=1)
    trials = np.concatenate([np.broadcast_to(g.normals[:2], (len(N), 2, 2)), N[:, None]], axis=1)
    margins = span_margin(trials)
    for c in np.argsort(margins):  # farthest inside a half-plane first
        if not far[c] or margins[c] >= 0:
            continue
        bad = _spanning(synth, np.vstack([g.points[:2], P[c]]), np.vstack([g.normals[:2], N[c]]),
                        f"{synth.grasps[k].id}-moved")
        if bad.report.force.status == "no_closure":
            return good, bad
    raise ValueError(f"{synth.name}: no candidate contact leaves the normals in a half-plane")


# --------------------------------------------------------------------------------------------------
# Figure 3


def fig3_outline(image: np.ndarray | None = None) -> Figure:
    """The qualitative outline of the figure-3 object: each segment's type on it, the string above.

    Parameters
    ----------
    image : numpy.ndarray, optional
        Camera image (default: the built-in ``figure3`` object).

    Returns
    -------
    matplotlib.figure.Figure
    """
    image = render("figure3") if image is None else image
    outline = outline_image(image)
    with style.context():
        fig = style.new_figure(5.4, 6.2)
        ax = fig.subplots()
        plot_outline(ax, outline)
        style.show_image(ax, image)
        _start_arrow(ax, outline)
        style.clean(ax)
        counts = Counter(outline.string)
        ax.set_title(f"string  {outline.string}", fontfamily="monospace", fontsize=12, fontweight="bold")
        tally = ", ".join(f"{counts[s]} {NAMES[s]}{'s' if counts[s] > 1 else ''}"
                          for s in "/)(><}{" if counts[s])
        fig.suptitle("Qualitative outline of the figure-3 object")
        ax.set_xlabel(textwrap.fill(f"{tally}.", 60) + "\nRead clockwise from the arrow; any cyclic rotation "
                      "of the string\ndescribes the same outline (shown: the lexicographically least).",
                      fontsize=8.5)
        fig.legend(handles=curvature_handles(sorted(counts, key="/)(><}{".index)), loc="outside lower center",
                   ncols=3, prop={"family": "monospace", "size": 8})
    return fig


def _start_arrow(ax: Axes, outline: Outline) -> None:
    """An arrow along the contour where the canonical string starts, in the direction of reading."""
    n = len(outline.contour)
    seg = outline.segments[0]
    i = seg.start + max(1, (seg.stop - seg.start) // 6)
    a, b = outline.contour[i % n], outline.contour[(i + max(3, n // 40)) % n]
    shift = -0.06 * outline.size * outline.normals()[i % n]  # just outside the object
    ax.annotate("", b + shift, a + shift, arrowprops={"arrowstyle": "-|>", "color": "black", "lw": 1.4},
                zorder=6)
    ax.annotate("start", a + shift, a + 2.2 * shift, ha="center", va="center", fontsize=8, zorder=6)


# --------------------------------------------------------------------------------------------------
# Figure 4


def fig4_regions(images: Mapping[str, np.ndarray] | None = None, alpha: float = ALPHA) -> Figure:
    """Feasible grasp regions on the polygon, the hexagonal nut and the circular contour.

    On curves, the dashed circle has the threshold diameter ``alpha * D`` (``D`` the object's
    size): a curve is feasible where its bounding circle under a finger pad is larger.

    Parameters
    ----------
    images : mapping of str to numpy.ndarray, optional
        Camera images of ``polygon``, ``nut`` and ``disc`` (default: rendered).
    alpha : float
        Curvature threshold, fraction of the object's size.

    Returns
    -------
    matplotlib.figure.Figure
    """
    images = {name: render(name) for name, _ in FIG4_OBJECTS} if images is None else images
    with style.context():
        fig = style.new_figure(10.5, 4.3)
        axes = fig.subplots(1, len(FIG4_OBJECTS))
        types: set[str] = set()
        for letter, ax, (name, label) in zip("abc", axes, FIG4_OBJECTS):
            outline = outline_image(images[name])
            regions = feasible_regions(outline, alpha)
            plot_regions(ax, outline, regions)
            style.show_image(ax, images[name])
            style.clean(ax)
            types |= {r.type for r in regions}
            curves = [r for r in regions if r.type != "/"]
            count = f"{len(regions)} feasible region{'s' * (len(regions) != 1)}"
            if curves:
                rho = min(r.rho for r in curves) / outline.size
                detail = f"{count}: $\\rho$ = {rho:.2f} D > $\\alpha$ = {alpha:.2f} D"
                for r in curves:
                    _threshold_circle(ax, r, alpha * outline.size)
            else:
                detail = f"{count} (straight: no curvature test)"
            ax.set_title(f"{letter}. {label}   {outline.string}\n{detail}")
        handles = curvature_handles(sorted(types, key="/)(".index), region=True)
        handles += [Line2D([], [], color="0.3", marker=r"$\rightarrow$", ls="none", ms=10, label="inward normal"),
                    Line2D([], [], color="0.3", ls="--", lw=1, label=r"threshold circle, diameter $\alpha$ D"),
                    Line2D([], [], color="0.4", marker="o", ls="none", ms=5, label="angle (not graspable)")]
        fig.legend(handles=handles, loc="outside lower center", ncols=len(handles), prop={"size": 8})
        fig.suptitle("Feasible grasp regions (D: object size, $\\rho$: bounding-circle diameter under a finger)")
    return fig


def _threshold_circle(ax: Axes, region, diameter: float) -> None:
    """The threshold circle, tangent to the contour inside, at the middle of a curved region."""
    i = len(region.points) // 2
    centre = region.points[i] + region.normals[i] * diameter / 2
    ax.add_patch(Circle(tuple(centre), diameter / 2, fill=False, ls="--", lw=1, color="0.3", zorder=5))


# --------------------------------------------------------------------------------------------------
# Figure 5


def _zone_words(z: Zones) -> str:
    parts = []
    for name, status in (("Z+", z.plus.status), ("Z-", z.minus.status), ("T", z.translations.status)):
        parts.append(f"{name} {'= ∅' if status == 'empty' else '≠ ∅' if status == 'nonempty' else status}")
    return ", ".join(parts)


def fig5_zones(synth: Synthesis | None = None, image: np.ndarray | None = None) -> Figure:
    """Zones of freedom of a synthesised FormGrasp grasp after one, two, three and four contacts.

    Parameters
    ----------
    synth : Synthesis, optional
        A certified FormGrasp synthesis (default: the ``polygon``, four fingers).
    image : numpy.ndarray, optional
        Its camera image, drawn underneath.

    Returns
    -------
    matplotlib.figure.Figure
    """
    image = render(OBJECT) if image is None and synth is None else image
    synth = synthesize(image, 4, name=OBJECT) if synth is None else synth
    k, steps = form_example(synth)
    report = synth.reports[k]
    with style.context():
        fig = style.new_figure(8.4, 9.2)
        axes = fig.subplots(2, 2).ravel()
        for count, (ax, z) in enumerate(zip(axes, steps), start=1):
            plot_form_step(ax, synth, k, count, None, z, labels=True)
            if image is not None:
                style.show_image(ax, image)
            style.clean(ax)
            head = f"{'abcd'[count - 1]}. {count} contact{'s' * (count > 1)}: "
            if z.status == "closure":
                ax.set_title(head + f"Z = ∅, form closure (depth {z.depth:+.2f})\n"
                             f"certified margin {report.force.margin:.3f}, $\\varepsilon$ = {_eps(report):.3f}",
                             color=style.GOOD)
            else:
                ax.set_title(head + f"{_zone_words(z)}\n(depth {z.depth:+.2f})")
            if count == 2:
                _mark_crossing(ax, synth.found[k])
        fig.legend(handles=_zone_handles(), loc="outside lower center", ncols=3)
        fig.suptitle(f"Zones of freedom of FormGrasp grasp {synth.grasps[k].id} (frictionless)")
    return fig


def _mark_crossing(ax: Axes, grasp) -> None:
    """``E``, where the first two lines of action cross (the paper's figure 5b), when in view."""
    e = _crossing(grasp.points[:2], grasp.normals[:2])
    (x0, x1), (y1, y0) = ax.get_xlim(), ax.get_ylim()
    if e is None or not (x0 < e[0] < x1 and y0 < e[1] < y1):
        return
    ax.plot(*e, "o", color="black", ms=4, zorder=9)
    ax.annotate("E", e, xytext=(6, -6), textcoords="offset points", fontsize=10, fontweight="bold", zorder=9,
                bbox={"boxstyle": "round,pad=0.1", "facecolor": "white", "edgecolor": "none", "alpha": 0.8})


def _zone_handles() -> list:
    return [Line2D([], [], ls="none", marker="o", mfc="white", mec="black", label="contact (order placed)"),
            Line2D([], [], color="black", label="inward normal"),
            Line2D([], [], ls="--", color="0.25", label="line of action"),
            Patch(label="Z+: centres of clockwise rotation", **style.ZPLUS),
            Patch(label="Z-: centres of counter-clockwise rotation", **style.ZMINUS),
            Patch(color=style.TCOLOR, alpha=0.45, label="T: free translations")]


# --------------------------------------------------------------------------------------------------
# Figures 6 and 7


def nguyen_example(synth: Synthesis) -> int:
    """The two-finger grasp figure 6 shows: the certified one with the largest Nguyen angle.

    The figure is about the angles between the normals and the grasp line, so it shows the
    certified grasp where they are largest (the grasp with the best margin is often almost
    antipodal, angles below a degree, which would leave nothing to see).
    """
    ok = [k for k, good in enumerate(synth.certified) if good]
    if not ok:
        return best_grasp(synth)
    return max(ok, key=lambda k: (max(synth.found[k].angles), k))


def _angle_arc(ax: Axes, point: np.ndarray, a: np.ndarray, b: np.ndarray, radius: float, text: str) -> None:
    """The angle from direction ``a`` to ``b`` at ``point``, as an arc with its value beside it."""
    ta, tb = math.atan2(a[1], a[0]), math.atan2(b[1], b[0])
    sweep = (tb - ta + math.pi) % (2 * math.pi) - math.pi  # the short way round
    t = ta + np.linspace(0.0, sweep, 30)
    ax.plot(point[0] + radius * np.cos(t), point[1] + radius * np.sin(t), color="black", lw=1.2, zorder=8)
    axis = point + 1.3 * radius * np.asarray(a) / np.linalg.norm(a)  # the cone's axis, out to the arc
    ax.plot([point[0], axis[0]], [point[1], axis[1]], ls=":", color="black", lw=1, zorder=5)
    # the value beside the arc, on the side of the normal away from the grasp line
    side = ta - math.copysign(math.radians(28), sweep)
    where = point + 1.25 * radius * np.array([math.cos(side), math.sin(side)])
    ax.text(*where, text, ha="center", va="center", fontsize=9, zorder=9,
            bbox={"boxstyle": "round,pad=0.15", "facecolor": "white", "edgecolor": "none", "alpha": 0.85})


def _eps(report: Report) -> float:
    return report.epsilons["L1"].hi if report.epsilons else 0.0


def _verdict(report: Report) -> str:
    """Certification in words: status, and margin and epsilon when in closure."""
    force = report.force
    if force.status != "closure":
        return f"certify: {force.status.replace('_', ' ')}"
    return f"certify: closure, margin {force.margin:.3f}, $\\varepsilon$ = {_eps(report):.3f}"


def _cone_handles(synth: Synthesis) -> list:
    return [Line2D([], [], ls="none", marker="o", mfc="white", mec="black", label="contact"),
            Line2D([], [], color="black", label="inward normal"),
            Patch(label=f"friction cone, half-angle {THETA_MIN} = atan $\\mu$ = {math.degrees(synth.theta_min):.1f}°",
                  facecolor=style.CONE["facecolor"], edgecolor=style.CONE["edgecolor"], alpha=0.4),
            Line2D([], [], lw=4, alpha=0.35, color=style.CURVATURE["/"]["color"], label="feasible region")]


def _force_synthesis(synth: Synthesis | None, image: np.ndarray | None,
                     fingers: int) -> tuple[Synthesis, np.ndarray | None]:
    """The given ForceGrasp synthesis, or the default one on the built-in object."""
    image = render(OBJECT) if image is None and synth is None else image
    return (synthesize(image, fingers, mu=MU, name=OBJECT) if synth is None else synth), image


def _grasp_figure(synth: Synthesis, k: int, image: np.ndarray | None, heading: str,
                  handles: list) -> tuple[Figure, Axes]:
    """A one-panel figure with grasp ``k`` drawn over the camera image, the cone legend plus
    ``handles`` below it and ``heading`` (with mu and the grasp's id) on top (inside
    ``style.context``)."""
    fig = style.new_figure(5.6, 6.6)
    ax = fig.subplots()
    plot_grasp(ax, synth, k, inset=False)
    if image is not None:
        style.show_image(ax, image)
    style.clean(ax)
    fig.legend(handles=_cone_handles(synth) + handles, loc="outside lower center", ncols=2)
    fig.suptitle(f"{heading}, $\\mu$ = {synth.mu:g}: {synth.grasps[k].id}")
    return fig, ax


def fig6_two_fingers(synth: Synthesis | None = None, image: np.ndarray | None = None) -> Figure:
    """A two-finger ForceGrasp grasp: friction cones, grasp line, Nguyen's angles.

    Parameters
    ----------
    synth : Synthesis, optional
        A certified two-finger ForceGrasp synthesis (default: the ``polygon``, ``mu = 0.5``).
    image : numpy.ndarray, optional
        Its camera image, drawn underneath.

    Returns
    -------
    matplotlib.figure.Figure
    """
    synth, image = _force_synthesis(synth, image, 2)
    k = nguyen_example(synth)
    g, report = synth.found[k], synth.reports[k]
    t1, t2 = g.angles
    ok = max(t1, t2) < synth.theta_min
    with style.context():
        fig, ax = _grasp_figure(synth, k, image, "Two fingers",
                                [Line2D([], [], color=style.GRASP_LINE, label="grasp line F1 F2")])
        for i, theta in enumerate((t1, t2)):
            p, q = g.points[i], g.points[1 - i]
            _angle_arc(ax, p, g.normals[i], q - p, 0.16 * synth.outline.size,
                       f"$\\theta_{i + 1}$ = {math.degrees(theta):.1f}°")
        relation = "<" if ok else "≥"
        ax.set_title(f"$\\theta_1$ = {math.degrees(t1):.1f}°, $\\theta_2$ = {math.degrees(t2):.1f}° {relation} "
                     f"{THETA_MIN} = {math.degrees(synth.theta_min):.1f}°: the grasp line "
                     f"{'lies inside' if ok else 'leaves'} both cones\n{_verdict(report)}",
                     color=style.GOOD if ok else style.BAD)
    return fig


def fig7_three_fingers(synth: Synthesis | None = None, image: np.ndarray | None = None) -> Figure:
    """A three-finger ForceGrasp grasp: friction cones and their non-empty intersection.

    Parameters
    ----------
    synth : Synthesis, optional
        A certified three-finger ForceGrasp synthesis (default: the ``polygon``, ``mu = 0.5``).
    image : numpy.ndarray, optional
        Its camera image, drawn underneath.

    Returns
    -------
    matplotlib.figure.Figure
    """
    synth, image = _force_synthesis(synth, image, 3)
    k = best_grasp(synth)
    g, report = synth.found[k], synth.reports[k]
    share = zone_share(synth, g.points, g.normals)
    with style.context():
        fig, ax = _grasp_figure(synth, k, image, "Three fingers", [
            Patch(label="friction zone (the cones' intersection)", **style.ZONE),
            Line2D([], [], ls="none", marker="*", color=style.MEET, ms=10, label="where the forces meet")])
        state = f"non-empty, {100 * share:.0f} % of the object's area" if share > 0 else "empty"
        ax.set_title(f"friction zone {state};\nangular margin {math.degrees(g.margin):.1f}°; {_verdict(report)}",
                     color=style.GOOD if share > 0 else style.BAD)
    return fig


# --------------------------------------------------------------------------------------------------
# Figure 8


def _normals_panel(ax: Axes, ex: Spanning) -> None:
    """The normals drawn from one point, their largest angular gap shaded, the verdict below."""
    angles = np.sort(np.arctan2(ex.normals[:, 1], ex.normals[:, 0]))
    gaps = np.diff(np.concatenate([angles, angles[:1] + 2 * np.pi]))
    i = int(np.argmax(gaps))
    colour = style.GOOD if ex.spans else style.BAD
    ax.add_patch(Circle((0, 0), 1.0, fill=False, color="0.75", lw=0.8))
    ax.add_patch(Wedge((0, 0), 0.75, math.degrees(angles[i]), math.degrees(angles[i] + gaps[i]), color=colour,
                       alpha=0.25, lw=0))
    mid = angles[i] + gaps[i] / 2
    ax.text(0.45 * math.cos(mid), 0.45 * math.sin(mid), f"gap\n{math.degrees(ex.gap):.0f}°", ha="center",
            va="center", fontsize=8.5, color=colour, fontweight="bold")
    for j, n in enumerate(ex.normals):
        ax.annotate("", n, (0, 0), arrowprops={"arrowstyle": "-|>", "color": "black", "lw": 1.4})
        ax.text(*(1.2 * n), str(j + 1), ha="center", va="center", fontsize=9, fontweight="bold")
    ax.set_xlim(-1.4, 1.4)
    ax.set_ylim(1.4, -1.4)  # same orientation as the image
    ax.set_aspect("equal")
    style.clean(ax)
    for spine in ax.spines.values():
        spine.set_visible(False)
    verdict = "positively span the plane" if ex.spans else "lie in a half-plane: do not span"
    ax.set_title("the normals from one point", fontsize=9)
    ax.set_xlabel(f"{verdict}\nlargest gap {math.degrees(ex.gap):.0f}° {'<' if ex.spans else '>'} 180°; "
                  f"certify.positive_span: {ex.certified.status.replace('_', ' ')}", color=colour, fontsize=9)


def fig8_spanning(synth: Synthesis | None = None, image: np.ndarray | None = None) -> Figure:
    """Normals that positively span the plane (a force-closure grasp) and normals that do not.

    Parameters
    ----------
    synth : Synthesis, optional
        A certified three-finger ForceGrasp synthesis (default: the ``polygon``, ``mu = 0.5``).
    image : numpy.ndarray, optional
        Its camera image, drawn underneath.

    Returns
    -------
    matplotlib.figure.Figure
    """
    image = render(OBJECT) if image is None and synth is None else image
    synth = synthesize(image, 3, mu=MU, name=OBJECT) if synth is None else synth
    examples = spanning_examples(synth)
    with style.context():
        fig = style.new_figure(8.4, 8.0)
        grid = fig.add_gridspec(2, 2, height_ratios=[1.0, 0.6])
        for col, (letter, ex) in enumerate(zip("ab", examples)):
            ax = fig.add_subplot(grid[0, col])
            _spanning_grasp(ax, synth, ex, image, first=col == 0)
            closure = ex.report.force.status == "closure"
            zone = f"friction zone {100 * ex.zone:.0f} % of the object" if ex.zone > 0 else "no friction zone"
            head = "ForceGrasp grasp" if closure else "contact 3 moved"
            but = "but " if ex.zone > 0 and not closure else ""
            ax.set_title(f"{letter}. {head}: {zone}\n{but}{_verdict(ex.report)}",
                         color=style.GOOD if closure else style.BAD)
            _normals_panel(fig.add_subplot(grid[1, col]), ex)
        handles = _cone_handles(synth) + [Patch(label="friction zone", **style.ZONE)]
        fig.legend(handles=handles, loc="outside lower center", ncols=3)
        fig.suptitle(f"Positive spanning of the normals, three fingers, $\\mu$ = {synth.mu:g}")
    return fig


def _spanning_grasp(ax: Axes, synth: Synthesis, ex: Spanning, image: np.ndarray | None, first: bool) -> None:
    """One grasp of figure 8 with its cones, drawn by :func:`plot_grasp`.

    The first is the synthesised grasp itself (friction zone and meeting point included); the
    second is drawn as a one-grasp synthesis (cones and contacts only).
    """
    if first:
        plot_grasp(ax, synth, best_grasp(synth), inset=False)
    else:
        found = ForceGrasp((-1, -1, -1), ex.points, ex.normals, (-1, -1, -1), (0.0, 0.0, 0.0), 0.0, None,
                           synth.theta_min)
        plot_grasp(ax, replace(synth, found=(found,), grasps=(ex.report.grasp,), reports=(ex.report,)), 0,
                   inset=False)
        zone = friction_zone(ex.points, ex.normals, synth.theta_min, 2 * synth.outline.size)
        for part in getattr(zone, "geoms", [zone]):  # plot_grasp draws it only with a meeting point
            if part.geom_type == "Polygon" and not part.is_empty:
                ax.add_patch(MplPolygon(np.asarray(part.exterior.coords), closed=True, zorder=4, **style.ZONE))
    if image is not None:
        style.show_image(ax, image)
    style.clean(ax)

# --------------------------------------------------------------------------------------------------
# Driver


def feasible_tuple(synth: Synthesis, k: int) -> RegionTuple:
    """The whole feasible regions grasp ``k`` of ``synth`` lies on, as a region tuple: straight
    regions (end points of the feasible run, the contact's normal) on straight elements, the
    run's points and normals on curves; the grasp's contact models, ``center`` and ``length``."""
    grasp = synth.grasps[k]
    regions = []
    for c, index in zip(grasp.contacts, grasp.meta["regions"]):
        run = synth.regions[index]
        params = {"mu": c.mu} if c.mu is not None else {}
        if run.type == "/":
            regions.append(StraightRegion(run.points[0], run.points[-1], c.n, model=c.model, **params))
        else:
            regions.append(CurvedRegion(run.points, run.normals, model=c.model, **params))
    return RegionTuple(regions, center=grasp.center, length=grasp.length)


def regions_example(synth: Synthesis) -> tuple[int, RegionVerdict | None]:
    """The grasp figure 9 shows: among the grasps with certified regions, the one of largest
    certified slide (the smallest certified extent over fingers and sides) whose whole feasible
    regions are **not** robust (so that both halves of the figure are about one grasp), and the
    verdict on those whole regions (a witness); failing that, the grasp of largest slide and
    None."""
    ranked = sorted((k for k, f in enumerate(synth.tolerances) if f is not None and f.status == "robust"),
                    key=lambda k: -synth.tolerances[k].slide)
    if not ranked:
        raise ValueError("no synthesised grasp has certified regions")
    for k in ranked:
        verdict = certify_regions(feasible_tuple(synth, k))
        if verdict.status == "not_robust":
            return k, verdict
    return ranked[0], None


def _cone(ax: Axes, p: np.ndarray, n: np.ndarray, theta: float, reach: float) -> None:
    """A friction cone of half-angle ``theta`` (radians) about the inward normal ``n``, drawn as
    a triangle of side ``reach`` (pixels)."""
    edges = [np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]]) @ n for a in (-theta, theta)]
    ax.add_patch(MplPolygon([p, p + reach * edges[0], p + reach * edges[1]], closed=True,
                            facecolor="tab:orange", edgecolor="tab:orange", alpha=0.22, lw=0.8, zorder=3))


def _draw_region(ax: Axes, region, color: str, width: float) -> None:
    if isinstance(region, StraightRegion):
        xy = np.array([region.a, region.b])
    else:
        xy = np.asarray(region.points)
    ax.plot(xy[:, 0], xy[:, 1], color=color, lw=width, alpha=0.8, solid_capstyle="round", zorder=6)


def fig9_regions(synth: Synthesis | None = None, image: np.ndarray | None = None) -> Figure:
    """Certified independent contact regions (figure 4 as a guarantee) and a region tuple that
    is not robust, with its witness.

    Left: a synthesised grasp with its certified independent regions (every choice of one contact
    per green stretch is in force closure; :func:`qualgrasp.qualitative.synthesis.independent.independent_grasp`),
    titled with its certified slide (how far every finger may slide either way), each finger's
    certified extents before and after it below. Right: the same fingers anywhere on the whole feasible regions they lie on, which is not robust:
    the witness grasp (one contact per region) is not in force closure, with a Farkas certificate.

    Parameters
    ----------
    synth : Synthesis, optional
        A synthesis with certified tolerances (default: three-finger ForceGrasp on the
        ``polygon``, ``mu = 0.5``).
    image : numpy.ndarray, optional
        Its camera image, drawn underneath.

    Returns
    -------
    matplotlib.figure.Figure
    """
    if synth is None:
        image = render(OBJECT) if image is None else image
        synth = synthesize(image, 3, mu=MU, name=OBJECT, quality=False)
    k, verdict = regions_example(synth)
    found = synth.tolerances[k]
    size = synth.outline.size
    with style.context():
        fig = style.new_figure(11.0, 6.4)
        left, right = fig.subplots(1, 2)
        plot_grasp(left, synth, k, inset=False)
        for region in found.regions.regions:
            _draw_region(left, region, style.GOOD, 7)
        left.set_title(f"{synth.grasps[k].id}: certified regions, every choice in closure\n"
                       f"every finger may slide {found.slide:.1f} px = {found.slide_fraction:.3f} of the "
                       f"size either way", color=style.GOOD)
        draw_frame(right, synth.outline, None)
        right.set_xlim(left.get_xlim())
        right.set_ylim(left.get_ylim())
        for region in feasible_tuple(synth, k).regions:
            _draw_region(right, region, style.BAD, 7)
        if verdict is not None:
            w = verdict.witness
            P, N = np.array([c.p for c in w.contacts]), np.array([c.n for c in w.contacts])
            for p, n in zip(P, N):
                _cone(right, p, n, synth.theta_min, 0.3 * size)
            plot_contacts(right, P, N, size)
            right.plot(*P.T, "X", color=style.BAD, ms=11, mec="white", zorder=9)
            right.set_title("the whole feasible regions: not robust\nwitness X (one contact per region): "
                            "no force closure, Farkas certificate", color=style.BAD)
        else:
            right.set_title("the whole feasible regions are robust too", color=style.GOOD)
        for ax in (left, right):
            if image is not None:
                style.show_image(ax, image)
            style.clean(ax)
        extents = ", ".join(f"{i}: {a:.1f}/{b:.1f}" for i, (a, b) in enumerate(found.extents, start=1))
        left.set_xlabel(f"certified extents before/after each finger (px): {extents}", color=style.GOOD)
        fig.legend(handles=[Line2D([], [], color=style.GOOD, lw=6, label="certified independent regions"),
                            Line2D([], [], color=style.BAD, lw=6, label="regions that are not robust"),
                            Line2D([], [], color="black", marker="X", ls="", mfc=style.BAD, ms=10,
                                   label="witness grasp")],
                   loc="outside lower center", ncols=3)
        fig.suptitle(f"Figure 9: independent contact regions, {synth.procedure.title} with "
                     f"{synth.fingers} fingers, $\\mu$ = {synth.mu:g}")
    return fig


def make_figures(out: str | Path, *, formats: Sequence[str] = ("pdf", "png"),
                 progress: Callable[[str], None] | None = None) -> list[Path]:
    """Draw figures 3 to 9 into ``out`` (created if needed) and return the paths written.

    Writes ``fig3_outline``, ``fig4_regions``, ``fig5_zones``, ``fig6_two_fingers``,
    ``fig7_three_fingers``, ``fig8_spanning`` and ``fig9_regions``, one file per format. The three syntheses
    (FormGrasp, ForceGrasp with two and three fingers on the ``polygon``) are computed once.

    Parameters
    ----------
    out : str or pathlib.Path
        Output folder.
    formats : sequence of str
        File formats matplotlib can write (``pdf``, ``png``, ``svg``...).
    progress : callable, optional
        Called with a short message before each figure.

    Returns
    -------
    list of pathlib.Path

    Raises
    ------
    ValueError
        A format matplotlib cannot write (checked before anything is computed).
    """
    formats = style.check_formats(formats)  # before any work: a typo should not cost the run
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    say = progress or (lambda message: None)
    image = render(OBJECT)
    builders: list[tuple[str, Callable[[], Figure]]] = [
        ("fig3_outline", lambda: fig3_outline()),
        ("fig4_regions", lambda: fig4_regions()),
        ("fig5_zones", lambda: fig5_zones(synthesize(image, 4, name=OBJECT, tolerance=False), image)),
        ("fig6_two_fingers", lambda: fig6_two_fingers(synthesize(image, 2, mu=MU, name=OBJECT, tolerance=False),
                                                      image)),
    ]
    triple: list[Synthesis] = []  # figures 7 and 8 share one synthesis

    def three() -> Synthesis:
        if not triple:
            triple.append(synthesize(image, 3, mu=MU, name=OBJECT))
        return triple[0]

    builders += [("fig7_three_fingers", lambda: fig7_three_fingers(three(), image)),
                 ("fig8_spanning", lambda: fig8_spanning(three(), image)),
                 ("fig9_regions", lambda: fig9_regions(three(), image))]
    paths: list[Path] = []
    for stem, build in builders:
        say(f"drawing {stem}")
        paths += style.save(build(), out, stem, formats)
    return paths

"""Figures of synthesised grasps (like the paper's figures 5 to 8).

* FormGrasp: contacts, inward normals, each contact's line of action (the chord to the farthest
  boundary point), and the zones of freedom left after each contact: ``Z+`` (centres of clockwise
  rotations on screen, red hatching), ``Z-`` (counter-clockwise, blue hatching) and the free
  translations ``T`` (green sector at the centroid), until the zone is empty (figure 5).
* ForceGrasp: contacts, normals, friction cones (half-angle ``theta_min``), the grasp line of two
  fingers (figure 6), the friction zone of three fingers with the point where the forces meet
  (figure 7) and, inset, the three normals drawn from one point, which positively span the plane
  (figure 8).

Functions draw on a given :class:`matplotlib.axes.Axes` in the image's pixel frame (x = column,
y = row, y axis pointing down, equal aspect), like :mod:`qualgrasp.qualitative.plots.outline`; the figure builders use
the object-oriented API and the Agg canvas (no pyplot, no display).
"""

from __future__ import annotations

import math

import numpy as np
import shapely.ops
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch, Polygon as PolygonPatch, Wedge
from shapely.geometry.base import BaseGeometry

from ..vision.edges import WEAK_EDGE
from ..synthesis.forcegrasp import ForceGrasp, friction_cone, friction_zone
from ..synthesis.formgrasp import FormGrasp, line_of_action_exit, zone_steps
from .outline import STYLE, draw_frame
from ..synthesis.pipeline import Synthesis
from ..synthesis.zones import Zones

__all__ = ["plot_zones", "plot_contacts", "plot_grasp", "plot_form_step", "synthesis_figure"]

ZPLUS = {"facecolor": "tab:red", "edgecolor": "tab:red", "hatch": "////", "alpha": 0.25}
ZMINUS = {"facecolor": "tab:blue", "edgecolor": "tab:blue", "hatch": "\\\\\\\\", "alpha": 0.25}
TCOLOR = "tab:green"
CONE = {"facecolor": "tab:orange", "edgecolor": "tab:orange", "alpha": 0.22, "lw": 0.8}


def _view(synth: Synthesis, pad: float) -> tuple[float, float, float, float]:
    lo = synth.outline.contour.min(axis=0) - pad * synth.outline.size
    hi = synth.outline.contour.max(axis=0) + pad * synth.outline.size
    return float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1])


def _set_view(ax: Axes, bounds: tuple[float, float, float, float]) -> None:
    ax.set_xlim(bounds[0], bounds[2])
    ax.set_ylim(bounds[3], bounds[1])  # y grows downwards


def _draw_geometry(ax: Axes, geom: BaseGeometry, style: dict, zorder: int = 2) -> None:
    parts = getattr(geom, "geoms", [geom])
    for g in parts:
        if g.is_empty:
            continue
        if g.geom_type == "Polygon":
            xy = np.asarray(g.exterior.coords)
            ax.add_patch(PolygonPatch(xy, closed=True, zorder=zorder, **style))
            # an opaque outline keeps small zones visible
            ax.plot(xy[:, 0], xy[:, 1], color=style["edgecolor"], lw=1, zorder=zorder)
        elif g.geom_type in ("LineString", "LinearRing"):
            xy = np.asarray(g.coords)
            ax.plot(xy[:, 0], xy[:, 1], color=style["edgecolor"], lw=2, zorder=zorder)
        elif g.geom_type == "Point":
            ax.plot(g.x, g.y, "o", color=style["edgecolor"], ms=6, zorder=zorder)


def plot_zones(ax: Axes, zones: Zones, bounds: tuple[float, float, float, float], size: float,
               labels: bool = False) -> Axes:
    """Draw ``Z+``, ``Z-`` (clipped to ``bounds``) and the free translations ``T``.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Where to draw (pixel frame).
    zones : Zones
        Zones of freedom (:func:`qualgrasp.qualitative.synthesis.zones.zones`).
    bounds : (xmin, ymin, xmax, ymax)
        Box the unbounded zones are clipped to, pixels.
    size : float
        Object size, pixels (scales the sector showing ``T``).
    labels : bool
        Also name every large zone (``Z+``, ``Z-``) inside it; small zones are always ringed
        and named.

    Returns
    -------
    matplotlib.axes.Axes
    """
    for zone, style, label in ((zones.plus, ZPLUS, "Z+"), (zones.minus, ZMINUS, "Z-")):
        geom = zone.polygon(bounds)
        _draw_geometry(ax, geom, style)
        if not geom.is_empty and geom.area < (0.06 * size) ** 2:
            # a small zone would hide under the contacts: ring it and name it
            c = np.asarray(geom.centroid.coords[0])
            ax.plot(*c, "o", ms=22, mfc="none", mec=style["edgecolor"], mew=1.5, zorder=9)
            ax.annotate(label, c, c + np.array([0.09, -0.09]) * size, color=style["edgecolor"], fontsize=9,
                        fontweight="bold", zorder=9, arrowprops={"arrowstyle": "-", "color": style["edgecolor"]})
        elif labels and not geom.is_empty and geom.area > 0:
            _zone_label(ax, geom, label, style["edgecolor"], size)
    t = zones.translations
    if not t.empty:
        a = math.degrees(math.atan2(t.centre[1], t.centre[0]))
        h = math.degrees(t.half_width)
        ax.add_patch(Wedge(tuple(zones.center), 0.18 * size, a - h, a + h, color=TCOLOR, alpha=0.45, zorder=3))
        for d in t.ends:
            ax.annotate("", zones.center + 0.22 * size * d, zones.center,
                        arrowprops={"arrowstyle": "->", "color": TCOLOR, "lw": 1.5}, zorder=3)
    return ax


def _zone_label(ax: Axes, geom: BaseGeometry, label: str, color: str, size: float) -> None:
    """The zone's name at the point of its largest part farthest from the part's edges."""
    part = max(getattr(geom, "geoms", [geom]), key=lambda g: g.area)
    where = shapely.ops.polylabel(part, tolerance=0.01 * size) if part.geom_type == "Polygon" else part.centroid
    ax.text(where.x, where.y, label, color=color, fontsize=10, fontweight="bold", ha="center", va="center",
            zorder=9, bbox={"boxstyle": "round,pad=0.2", "facecolor": "white", "edgecolor": color, "lw": 0.8})


def plot_contacts(ax: Axes, points: np.ndarray, normals: np.ndarray, size: float, labels: bool = True) -> Axes:
    """Contacts as numbered markers with their inward normals (pixel frame)."""
    v = normals * 0.12 * size
    ax.quiver(points[:, 0], points[:, 1], v[:, 0], v[:, 1], angles="xy", scale_units="xy", scale=1,
              color="black", width=0.006, zorder=6)
    ax.plot(points[:, 0], points[:, 1], "o", ms=9, mfc="white", mec="black", mew=1.5, zorder=7)
    if labels:
        for k, p in enumerate(points):
            ax.annotate(str(k + 1), p, p - normals[k] * 0.07 * size, ha="center", va="center", fontsize=9,
                        fontweight="bold", zorder=8)
    return ax


def _regions(ax: Axes, synth: Synthesis) -> None:
    for region in synth.regions:
        ax.plot(region.points[:, 0], region.points[:, 1], lw=4, alpha=0.35, solid_capstyle="butt",
                color=STYLE[region.type]["color"], zorder=2)


def _chords(ax: Axes, grasp: FormGrasp, synth: Synthesis, count: int) -> None:
    """Lines of action of the first ``count`` contacts, drawn through the object (figure 5)."""
    for p, n in zip(grasp.points[:count], grasp.normals[:count]):
        end = line_of_action_exit(p, n, synth.outline.contour)
        end = p + 0.5 * synth.outline.size * n if end is None else end
        ax.plot([p[0], end[0]], [p[1], end[1]], ls="--", color="0.25", lw=1, zorder=4)


def plot_form_step(ax: Axes, synth: Synthesis, k: int, count: int, image: np.ndarray | None = None,
                   zones: Zones | None = None, labels: bool = False) -> Axes:
    """The zones of freedom of FormGrasp grasp ``k`` after its first ``count`` contacts (figure 5).

    ``zones`` saves recomputing them; ``labels`` names every zone in place (:func:`plot_zones`).
    """
    grasp = synth.found[k]
    bounds = _view(synth, 0.35)
    draw_frame(ax, synth.outline, image)
    _set_view(ax, bounds)
    _regions(ax, synth)
    z = zones if zones is not None else zone_steps(grasp, synth.center, synth.length)[count - 1]
    plot_zones(ax, z, bounds, synth.outline.size, labels)
    _chords(ax, grasp, synth, count)
    plot_contacts(ax, grasp.points[:count], grasp.normals[:count], synth.outline.size)
    state = "Z empty: form closure" if z.status == "closure" else f"depth {z.depth:+.3f}"
    ax.set_title(f"{count} contact{'s' if count > 1 else ''}: {state}", fontsize=10)
    return ax


def plot_grasp(ax: Axes, synth: Synthesis, k: int, image: np.ndarray | None = None, inset: bool = True) -> Axes:
    """One synthesised grasp: contacts, normals and, for ForceGrasp, cones, grasp line, friction zone.

    ``inset``: for three fingers, also draw the normals from one point in an inset (figure 8);
    off when the figure shows them in a panel of their own.
    """
    grasp = synth.found[k]
    size = synth.outline.size
    draw_frame(ax, synth.outline, image)
    _set_view(ax, _view(synth, 0.12))
    _regions(ax, synth)
    if isinstance(grasp, ForceGrasp):
        zone = None
        reach = np.full(len(grasp.points), 0.3 * size)
        if len(grasp.points) > 2:
            zone = friction_zone(grasp.points, grasp.normals, grasp.theta_min, 2 * size)
            if not zone.is_empty:  # draw the cones long enough to hold the whole zone
                corners = np.asarray(zone.exterior.coords) if zone.geom_type == "Polygon" else grasp.point[None]
                far = np.linalg.norm(corners[None] - grasp.points[:, None], axis=2).max(axis=1)
                reach = np.minimum(2 * size, 1.1 * far / math.cos(grasp.theta_min))
        for p, n, r in zip(grasp.points, grasp.normals, reach):
            _draw_cone(ax, p, n, grasp.theta_min, r)
        if len(grasp.points) == 2 or grasp.point is None:  # the grasp line of a pair (and its third finger)
            a, b = grasp.points[:2]
            ax.plot([a[0], b[0]], [a[1], b[1]], color="tab:red", lw=1.5, zorder=5)
        elif grasp.point is not None:
            _draw_geometry(ax, zone, {"facecolor": "tab:green", "edgecolor": "darkgreen", "alpha": 0.45}, zorder=4)
            for p in grasp.points:
                ax.plot([p[0], grasp.point[0]], [p[1], grasp.point[1]], color="darkgreen", lw=1, zorder=5)
            ax.plot(*grasp.point, "*", color="darkgreen", ms=12, mec="white", zorder=6)
            if inset:
                _normals_inset(ax, grasp.normals)
    else:
        _chords(ax, grasp, synth, len(grasp.points))
    plot_contacts(ax, grasp.points, grasp.normals, size)
    weak = _weak_contacts(synth, k)
    if len(weak):
        ax.scatter(grasp.points[weak, 0], grasp.points[weak, 1], s=260, facecolors="none", edgecolors="tab:red",
                   linewidths=2.2, zorder=7)
    ax.set_title(_caption(synth, k), fontsize=9)
    return ax


def _weak_contacts(synth: Synthesis, k: int) -> np.ndarray:
    """Indices of the contacts of grasp ``k`` on a weak edge (its field ``edge_strength``)."""
    strengths = synth.grasps[k].meta.get("edge_strength") or ()
    return np.flatnonzero(np.asarray(strengths, dtype=float) < WEAK_EDGE) if len(strengths) else np.zeros(0, int)


def _draw_cone(ax: Axes, point: np.ndarray, normal: np.ndarray, theta_min: float, reach: float) -> None:
    """A friction cone: shaded, with its two edges drawn and no far side (the cone is unbounded)."""
    xy = np.asarray(friction_cone(point, normal, theta_min, reach).exterior.coords)[:3]
    ax.add_patch(PolygonPatch(xy, closed=True, facecolor=CONE["facecolor"], alpha=CONE["alpha"], lw=0, zorder=3))
    ax.plot(xy[[1, 0, 2], 0], xy[[1, 0, 2], 1], color=CONE["edgecolor"], lw=CONE["lw"], zorder=3)


def _normals_inset(ax: Axes, normals: np.ndarray) -> None:
    """The normals drawn from one point (figure 8): they positively span the plane."""
    inset = ax.inset_axes([0.74, 0.74, 0.24, 0.24])
    inset.set_xlim(-1.3, 1.3)
    inset.set_ylim(1.3, -1.3)  # same orientation as the image
    inset.set_aspect("equal")
    inset.set_xticks([])
    inset.set_yticks([])
    inset.quiver(np.zeros(len(normals)), np.zeros(len(normals)), normals[:, 0], normals[:, 1], angles="xy",
                 scale_units="xy", scale=1, color="black", width=0.04)
    inset.set_title("normals", fontsize=7, pad=2)


def _caption(synth: Synthesis, k: int) -> str:
    text = str(synth.grasps[k].id)
    if synth.reports:
        r = synth.reports[k]
        eps = r.epsilons["L1"].hi if r.epsilons else float("nan")
        text += f"\n{r.force.status}, margin {r.force.margin:.3f}, eps {eps:.3f}"
    weak = _weak_contacts(synth, k)
    if len(weak):  # the contacts are numbered from 1 in the figure
        text += f"\nWEAK EDGE at contact {', '.join(str(i + 1) for i in weak)} (red ring)"
    return text


def _ranked(synth: Synthesis) -> list[int]:
    """Grasp indices, best first (certified margin, else the qualitative margin)."""
    if synth.reports:
        key = [r.force.margin for r in synth.reports]
    else:
        key = [synth.procedure.score(g) for g in synth.found]
    return sorted(range(len(synth.found)), key=lambda i: -key[i])


def _legend(fig: Figure, synth: Synthesis) -> None:
    handles = [Line2D([], [], ls="none", marker="o", mfc="white", mec="black", label="contact"),
               Line2D([], [], color="black", label="inward normal")]
    if not synth.procedure.friction:
        handles += [Patch(label="Z+ (clockwise)", **ZPLUS), Patch(label="Z- (counter-clockwise)", **ZMINUS),
                    Patch(color=TCOLOR, alpha=0.45, label="free translations T"),
                    Line2D([], [], ls="--", color="0.25", label="line of action")]
    else:
        handles += [Patch(label=f"friction cone ({math.degrees(synth.theta_min):.1f} deg)", **CONE)]
        if synth.fingers == 2:
            handles.append(Line2D([], [], color="tab:red", label="grasp line"))
        else:
            handles += [Patch(facecolor="tab:green", alpha=0.45, label="friction zone"),
                        Line2D([], [], ls="none", marker="*", color="darkgreen", label="forces meet")]
    fig.legend(handles=handles, loc="outside lower center", ncols=len(handles), fontsize=8, frameon=False)


def synthesis_figure(synth: Synthesis, image: np.ndarray | None = None, count: int = 4) -> Figure:
    """A figure of a synthesis: its best grasps and, for FormGrasp, the zones of the best one.

    FormGrasp: first row, the zones of freedom of the best grasp after each of its contacts
    (figure 5); second row, the next best grasps. ForceGrasp: the ``count`` best grasps with their
    friction cones (figures 6 to 8). With no grasp: the feasible regions and a note.

    Parameters
    ----------
    synth : Synthesis
        Result of :func:`qualgrasp.qualitative.synthesis.pipeline.synthesize`.
    image : numpy.ndarray, optional
        The image, drawn faintly underneath.
    count : int
        Number of grasps shown.

    Returns
    -------
    matplotlib.figure.Figure
        Bound to an Agg canvas; save it with ``fig.savefig(path)``.
    """
    order = _ranked(synth)
    title = (f"{synth.name}: {synth.procedure.title}, {synth.fingers} fingers"
             + (f", mu = {synth.mu:.3g}" if synth.mu is not None else ", frictionless")
             + f": {len(synth.grasps)} grasp(s)")
    if synth.certified_fraction is not None:
        title += f", {100 * synth.certified_fraction:.0f} % certified"
    # the outline and regions the grasps were planned on (their region indices refer to these)
    title += (f"\noutline {synth.outline.string} at scale {synth.scale:.4g}, {len(synth.regions)} feasible "
              f"region(s) at alpha {synth.alpha:g}")
    if not order:
        fig = Figure(figsize=(7.5, 6.0), layout="constrained")
        FigureCanvasAgg(fig)
        ax = fig.subplots()
        draw_frame(ax, synth.outline, image)
        _regions(ax, synth)
        P = np.asarray(synth.candidates.points)
        ax.plot(P[:, 0], P[:, 1], ".", color="black", ms=4, zorder=5)
        ax.set_title(f"no grasp found ({len(P)} candidate contacts, dots)", fontsize=10)
        fig.suptitle(title)
        return fig
    if isinstance(synth.found[order[0]], FormGrasp):  # zones of freedom, contact by contact
        best, rest = order[0], order[1:count + 1]
        steps = zone_steps(synth.found[best], synth.center, synth.length)
        cols = max(len(steps), len(rest), 1)
        fig = Figure(figsize=(3.6 * cols, 3.9 * (2 if rest else 1) + 0.6), layout="constrained")
        FigureCanvasAgg(fig)
        axes = fig.subplots(2 if rest else 1, cols, squeeze=False)
        for c, z in enumerate(steps):
            plot_form_step(axes[0, c], synth, best, c + 1, image, z)
        axes[0, 0].set_title(f"{synth.grasps[best].id}\n" + axes[0, 0].get_title(), fontsize=9)
        for c, k in enumerate(rest):
            plot_grasp(axes[1, c], synth, k, image)
        for ax in axes.ravel()[len(steps) if not rest else 0:]:
            if not ax.has_data():
                ax.set_axis_off()
    else:
        shown = order[:count]
        fig = Figure(figsize=(max(3.8 * len(shown), 7.5), 4.6), layout="constrained")
        FigureCanvasAgg(fig)
        axes = fig.subplots(1, len(shown), squeeze=False)[0]
        for ax, k in zip(axes, shown):
            plot_grasp(ax, synth, k, image)
    for ax in fig.axes:
        if ax.get_label() != "<colorbar>" and ax.get_xlabel():
            ax.tick_params(labelsize=7)
            ax.xaxis.label.set_size(8)
            ax.yaxis.label.set_size(8)
    _legend(fig, synth)
    fig.suptitle(title)
    return fig

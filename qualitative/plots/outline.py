"""Figures of outlines and feasible grasp regions (like the paper's figures 3 and 4).

Functions draw on a given :class:`matplotlib.axes.Axes` in the image's pixel frame (x = column,
y = row, y axis pointing down, equal aspect). :func:`outline_figure` builds a stand-alone figure
with the object-oriented API and the Agg canvas, so nothing here touches pyplot's global state or
needs a display.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.path import Path as MplPath

from ..vision.outline import Outline
from ..vision.grammar import NAMES
from ..synthesis.regions import Region

__all__ = ["STYLE", "draw_frame", "plot_outline", "plot_regions", "outline_figure", "curvature_handles"]

# Colour and marker of each curvature type; point-like types are drawn as markers at the apex.
STYLE = {
    "/": {"color": "tab:blue"},
    ")": {"color": "tab:green"},
    "(": {"color": "tab:orange"},
    ">": {"color": "tab:red", "marker": "o"},
    "<": {"color": "tab:purple", "marker": "s"},
    "}": {"color": "black", "marker": "*"},
    "{": {"color": "tab:brown", "marker": "X"},
}


def draw_frame(ax: Axes, outline: Outline, image: np.ndarray | None) -> None:
    """Draw the image faintly (if given) and the object's contour on ``ax``, in pixels (y down)."""
    if image is not None:
        image = np.asarray(image)
        # 8-bit images on their own scale; others (float, 16-bit, negative) on their range
        low, high = (0, 255) if image.dtype == np.uint8 else (float(np.min(image)), float(np.max(image)))
        ax.imshow(image, cmap="gray", vmin=low, vmax=high if high > low else low + 1, alpha=0.35,
                  interpolation="nearest")
    ring = np.vstack([outline.contour, outline.contour[:1]])
    ax.plot(ring[:, 0], ring[:, 1], color="0.6", lw=0.8, zorder=1)
    ax.set_aspect("equal")
    pad = 0.08 * outline.size
    lo, hi = outline.contour.min(axis=0) - pad, outline.contour.max(axis=0) + pad
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(hi[1], lo[1])  # image convention: y grows downwards
    ax.set_xlabel("x (column, px)")
    ax.set_ylabel("y (row, px)")


def plot_outline(ax: Axes, outline: Outline, image: np.ndarray | None = None, labels: bool = True) -> Axes:
    """Draw an outline: each segment coloured by type, its symbol written next to it.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Where to draw.
    outline : Outline
        The outline.
    image : numpy.ndarray, optional
        Image drawn faintly underneath (pixel frame).
    labels : bool
        Write each segment's symbol just outside the contour, like the paper's figure 3.

    Returns
    -------
    matplotlib.axes.Axes
    """
    draw_frame(ax, outline, image)
    normals = outline.normals()
    offset = 0.05 * outline.size
    for seg in outline.segments:
        style = STYLE[seg.symbol]
        if seg.is_point:
            where = seg.position
            ax.plot(*where, ls="none", ms=8, mec="white", mew=0.8, zorder=4, **style)
        else:
            ax.plot(seg.points[:, 0], seg.points[:, 1], lw=2.5, zorder=3, solid_capstyle="butt", **style)
            where = seg.points[len(seg.points) // 2]
        if labels:
            where, text = _label_spot(outline, seg, normals, offset)
            ax.annotate(seg.symbol, where, text, ha="center", va="center", fontsize=13,
                        fontfamily="monospace", fontweight="bold", color=style["color"], zorder=5,
                        arrowprops={"arrowstyle": "-", "color": style["color"], "lw": 0.6})
    _legend(ax, sorted({seg.symbol for seg in outline.segments}, key="/)(><}{".index))
    ax.set_title(f"outline {outline.string}", fontfamily="monospace")
    return ax


def _label_spot(outline: Outline, seg, normals: np.ndarray, offset: float) -> tuple[np.ndarray, np.ndarray]:
    """Where a segment's symbol goes: ``(anchor on the segment, text position outside the object)``.

    Candidates slide along the middle half of a line-like segment and out along the outward
    normal (half to twice ``offset``); of those outside the object, the one farthest from the whole
    contour wins, its clearance capped at ``offset`` so that a label in open space stays near its
    segment. This keeps symbols
    off other parts of the outline in narrow gaps (figure 3's slot between the disc and the thorn).
    """
    n = len(outline.contour)
    mid = (seg.start + (seg.stop - seg.start) // 2) % n
    if seg.is_point:
        idx = np.array([mid])
        anchors = np.asarray(seg.position, dtype=float)[None]
    else:
        idx = (seg.start + np.linspace(0.25, 0.75, 9) * (seg.stop - seg.start)).astype(int) % n
        anchors = outline.contour[idx]
    steps = np.linspace(0.5, 2.0, 7) * offset
    spots = anchors[:, None] - steps[None, :, None] * normals[idx][:, None]  # (anchors, steps, 2)
    clear = np.linalg.norm(spots[:, :, None] - outline.contour[None, None], axis=3).min(axis=2)
    # prefer clearance, then staying near the segment's middle and the nominal offset
    cost = (np.abs(np.arange(len(idx)) - len(idx) // 2)[:, None] / max(len(idx), 1)
            + np.abs(steps - offset)[None] / offset)
    score = np.minimum(clear, offset) - 0.05 * offset * cost
    inside = MplPath(outline.contour).contains_points(spots.reshape(-1, 2)).reshape(score.shape)
    score[inside] = -np.inf  # a label on the object would read as belonging to the wrong segment
    if not np.isfinite(score).any():
        return anchors[len(idx) // 2], anchors[len(idx) // 2] - offset * normals[idx[len(idx) // 2]]
    a, t = np.unravel_index(int(np.argmax(score)), score.shape)
    return anchors[a], spots[a, t]


def plot_regions(ax: Axes, outline: Outline, regions: Sequence[Region], image: np.ndarray | None = None,
                 normals: int = 5) -> Axes:
    """Draw the feasible grasp regions on the contour, with some of their inward normals.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Where to draw.
    outline : Outline
        The outline the regions belong to.
    regions : sequence of Region
        Feasible regions (:func:`qualgrasp.qualitative.synthesis.regions.feasible_regions`).
    image : numpy.ndarray, optional
        Image drawn faintly underneath (pixel frame).
    normals : int
        Number of inward normals drawn per region (0 for none).

    Returns
    -------
    matplotlib.axes.Axes
    """
    draw_frame(ax, outline, image)
    for seg in outline.segments:
        if seg.is_point:
            ax.plot(*seg.position, ls="none", ms=5, color="0.4", marker=STYLE[seg.symbol]["marker"], zorder=2)
    length = 0.07 * outline.size
    for region in regions:
        style = STYLE[region.type]
        line = region.points
        if region.stop - region.start >= len(outline.contour):  # all round a closed curve: close the ring
            line = np.vstack([line, line[:1]])
        ax.plot(line[:, 0], line[:, 1], lw=5, alpha=0.8, zorder=3, solid_capstyle="butt", color=style["color"])
        if normals and len(region.points):
            pick = np.unique(np.linspace(0, len(region.points) - 1, normals).round().astype(int))
            p, v = region.points[pick], region.normals[pick] * length
            ax.quiver(p[:, 0], p[:, 1], v[:, 0], v[:, 1], angles="xy", scale_units="xy", scale=1,
                      color=style["color"], width=0.004, zorder=4)
    types = sorted({r.type for r in regions}, key="/)(".index)
    _legend(ax, types, region=True)
    ax.set_title(f"{len(regions)} feasible grasp region(s)")
    return ax


def curvature_handles(symbols: Sequence[str], region: bool = False) -> list[Line2D]:
    """Legend entries of curvature types, styled as drawn here (``region``: as feasible regions)."""
    handles = []
    for s in symbols:
        style = STYLE[s]
        label = f"{s}  {NAMES[s]}" + (" region" if region else "")
        if "marker" in style:
            handles.append(Line2D([], [], ls="none", ms=8, label=label, **style))
        else:
            handles.append(Line2D([], [], lw=5 if region else 2.5, label=label, **style))
    return handles


def _legend(ax: Axes, symbols: Sequence[str], region: bool = False) -> None:
    handles = curvature_handles(symbols, region)
    if handles:
        ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.12), ncols=2,
                  prop={"family": "monospace", "size": 8}, frameon=False)


def outline_figure(outline: Outline, regions: Sequence[Region] | None = None,
                   image: np.ndarray | None = None) -> Figure:
    """A figure with the outline (left) and, when given, the feasible regions (right).

    Save it with ``fig.savefig(path)``; it is bound to an Agg canvas (no display needed).
    """
    panels = 1 if regions is None else 2
    fig = Figure(figsize=(5.5 * panels, 6.0), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(1, panels, squeeze=False)[0]
    plot_outline(axes[0], outline, image)
    if regions is not None:
        plot_regions(axes[1], outline, regions, image)
    return fig

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

from .outline import NAMES, Outline
from .regions import Region

__all__ = ["STYLE", "plot_outline", "plot_regions", "outline_figure"]

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


def _frame(ax: Axes, outline: Outline, image: np.ndarray | None) -> None:
    if image is not None:
        ax.imshow(image, cmap="gray", vmin=0, vmax=255 if np.asarray(image).dtype == np.uint8 else None,
                  alpha=0.35, interpolation="nearest")
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
    _frame(ax, outline, image)
    n = len(outline.contour)
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
            mid = (seg.start + (seg.stop - seg.start) // 2) % n
            text = where - offset * normals[mid]  # outside the object
            ax.annotate(seg.symbol, where, text, ha="center", va="center", fontsize=13,
                        fontfamily="monospace", fontweight="bold", color=style["color"], zorder=5,
                        arrowprops={"arrowstyle": "-", "color": style["color"], "lw": 0.6})
    _legend(ax, sorted({seg.symbol for seg in outline.segments}, key="/)(><}{".index))
    ax.set_title(f"outline {outline.string}", fontfamily="monospace")
    return ax


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
        Feasible regions (:func:`qualitative.regions.feasible_regions`).
    image : numpy.ndarray, optional
        Image drawn faintly underneath (pixel frame).
    normals : int
        Number of inward normals drawn per region (0 for none).

    Returns
    -------
    matplotlib.axes.Axes
    """
    _frame(ax, outline, image)
    for seg in outline.segments:
        if seg.is_point:
            ax.plot(*seg.position, ls="none", ms=5, color="0.4", marker=STYLE[seg.symbol]["marker"], zorder=2)
    length = 0.07 * outline.size
    for region in regions:
        style = STYLE[region.type]
        ax.plot(region.points[:, 0], region.points[:, 1], lw=5, alpha=0.8, zorder=3,
                solid_capstyle="butt", color=style["color"])
        if normals and len(region.points):
            pick = np.unique(np.linspace(0, len(region.points) - 1, normals).round().astype(int))
            p, v = region.points[pick], region.normals[pick] * length
            ax.quiver(p[:, 0], p[:, 1], v[:, 0], v[:, 1], angles="xy", scale_units="xy", scale=1,
                      color=style["color"], width=0.004, zorder=4)
    types = sorted({r.type for r in regions}, key="/)(".index)
    _legend(ax, types, region=True)
    ax.set_title(f"{len(regions)} feasible grasp region(s)")
    return ax


def _legend(ax: Axes, symbols: Sequence[str], region: bool = False) -> None:
    handles = []
    for s in symbols:
        style = STYLE[s]
        label = f"{s}  {NAMES[s]}" + (" region" if region else "")
        if "marker" in style:
            handles.append(Line2D([], [], ls="none", ms=8, label=label, **style))
        else:
            handles.append(Line2D([], [], lw=5 if region else 2.5, label=label, **style))
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

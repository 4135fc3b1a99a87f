"""A figure to inspect a segmentation: the object's contour over the whole image, at full contrast.

The grasp figures (:mod:`qualgrasp.qualitative.plots.grasp`) draw the image faintly and zoom on
the object; to see *what was segmented* -- a shadow taken in, a texture followed, an object cut
by the frame -- the user needs the whole image with the contour on it, and the contacts coloured
by their edge evidence (:mod:`qualgrasp.qualitative.vision.edges`). Built with the object-oriented API
on the Agg canvas, like :mod:`qualgrasp.qualitative.plots.outline`: no pyplot state, no display needed.
"""

from __future__ import annotations

import numpy as np
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from ..vision.edges import WEAK_EDGE

__all__ = ["plot_segmentation", "segmentation_figure"]

CONTOUR = "tab:cyan"
STRONG = "tab:green"
WEAK = "tab:red"


def plot_segmentation(ax: Axes, image: np.ndarray, contour: np.ndarray, points=None, strengths=None) -> Axes:
    """Draw the image at full contrast, the contour over it and, if given, contacts coloured by
    their edge strength (green at least :data:`~qualgrasp.qualitative.vision.edges.WEAK_EDGE`, red
    below: a weak edge).

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Where to draw (pixel frame: x = column, y = row, y down).
    image : numpy.ndarray
        ``(H, W)`` grey image (8-bit on 0..255, others on their range).
    contour : numpy.ndarray
        ``(m, 2)`` closed contour (x, y), pixels.
    points : array_like, optional
        ``(n, 2)`` contact points, pixels.
    strengths : array_like, optional
        ``(n,)`` their edge strengths (:func:`qualgrasp.qualitative.vision.edges.edge_strength`).

    Returns
    -------
    matplotlib.axes.Axes
        ``ax``.

    Examples
    --------
    >>> from matplotlib.figure import Figure
    >>> from qualgrasp.qualitative.objects import render
    >>> from qualgrasp.qualitative.vision.contour import extract_contour
    >>> image = render("disc")
    >>> ax = plot_segmentation(Figure().subplots(), image, extract_contour(image))
    >>> len(ax.lines), [float(v) for v in ax.get_xlim()]  # the whole image
    (1, [-0.5, 511.5])
    """
    image = np.asarray(image)
    low, high = (0, 255) if image.dtype == np.uint8 else (float(np.min(image)), float(np.max(image)))
    ax.imshow(image, cmap="gray", vmin=low, vmax=high if high > low else low + 1, interpolation="nearest")
    ring = np.vstack([contour, contour[:1]])
    ax.plot(ring[:, 0], ring[:, 1], color=CONTOUR, lw=1.2)
    if points is not None and len(points):
        points = np.asarray(points, dtype=float)
        weak = np.asarray(strengths, dtype=float) < WEAK_EDGE if strengths is not None else np.zeros(len(points), bool)
        for flag, colour in ((False, STRONG), (True, WEAK)):
            if (weak == flag).any():
                ax.scatter(points[weak == flag, 0], points[weak == flag, 1], s=36, c=colour, edgecolors="white",
                           linewidths=0.8, zorder=3)
    rows, cols = image.shape[:2]
    ax.set_xlim(-0.5, cols - 0.5)
    ax.set_ylim(rows - 0.5, -0.5)
    ax.set_aspect("equal")
    ax.set_xlabel("x (column, px)")
    ax.set_ylabel("y (row, px)")
    return ax


def segmentation_figure(image: np.ndarray, contour: np.ndarray, points=None, strengths=None,
                        title: str | None = None) -> Figure:
    """A stand-alone figure of :func:`plot_segmentation`, with a legend.

    Parameters
    ----------
    image, contour, points, strengths
        As for :func:`plot_segmentation`.
    title : str, optional
        Figure title (e.g. the image's name and the segmentation method).

    Returns
    -------
    matplotlib.figure.Figure
        Bound to an Agg canvas; save it with ``fig.savefig(path)``.

    Examples
    --------
    >>> from qualgrasp.qualitative.objects import render
    >>> from qualgrasp.qualitative.vision.contour import extract_contour
    >>> image = render("square")
    >>> fig = segmentation_figure(image, extract_contour(image), [[180, 256]], [0.9], title="square")
    >>> len(fig.axes), fig.legends[0].get_texts()[1].get_text()
    (1, 'contact on a strong edge')
    """
    fig = Figure(figsize=(6.4, 6.4), layout="constrained")
    FigureCanvasAgg(fig)
    plot_segmentation(fig.subplots(), image, contour, points, strengths)
    handles = [Line2D([], [], color=CONTOUR, label="segmented contour"),
               Line2D([], [], ls="none", marker="o", color=STRONG, label="contact on a strong edge"),
               Line2D([], [], ls="none", marker="o", color=WEAK, label=f"weak edge (strength < {WEAK_EDGE:g})")]
    fig.legend(handles=handles, loc="outside lower center", ncols=3, fontsize=8, frameon=False)
    if title:
        fig.suptitle(title)
    return fig

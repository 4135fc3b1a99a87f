"""The one style of the paper's figures (:mod:`qualgrasp.experiments.figures`): fonts, colours, line widths.

Colours are shared with the plotting helpers so that a symbol, a zone sign or a friction cone has
the same colour in every figure the project draws: curvature types come from
:data:`qualgrasp.qualitative.plots.outline.STYLE`, zones of freedom and friction cones from
:mod:`qualgrasp.qualitative.plots.grasp`. Settings are applied with :func:`context`, a
:func:`matplotlib.rc_context`, around building **and** saving a figure (some settings, such as
the hatch width and the PDF font type, are read only when the figure is drawn), so nothing leaks
into the caller's matplotlib state. Figures are plain :class:`matplotlib.figure.Figure` objects bound
to an Agg canvas: no pyplot, no display.
"""

from __future__ import annotations

from contextlib import contextmanager
from pathlib import Path
from typing import Iterator, Sequence

import matplotlib
import numpy as np
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from qualgrasp.certify.files import atomic_output
from qualgrasp.qualitative.plots.grasp import CONE, TCOLOR, ZMINUS, ZPLUS
from qualgrasp.qualitative.objects import BACKGROUND, FOREGROUND
from qualgrasp.qualitative.plots.outline import STYLE as CURVATURE
from qualgrasp.qualitative.synthesis import procedures

__all__ = ["RC", "DPI", "CURVATURE", "ZPLUS", "ZMINUS", "TCOLOR", "CONE", "GOOD", "BAD", "GRASP_LINE",
           "ZONE", "MEET", "OBJECT", "PROCEDURE_COLOURS", "procedure_colour", "context", "new_figure", "show_image",
           "clean", "check_formats", "save"]

DPI = 200
GOOD = "tab:green"  # a verdict that holds: closure, positive spanning
BAD = "tab:red"  # one that does not
GRASP_LINE = "tab:red"  # the two-finger grasp line, as drawn by qualitative.plots.grasp
ZONE = {"facecolor": "tab:green", "edgecolor": "darkgreen", "alpha": 0.45}  # friction zone, idem
MEET = "darkgreen"  # where the three forces meet, idem
OBJECT = 0.84  # grey level of the object as shown (1 = white background)
#: Colours of the synthesis procedures (and of their baselines), in the registry's order.
PROCEDURE_COLOURS = ("tab:blue", "tab:orange", "tab:purple", "tab:green", "tab:brown", "tab:pink", "tab:olive",
                     "tab:cyan")

RC = {
    "font.family": "DejaVu Sans",
    "font.size": 9,
    "axes.titlesize": 9.5,
    "axes.titlelocation": "center",
    "figure.titlesize": 11,
    "figure.titleweight": "bold",
    "legend.fontsize": 8,
    "legend.frameon": False,
    "lines.linewidth": 1.2,
    "hatch.linewidth": 0.6,
    "axes.linewidth": 0.6,
    "axes.edgecolor": "0.75",
    "savefig.dpi": DPI,
    "savefig.pad_inches": 0.04,
    "pdf.fonttype": 42,  # embed TrueType, so the text stays text (editable, searchable)
    "ps.fonttype": 42,
}


def procedure_colour(procedure: procedures.Procedure) -> str:
    """The colour of ``procedure`` in every plot: :data:`PROCEDURE_COLOURS` in the order procedures
    are registered (cycling after eight), so a new procedure needs no plotting code.

    Examples
    --------
    >>> procedure_colour(procedures.get("forcegrasp2"))
    'tab:blue'
    """
    index = procedures.names().index(procedure.name)
    return PROCEDURE_COLOURS[index % len(PROCEDURE_COLOURS)]


@contextmanager
def context() -> Iterator[None]:
    """The figures' matplotlib settings, restored on exit."""
    with matplotlib.rc_context(RC):
        yield


def new_figure(width: float, height: float) -> Figure:
    """A constrained-layout figure of ``width x height`` inches on an Agg canvas (no pyplot)."""
    fig = Figure(figsize=(width, height), layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def show_image(ax: Axes, image: np.ndarray) -> None:
    """The camera image underneath, mapped to a light grey object on white.

    The grey level is rescaled from the renderer's ``FOREGROUND``/``BACKGROUND`` so the object
    reads as a light silhouette (holes included, e.g. the nut's) and every overlay stays legible;
    anti-aliased edges keep their partial coverage. Drawn below everything else and without
    changing the view the plotting helpers set.
    """
    xlim, ylim = ax.get_xlim(), ax.get_ylim()
    # only the pixels in view: resampling the whole image for every panel and format is most of
    # the drawing time, and would bloat the PDFs
    rows, cols = np.asarray(image).shape[:2]
    c0, c1 = max(int(np.floor(min(xlim))) - 1, 0), min(int(np.ceil(max(xlim))) + 2, cols)
    r0, r1 = max(int(np.floor(min(ylim))) - 1, 0), min(int(np.ceil(max(ylim))) + 2, rows)
    crop = np.asarray(image, dtype=float)[r0:r1, c0:c1]
    coverage = np.clip((BACKGROUND - crop) / (BACKGROUND - FOREGROUND), 0.0, 1.0)
    ax.imshow(1.0 - (1.0 - OBJECT) * coverage, cmap="gray", vmin=0.0, vmax=1.0, interpolation="bilinear",
              extent=(c0 - 0.5, c1 - 0.5, r1 - 0.5, r0 - 0.5), zorder=0)
    ax.set_xlim(xlim)
    ax.set_ylim(ylim)


def clean(ax: Axes) -> None:
    """Hide ticks and axis labels (pixel coordinates mean nothing to a reader); keep a light frame."""
    ax.set_xticks([])
    ax.set_yticks([])
    ax.set_xlabel("")
    ax.set_ylabel("")
    legend = ax.get_legend()
    if legend is not None:  # the helpers' per-panel legends: the figures use one legend each
        legend.remove()


def check_formats(formats: Sequence[str]) -> tuple[str, ...]:
    """The formats, lower case, once checked against what matplotlib can write.

    Raises
    ------
    ValueError
        No format, or one matplotlib cannot write (the message lists those it can).
    """
    kinds = tuple(str(f).lower().lstrip(".") for f in formats)
    supported = FigureCanvasAgg(Figure()).get_supported_filetypes()
    bad = [f for f in kinds if f not in supported]
    if not kinds or bad:
        raise ValueError(f"cannot write figures as {', '.join(bad) or 'nothing'}; "
                         f"formats: {', '.join(sorted(supported))}")
    return kinds


def save(fig: Figure, out: Path, stem: str, formats: Sequence[str]) -> list[Path]:
    """Write ``out/stem.<format>`` for every format, in the figures' style; the paths written."""
    paths = []
    with context():
        for fmt in formats:
            path = out / f"{stem}.{fmt}"
            with atomic_output(path, "--out") as tmp:
                fig.savefig(tmp, format=fmt)
            paths.append(path)
    return paths

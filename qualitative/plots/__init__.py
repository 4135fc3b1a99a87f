"""Figures, above the domain code: no module of :mod:`qualgrasp.qualitative.vision`,
:mod:`~qualgrasp.qualitative.reasoning` or :mod:`~qualgrasp.qualitative.synthesis` imports them.

* :mod:`.outline`: outlines and feasible grasp regions (the paper's figures 3 and 4);
* :mod:`.grasp`: synthesised grasps, zones, friction cones (figures 5 to 8);
* :mod:`.segmentation`: a segmentation over the whole image, contacts coloured by edge evidence.

Every figure is built with matplotlib's object-oriented API on the Agg canvas: no pyplot state,
no display needed.
"""

from .outline import STYLE, curvature_handles, draw_frame, outline_figure, plot_outline, plot_regions
from .grasp import plot_contacts, plot_form_step, plot_grasp, plot_zones, synthesis_figure
from .segmentation import plot_segmentation, segmentation_figure

__all__ = [
    "STYLE", "draw_frame", "plot_outline", "plot_regions", "outline_figure", "curvature_handles",
    "plot_zones", "plot_contacts", "plot_grasp", "plot_form_step", "synthesis_figure",
    "plot_segmentation", "segmentation_figure",
]

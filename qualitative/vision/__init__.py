"""Vision: from an image to the object's contour and its qualitative outline.

The modules, in pipeline order:

* :mod:`.headers`: an image file's size read from its header, before it is decoded;
* :mod:`.segmentation`: the segmentation methods beyond Otsu's threshold (multi-Otsu, adaptive,
  GrabCut);
* :mod:`.contour`: reading an image, segmenting it and extracting the object's outer contour at
  sub-pixel accuracy;
* :mod:`.edges`: edge evidence at a contact (does the image show the object's edge there?);
* :mod:`.grammar`: the grammar of qualitative outline strings (Galton & Meathrel): alphabet,
  canonical rotation, well-formedness;
* :mod:`.outline`: qualitative outlines extracted from a contour at one scale;
* :mod:`.scales`: the finger's scale, the planning scale and the hierarchy of strings over scales.

This package imports nothing of :mod:`qualgrasp.qualitative.reasoning`,
:mod:`~qualgrasp.qualitative.synthesis` or :mod:`~qualgrasp.qualitative.plots`.

Examples
--------
>>> from qualgrasp.qualitative.objects import render
>>> from qualgrasp.qualitative.vision import outline_image
>>> outline_image(render("figure3")).string
'/}(</{)>'
"""

from .contour import (MAX_CONTOUR, MAX_PIXELS, METHODS, MIN_AREA, Segmentation, extract_contour, gaussian_blur,
                      object_mask, read_image, read_mask, refine_contour, segment, signed_area)
from .headers import HEADER_BYTES, header_size
from .segmentation import (ADAPTIVE_BLOCK, GRABCUT_ITERATIONS, GRABCUT_MARGIN, GRABCUT_SEED, adaptive_mask,
                           border_pixels, grabcut_mask, grabcut_rect, multiotsu_mask)
from .edges import (EDGE_BLUR, EDGE_REACH, RING, SHARPNESS, WEAK_EDGE, edge_contrast, edge_evidence, edge_strength,
                    weak_edge)
from .grammar import (CONVEX_POINTS, CURVE_SET, CURVES, LINE_LIKE, LINE_SET, NAMES, POINT_LIKE, POINT_SET, SYMBOLS,
                      canonical, check_turnings, is_well_formed, least_rotation, turning_range, validate)
from .outline import (DEFAULT_SCALE, SCALE_MAX, SCALE_MIN, WINDOW, Outline, Segment, canonical_at, check_scale,
                      outline_contour, outline_image, outline_to_dict, prepare_contour, resample, tls_line)
from .scales import ScaleInterval, finger_scale, outline_contour_scales, outline_scales, planning_scale

__all__ = [
    "MIN_AREA", "MAX_PIXELS", "MAX_CONTOUR", "METHODS", "Segmentation", "read_image", "read_mask", "gaussian_blur",
    "segment", "object_mask", "extract_contour", "refine_contour", "signed_area",
    "HEADER_BYTES", "header_size",
    "multiotsu_mask", "ADAPTIVE_BLOCK", "GRABCUT_MARGIN", "GRABCUT_ITERATIONS", "GRABCUT_SEED", "border_pixels",
    "adaptive_mask", "grabcut_rect", "grabcut_mask",
    "EDGE_BLUR", "EDGE_REACH", "RING", "WEAK_EDGE", "SHARPNESS", "edge_contrast", "edge_strength", "edge_evidence",
    "weak_edge",
    "SYMBOLS", "NAMES", "LINE_LIKE", "POINT_LIKE", "CURVES", "CONVEX_POINTS", "LINE_SET", "POINT_SET", "CURVE_SET",
    "canonical", "least_rotation", "turning_range", "validate", "check_turnings", "is_well_formed",
    "DEFAULT_SCALE", "WINDOW", "SCALE_MAX", "SCALE_MIN", "Segment", "Outline", "resample", "check_scale",
    "prepare_contour", "outline_contour", "outline_image", "canonical_at", "tls_line", "outline_to_dict",
    "ScaleInterval", "finger_scale", "planning_scale", "outline_contour_scales", "outline_scales",
]

"""Grasp synthesis: feasible regions, candidate contacts, the procedures and the pipeline.

* :mod:`.regions`: feasible grasp regions on a qualitative outline (the paper's definitions 1
  and 2);
* :mod:`.candidates`: candidate contact points on the regions, and the object's reference frame;
* :mod:`.zones`: Reuleaux's zones of freedom, for FormGrasp;
* :mod:`.formgrasp` and :mod:`.forcegrasp`: the searches of FormGrasp (frictionless form closure)
  and ForceGrasp (force closure with friction);
* :mod:`.procedures`: the synthesis procedures as registered objects;
* :mod:`.independent`: independent contact regions of a grasp on an image;
* :mod:`.pipeline`: :func:`synthesize`, from an image to certified grasps.

Names that two modules use for different things, or that are also a module's name, are not
repeated here: ``MARGIN`` (:data:`.regions.MARGIN`, :data:`.forcegrasp.MARGIN`), the functions
:func:`.candidates.candidates` and :func:`.zones.zones`, and the registry functions of
:mod:`.procedures`.

Examples
--------
The regions a square's grasps are planned on (:func:`.pipeline.synthesize` has the whole
pipeline's example):

>>> import numpy as np
>>> from qualgrasp.qualitative.synthesis import planning_regions
>>> outline, regions = planning_regions(np.array([[0, 0], [100, 0], [100, 100], [0, 100]], float))
>>> outline.string, len(regions)
('/>/>/>/>', 4)
"""

from .pipeline import (FALLBACK_SCALES, FALLBACK_STEP, MU, NORMAL, NOT_COUNTED, POSITION, SPREAD, NotCounted,
                       Synthesis, below_resolution, choose, counted, normal_span, on_weak_edge, resolution,
                       search_alphas, search_attempts, search_scales, set_edge_strength, synthesize, to_grasp,
                       unresolved_reasons)
from .regions import (ALPHA, ALPHA_MAX, FINGER_WIDTH, GRASPABLE, ON_LINE, Region, feasible_regions, on_fine_outline,
                      planning_regions, regions_image, regions_to_dict)
from .candidates import ERROR, GAP, INSET, PER_REGION, STEP, Candidates, object_frame, separated
from .zones import TOL, Translations, Zone, Zones, centre_of, free_depth, grasp_zones, twist_constraints
from .formgrasp import (FormGrasp, closure_depth4, deepest_closure, form_grasps, line_of_action_exit, ray_edges,
                        zone_steps)
from .forcegrasp import (ForceGrasp, angle_between, best_pair_angle, best_triplet_margins, friction, friction_cone,
                         friction_zone, nguyen_angles, pair_grasps, positively_spans, span_margin, triplet_grasps)
from .independent import (ON_OUTLINE, IndependentSummary, contact_limits, independent_file, independent_grasp,
                          outline_boundary, planned_regions)
from .procedures import Procedure, SearchInput

__all__ = [
    "MU", "POSITION", "NORMAL", "SPREAD", "FALLBACK_SCALES", "FALLBACK_STEP", "NOT_COUNTED", "NotCounted",
    "Synthesis", "synthesize", "to_grasp", "choose", "resolution", "normal_span", "below_resolution", "on_weak_edge",
    "set_edge_strength", "unresolved_reasons", "counted", "search_scales", "search_alphas", "search_attempts",
    "ALPHA", "ALPHA_MAX", "FINGER_WIDTH", "GRASPABLE", "ON_LINE", "Region", "feasible_regions", "on_fine_outline",
    "planning_regions", "regions_image", "regions_to_dict",
    "STEP", "INSET", "PER_REGION", "GAP", "ERROR", "Candidates", "object_frame", "separated",
    "TOL", "Zone", "Translations", "Zones", "grasp_zones", "free_depth", "twist_constraints", "centre_of",
    "FormGrasp", "form_grasps", "deepest_closure", "closure_depth4", "line_of_action_exit", "ray_edges", "zone_steps",
    "ForceGrasp", "friction", "angle_between", "nguyen_angles", "span_margin", "positively_spans", "pair_grasps",
    "best_pair_angle", "triplet_grasps", "best_triplet_margins", "friction_cone", "friction_zone",
    "ON_OUTLINE", "outline_boundary", "contact_limits", "planned_regions", "independent_grasp", "independent_file",
    "IndependentSummary",
    "Procedure", "SearchInput",
]

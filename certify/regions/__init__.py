"""Region certificates: certified robustness of a grasp to where exactly each finger lands.

A **contact region** is a set of possible contacts for one finger, with the finger's contact
model (``frictionless``, ``point`` with ``mu``, ``pad`` with ``mu`` and ``width``; planar only): a
:class:`StraightRegion` (the finger anywhere on a segment ``[a, b]`` of a straight edge, inward
normal ``n``) or a :class:`CurvedRegion` (anywhere on a curve given as a polyline of boundary points
with their inward normals). A :class:`RegionTuple` holds one region per finger and an optional
``normal_tol`` (radians: every true normal may differ from the stated one by up to that angle).

The tuple is **robust** when every choice of one contact per region is in force closure under the
declared models; **not robust** when some choice is not, witnessed by that choice (a grasp in
certify's format) and its Farkas certificate; **undecided** when the question could not be
settled. :func:`certify_regions` decides (straight regions with ``normal_tol = 0`` exactly, by 10
small linear programmes; curved regions and ``normal_tol > 0`` by a conservative branch and
bound within a budget) and :func:`verify_regions` re-checks the evidence without a solver.
:func:`independent_regions` finds how far each finger of a grasp may slide along the object's
boundary. The modules:

* :mod:`.data`: the regions, their JSON and the reading of curved stretches;
* :mod:`.decide`: :func:`certify_regions` and :func:`verify_regions`, with its two routes, the
  exact one for straight regions (``_exact``) and the branch and bound (``_branch``);
* :mod:`.boundary`: independent regions along a closed boundary;
* :mod:`.files`: region-set files (``qualgrasp certify-regions``).
"""

from ._branch import DEFAULT_BUDGET
from .boundary import Boundary, IndependentRegions, enclosing_diameter, independent_regions
from .data import (CurvedRegion, RegionTuple, StraightRegion, region_from_dict, region_to_dict, tuple_from_dict,
                   tuple_to_dict)
from .decide import DEFAULT_TOL, STATUSES, RegionVerdict, certify_regions, in_region, verify_regions
from .files import RegionSummary, certify_region_file, error_row, read_region_lines, verify_region_file

__all__ = [
    "StraightRegion", "CurvedRegion", "RegionTuple", "region_from_dict", "region_to_dict",
    "tuple_from_dict", "tuple_to_dict",
    "RegionVerdict", "certify_regions", "verify_regions", "in_region", "STATUSES", "DEFAULT_BUDGET", "DEFAULT_TOL",
    "Boundary", "IndependentRegions", "independent_regions", "enclosing_diameter",
    "RegionSummary", "certify_region_file", "verify_region_file", "read_region_lines", "error_row",
]

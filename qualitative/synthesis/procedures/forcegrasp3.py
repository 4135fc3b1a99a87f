"""``forcegrasp3``: ForceGrasp with three fingers (paper 5.1.3-5.1.4, Ponce and Faverjon's
friction zone), point contacts with friction; see
:func:`qualgrasp.qualitative.synthesis.forcegrasp.triplet_grasps`."""

from __future__ import annotations

import math

from ..forcegrasp import ForceGrasp, best_triplet_margins, triplet_grasps
from .base import Procedure, SearchInput, register
from .forcegrasp2 import force_meta

__all__ = ["FORCEGRASP3"]


def _search(s: SearchInput) -> list[ForceGrasp]:
    return triplet_grasps(s.candidates, s.contour, s.theta_min, s.size, margin=s.margin)


def _diagnose(s: SearchInput) -> str:
    normals, best = best_triplet_margins(s.candidates, s.contour, s.theta_min, s.size)
    need = s.margin * s.theta_min
    if normals is None:
        return "no three candidate contacts are far enough apart for three fingers"
    gap, limit = 180 - 2 * math.degrees(normals), 180 - 2 * math.degrees(need)
    if normals <= 0:
        return (f"the normals never positively span the plane: the best three leave a gap of {gap:.1f} "
                f"degrees between them, against at most {limit:.1f} (180 less twice the margin)")
    if normals < need:
        return (f"the normals span the plane without the margin: the best three leave a gap of {gap:.1f} "
                f"degrees between them, against at most {limit:.1f} (180 less twice the margin)")
    if best is None or best < 0:
        told = "" if best is None else f" (short by {-math.degrees(best):.1f} degrees)"
        return ("normals span the plane, but no three contacts have friction cones with a common point "
                f"inside their triangle{told}")
    return (f"the best three contacts' friction cones meet with a margin of {math.degrees(best):.1f} "
            f"degrees, against the margin {math.degrees(need):.1f}")


FORCEGRASP3 = register(Procedure(
    name="forcegrasp3", title="ForceGrasp", fingers=3, model="point", tag="force3",
    search=_search, score=lambda g: g.margin, meta=force_meta, diagnose=_diagnose,
    description="three fingers with friction: a common point of the friction cones, normals "
                "spanning the plane (Ponce and Faverjon)",
    failure="no three candidate contacts have normals that positively span the plane "
            "and friction cones with a common point"))

"""``forcegrasp3``: ForceGrasp with three fingers (paper 5.1.3-5.1.4, Ponce and Faverjon's
friction zone), point contacts with friction; see
:func:`qualgrasp.qualitative.forcegrasp.triplet_grasps`."""

from __future__ import annotations

from ..forcegrasp import ForceGrasp, triplet_grasps
from .base import Procedure, SearchInput, register
from .forcegrasp2 import force_meta

__all__ = ["FORCEGRASP3"]


def _search(s: SearchInput) -> list[ForceGrasp]:
    return triplet_grasps(s.candidates, s.contour, s.theta_min, s.size, margin=s.margin)


FORCEGRASP3 = register(Procedure(
    name="forcegrasp3", title="ForceGrasp", fingers=3, model="point", tag="force3", colour="tab:orange",
    search=_search, score=lambda g: g.margin, meta=force_meta,
    description="three fingers with friction: a common point of the friction cones, normals "
                "spanning the plane (Ponce and Faverjon)",
    failure="no three candidate contacts have normals that positively span the plane "
            "and friction cones with a common point"))

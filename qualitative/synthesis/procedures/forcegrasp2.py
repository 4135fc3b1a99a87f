"""``forcegrasp2``: ForceGrasp with two fingers (paper 5.1.3-5.1.4, Nguyen's condition), point
contacts with friction; see :func:`qualgrasp.qualitative.synthesis.forcegrasp.pair_grasps`."""

from __future__ import annotations

import math

from ..forcegrasp import ForceGrasp, best_pair_angle, pair_grasps
from .base import Procedure, SearchInput, register

__all__ = ["FORCEGRASP2", "force_meta"]


def force_meta(found: ForceGrasp) -> dict:
    """Fields recorded on a ForceGrasp grasp: its angular margin (radians) and, with three
    fingers, the point where the forces meet."""
    meta = {"cone_margin": found.margin}
    if found.point is not None:
        meta["meeting_point"] = [float(v) for v in found.point]
    return meta


def _search(s: SearchInput) -> list[ForceGrasp]:
    return pair_grasps(s.candidates, s.theta_min, s.size, margin=s.margin)


def _diagnose(s: SearchInput) -> str:
    best = best_pair_angle(s.candidates, s.size)
    if best is None:
        return "no two candidate contacts are far enough apart for two fingers"
    limit = (1 - s.margin) * s.theta_min
    return (f"the best pair's larger angle to the grasp line is {math.degrees(best):.1f} degrees, against "
            f"theta_min {math.degrees(s.theta_min):.1f} less the margin ({math.degrees(limit):.1f})")


FORCEGRASP2 = register(Procedure(
    name="forcegrasp2", title="ForceGrasp", fingers=2, model="point", tag="force2",
    search=_search, score=lambda g: g.margin, meta=force_meta, diagnose=_diagnose,
    description="two fingers with friction: the grasp line inside both friction cones (Nguyen)",
    failure="no pair of candidate contacts has its grasp line inside both friction "
            "cones (Nguyen's condition, theta_min with the angular margin)"))

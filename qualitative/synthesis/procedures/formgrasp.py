"""``formgrasp``: FormGrasp (paper 5.1.1-5.1.2), four frictionless fingers placed by Reuleaux's
zones of freedom; see :func:`qualgrasp.qualitative.synthesis.formgrasp.form_grasps`."""

from __future__ import annotations

import math

import numpy as np

from ..forcegrasp import span_margin
from ..formgrasp import FormGrasp, deepest_closure, form_grasps
from .base import Procedure, SearchInput, register

__all__ = ["FORMGRASP"]


def _search(s: SearchInput) -> list[FormGrasp]:
    return form_grasps(s.candidates, s.contour, s.center, s.length, s.size, error=s.error)


def _diagnose(s: SearchInput) -> str:
    normals = float(span_margin(s.candidates.normals))
    if normals <= 0:
        return (f"translations stay free: every candidate's normal lies in one half-plane (largest gap "
                f"{180 - 2 * math.degrees(normals):.1f} degrees between them)")
    depth = deepest_closure(s.candidates, s.center, s.length, s.size)
    need = s.error / s.length
    if depth is None:
        return "no four candidate contacts are far enough apart for four fingers"
    if not np.isfinite(depth):
        return "rotations stay free: every set of four candidate contacts leaves a zone of free centres"
    return (f"the deepest set of four closes the zone by {-depth:.2g} (the sine of the angle its constraints "
            f"may turn), against {need:.2g} for {s.error:g} px of error at the object's radius")


FORMGRASP = register(Procedure(
    name="formgrasp", title="FormGrasp", fingers=4, model="frictionless", tag="form",
    search=_search, score=lambda g: -g.depth, meta=lambda g: {"zone_depth": g.depth}, diagnose=_diagnose,
    description="four frictionless fingers until the zone of freedom is empty (Reuleaux, Nielsen)",
    failure="the zones of freedom of no candidate tuple close within four "
            "frictionless contacts"))

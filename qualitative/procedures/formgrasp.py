"""``formgrasp``: FormGrasp (paper 5.1.1-5.1.2), four frictionless fingers placed by Reuleaux's
zones of freedom; see :func:`qualgrasp.qualitative.formgrasp.form_grasps`."""

from __future__ import annotations

from ..formgrasp import FormGrasp, form_grasps
from .base import Procedure, SearchInput, register

__all__ = ["FORMGRASP"]


def _search(s: SearchInput) -> list[FormGrasp]:
    return form_grasps(s.candidates, s.contour, s.center, s.length, s.size, error=s.error)


FORMGRASP = register(Procedure(
    name="formgrasp", title="FormGrasp", fingers=4, model="frictionless", tag="form", colour="tab:purple",
    search=_search, score=lambda g: -g.depth, meta=lambda g: {"zone_depth": g.depth},
    description="four frictionless fingers until the zone of freedom is empty (Reuleaux, Nielsen)",
    failure="the zones of freedom of no candidate tuple close within four "
            "frictionless contacts"))

"""Region certificates: is every choice of one contact per region in force closure?

A region tuple (:class:`qualgrasp.certify.regions.data.RegionTuple`) is **robust** when every
choice of one contact per region is in force closure under the declared contact models, **not
robust** when some choice is not -- witnessed by that choice, a grasp in certify's format, and its
Farkas certificate (certify's, re-checked exactly) -- and **undecided** when the question could not
be settled (a budget ran out, or the worst choice lies on the closure boundary).

:func:`certify_regions` picks the route:

``point``
    Every region a single point and ``normal_tol = 0``: the tuple is one grasp, and its verdict
    is certify's (closure: robust, no_closure: not robust with the grasp as witness,
    degenerate: undecided).
``exact``
    Straight regions, ``normal_tol = 0``: decided exactly, with no budget, by 10 small linear
    programmes whose dual multipliers are re-checked in exact rationals
    (:mod:`qualgrasp.certify.regions._exact`).
``branch``
    Curved regions or ``normal_tol > 0``: branch and bound over wrench directions and pieces of
    the regions, conservative, within a budget (:mod:`qualgrasp.certify.regions._branch`).

:func:`verify_regions` re-checks a verdict without any solver: the certificate of a robust tuple
(exactly for ``point`` and ``exact``; for ``branch``, every bound recomputed in floating point
with rigorous error bounds), and for a witness that each of its contacts lies in its region
(exactly on the segment of a straight region, at one of the given points of a curved one, with
the region's model and parameters, its normal equal to the stated one or within ``normal_tol`` of
it) and that its Farkas certificate passes :func:`qualgrasp.certify.verify`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping

import numpy as np

from ..core.certificates import Certificate, Check, verify
from ..core.closure import Verdict, force_closure
from ..errors import CertificateError, GraspError
from ..core.grasp import Contact, Grasp, grasp_from_dict, grasp_to_dict
from ._branch import DEFAULT_BUDGET, cells_certificate, check_cells, decide_branch
from .data import RegionTuple, StraightRegion
from ._exact import (check_faces, check_faces_float, faces_certificate, generator_rows, on_segment,
                     solve_faces, straight_witness)

__all__ = ["STATUSES", "RegionVerdict", "certify_regions", "verify_regions", "in_region", "DEFAULT_BUDGET",
           "DEFAULT_TOL"]

STATUSES = ("robust", "not_robust", "undecided")
#: Default tolerance on the LP slack of the exact route (the generator rows are of order 1).
DEFAULT_TOL = 1e-9


@dataclass(frozen=True)
class RegionVerdict:
    """Outcome of :func:`certify_regions`.

    Attributes
    ----------
    status : {'robust', 'not_robust', 'undecided'}
    certificate : dict
        JSON-able evidence: kind ``faces`` (exact route), ``cells`` (branch and bound) or
        ``grasp`` (point route) for a robust tuple; kind ``witness`` (which choice, and its Farkas
        certificate under ``force``) for a tuple that is not robust; kind ``undecided`` otherwise.
    witness : Grasp or None
        A choice of one contact per region that is not in force closure.
    witness_verdict : Verdict or None
        Certify's verdict on the witness (``no_closure``, with its Farkas certificate).
    reason : str or None
        Why the verdict is undecided.
    route : {'point', 'exact', 'branch'}
    work : int
        Work units spent by the branch and bound (0 on the other routes).
    margin : float or None
        Exact route, robust: the smallest ``-sigma*`` over the faces, a measure of how far the
        worst choice is from the closure boundary (unit of the generator rows).
    """

    status: str
    certificate: dict
    witness: Grasp | None = None
    witness_verdict: Verdict | None = None
    reason: str | None = None
    route: str = ""
    work: int = 0
    margin: float | None = None

    @property
    def robust(self) -> bool | None:
        """True, False, or None when undecided."""
        return None if self.status == "undecided" else self.status == "robust"

    def row(self, verified: bool | None = None, line: int | None = None, id: Any = None) -> dict[str, Any]:
        """The results row of this verdict (see :func:`qualgrasp.certify.regions.certify_region_file`)."""
        witness = None
        if self.witness is not None:
            witness = {"grasp": grasp_to_dict(self.witness), "certificate": self.witness_verdict.certificate.to_json()}
        return {"id": id, "line": line, "status": self.status, "route": self.route,
                "certificate": self.certificate, "witness": witness, "reason": self.reason, "work": self.work,
                "margin": self.margin, "verified": verified, "error": None}


def _as_tuple(regions) -> RegionTuple:
    if isinstance(regions, RegionTuple):
        return regions
    if isinstance(regions, (list, tuple)):
        return RegionTuple(regions)
    raise GraspError(f"expected a RegionTuple or a sequence of regions, got {type(regions).__name__}")


def _point_of(region):
    if isinstance(region, StraightRegion):
        return region.a, region.n, {"s": 0.0}
    return tuple(map(float, region.points[0])), tuple(map(float, region.normals[0])), {"point": 0, "turn": 0}


def certify_regions(regions, *, budget: int = DEFAULT_BUDGET, tol: float = DEFAULT_TOL) -> RegionVerdict:
    """Is every choice of one contact per region in force closure?

    Parameters
    ----------
    regions : RegionTuple or sequence of StraightRegion / CurvedRegion
        One region per finger (a plain sequence gets the default ``center`` and ``length``).
    budget : int
        Work units of the branch and bound (curved regions, ``normal_tol > 0``): one unit is one
        bound of one piece of one region on one cell of wrench directions (64 vertex evaluations
        per generator; about 10 microseconds, so the default takes at most about 2 s).
        Straight regions with ``normal_tol = 0`` are decided exactly, with no budget.
    tol : float
        Exact route: an LP slack within ``tol`` of 0 is on the closure boundary; the verdict is
        then robust only when the exact check accepts the certificate anyway, not robust only
        when certify proves a witness, and undecided otherwise.

    Returns
    -------
    RegionVerdict
        ``status`` (``robust``, ``not_robust``, ``undecided``), ``certificate``, ``witness`` and
        its ``witness_verdict``, ``reason``, ``route``.

    Raises
    ------
    GraspError
        ``regions`` is not a region tuple or a sequence of regions.

    Examples
    --------
    Two point contacts with friction 0.5 sliding on opposite faces of a square: the grasp line
    stays inside both friction cones while the fingers' heights differ by less than ``2 mu``.

    >>> from qualgrasp.certify.regions import RegionTuple, StraightRegion, certify_regions
    >>> def fingers(d):
    ...     return RegionTuple([StraightRegion((1, -d), (1, d), (-1, 0), "point", mu=0.5),
    ...                         StraightRegion((-1, -d), (-1, d), (1, 0), "point", mu=0.5)])
    >>> certify_regions(fingers(0.4)).status
    'robust'
    >>> v = certify_regions(fingers(0.6))
    >>> p, q = (c.p for c in v.witness.contacts)   # the fingers at opposite ends
    >>> v.status, abs(p[1] - q[1]), v.witness_verdict.status
    ('not_robust', 1.2, 'no_closure')
    """
    regions = _as_tuple(regions)
    if regions.points_only:
        return _point_route(regions)
    if regions.straight and regions.normal_tol == 0:
        return _exact_route(regions, tol)
    return _branch_route(regions, budget)


def _point_route(regions: RegionTuple) -> RegionVerdict:
    picks = [_point_of(r) for r in regions.regions]
    grasp = Grasp(tuple(r.contact(p, n) for r, (p, n, _) in zip(regions.regions, picks)),
                  center=regions.center, length=regions.length)
    v = force_closure(grasp)
    if v.status == "closure":
        return RegionVerdict("robust", {"kind": "grasp", "force": v.certificate.to_json(), "margin": v.margin},
                             route="point")
    if v.status == "no_closure":
        return RegionVerdict("not_robust", _witness_certificate([d for _, _, d in picks], v), grasp, v,
                             route="point")
    reason = f"the grasp is degenerate (certify: {v.certificate.reason})"
    return RegionVerdict("undecided", {"kind": "undecided", "reason": reason}, reason=reason, route="point")


def _witness_certificate(choice, verdict: Verdict) -> dict:
    return {"kind": "witness", "choice": list(choice), "force": verdict.certificate.to_json()}


def _exact_route(regions: RegionTuple, tol: float) -> RegionVerdict:
    k = len(regions.regions)
    rows, owner = generator_rows(regions)
    G, owner = np.array(rows, dtype=float), np.array(owner)
    sols = solve_faces(G, k)
    worst = max(s.sigma for s in sols)
    if worst <= tol:
        cert = faces_certificate(sols)
        if check_faces_float(G, k, sols) or check_faces(regions, cert):
            return RegionVerdict("robust", cert, route="exact", margin=float(-worst))
    grasp, verdict, params = straight_witness(regions, G, owner, sols, tol)
    if grasp is not None:
        return RegionVerdict("not_robust", _witness_certificate([{"s": t} for t in params], verdict), grasp,
                             verdict, route="exact")
    if worst > tol:
        reason = (f"a separating direction exists (LP slack {worst:.3g}) but no choice certify proves not "
                  f"in closure was found ({verdict})")
    elif worst >= -tol:
        reason = f"the worst choice lies on the closure boundary (largest LP slack {worst:.3g}, tol {tol:g}; {verdict})"
    else:
        reason = "the LP multipliers did not pass the exact check"
    return RegionVerdict("undecided", {"kind": "undecided", "reason": reason, "slack": worst}, reason=reason,
                         route="exact")


def _branch_route(regions: RegionTuple, budget: int) -> RegionVerdict:
    res = decide_branch(regions, budget)
    if res.status == "robust":
        return RegionVerdict("robust", cells_certificate(res.cells, res.geometry), route="branch", work=res.work)
    if res.status == "not_robust":
        return RegionVerdict("not_robust", _witness_certificate(res.choice, res.verdict), res.witness,
                             res.verdict, route="branch", work=res.work)
    return RegionVerdict("undecided", {"kind": "undecided", "reason": res.reason, "work": res.work},
                         reason=res.reason, route="branch", work=res.work)


# --------------------------------------------------------------------------------------------------
# Verification

def normal_within(n, stated, tol: float) -> bool:
    """Is the unit normal ``n`` within ``tol`` radians of ``stated``? Exact equality when ``tol``
    is 0; otherwise the angle (``atan2`` of the cross and dot products, accurate to about
    ``1e-16``) must be at most ``tol - 1e-13``, so the true angle is at most ``tol``
    (candidate normals are turned by ``tol - 1e-9 tol - 1e-12``)."""
    if tuple(map(float, n)) == tuple(map(float, stated)):
        return True
    if tol <= 0:
        return False
    cross = n[0] * stated[1] - n[1] * stated[0]
    dot = n[0] * stated[0] + n[1] * stated[1]
    return dot > 0 and math.atan2(abs(cross), dot) <= tol - 1e-13


def in_region(region, contact: Contact, normal_tol: float = 0.0) -> str | None:
    """Why ``contact`` is not a contact of ``region`` (None when it is): same model and
    parameters; a point exactly on the segment (straight) or equal to one of the given points
    (curved); a normal equal to the stated one, or within ``normal_tol`` of it."""
    if contact.model != region.model or tuple(contact.params) != tuple(region.params):
        return f"model {contact.model} {dict(contact.params)} is not the region's {region.model} {dict(region.params)}"
    if len(contact.p) != 2:
        return "the contact is not planar"
    if isinstance(region, StraightRegion):
        if not on_segment(contact.p, region.a, region.b):
            return f"point {list(contact.p)} is not exactly on the segment"
        if not normal_within(contact.n, region.n, normal_tol):
            return f"normal {list(contact.n)} is not the region's {list(region.n)} (normal_tol {normal_tol})"
        return None
    hits = np.flatnonzero((region.points == np.array(contact.p)).all(axis=1))
    if not len(hits):
        return f"point {list(contact.p)} is not one of the region's points"
    if not any(normal_within(contact.n, tuple(region.normals[j]), normal_tol) for j in hits):
        return f"normal {list(contact.n)} is not the stated one at that point (normal_tol {normal_tol})"
    return None


def verify_regions(regions, verdict_or_row) -> Check:
    """Re-check a region verdict without any solver (module docstring).

    Parameters
    ----------
    regions : RegionTuple or sequence of regions
        The tuple the verdict is about.
    verdict_or_row : RegionVerdict or mapping
        A verdict of :func:`certify_regions`, or a results row (``status``, ``certificate``,
        ``witness`` with ``grasp`` and ``certificate``).

    Returns
    -------
    Check
        Truthy when the evidence proves the status; ``reason`` says what failed. An undecided
        verdict claims nothing and passes. A malformed certificate is a failed check, never an
        exception.

    Examples
    --------
    >>> from qualgrasp.certify.regions import RegionTuple, StraightRegion, certify_regions, verify_regions
    >>> t = RegionTuple([StraightRegion((1, -0.3), (1, 0.3), (-1, 0), "point", mu=0.5),
    ...                  StraightRegion((-1, -0.3), (-1, 0.3), (1, 0), "point", mu=0.5)])
    >>> v = certify_regions(t)
    >>> bool(verify_regions(t, v))
    True
    >>> moved = RegionTuple([StraightRegion((1, -0.9), (1, 0.3), (-1, 0), "point", mu=0.5), t.regions[1]],
    ...                     center=t.center, length=t.length)
    >>> verify_regions(moved, v).reason
    'face [2, 1, 1]: the combined row does not exclude the face (box minimum not positive)'
    """
    try:
        regions = _as_tuple(regions)
    except GraspError as err:
        return Check(False, str(err))
    if isinstance(verdict_or_row, RegionVerdict):
        status, cert = verdict_or_row.status, verdict_or_row.certificate
        witness = verdict_or_row.witness
        farkas = verdict_or_row.witness_verdict.certificate if verdict_or_row.witness_verdict else None
    elif isinstance(verdict_or_row, Mapping):
        status, cert = verdict_or_row.get("status"), verdict_or_row.get("certificate")
        witness = farkas = None
        w = verdict_or_row.get("witness")
        if w is not None:
            try:
                witness = grasp_from_dict(w["grasp"])
                farkas = Certificate.from_json(w["certificate"])
            except (GraspError, CertificateError, KeyError, TypeError) as err:
                return Check(False, f"malformed witness: {err}")
    else:
        return Check(False, f"expected a RegionVerdict or a results row, got {type(verdict_or_row).__name__}")
    if status not in STATUSES:
        return Check(False, f"unknown status {status!r}")
    if not isinstance(cert, Mapping):
        return Check(False, "the verdict has no certificate")
    kind = cert.get("kind")
    if status == "undecided":
        return Check(True) if kind == "undecided" and witness is None else Check(False, "an undecided verdict "
                                                                                     "carries no certificate or witness")
    if status == "robust":
        if witness is not None:
            return Check(False, "a robust verdict has no witness")
        if kind == "faces":
            return check_faces(regions, dict(cert))
        if kind == "cells":
            return check_cells(regions, dict(cert))
        if kind == "grasp":
            if not regions.points_only:
                return Check(False, "a grasp certificate applies to tuples of single points")
            picks = [_point_of(r) for r in regions.regions]
            grasp = Grasp(tuple(r.contact(p, n) for r, (p, n, _) in zip(regions.regions, picks)),
                          center=regions.center, length=regions.length)
            try:
                c = Certificate.from_json(cert.get("force"))
            except CertificateError as err:
                return Check(False, f"grasp certificate: {err}")
            return verify(grasp, c, status="closure")
        return Check(False, f"a robust verdict needs a faces, cells or grasp certificate, got {kind!r}")
    # not robust: the witness
    if kind != "witness" or witness is None or farkas is None:
        return Check(False, "a not_robust verdict needs a witness grasp and its certificate")
    if len(witness.contacts) != len(regions.regions):
        return Check(False, f"the witness has {len(witness.contacts)} contacts for {len(regions.regions)} regions")
    for i, (r, c) in enumerate(zip(regions.regions, witness.contacts)):
        why = in_region(r, c, regions.normal_tol)
        if why is not None:
            return Check(False, f"witness contact {i}: {why}")
    if cert.get("force") is not None:
        try:
            if Certificate.from_json(cert["force"]) != farkas:
                return Check(False, "the witness certificate differs from the verdict's")
        except CertificateError as err:
            return Check(False, f"witness certificate: {err}")
    check = verify(witness, farkas, status="no_closure")
    return check if check else Check(False, f"witness certificate: {check.reason}")

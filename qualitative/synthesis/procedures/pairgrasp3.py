"""``pairgrasp3``: three fingers with friction beyond the paper's condition -- an opposed pair in
force closure and a third finger.

The paper's three-finger condition (``forcegrasp3``: the three normals positively span the plane
and the friction cones have a common point) is sufficient but leaves out every grasp whose closure
comes from two fingers on opposed faces: with two fingers on parallel faces, any third normal
leaves the three in a closed half-plane (a gap of 180 degrees), so a rectangle, an L-shape or any
polygon whose only opposed faces are parallel gets no three-finger grasp, although two of its
fingers already hold it in force closure with friction.

Reading (qualitative, on the feasible regions):

* **An opposed pair.** Two fingers on feasible regions meeting Nguyen's two-finger condition with
  the angular margin, as ``forcegrasp2`` chooses them (one pair per region pair,
  :func:`qualgrasp.qualitative.synthesis.forcegrasp.pair_grasps`): the grasp line strictly inside both
  friction cones, ``max(theta_1, theta_2) <= (1 - margin) theta_min``.
* **A third finger anywhere feasible.** A candidate contact on any feasible region at least
  :data:`qualgrasp.qualitative.synthesis.candidates.GAP` of the object's size from both (a pad's room).
  Adding a contact to a grasp in force closure keeps it in force closure: the three contacts'
  wrench cone contains the pair's, which is already the whole wrench space. The pair's margin is
  the grasp's margin (``cone_margin``).
* **Where the third finger adds most.** On a straight region when one has room: its normal is
  pinned down by the whole edge's fitted line, so it adds the least image uncertainty (synthesis
  counts a grasp only when its certified epsilon exceeds the wrench change a pixel of error at
  any of its contacts can cause, :func:`qualgrasp.qualitative.synthesis.pipeline.resolution`). There, the
  pair holds forces across its grasp line only by friction, so the third finger goes where its
  normal is closest to perpendicular to the grasp line (largest ``|sin|`` of the angle between
  them; field ``third_angle``: that angle in radians); among candidates within 1 % of the best,
  the one farthest from the grasp line (the longest lever against turning), then the farthest
  from its region's ends.

Every grasp is certified like every other synthesised grasp
(:func:`qualgrasp.certify.certify_grasp`); it certifies because its pair does.

Why nothing was found, in numbers: no pair meets Nguyen's condition (the best pair's larger angle
to the grasp line against ``theta_min`` less the margin, as for ``forcegrasp2``), or no candidate
lies far enough from a good pair for a third finger (the farthest one's distance against the gap).
"""

from __future__ import annotations

import math

import numpy as np

from ..candidates import GAP, Candidates, separated
from ..forcegrasp import ForceGrasp, angle_between, best_pair_angle, pair_grasps
from .base import Procedure, SearchInput, register
from .forcegrasp2 import force_meta

__all__ = ["PAIRGRASP3", "pair_and_third", "third_finger"]

_TIE = 0.01


def third_finger(cands: Candidates, pair: ForceGrasp, size: float, *, gap: float = GAP) -> int | None:
    """The candidate a third finger goes to beside an opposed ``pair`` (module notes), or None when
    no candidate is at least ``gap * size`` from both of its contacts.

    Examples
    --------
    A pair across a square's middle and candidates on the other two sides: the third finger goes
    on a side whose normal is perpendicular to the grasp line, as far from it as the side allows.

    >>> import numpy as np
    >>> from qualgrasp.qualitative.synthesis.candidates import Candidates
    >>> P = np.array([[0., 50], [100, 50], [50, 0], [20, 100], [50, 100]])
    >>> N = np.array([[1., 0], [-1, 0], [0, 1], [0, -1], [0, -1]])
    >>> c = Candidates(P, N, np.arange(5), np.full(5, 10.0))
    >>> pair = ForceGrasp((0, 1), P[:2], N[:2], (0, 1), (0.0, 0.0), 0.46, None, 0.46)
    >>> third_finger(c, pair, 140.0)
    2
    """
    P, N = np.asarray(cands.points), np.asarray(cands.normals)
    i, j = pair.contacts
    far = separated(np.vstack([P, P[[i, j]]]), gap, size)[: len(P), len(P):].all(axis=1)
    ok = np.flatnonzero(far)
    if not len(ok):
        return None
    straight = np.array([_straight(cands, int(r)) for r in cands.region[ok]])
    if straight.any():  # a normal pinned down by a whole edge's fitted line
        ok = ok[straight]
    line = P[j] - P[i]
    across = np.abs(np.sin(angle_between(N[ok], line)))
    lever = np.abs((P[ok] - P[i]) @ np.array([-line[1], line[0]])) / np.linalg.norm(line)
    near = across >= across.max() - _TIE
    key = np.lexsort((-np.asarray(cands.clearance)[ok], -lever, ~near))
    return int(ok[key[0]])


def _straight(cands: Candidates, region: int) -> bool:
    """Whether every candidate of ``region`` has the same normal (a straight region's, its line's)."""
    N = np.asarray(cands.normals)[cands.of_region(region)]
    return bool(np.allclose(N, N[0], atol=1e-9))


def pair_and_third(cands: Candidates, theta_min: float, size: float, *, margin: float,
                   gap: float = GAP) -> list[ForceGrasp]:
    """Three-finger grasps: every opposed pair of
    :func:`qualgrasp.qualitative.synthesis.forcegrasp.pair_grasps` with its third finger
    (:func:`third_finger`); a pair with no room for a third finger gives none. The contacts are
    the pair's two, then the third; ``angles`` are the pair's angles to the grasp line and 0 for
    the third finger (it pushes along its normal); ``margin`` is the pair's; ``point`` is None."""
    P, N = np.asarray(cands.points), np.asarray(cands.normals)
    found = []
    for pair in pair_grasps(cands, theta_min, size, margin=margin, gap=gap):
        k = third_finger(cands, pair, size, gap=gap)
        if k is None:
            continue
        idx = [*pair.contacts, k]
        found.append(ForceGrasp(tuple(idx), P[idx], N[idx], (*pair.regions, int(cands.region[k])),
                                (*pair.angles, 0.0), pair.margin, None, theta_min))
    return found


def _search(s: SearchInput) -> list[ForceGrasp]:
    return pair_and_third(s.candidates, s.theta_min, s.size, margin=s.margin)


def _meta(found: ForceGrasp) -> dict:
    line = found.points[1] - found.points[0]
    return {**force_meta(found), "opposed": [0, 1],
            "third_angle": float(angle_between(found.normals[2], line))}


def _diagnose(s: SearchInput) -> str:
    best = best_pair_angle(s.candidates, s.size)
    limit = (1 - s.margin) * s.theta_min
    if best is None:
        return "no two candidate contacts are far enough apart for two fingers"
    if best > limit:
        return (f"no opposed pair: the best pair's larger angle to the grasp line is {math.degrees(best):.1f} "
                f"degrees, against theta_min {math.degrees(s.theta_min):.1f} less the margin "
                f"({math.degrees(limit):.1f})")
    P = np.asarray(s.candidates.points)
    room = 0.0
    for pair in pair_grasps(s.candidates, s.theta_min, s.size, margin=s.margin):
        d = np.minimum(*(np.linalg.norm(P - P[c], axis=1) for c in pair.contacts))
        room = max(room, float(d.max()))
    return (f"opposed pairs exist, but no candidate contact is far enough from one for a third finger: the "
            f"farthest is {room:.1f} px from the nearer of the pair, against {GAP * s.size:.1f} px "
            f"({GAP:g} of the object's size)")


PAIRGRASP3 = register(Procedure(
    name="pairgrasp3", title="PairGrasp", fingers=3, model="point", tag="pair3",
    search=_search, score=lambda g: g.margin, meta=_meta, diagnose=_diagnose,
    description="three fingers with friction: an opposed pair in force closure (Nguyen) and a third "
                "finger where it adds most, beyond the paper's condition",
    failure="no pair of candidate contacts on opposed regions meets Nguyen's condition with room for "
            "a third finger"))

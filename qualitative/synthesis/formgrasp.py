"""FormGrasp (paper 5.1.2): frictionless form-closure grasps from zones of freedom.

Our reading of the procedure, with the choices the paper leaves open:

1. ``S`` is the set of candidate contacts on feasible regions (:mod:`qualgrasp.qualitative.synthesis.candidates`).
2. For each start point ``s`` in ``S``:

   a. place the first contact at ``s``;
   b. follow its line of action (the inward normal) through the object to the farthest boundary
      intersection: the chord from ``s`` to that point partitions the object, and the plane, into
      the two discrete spaces of the contact (allowed positive and negative rotation centres; the
      paper's figure 5, chord ``AB``). The far end is **not** a contact: on a polygon with parallel
      sides it is the exactly opposite point, and two collinear opposed contacts leave a free line
      of centres that two more frictionless contacts can never close (five would be needed);
   c. add the contacts that shrink the zone of freedom until it is empty, or give up when more
      than four would be needed. No two or three frictionless contacts immobilise a planar
      object, so "shrinking" is judged on the zone left at the end: the three contacts added are
      those that, with ``s``, leave the **deepest empty** zone (most negative depth,
      :func:`qualgrasp.qualitative.synthesis.zones.free_depth`: the zone is cancelled "to the maximum extent", with the
      largest angular margin). Every completion is examined (a set of four is evaluated once, in
      closed form: four unit constraints ``a_i`` close the zone iff the origin lies inside their
      tetrahedron, and the depth is minus the origin's distance to its nearest face), so the
      result does not depend on a greedy order; the order kept for the figures is greedy (each
      next contact the one leaving the smallest zone);
   d. the contacts form a grasp when the zone is empty by more than ``error / length``: the depth
      is the sine of the smallest angle by which the contacts' constraint directions must turn
      before the object can move, and a contact displaced by ``error`` pixels changes its moment
      arm by ``error / length``; contour normals estimated from an image are off by an angle of
      the same order. So the grasp survives errors of about ``error`` pixels, stays away from the
      closure boundary (where certification would call it degenerate), and the near-misses of a
      disc, whose estimated normals miss the centre by a fraction of a degree (measured: empty
      zones of depth up to about ``1 / length``), do not count as grasps.

3. One grasp per start point; a grasp found again from another start point (the same set of
   contacts) is kept once, under its first start point.

Fingers are pads: two contacts are at least ``gap`` apart (fraction of the object's size).
Everything is in pixels of the input image (x = column, y = row), normals inward.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from functools import cache

import numpy as np

from ...certify.core import cross

from .candidates import ERROR, GAP, Candidates, separated
from ..errors import SynthesisError
from .zones import Zones, free_depth, unit_wrenches, zones

__all__ = ["ERROR", "FormGrasp", "form_grasps", "deepest_closure", "closure_depth4", "line_of_action_exit", "ray_edges",
           "zone_steps"]

@dataclass(frozen=True, eq=False)
class FormGrasp:
    """A frictionless form-closure grasp found by FormGrasp.

    Attributes
    ----------
    contacts : tuple of int
        Candidate indices, in the order they were placed (the start point first).
    points, normals : numpy.ndarray
        ``(m, 2)`` contact points and inward unit normals, pixels.
    regions : tuple of int
        Region index of each contact.
    start : int
        Candidate index of the start point (the grasp's origin in ``S``).
    exit : numpy.ndarray or None
        Farthest boundary intersection of the start contact's line of action (pixels), or None.
    depth : float
        Depth of the zone of freedom of all contacts (negative: empty), about the object's frame.
    depths : tuple of float
        Depth after each contact was placed (the zone shrinking).
    """

    contacts: tuple[int, ...]
    points: np.ndarray
    normals: np.ndarray
    regions: tuple[int, ...]
    start: int
    exit: np.ndarray | None
    depth: float
    depths: tuple[float, ...]


def ray_edges(start: np.ndarray, direction: np.ndarray, contour: np.ndarray):
    """Where the line ``start + t * direction`` meets the line of every edge of a closed contour.

    Returns ``(t, s, denom)``, each ``(n,)``: the parameter along the ray, the parameter along
    edge ``i`` (from ``contour[i]``, 0, to the next point, 1) and the cross product of the
    direction with the edge (0 for parallel edges, where ``t`` and ``s`` are not finite). Callers
    keep the crossings they need (``0 <= s <= 1``, ``t > 0``).
    """
    e = np.roll(contour, -1, axis=0) - contour
    w = contour - start
    denom = cross(direction, e)
    with np.errstate(divide="ignore", invalid="ignore"):
        return cross(w, e) / denom, cross(w, direction) / denom, denom


def line_of_action_exit(point: np.ndarray, direction: np.ndarray, contour: np.ndarray) -> np.ndarray | None:
    """Farthest intersection of the ray ``point + t * direction`` (``t > 0``) with a closed contour.

    Parameters
    ----------
    point, direction : numpy.ndarray
        ``(2,)`` start and direction of the ray (the inward normal of a contact).
    contour : numpy.ndarray
        ``(n, 2)`` closed polyline (closing point not repeated), pixels.

    Returns
    -------
    numpy.ndarray or None
        The intersection farthest from ``point`` (ignoring the start's own neighbourhood), or None.
    """
    t, s, denom = ray_edges(point, direction, contour)
    scale = float(np.linalg.norm(contour.max(axis=0) - contour.min(axis=0)))
    hit = (np.abs(denom) > 1e-12) & (s >= 0) & (s < 1) & (t > 1e-6 * scale)
    if not hit.any():
        return None
    return point + t[hit].max() * direction


def form_grasps(cands: Candidates, contour: np.ndarray, center: np.ndarray, length: float, size: float, *,
                error: float = ERROR, gap: float = GAP) -> list[FormGrasp]:
    """Frictionless form-closure grasps of four contacts by FormGrasp, one per start point.

    Parameters
    ----------
    cands : Candidates
        Candidate contacts (the set ``S``).
    contour : numpy.ndarray
        ``(n, 2)`` the object's closed contour (lines of action are followed to it), pixels.
    center, length : numpy.ndarray, float
        Object frame (area centroid, radius, pixels) in which zone depths are measured.
    size : float
        Object size (pixels) that ``gap`` is a fraction of.
    error : float
        Position error (pixels) a grasp must survive: its zone must be empty by a depth of more
        than ``error / length`` (see module notes).
    gap : float
        Smallest distance between two contacts, fraction of ``size``.

    Returns
    -------
    list of FormGrasp
        In the order of their start points, duplicates removed. Four contacts each: the planar
        minimum, and the finger budget (a start point that would need more gives no grasp).
    """
    if not (error >= 0 and gap >= 0):
        raise SynthesisError(f"need error >= 0 and gap >= 0, got {error} and {gap}")
    depth = error / length
    P, N = np.asarray(cands.points), np.asarray(cands.normals)
    if len(P) < 4:
        return []
    far = separated(P, gap, size)
    a = unit_wrenches(P, N, center, length)
    best_set, best_depth = _best_completions(a, far)
    found: list[FormGrasp] = []
    seen: set[frozenset] = set()
    for s in range(len(P)):
        if not best_depth[s] < -depth:
            continue
        key = frozenset(int(i) for i in best_set[s])
        if key in seen:
            continue
        seen.add(key)
        idx = np.array(_greedy_order(s, best_set[s], P, N, center, length))
        depths = [float(free_depth(P[idx[:k]][None], N[idx[:k]][None], center, length)[0])
                  for k in range(1, len(idx) + 1)]
        found.append(FormGrasp(tuple(int(i) for i in idx), P[idx], N[idx],
                               tuple(int(cands.region[i]) for i in idx), s,
                               line_of_action_exit(P[s], N[s], contour), depths[-1], tuple(depths)))
    return found


def deepest_closure(cands: Candidates, center: np.ndarray, length: float, size: float, *,
                    gap: float = GAP) -> float | None:
    """Why :func:`form_grasps` found nothing, in numbers: the depth of the emptiest zone of
    freedom any four candidates at least ``gap * size`` apart leave (negative: the zone is empty;
    ``+inf`` when every set of four leaves free motions; None when no four candidates are that far
    apart). A start point gives a grasp when its depth is below ``-error / length``.

    Examples
    --------
    Four contacts on a square's sides, each off its side's centre by 15 % of the side: two
    opposite pairs offset the same way close the zone of freedom; a pinwheel (every offset turning
    the same way) leaves rotations one way free:

    >>> import numpy as np
    >>> from qualgrasp.qualitative.synthesis.candidates import Candidates
    >>> n = np.array([[0, 1], [-1, 0], [0, -1], [1, 0]], float)
    >>> def square(offsets):
    ...     a, b, c, d = offsets
    ...     p = np.array([[a, -100], [100, b], [c, 100], [-100, d]], float)
    ...     return deepest_closure(Candidates(p, n, np.arange(4), np.full(4, 10.0)), np.zeros(2), 141.4, 283)
    >>> round(square([30, -30, -30, 30]), 3)
    -0.191
    >>> square([30, 30, -30, -30])
    inf
    """
    P, N = np.asarray(cands.points), np.asarray(cands.normals)
    _, depth = _best_completions(unit_wrenches(P, N, center, length), separated(P, gap, size))
    return None if np.isnan(depth).all() else float(np.nanmin(depth))


def _det(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    return np.einsum("...k,...k->...", a, cross(b, c))


def closure_depth4(a: np.ndarray) -> np.ndarray:
    """Depth of the zone of freedom of four contacts, closed form, where it is empty (batch).

    Parameters
    ----------
    a : numpy.ndarray
        ``(B, 4, 3)`` unit twist constraints.

    Returns
    -------
    numpy.ndarray
        ``(B,)``: minus the distance from the origin to the nearest face of the tetrahedron of the
        four ``a_i`` when the origin lies strictly inside it (the zone is empty; equal to
        :func:`qualgrasp.qualitative.synthesis.zones.free_depth`), ``+inf`` otherwise (the zone is not empty).
    """
    a0, a1, a2, a3 = (a[:, i] for i in range(4))
    # barycentric weights of the origin: sum_i C_i a_i = 0
    C = np.stack([_det(a1, a2, a3), -_det(a0, a2, a3), _det(a0, a1, a3), -_det(a0, a1, a2)], axis=1)
    inside = (C > 0).all(axis=1) | (C < 0).all(axis=1)
    faces = [(a1, a2, a3), (a0, a2, a3), (a0, a1, a3), (a0, a1, a2)]
    area = np.stack([np.linalg.norm(cross(q - p, r - p), axis=1) for p, q, r in faces], axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        dist = np.abs(C) / area
    return np.where(inside, -dist.min(axis=1), np.inf)


def _best_completions(a: np.ndarray, far: np.ndarray, chunk: int = 200_000) -> tuple[np.ndarray, np.ndarray]:
    """For every candidate, the deepest set of four containing it, and its depth (``+inf``: no
    such set closes; NaN: no four candidates pairwise ``far`` include it)."""
    m = len(a)
    best_set = np.full((m, 4), -1, dtype=np.intp)
    best_depth = np.full(m, np.nan)
    for i in range(m - 3):
        rest = np.flatnonzero(far[i, i + 1:]) + i + 1
        if len(rest) < 3:
            continue
        j, k, l = (rest[t] for t in _triples(len(rest)))
        ok = far[j, k] & far[j, l] & far[k, l]
        sets = np.column_stack([np.full(ok.sum(), i), j[ok], k[ok], l[ok]])
        for lo in range(0, len(sets), chunk):
            part = sets[lo:lo + chunk]
            d = closure_depth4(a[part])
            order = np.argsort(d, kind="stable")
            for col in range(4):
                members, first = np.unique(part[order, col], return_index=True)
                values = d[order][first]
                better = ~(values >= best_depth[members])  # also where none was seen yet (NaN)
                best_depth[members[better]] = values[better]
                best_set[members[better]] = part[order][first[better]]
    return best_set, best_depth


@cache
def _triples(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    t = np.array(list(itertools.combinations(range(n), 3)), dtype=np.intp).reshape(-1, 3)
    return t[:, 0], t[:, 1], t[:, 2]


def _greedy_order(s: int, members: np.ndarray, P, N, center, length) -> list[int]:
    """``s`` first, then each next contact the one leaving the smallest zone (for the figures)."""
    order, rest = [s], [int(v) for v in members if v != s]
    while rest:
        d = [free_depth(P[order + [r]][None], N[order + [r]][None], center, length)[0] for r in rest]
        order.append(rest.pop(int(np.argmin(d))))
    return order


def zone_steps(grasp: FormGrasp, center: np.ndarray, length: float) -> list[Zones]:
    """The zones of freedom after each contact of a FormGrasp grasp was placed (for figures)."""
    return [zones(grasp.points[:k], grasp.normals[:k], center=center, length=length)
            for k in range(1, len(grasp.points) + 1)]

"""ForceGrasp (paper 5.1.3-5.1.4): two- and three-finger force-closure grasps with friction.

Friction is Coulomb friction with coefficient ``mu``; the friction threshold is
``theta_min = atan(mu)``, the half-angle of each friction cone (paper, definition 14). Given
``theta_min`` directly, ``mu = tan(theta_min)``. Angles are in radians, positions in pixels of the
input image (x = column, y = row), normals point into the object.

Two fingers (Nguyen 1988; paper definitions 14-15)
    Contacts ``F_1``, ``F_2`` are in force closure iff the grasp line lies strictly inside both
    friction cones: ``theta_1 = angle(n_1, F_2 - F_1) < theta_min`` and
    ``theta_2 = angle(n_2, F_1 - F_2) < theta_min``. A **feasible region pair** holds such a pair,
    one point on each region (the same region twice is allowed: two points of a disc's single
    curve). For each pair of regions we choose, among the candidate points
    (:mod:`qualgrasp.qualitative.synthesis.candidates`), the pair **farthest from the cone boundaries**: largest margin
    ``theta_min - max(theta_1, theta_2)``; among pairs within 1 % of ``theta_min`` of the best, the
    one farthest from the regions' ends. One grasp per region pair.

Three fingers (Ponce & Faverjon 1995, proposition 3; paper definitions 16-17)
    The **friction zone** of three contacts is the intersection of their inward friction cones
    (wedges of half-angle ``theta_min`` about the normals); that of three regions is the
    intersection, over the regions, of the union of their points' cones (definition 16). The
    paper accepts a triplet when the friction zone is non-empty and the three normals positively
    span the plane (largest angular gap below pi). Those two conditions are not quite sufficient:
    forces aimed at a point ``x`` of the friction zone are concurrent at ``x`` (no torque about
    it) and balance with positive weights only when their directions ``x - F_i`` positively span
    the plane, i.e. ``x`` lies inside the contact triangle. With ``x`` strictly inside every cone
    and the triangle, that internal force lies strictly inside the cones, which proves force
    closure (Murray, Li & Sastry, proposition 5.2). So for every region triplet we search a grid of
    points ``x`` over the object's convex hull, take for each ``x`` the candidate point of each
    region with ``x`` deepest in its cone, and keep the ``x`` with the largest margin: the
    smallest of the three cone margins ``theta_min - angle(n_i, x - F_i)``, of the spanning margin
    of the force directions and of the normals (``(pi - largest gap) / 2``). One grasp per region
    triplet. The normals' spanning margin bounds the margin whatever the point, so a triplet none
    of whose contact triples has normals spanning with the accepted margin is skipped unsearched;
    each candidate's cone margins and directions on the coarse grid are computed once and shared
    by every triplet. Neither changes a grasp found.

A grasp is kept when its margin is at least ``margin * theta_min``: contacts stay inside their
cones (and forces keep spanning) under angular errors of that size, e.g. normals estimated from
the image.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np
import shapely
from shapely.geometry import Polygon
from shapely.geometry.base import BaseGeometry

from .candidates import GAP, Candidates, separated
from ..errors import SynthesisError

__all__ = ["MARGIN", "GAP", "ForceGrasp", "friction", "angle_between", "nguyen_angles", "span_margin",
           "positively_spans", "pair_grasps", "best_pair_angle", "triplet_grasps", "best_triplet_margins",
           "friction_cone", "friction_zone"]

MARGIN = 0.25
GRID = 40
REFINE = 3
_TIE = 0.01


@dataclass(frozen=True, eq=False)
class ForceGrasp:
    """A force-closure grasp found by ForceGrasp.

    Attributes
    ----------
    contacts : tuple of int
        Candidate indices of the contacts.
    points, normals : numpy.ndarray
        ``(m, 2)`` contact points and inward unit normals, pixels.
    regions : tuple of int
        Region index of each contact.
    angles : tuple of float
        Angle between each normal and its force direction (the grasp line for two fingers and
        for the opposed pair of ``pairgrasp3``, whose third finger pushes along its normal: 0;
        the direction to ``point`` for three fingers by the friction zone), radians.
    margin : float
        Smallest angular distance to the closure boundary (cone edges, spanning), radians.
    point : numpy.ndarray or None
        Three fingers by the friction zone: the point where the forces meet (pixels); None for
        two fingers and for an opposed pair with a third finger.
    theta_min : float
        Half-angle of the friction cones, radians.
    """

    contacts: tuple[int, ...]
    points: np.ndarray
    normals: np.ndarray
    regions: tuple[int, ...]
    angles: tuple[float, ...]
    margin: float
    point: np.ndarray | None
    theta_min: float


def friction(mu: float | None = None, theta_min: float | None = None) -> tuple[float, float]:
    """``(mu, theta_min)`` from either one: ``theta_min = atan(mu)`` (radians).

    Raises
    ------
    SynthesisError
        Both or neither given, ``mu <= 0`` or not finite, ``theta_min`` outside ``(0, pi/2)``.
    """
    if (mu is None) == (theta_min is None):
        raise SynthesisError("give the friction coefficient mu or the friction threshold theta_min, not both")
    if mu is not None:
        if not (math.isfinite(mu) and mu > 0):
            raise SynthesisError(f"friction coefficient mu must be finite and > 0, got {mu}")
        return float(mu), math.atan(mu)
    if not (0 < theta_min < math.pi / 2):
        raise SynthesisError(f"theta_min must lie strictly between 0 and 90 degrees, got {math.degrees(theta_min):g}")
    return math.tan(theta_min), float(theta_min)


def angle_between(u, v) -> np.ndarray:
    """Unsigned angle between planar vectors (last axis 2; arrays broadcast), radians, accurate
    near 0 and pi.

    Examples
    --------
    >>> round(float(np.degrees(angle_between([1, 0], [1, 1]))), 6)
    45.0
    """
    u, v = np.asarray(u, dtype=float), np.asarray(v, dtype=float)
    cross = u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]
    dot = (u * v).sum(axis=-1)
    return np.arctan2(np.abs(cross), dot)


def nguyen_angles(p1, n1, p2, n2) -> tuple[np.ndarray, np.ndarray]:
    """Angles ``theta_1 = angle(n_1, p_2 - p_1)`` and ``theta_2 = angle(n_2, p_1 - p_2)`` (radians).

    Arrays broadcast over leading axes; the last axis holds (x, y).
    """
    d = np.asarray(p2, dtype=float) - np.asarray(p1, dtype=float)
    return angle_between(np.asarray(n1, dtype=float), d), angle_between(np.asarray(n2, dtype=float), -d)


def span_margin(vectors) -> np.ndarray:
    """``(pi - G) / 2`` for ``G`` the largest angular gap between planar vectors (last two axes ``(k, 2)``).

    Positive iff the vectors positively span the plane (the angular-gap rule); its value is the
    angle by which any of them may turn without losing that.
    """
    v = np.asarray(vectors, dtype=float)
    return _angle_span(np.arctan2(v[..., 1], v[..., 0]))


def _angle_span(angles: np.ndarray) -> np.ndarray:
    """:func:`span_margin` of the vectors at direction ``angles`` (last axis, radians): the
    search looks directions up instead of recomputing them, with the same arithmetic."""
    angles = np.sort(angles, axis=-1)
    gaps = np.diff(np.concatenate([angles, angles[..., :1] + 2 * np.pi], axis=-1), axis=-1)
    return (np.pi - gaps.max(axis=-1)) / 2


def positively_spans(vectors) -> bool:
    """True when planar vectors positively span the plane (largest angular gap below pi)."""
    return bool(span_margin(vectors) > 0)


def _check(theta_min: float, margin: float, gap: float) -> None:
    if not (0 < theta_min < math.pi / 2):
        raise SynthesisError(f"theta_min must lie strictly between 0 and pi/2 radians, got {theta_min}")
    if not (0 <= margin < 1 and gap >= 0):
        raise SynthesisError(f"need 0 <= margin < 1 (a fraction of theta_min) and gap >= 0, got {margin} and {gap}")


def best_pair_angle(cands: Candidates, size: float, *, gap: float = GAP) -> float | None:
    """The best two-finger candidate pair for Nguyen's condition: the smallest, over pairs of
    candidates at least ``gap * size`` apart, of the larger of their two angles to the grasp line
    (radians); a pair is a grasp when this is below ``theta_min`` (less the margin). None when no
    pair is far enough apart. Tells why :func:`pair_grasps` found nothing."""
    P, N = np.asarray(cands.points), np.asarray(cands.normals)
    A, B = np.nonzero(np.triu(separated(cands.points, gap, size), 1))
    if not len(A):
        return None
    t1, t2 = nguyen_angles(P[A], N[A], P[B], N[B])
    return float(np.maximum(t1, t2).min())


def pair_grasps(cands: Candidates, theta_min: float, size: float, *, margin: float = MARGIN,
                gap: float = GAP) -> list[ForceGrasp]:
    """Two-finger force-closure grasps, one per feasible region pair (Nguyen's condition).

    Parameters
    ----------
    cands : Candidates
        Candidate contacts on the feasible regions.
    theta_min : float
        Friction cone half-angle ``atan(mu)``, radians.
    size : float
        Object size, pixels (``gap`` is a fraction of it).
    margin : float
        Smallest accepted margin ``theta_min - max(theta_1, theta_2)``, fraction of ``theta_min``.
    gap : float
        Smallest distance between the two contacts, fraction of ``size``.

    Returns
    -------
    list of ForceGrasp
        Ordered by region pair.
    """
    _check(theta_min, margin, gap)
    P, N = np.asarray(cands.points), np.asarray(cands.normals)
    far = separated(cands.points, gap, size)
    regions = np.unique(cands.region)
    found = []
    for r1, r2 in itertools.combinations_with_replacement(regions, 2):
        a, b = cands.of_region(r1), cands.of_region(r2)
        A, B = np.meshgrid(a, b, indexing="ij")
        A, B = A.ravel(), B.ravel()
        keep = far[A, B] & ((r1 != r2) | (A < B))
        A, B = A[keep], B[keep]
        if not len(A):
            continue
        t1, t2 = nguyen_angles(P[A], N[A], P[B], N[B])
        slack = theta_min - np.maximum(t1, t2)
        best = slack.max()
        if best < margin * theta_min:
            continue
        near = np.flatnonzero(slack >= best - _TIE * theta_min)
        clear = np.minimum(cands.clearance[A[near]], cands.clearance[B[near]])
        k = near[int(np.argmax(clear))]
        i, j = int(A[k]), int(B[k])
        found.append(ForceGrasp((i, j), P[[i, j]], N[[i, j]], (int(r1), int(r2)),
                                (float(t1[k]), float(t2[k])), float(slack[k]), None, theta_min))
    return found


def _grid(contour: np.ndarray, size: float, count: int) -> np.ndarray:
    """Points on a square grid of spacing ``size / count`` inside the contour's convex hull."""
    hull = shapely.convex_hull(shapely.MultiPoint(contour))
    lo, hi = contour.min(axis=0), contour.max(axis=0)
    step = size / count
    xs = np.arange(lo[0] + step / 2, hi[0], step)
    ys = np.arange(lo[1] + step / 2, hi[1], step)
    X, Y = np.meshgrid(xs, ys)
    pts = np.column_stack([X.ravel(), Y.ravel()])
    return pts[shapely.contains_xy(hull, pts[:, 0], pts[:, 1])]


def _pick(order: np.ndarray, taken: list[np.ndarray], far: np.ndarray) -> np.ndarray:
    """For every point, the first candidate in ``order`` (rows: candidates by preference, columns:
    points) far from all ``taken`` ones; -1 when none is."""
    ok = np.ones(order.shape, bool)
    for t in taken:
        ok &= far[t[None, :], order] & (t[None, :] >= 0)
    first = np.argmax(ok, axis=0)
    pick = order[first, np.arange(order.shape[1])]
    return np.where(ok.any(axis=0), pick, -1)


def triplet_grasps(cands: Candidates, contour: np.ndarray, theta_min: float, size: float, *,
                   margin: float = MARGIN, gap: float = GAP, grid: int = GRID) -> list[ForceGrasp]:
    """Three-finger force-closure grasps, one per feasible region triplet (friction zone).

    Parameters
    ----------
    cands : Candidates
        Candidate contacts on the feasible regions.
    contour : numpy.ndarray
        ``(n, 2)`` object contour; the meeting point is searched in its convex hull.
    theta_min : float
        Friction cone half-angle ``atan(mu)``, radians.
    size : float
        Object size, pixels.
    margin : float
        Smallest accepted margin (see module notes), fraction of ``theta_min``.
    gap : float
        Smallest distance between two contacts, fraction of ``size``.
    grid : int
        Points per object size of the coarse grid searched for the meeting point; the best points
        are then refined on finer grids around them (``REFINE`` levels, each a third of the last).

    Returns
    -------
    list of ForceGrasp
        Ordered by region triplet.
    """
    _check(theta_min, margin, gap)
    P, N = np.asarray(cands.points), np.asarray(cands.normals)
    found = []
    for triple, best in _triplets(cands, contour, theta_min, size, margin, gap, grid, prune="margin"):
        if best is None or best[1] < margin * theta_min:
            continue
        idx, score, x = best
        ang = angle_between(N[idx], x - P[idx])
        found.append(ForceGrasp(tuple(int(i) for i in idx), P[idx], N[idx],
                                tuple(int(cands.region[i]) for i in idx), tuple(float(v) for v in ang),
                                float(score), x.copy(), theta_min))
    return found


def best_triplet_margins(cands: Candidates, contour: np.ndarray, theta_min: float, size: float, *,
                         gap: float = GAP, grid: int = GRID) -> tuple[float | None, float | None]:
    """Why :func:`triplet_grasps` found nothing, in numbers (radians): ``(normals, best)``.

    ``normals`` is the largest spanning margin ``(pi - G) / 2`` of the normals of any three
    candidates at least ``gap * size`` apart (``G`` their largest angular gap; positive when they
    positively span the plane), ``best`` the largest margin of any triplet (the smallest of its
    cone, force and normal spanning margins at its best meeting point, as :func:`triplet_grasps`
    scores them; negative when no triplet's friction cones have a common point inside its
    contact triangle). A triplet is a grasp when ``best`` reaches the margin. ``normals`` is None
    when no three candidates are far enough apart, ``best`` when no triplet has admissible
    contacts.

    Examples
    --------
    The three normals of an equilateral triangle span the plane with a margin of 30 degrees:

    >>> import numpy as np
    >>> from qualgrasp.qualitative.synthesis.candidates import Candidates
    >>> a = np.radians([90, 210, 330])
    >>> n = -np.c_[np.cos(a), np.sin(a)]
    >>> c = Candidates(-50 * n, n, np.arange(3), np.full(3, 10.0))
    >>> normals, best = best_triplet_margins(c, -100 * n, np.radians(30), 200)
    >>> round(float(np.degrees(normals)), 1), bool(best > 0)
    (30.0, True)
    """
    far = separated(cands.points, gap, size)
    scores = [best[1] for _, best in _triplets(cands, contour, theta_min, size, -1.0, gap, grid, prune="best")
              if best is not None]
    return _best_spread(np.asarray(cands.normals), far), (max(scores) if scores else None)


def _best_spread(N: np.ndarray, far: np.ndarray) -> float | None:
    """Largest spanning margin of the normals of three pairwise ``far`` candidates (None: no such three)."""
    best = None
    for i in range(len(N) - 2):
        rest = np.flatnonzero(far[i, i + 1:]) + i + 1
        j, k = (rest[t] for t in np.triu_indices(len(rest), 1))
        j, k = j[far[j, k]], k[far[j, k]]
        if len(j):
            m = float(span_margin(np.stack([np.broadcast_to(N[i], N[j].shape), N[j], N[k]], axis=1)).max())
            best = m if best is None else max(best, m)
    return best


@dataclass(frozen=True, eq=False)
class _Looks:
    """Per-candidate quantities at the points ``X`` (pixels), computed once and looked up by every
    region triplet scored there: ``cone[row, g] = theta_min - angle(n_c, X[g] - p_c)`` and
    ``heading[row, g]``, the direction angle of ``X[g] - p_c``, for the candidate ``c`` of
    ``row = rows[c]`` (-1: not computed); ``normals[c]``, the direction angle of ``n_c``."""

    X: np.ndarray
    rows: np.ndarray
    cone: np.ndarray
    heading: np.ndarray
    normals: np.ndarray

    @classmethod
    def at(cls, X: np.ndarray, idx: np.ndarray, P: np.ndarray, N: np.ndarray, theta_min: float) -> "_Looks":
        rows = np.full(len(P), -1, dtype=np.intp)
        rows[idx] = np.arange(len(idx))
        d = X[None] - P[idx][:, None, :]
        cone = theta_min - angle_between(N[idx][:, None, :], d)
        return cls(X, rows, cone, np.arctan2(d[..., 1], d[..., 0]), np.arctan2(N[:, 1], N[:, 0]))


def _triplets(cands: Candidates, contour: np.ndarray, theta_min: float, size: float, margin: float,
              gap: float, grid: int, prune: str | None = None):
    """Every region triplet with its best ``(contacts, margin, meeting point)`` (None when it has
    no admissible contacts); a region used more than once keeps the point triples whose normals
    span with ``margin``.

    A triplet's margin is never above its normals' spanning margin, whatever the meeting point,
    so some triplets give None unsearched: with ``prune="margin"``, three distinct regions none of
    whose triples of normals span with ``margin``; with ``prune="best"``, every triplet none of
    whose triples of normals span with more than the best margin found so far (the largest
    margin stays that of the plain search).
    """
    if grid < 2:
        raise SynthesisError(f"grid must be at least 2, got {grid}")
    P, N = np.asarray(cands.points), np.asarray(cands.normals)
    X = _grid(np.asarray(contour, dtype=float), size, grid)
    if not len(P) or not len(X):
        return
    far = separated(cands.points, gap, size)
    regions = np.unique(cands.region)
    members = {int(r): cands.of_region(r) for r in regions}
    coarse = _Looks.at(X, np.arange(len(P)), P, N, theta_min)
    directions = {r: np.unique(coarse.normals[idx]) for r, idx in members.items()}
    curved = {r: len(np.unique(np.round(N[idx], 9), axis=0)) > 1 for r, idx in members.items()}
    bounds = _spread_bounds(directions) if prune else {}
    floor = margin * theta_min if prune == "margin" else -np.inf
    picks: dict[tuple, np.ndarray] = {}  # the first regions' picks on the coarse grid, shared by triplets
    for triple in itertools.combinations_with_replacement((int(r) for r in regions), 3):
        if picks and (triple[0],) not in picks:
            picks.clear()  # triplets come in order: the first region's picks are done with
        if len(set(triple)) < 3 and not all(curved[r] for r in triple if triple.count(r) > 1):
            continue  # two contacts on one straight region share their normal: never spanning
        combos = None
        if len(set(triple)) < 3:
            combos = _combinations(triple, cands, far)
            # the normals' spanning margin bounds the score whatever the meeting point
            spans = span_margin(np.moveaxis(N[combos], 0, 1))
            combos = combos[:, spans >= margin * theta_min]
            if not combos.shape[1] or (prune and spans.max() < floor):
                yield triple, None
                continue
        elif prune and bounds[triple] < floor:
            yield triple, None
            continue
        best = _search(triple, combos, coarse, size / grid, cands, members, far, theta_min, picks)
        if prune == "best" and best is not None:
            floor = max(floor, best[1])
        yield triple, best


def _spread_bounds(directions: dict[int, np.ndarray]) -> dict[tuple[int, int, int], float]:
    """For every three distinct regions ``r1 < r2 < r3`` (keys of ``directions``, each region's
    distinct normal directions, radians), the largest spanning margin of three normals, one on
    each: a bound on the normal spanning margin of any of their contact triples. One call per
    region pair, over all the third regions after it."""
    keys = sorted(directions)
    bounds = {}
    for a, b in itertools.combinations(range(len(keys)), 2):
        rest = [directions[r] for r in keys[b + 1:]]
        if not rest:
            continue
        A, B, C = np.meshgrid(directions[keys[a]], directions[keys[b]], np.concatenate(rest), indexing="ij")
        span = _angle_span(np.stack([A, B, C], axis=-1)).max(axis=(0, 1))
        starts = np.cumsum([0] + [len(d) for d in rest[:-1]])
        for r, value in zip(keys[b + 1:], np.maximum.reduceat(span, starts)):
            bounds[keys[a], keys[b], r] = float(value)
    return bounds


def _search(triple, combos, coarse: _Looks, step, cands, members, far, theta_min, picks, keep: int = 8):
    """Best (contacts, margin, meeting point): the coarse grid, then finer grids around the best."""
    offsets = np.stack(np.meshgrid(np.arange(-2, 3), np.arange(-2, 3)), axis=-1).reshape(-1, 2)
    P, N = np.asarray(cands.points), np.asarray(cands.normals)
    used = np.unique(np.concatenate([members[r] for r in set(triple)]))
    score, T = _scores(triple, combos, coarse, members, far, picks)
    X = coarse.X
    for _ in range(REFINE):
        if not np.isfinite(score).any():
            return None
        step /= 3
        top = np.argsort(-score)[:keep]
        X = np.vstack([X[top], (X[top][:, None, :] + step * offsets[None]).reshape(-1, 2)])
        score, T = _scores(triple, combos, _Looks.at(X, used, P, N, theta_min), members, far, None)
    g = int(np.argmax(score))
    if not np.isfinite(score[g]):
        return None
    return T[:, g], float(score[g]), X[g]


def _scores(triple, combos, looks: _Looks, members, far, picks) -> tuple[np.ndarray, np.ndarray]:
    """Margin at every point of ``looks.X`` with its best contacts: ``(G,)`` scores, ``(3, G)`` contacts.

    Distinct regions: each region's candidate deepest in its cone at the point (``picks``, when
    given, keeps the first regions' picks for the next triplets). A region used more than once:
    the best of the admissible ``combos`` (``(3, C)``) at the point.
    """
    if combos is None:
        taken: list[np.ndarray] = []
        for k, r in enumerate(triple):
            key = triple[:k + 1]
            if picks is None or key not in picks:
                idx = members[r]
                order = idx[np.argsort(-looks.cone[looks.rows[idx]], axis=0, kind="stable")]
                pick = _pick(order, taken, far)
                if picks is not None and k < 2:
                    picks[key] = pick
            else:
                pick = picks[key]
            taken.append(pick)
        T = np.stack(taken)
        valid = (T >= 0).all(axis=0)
        T = np.where(valid, T, 0)
        score = _margins(T, np.arange(len(looks.X)), looks)
        return np.where(valid, score, -np.inf), T
    best = np.full(len(looks.X), -np.inf)
    T = np.zeros((3, len(looks.X)), dtype=np.intp)
    G = np.arange(len(looks.X))
    for lo in range(0, combos.shape[1], 256):  # chunks bound the (3, C, G) temporaries
        part = combos[:, lo:lo + 256]
        score = _margins(part[:, :, None], G[None], looks)  # (C, G)
        c = np.argmax(score, axis=0)
        better = score[c, G] > best
        best[better] = score[c, G][better]
        T[:, better] = part[:, c[better]]
    return best, T


def _margins(T: np.ndarray, G: np.ndarray, looks: _Looks) -> np.ndarray:
    """Smallest of the cone margins of the meeting points ``looks.X[G]`` and the spanning margins
    of the force directions and of the normals, for contact triples ``T`` (first axis: the three)."""
    R = looks.rows[T]
    cone = looks.cone[R, G].min(axis=0)
    forces = _angle_span(np.moveaxis(looks.heading[R, G], 0, -1))
    normals = _angle_span(np.moveaxis(looks.normals[T], 0, -1))
    return np.minimum(np.minimum(cone, forces), normals)


def _combinations(triple, cands: Candidates, far: np.ndarray, limit: int = 2048) -> np.ndarray:
    """A region used twice or thrice: every admissible triple of its points (with the other
    region's points), ``(3, C)``; evenly thinned to ``limit`` triples. The point deepest in the
    cone is no guide here (on a disc every point is equally deep from the centre): the spread
    of the points decides."""
    parts = []
    for r in sorted(set(triple)):
        idx = cands.of_region(r)
        parts.append(list(itertools.combinations(idx, triple.count(r))))
    rows = np.array([sum(combo, ()) for combo in itertools.product(*parts)], dtype=np.intp).reshape(-1, 3)
    ok = far[rows[:, 0], rows[:, 1]] & far[rows[:, 0], rows[:, 2]] & far[rows[:, 1], rows[:, 2]]
    rows = rows[ok]
    if len(rows) > limit:
        rows = rows[np.linspace(0, len(rows) - 1, limit).astype(int)]
    return rows.T


def friction_cone(point, normal, theta_min: float, reach: float) -> Polygon:
    """The inward friction cone of a contact as a triangle of side ``reach`` (pixels).

    Parameters
    ----------
    point, normal : array_like
        Contact point and inward unit normal, pixels.
    theta_min : float
        Half-angle, radians.
    reach : float
        Length of the cone's edges (the cone itself is unbounded).
    """
    p = np.asarray(point, dtype=float)
    n = np.asarray(normal, dtype=float)
    n = n / np.linalg.norm(n)
    edges = [p + reach * np.array([n[0] * math.cos(s) - n[1] * math.sin(s),
                                   n[0] * math.sin(s) + n[1] * math.cos(s)]) for s in (-theta_min, theta_min)]
    return Polygon([p, *edges])


def friction_zone(points: Sequence, normals: Sequence, theta_min: float, reach: float) -> BaseGeometry:
    """Intersection of the contacts' inward friction cones (each cut at ``reach`` pixels)."""
    zone = None
    for p, n in zip(points, normals):
        cone = friction_cone(p, n, theta_min, reach)
        zone = cone if zone is None else zone.intersection(cone)
    return zone if zone is not None else Polygon()

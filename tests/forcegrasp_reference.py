"""The reference route for the tests of the three-finger ForceGrasp search
(:func:`qualgrasp.qualitative.synthesis.forcegrasp.triplet_grasps`): the search as it was before
issue 27 part 5 made it fast, moved verbatim (every region triplet scored on the whole grid, no
pruning, nothing shared between triplets), so that a test can check the fast search returns the
same grasps. Only the parameter checks are left out (the fast route's tests cover them)."""

import itertools

import numpy as np
import shapely

from qualgrasp.qualitative.errors import SynthesisError
from qualgrasp.qualitative.synthesis.candidates import GAP, Candidates, separated
from qualgrasp.qualitative.synthesis.forcegrasp import GRID, MARGIN, REFINE, ForceGrasp, angle_between, span_margin


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



def triplet_grasps_reference(cands: Candidates, contour: np.ndarray, theta_min: float, size: float, *,
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
    P, N = np.asarray(cands.points), np.asarray(cands.normals)
    found = []
    for triple, best in _triplets(cands, contour, theta_min, size, margin, gap, grid):
        if best is None or best[1] < margin * theta_min:
            continue
        idx, score, x = best
        ang = angle_between(N[idx], x - P[idx])
        found.append(ForceGrasp(tuple(int(i) for i in idx), P[idx], N[idx],
                                tuple(int(cands.region[i]) for i in idx), tuple(float(v) for v in ang),
                                float(score), x.copy(), theta_min))
    return found



def _triplets(cands: Candidates, contour: np.ndarray, theta_min: float, size: float, margin: float,
              gap: float, grid: int):
    """Every region triplet with its best ``(contacts, margin, meeting point)`` (None when it has
    no admissible contacts); a region used more than once keeps the point triples whose normals
    span with ``margin``."""
    if grid < 2:
        raise SynthesisError(f"grid must be at least 2, got {grid}")
    P, N = np.asarray(cands.points), np.asarray(cands.normals)
    X = _grid(np.asarray(contour, dtype=float), size, grid)
    if not len(P) or not len(X):
        return
    far = separated(cands.points, gap, size)
    regions = np.unique(cands.region)
    curved = {int(r): len(np.unique(np.round(N[cands.of_region(r)], 9), axis=0)) > 1 for r in regions}
    for triple in itertools.combinations_with_replacement(regions, 3):
        if len(set(triple)) < 3 and not all(curved[int(r)] for r in triple if triple.count(r) > 1):
            continue  # two contacts on one straight region share their normal: never spanning
        combos = None
        if len(set(triple)) < 3:
            combos = _combinations(triple, cands, far)
            # the normals' spanning margin bounds the score whatever the meeting point
            combos = combos[:, span_margin(np.moveaxis(N[combos], 0, 1)) >= margin * theta_min]
            if not combos.shape[1]:
                yield triple, None
                continue
        yield triple, _search(triple, combos, X, size / grid, cands, far, theta_min)


def _search(triple, combos, X, step, cands, far, theta_min, keep: int = 8):
    """Best (contacts, margin, meeting point): the grid ``X``, then finer grids around the best."""
    offsets = np.stack(np.meshgrid(np.arange(-2, 3), np.arange(-2, 3)), axis=-1).reshape(-1, 2)
    score, T = _scores(triple, combos, X, cands, far, theta_min)
    for _ in range(REFINE):
        if not np.isfinite(score).any():
            return None
        step /= 3
        top = np.argsort(-score)[:keep]
        X = np.vstack([X[top], (X[top][:, None, :] + step * offsets[None]).reshape(-1, 2)])
        score, T = _scores(triple, combos, X, cands, far, theta_min)
    g = int(np.argmax(score))
    if not np.isfinite(score[g]):
        return None
    return T[:, g], float(score[g]), X[g]


def _scores(triple, combos, X, cands, far, theta_min) -> tuple[np.ndarray, np.ndarray]:
    """Margin at every point of ``X`` with its best contacts: ``(G,)`` scores, ``(3, G)`` contacts.

    Distinct regions: each region's candidate deepest in its cone at the point. A region used more
    than once: the best of the admissible ``combos`` (``(3, C)``) at the point.
    """
    P, N = np.asarray(cands.points), np.asarray(cands.normals)
    if combos is None:
        taken: list[np.ndarray] = []
        for r in triple:
            idx = cands.of_region(r)
            cone = theta_min - angle_between(N[idx][:, None, :], X[None] - P[idx][:, None, :])
            taken.append(_pick(idx[np.argsort(-cone, axis=0, kind="stable")], taken, far))
        T = np.stack(taken)
        valid = (T >= 0).all(axis=0)
        T = np.where(valid, T, 0)
        score = _margins(T, X, P, N, theta_min)
        return np.where(valid, score, -np.inf), T
    best = np.full(len(X), -np.inf)
    T = np.zeros((3, len(X)), dtype=np.intp)
    for lo in range(0, combos.shape[1], 256):  # chunks bound the (3, C, G, 2) temporaries
        part = combos[:, lo:lo + 256]
        score = _margins(part[:, :, None], X[None], P, N, theta_min)  # (C, G)
        c = np.argmax(score, axis=0)
        better = score[c, np.arange(len(X))] > best
        best[better] = score[c, np.arange(len(X))][better]
        T[:, better] = part[:, c[better]]
    return best, T


def _margins(T: np.ndarray, X: np.ndarray, P, N, theta_min: float) -> np.ndarray:
    """Smallest of the cone margins of the meeting points ``X`` and the spanning margins of the
    force directions and of the normals, for contact triples ``T`` (first axis: the three)."""
    d = X - P[T]  # (3, ..., 2)
    cone = (theta_min - angle_between(N[T], d)).min(axis=0)
    forces = span_margin(np.moveaxis(d, 0, -2))
    normals = span_margin(np.moveaxis(N[T], 0, -2))
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


def best_triplet_score_reference(cands: Candidates, contour: np.ndarray, theta_min: float, size: float, *,
                                 gap: float = GAP, grid: int = GRID) -> float | None:
    """The largest margin of any region triplet, as the search scores it (the ``best`` of
    :func:`qualgrasp.qualitative.synthesis.forcegrasp.best_triplet_margins`); None when no triplet has
    admissible contacts."""
    scores = [best[1] for _, best in _triplets(cands, contour, theta_min, size, -1.0, gap, grid) if best is not None]
    return max(scores) if scores else None

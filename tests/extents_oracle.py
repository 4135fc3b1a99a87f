"""Independent routes for the tests of certified extents: a closure oracle by linear programming
(scipy's HiGHS on the friction cones' edge wrenches, not certify's solvers), the arc length a
region tuple covers around each contact, and placements sampled along a boundary polygon."""

import itertools

import numpy as np
from scipy.optimize import linprog

from qualgrasp.certify.regions import StraightRegion


def edge_wrenches(points, normals, mus, center, length) -> np.ndarray:
    """``(3, m)`` planar wrenches of the friction cones' edges (the normal alone when mu = 0),
    torques about ``center`` divided by ``length``."""
    cols = []
    c = np.asarray(center, float)
    for p, n, mu in zip(points, normals, mus):
        n = np.asarray(n, float) / np.linalg.norm(n)
        t = np.array([-n[1], n[0]])
        forces = [n] if mu == 0 else [n + mu * t, n - mu * t]
        for f in forces:
            r = np.asarray(p, float) - c
            cols.append([f[0], f[1], (r[0] * f[1] - r[1] * f[0]) / length])
    return np.array(cols).T


def closure_margin(points, normals, mus, center, length) -> float:
    """Largest ``t`` with ``sum l_i w_i = 0``, ``sum l_i = 1``, ``l_i >= t`` over the edge
    wrenches ``w_i``; force closure iff it is positive and the wrenches have rank 3 (-1 when they
    do not). A strictly positive combination summing to zero with full rank: the origin is
    interior to their convex hull, so they positively span the plane's wrenches."""
    W = edge_wrenches(points, normals, mus, center, length)
    m = W.shape[1]
    if np.linalg.matrix_rank(W, tol=1e-9) < 3:
        return -1.0
    # variables (l_1..l_m, t); maximise t
    cost = np.zeros(m + 1)
    cost[-1] = -1.0
    A_eq = np.vstack([np.hstack([W, np.zeros((3, 1))]), np.hstack([np.ones(m), [0.0]])])
    b_eq = np.array([0.0, 0.0, 0.0, 1.0])
    A_ub = np.hstack([-np.eye(m), np.ones((m, 1))])  # t - l_i <= 0
    res = linprog(cost, A_ub=A_ub, b_ub=np.zeros(m), A_eq=A_eq, b_eq=b_eq,
                  bounds=[(0, None)] * m + [(None, None)], method="highs")
    if res.status == 2:  # no non-negative combination sums to zero: not in closure
        return -1.0
    assert res.status == 0, res.message
    return float(res.x[-1])


def polyline_extents(polyline: np.ndarray, p) -> tuple[float, float]:
    """Arc length along ``polyline`` from its first point to the point nearest ``p``, and from
    there to its last point."""
    P = np.asarray(polyline, float)
    if len(P) == 1:
        return 0.0, 0.0
    D = np.diff(P, axis=0)
    L = np.hypot(D[:, 0], D[:, 1])
    t = np.clip(np.einsum("ij,ij->i", np.asarray(p, float) - P[:-1], D) / np.where(L > 0, L * L, 1), 0, 1)
    near = P[:-1] + t[:, None] * D
    j = int(np.argmin(np.hypot(*(near - np.asarray(p, float)).T)))
    before = float(L[:j].sum() + t[j] * L[j])
    return before, float(L.sum() - before)


def region_extents(region, p) -> tuple[float, float]:
    """``(before, after)`` arc length covered by ``region`` around the contact at ``p``."""
    poly = np.array([region.a, region.b]) if isinstance(region, StraightRegion) else region.points
    return polyline_extents(poly, p)


class Polygon:
    """A closed boundary polygon with per-point normals, read as arc length: ``at(u)`` is the
    point at arc length ``u`` (modulo the perimeter) with the normalised interpolation of its
    edge's end normals."""

    def __init__(self, points, normals):
        self.P = np.asarray(points, float)
        self.N = np.asarray(normals, float)
        D = np.roll(self.P, -1, axis=0) - self.P
        self.cum = np.concatenate([[0.0], np.cumsum(np.hypot(D[:, 0], D[:, 1]))])

    @property
    def perimeter(self) -> float:
        return float(self.cum[-1])

    def arc(self, p) -> float:
        """Arc length of the boundary point nearest ``p``."""
        P, n = self.P, len(self.P)
        D = np.roll(P, -1, axis=0) - P
        L2 = (D * D).sum(axis=1)
        t = np.clip(((np.asarray(p, float) - P) * D).sum(axis=1) / np.where(L2 > 0, L2, 1), 0, 1)
        e = int(np.argmin(np.hypot(*(P + t[:, None] * D - np.asarray(p, float)).T)))
        return float(self.cum[e] + t[e] * np.sqrt(L2[e])) % self.perimeter if n else 0.0

    def at(self, u: float, from_below: bool = False):
        """Point and normal at arc length ``u``; at a boundary point shared by two edges (a
        corner), on the edge after it, or before it when ``from_below`` (approached from
        smaller arc lengths)."""
        u = u % self.perimeter
        if from_below and u == 0:
            u = self.perimeter
        e = int(np.searchsorted(self.cum, u, side="left" if from_below else "right")) - 1
        e = min(max(e, 0), len(self.P) - 1)
        length = self.cum[e + 1] - self.cum[e]
        lam = 0.0 if length <= 0 else (u - self.cum[e]) / length
        f = (e + 1) % len(self.P)
        p = self.P[e] + lam * (self.P[f] - self.P[e])
        n = (1 - lam) * self.N[e] + lam * self.N[f]
        return p, n / np.linalg.norm(n)


def placements_within(boundary: Polygon, s: float, before: float, after: float, count: int) -> list:
    """``count`` placements ``(p, n)`` evenly spread by arc length over ``[s - before, s + after]``
    (both ends and the contact's own position among them)."""
    u = np.unique(np.concatenate([np.linspace(s - before, s + after, count), [s]]))
    return [boundary.at(v, from_below=v > s) for v in u]  # a stretch's end on a corner: its own side


def every_choice_holds(choices: list, mus, center, length, rng, random: int = 300) -> tuple[bool, float]:
    """Every combination of one placement per finger at an end of its stretch, and ``random``
    random combinations: all in closure by :func:`closure_margin`? Returns (all held, smallest
    margin)."""
    ends = [[c[0], c[-1]] for c in choices]
    combos = list(itertools.product(*ends))
    for _ in range(random):
        combos.append(tuple(c[int(rng.integers(len(c)))] for c in choices))
    worst = np.inf
    for combo in combos:
        m = closure_margin([q[0] for q in combo], [q[1] for q in combo], mus, center, length)
        worst = min(worst, m)
        if m <= 0:
            return False, m
    return True, float(worst)

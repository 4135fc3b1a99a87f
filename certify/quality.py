"""Grasp quality: Ferrari-Canny epsilon of the L1 and L-infinity grasp wrench spaces.

The grasp wrench space (GWS) is built from each contact's wrenches with unit normal force,
``W_i = {G_i f : f in cone_i, f_n = 1}``. The L1 GWS is ``conv(0 and all W_i)`` (total normal
force at most 1), the L-infinity GWS the Minkowski sum of the ``conv(0, W_i)`` (each normal force
at most 1). Epsilon is the radius of the largest ball centred at the origin inside the GWS,
``epsilon = min over unit u of h(u)``, with the support function

    h_L1(u) = max_i max(0, a_n,i + mu_i norm(a_t,i))      h_Linf(u) = sum_i max(0, a_n,i + mu_i norm(a_t,i))

(``(a_n, a_t)`` the components of ``G_i' u`` in the contact frame; frictionless: ``a_n`` only).

Torque scaling is explicit: wrenches are ``(f, (p - center) x f / length)``, so epsilon depends on
``center`` and ``length`` (every :class:`Epsilon` states both). Scaling the object, the contacts,
``center`` and ``length`` together leaves epsilon unchanged; dividing ``length`` by ``s`` multiplies
the torque coordinates by ``s``. The min-weight margin of :mod:`qualgrasp.certify.closure` depends on neither.

Planar grasps: every contact model is polyhedral in the plane, so epsilon is exact: the minimum
of ``h`` over a finite set of directions that contains every facet normal of the GWS (normals of
triples of generator points for L1; cross products of pairs of edges of the per-contact polytopes
``conv(0, generators of the contact)`` for L-infinity, since every facet of a Minkowski sum in 3-D
is a facet of a summand or spanned by two summands' edges).

Spatial grasps with exact cones: rigorous bounds ``lo <= epsilon <= hi`` by branch and bound over
the sphere of wrench directions. ``h(u)`` at any unit ``u`` is an upper bound; the best one is
refined by local minimisation (a tangent-plane SOCP). The sphere is covered by cells (the faces of
the cube ``[-1, 1]^d`` cut into boxes, projected radially); each cell gets a lower bound of ``h``
over it from global linear minorants of the contacts' pieces (and, for L1, the exact minimum over
the flat cell, an SOCP solved by clarabel whose dual is turned into a minorant valid whatever the
solver's accuracy). Cells whose bound reaches ``(1 - rel_gap) hi`` are retired, the others split,
until ``hi - lo <= rel_gap * hi`` or the budget of cells is spent.

Epsilon is 0 for grasps not in closure (and for degenerate ones): the closure verdict is decided
first, so flat hulls and rank-deficient sets never reach qhull.
"""

from __future__ import annotations

from dataclasses import dataclass

import clarabel
import numpy as np
import scipy.sparse as sp
from scipy.spatial import ConvexHull, QhullError

from ._kernels.epsilon import planar_epsilon as kernel_planar_epsilon
from .closure import Verdict, force_closure
from .grasp import Grasp
from .problem import System, grasp_system
from .solvers.clarabel_direct import settings

__all__ = ["NORMS", "Epsilon", "epsilon", "planar_epsilon", "epsilon_of_points", "epsilon_linearised"]

NORMS = ("L1", "Linf")


@dataclass(frozen=True)
class Epsilon:
    """Ferrari-Canny epsilon with the torque scaling it was computed with.

    Attributes
    ----------
    norm : {'L1', 'Linf'}
    lo, hi : float
        Rigorous bounds ``lo <= epsilon <= hi`` (equal for planar grasps, 0 when not in closure).
    direction : tuple of float or None
        Unit wrench direction where ``h`` attains ``hi``: the weakest direction of the grasp.
    center : tuple of float
        Reference point of torques used.
    length : float
        Length dividing torques used.
    exact : bool
        True when ``lo == hi`` by construction (planar grasps, grasps not in closure).
    rounds : int
        Branch-and-bound rounds spent (spatial grasps).
    """

    norm: str
    lo: float
    hi: float
    direction: tuple[float, ...] | None
    center: tuple[float, ...]
    length: float
    exact: bool
    rounds: int = 0

    @property
    def gap(self) -> float:
        """Relative gap ``(hi - lo) / hi`` (0 when ``hi`` is 0)."""
        return (self.hi - self.lo) / self.hi if self.hi > 0 else 0.0


def _check_norm(norm: str) -> None:
    if norm not in NORMS:
        raise ValueError(f"unknown norm {norm!r}; use 'L1' or 'Linf'")


def planar_epsilon(grasp: Grasp, norm: str) -> tuple[float, np.ndarray]:
    """Exact planar epsilon and its direction (the compiled kernel that also serves whole
    batches), over the grasp's generator wrenches (:func:`qualgrasp.certify.problem.grasp_system`)."""
    system = grasp_system(grasp)
    owner = np.array([b.contact for b in system.blocks], dtype=np.int64)
    eps, arg = kernel_planar_epsilon(np.ascontiguousarray(system.columns[None]), owner,
                                     len(grasp.contacts), norm == "Linf")
    return float(eps[0]), arg[0]


def _zero(grasp: Grasp, norm: str) -> Epsilon:
    return Epsilon(norm, 0.0, 0.0, None, tuple(grasp.center), grasp.length, True)


def epsilon(grasp: Grasp, norm: str = "L1", *, rel_gap: float = 0.01, budget: int = 200_000,
            verdict: Verdict | None = None) -> Epsilon:
    """Ferrari-Canny epsilon of ``grasp`` for the ``norm`` GWS (module docstring).

    Parameters
    ----------
    grasp : Grasp
    norm : {'L1', 'Linf'}
    rel_gap : float
        Spatial grasps: stop when ``hi - lo <= rel_gap * hi``.
    budget : int
        Spatial grasps: the most work spent, in cells of the sphere of directions examined (an
        exact cell bound, an SOCP, counts as :data:`EXACT_CELL_COST` cells); the gap reached is
        reported. A count, not a time, so that results are reproducible on any machine.
    verdict : Verdict, optional
        The grasp's force-closure verdict, if already known.

    Returns
    -------
    Epsilon
        Bounds with the ``center`` and ``length`` used; 0 unless the grasp is in force closure.

    Raises
    ------
    ValueError
        Unknown ``norm``.

    Examples
    --------
    Two antipodal point contacts on the unit circle with ``mu = 0.5`` (exact in the plane):

    >>> from qualgrasp.certify import Contact, Grasp
    >>> from qualgrasp.certify.quality import epsilon
    >>> g = Grasp((Contact((1, 0), (-1, 0), "point", 0.5), Contact((-1, 0), (1, 0), "point", 0.5)))
    >>> e = epsilon(g, "L1")
    >>> round(e.lo, 6), e.exact, e.center, e.length
    (0.333333, True, (0.0, 0.0), 1.0)
    """
    _check_norm(norm)
    verdict = verdict or force_closure(grasp)
    if verdict.status != "closure":
        return _zero(grasp, norm)
    if grasp.dim == 2:
        eps, u = planar_epsilon(grasp, norm)
        return Epsilon(norm, eps, eps, tuple(float(v) for v in u), tuple(grasp.center),
                       grasp.length, True)
    return _refine(grasp, grasp_system(grasp, socp=True), norm, rel_gap, budget)


class _Pieces:
    """Each contact's support ``c_b(v) = p_b . v + kappa_b norm(T_b v)`` as stacked arrays.

    ``h_L1 = max_b max(0, c_b)`` and ``h_Linf = sum_b max(0, c_b)``. Because
    ``norm(x) >= s . x`` for every ``norm(s) <= 1``, ``g_b = p_b + kappa_b T_b' s`` with
    ``s = T_b v0 / norm(T_b v0)`` is a global linear minorant of ``c_b``, exact along ``v0``.
    """

    def __init__(self, system: System) -> None:
        C = system.columns
        d = C.shape[0]
        rows = []
        self.p = np.zeros((len(system.blocks), d))
        self.kappa = np.zeros(len(system.blocks))
        for i, b in enumerate(system.blocks):
            cols = C[:, list(b.cols)].T  # functional rows: a = cols @ v
            if b.cone == "ray":
                self.p[i] = cols[0]
                rows.append(np.zeros((0, d)))
                continue
            n = np.asarray(b.n, dtype=float)
            rn = np.linalg.norm(n)
            n_hat = n / rn
            dim = len(n)
            self.p[i] = n_hat @ cols[:dim]
            T = cols[:dim] - np.outer(n_hat, self.p[i])
            if len(b.cols) > dim:  # moment columns, weighted as in qualgrasp.certify.cones.polar
                T = np.vstack([T, float(b.g) / rn * cols[dim:]])
            rows.append(T)
            self.kappa[i] = float(b.mu)
        r = max(1, max(len(t) for t in rows))
        self.T = np.zeros((len(rows), r, d))
        for i, t in enumerate(rows):
            self.T[i, : len(t)] = t

    def at(self, V: np.ndarray):
        """Values ``c`` (n, nb) and minorant gradients ``g`` (n, nb, d) at directions ``V``."""
        Tv = np.einsum("brd,nd->nbr", self.T, V)
        norm = np.linalg.norm(Tv, axis=2)
        c = V @ self.p.T + self.kappa * norm
        s = np.divide(Tv, norm[..., None], out=np.zeros_like(Tv), where=norm[..., None] > 0)
        g = self.p + self.kappa[:, None] * np.einsum("nbr,brd->nbd", s, self.T)
        return c, g

    def h(self, V: np.ndarray, norm: str) -> np.ndarray:
        c = np.maximum(self.at(V)[0], 0.0)
        return c.max(axis=1) if norm == "L1" else c.sum(axis=1)

    def cell_bound(self, V: np.ndarray, centre: np.ndarray, norm: str, rounds: int = 24) -> np.ndarray:
        """Lower bound of ``h`` over each flat cell ``conv(V[i])`` (V: (n, m, d)).

        Each piece is linearised at the cell's centre: ``g_b`` is a global linear minorant of
        piece ``b``. For L1 any convex combination of them is a minorant of ``h``; for
        L-infinity any weights in [0, 1]. The minimum of a linear minorant over a cell is at a
        vertex. The weights are improved by a few rounds of multiplicative (L1) or projected
        (L-infinity) updates against the worst vertex: every round's value is a valid bound, and
        the best is kept.
        """
        c, g = self.at(centre)
        M = np.einsum("nbd,nmd->nbm", g, V)  # minorant of piece b at vertex j
        n = len(M)
        rows = np.arange(n)
        if norm == "L1":
            w = np.where(c >= c.max(axis=1, keepdims=True) - 1e-12, 1.0, 0.0)
            w /= w.sum(axis=1, keepdims=True)
        else:
            w = (c > 0).astype(float)
        scale = np.abs(M).max(axis=(1, 2))[:, None] + 1e-300
        best = np.zeros(n)
        for k in range(rounds):
            vals = np.einsum("nb,nbm->nm", w, M)
            j = np.argmin(vals, axis=1)
            best = np.maximum(best, vals[rows, j])
            grad = M[rows, :, j] / scale
            step = 2.0 / np.sqrt(k + 1)
            if norm == "L1":
                w = w * np.exp(step * grad)
                w /= w.sum(axis=1, keepdims=True)
            else:
                w = np.clip(w + 0.5 * step * grad, 0.0, 1.0)
        return best

    def tangent_minimum(self, u0: np.ndarray, norm: str):
        """Minimise ``h`` over the tangent plane ``u . u0 = 1`` (an SOCP, solved by clarabel).

        Returns the unit minimiser direction and the gradient of the minorant given by the
        multipliers: ``sum_b w_b (p_b + kappa_b T_b' s_b)`` with ``w_b`` the multiplier of piece
        ``b`` and ``s_b = -z_rest / w_b`` its dual subgradient (norm at most 1, meaningful even
        at a cone's apex where ``T_b u = 0``). At a minimiser of ``h`` on the sphere the
        tangent-plane problem has the same solution, so iterating from ``u / norm(u)`` converges
        to it, and this minorant is then tight to second order around it.
        """

        nb, r, d = self.T.shape
        nt = 1 if norm == "L1" else nb
        n = d + nt
        rows = [np.r_[u0, np.zeros(nt)]]
        cones = [clarabel.ZeroConeT(1)]
        b = [1.0]
        rows += list(np.hstack([np.zeros((nt, d)), -np.eye(nt)]))
        cones.append(clarabel.NonnegativeConeT(nt))
        b += [0.0] * nt
        for i in range(nb):
            tcol = np.zeros(nt)
            tcol[0 if norm == "L1" else i] = -1.0
            rows.append(np.r_[self.p[i], tcol])
            rk = int(np.count_nonzero(np.abs(self.T[i]).sum(axis=1)))
            rows += list(np.hstack([-self.kappa[i] * self.T[i, :rk], np.zeros((rk, nt))]))
            cones.append(clarabel.SecondOrderConeT(1 + rk) if rk else clarabel.NonnegativeConeT(1))
            b += [0.0] * (1 + rk)
        A = sp.csc_matrix(np.array(rows))
        q = np.r_[np.zeros(d), np.ones(nt)]

        sol = clarabel.DefaultSolver(sp.csc_matrix((n, n)), q, A, np.array(b), cones,
                                     settings()).solve()
        if str(sol.status) not in ("Solved", "AlmostSolved"):
            return None, None
        x, z = np.asarray(sol.x), np.asarray(sol.z)
        grad, k = np.zeros(d), 1 + nt
        for i in range(nb):
            rk = int(np.count_nonzero(np.abs(self.T[i]).sum(axis=1)))
            w = min(max(z[k], 0.0), 1.0)
            g = self.p[i].copy()
            if rk and z[k] > 0:
                s_dual = -z[k + 1:k + 1 + rk] / z[k]
                s_dual /= max(1.0, np.linalg.norm(s_dual))  # stay a valid subgradient
                g += self.kappa[i] * s_dual @ self.T[i, :rk]
            grad += w * g
            k += 1 + rk
        if norm == "L1":
            grad /= max(1.0, sum(min(max(z[j], 0.0), 1.0) for j in self._starts(nt)))
        u = x[:d]
        return u / np.linalg.norm(u), grad

    def _starts(self, nt: int):
        """Positions in clarabel's ``z`` of each piece's first (scalar) multiplier."""
        k, out = 1 + nt, []
        for i in range(len(self.p)):
            out.append(k)
            k += 1 + int(np.count_nonzero(np.abs(self.T[i]).sum(axis=1)))
        return out

    def local_minimum(self, u: np.ndarray, norm: str, iters: int = 8):
        """Refine ``u`` towards a local minimiser of ``h`` on the sphere; return ``(u, h(u),
        minorant gradient)``, the minorant built from the multipliers at the final ``u``."""
        h_u = float(self.h(u[None], norm)[0])
        grad = np.zeros(len(u))
        for _ in range(iters):
            v, gv = self.tangent_minimum(u, norm)
            if v is None:
                break
            grad = gv
            h_v = float(self.h(v[None], norm)[0])
            if h_v >= h_u * (1 - 1e-12) or np.linalg.norm(v - u) < 1e-10:
                break
            u, h_u = v, h_v
        return u, h_u, grad


#: Work of one exact cell bound (an SOCP) in units of cheap cell bounds, for the budget.
EXACT_CELL_COST = 25


class _CellSolver:
    """Exact minimum of ``h`` over flat cells ``conv(V)``, as a rigorous lower bound.

    For a cell with vertices ``V`` (m, d) it solves ``min over lambda in the simplex of
    h(V' lambda)`` (an SOCP, clarabel with prebuilt sparse structure refilled per cell), then
    turns the dual solution into a linear minorant of ``h`` (weights ``w_b`` and dual
    subgradients ``s_b``, clipped to be exactly feasible) and returns its minimum over the
    vertices: a bound valid whatever the solver's accuracy, equal to the flat minimum when the
    solver is accurate.
    """

    def __init__(self, pieces: _Pieces, m: int, norm: str) -> None:

        self.pieces, self.m, self.norm = pieces, m, norm
        self.rk = [int(np.count_nonzero(np.abs(t).sum(axis=1))) for t in pieces.T]
        nt = 1 if norm == "L1" else len(pieces.p)
        n = m + nt
        # rows: simplex (1), lambda >= 0 and t >= 0 (n), then per piece 1 + rk rows
        rows, cols, self.piece_rows = [np.zeros(m, int)], [np.arange(m)], []
        rows.append(1 + np.arange(n)), cols.append(np.arange(n))
        r = 1 + n
        cones = [clarabel.ZeroConeT(1), clarabel.NonnegativeConeT(n)]
        for i, rk in enumerate(self.rk):
            block = np.arange(r, r + 1 + rk)
            self.piece_rows.append(block)
            rows.append(np.repeat(block, m)), cols.append(np.tile(np.arange(m), 1 + rk))
            rows.append(np.array([r])), cols.append(np.array([m + (0 if norm == "L1" else i)]))
            cones.append(clarabel.SecondOrderConeT(1 + rk) if rk else clarabel.NonnegativeConeT(1))
            r += 1 + rk
        rows, cols = np.concatenate(rows), np.concatenate(cols)
        order = sp.csc_matrix((np.arange(len(rows), dtype=float), (rows, cols)), shape=(r, n))
        self.perm = order.data.astype(int)
        self.template = np.concatenate([np.ones(m), -np.ones(n)] + [
            np.concatenate([np.zeros(m * (1 + rk)), [-1.0]]) for rk in self.rk])
        self.fill = np.concatenate([
            m + n + sum((1 + rk) * m + 1 for rk in self.rk[:i]) + np.arange((1 + rk) * m)
            for i, rk in enumerate(self.rk)])
        b = np.zeros(r)
        b[0] = 1.0
        settings_ = settings()
        settings_.tol_gap_abs = settings_.tol_gap_rel = settings_.tol_feas = 1e-5
        self.solver = clarabel.DefaultSolver(
            sp.csc_matrix((n, n)), np.r_[np.zeros(m), np.ones(nt)],
            sp.csc_matrix((self._values(np.ones((m, pieces.p.shape[1])))[self.perm], order.indices,
                           order.indptr), shape=(r, n)),
            b, cones, settings_)

    def _values(self, V: np.ndarray) -> np.ndarray:
        P, vals = self.pieces, self.template.copy()
        blocks = []
        for i, rk in enumerate(self.rk):
            blocks.append(P.p[i] @ V.T)
            if rk:
                blocks.append((-P.kappa[i] * P.T[i, :rk] @ V.T).ravel())
        vals[self.fill] = np.concatenate(blocks)
        return vals

    def bound(self, V: np.ndarray) -> float:
        self.solver.update(A=self._values(V)[self.perm])
        sol = self.solver.solve()
        if str(sol.status) not in ("Solved", "AlmostSolved"):
            return 0.0
        z = np.asarray(sol.z)
        P = self.pieces
        g, total = np.zeros(V.shape[1]), 0.0
        for i, (rk, block) in enumerate(zip(self.rk, self.piece_rows)):
            z0 = z[block[0]]
            w = min(max(z0, 0.0), 1.0)
            gi = P.p[i].copy()
            if rk and z0 > 0:
                s_dual = -z[block[1:]] / z0
                s_dual /= max(1.0, np.linalg.norm(s_dual))
                gi += P.kappa[i] * s_dual @ P.T[i, :rk]
            g += w * gi
            total += w
        if self.norm == "L1" and total > 1.0:
            g /= total
        return max(0.0, float((V @ g).min()))


def _face_cells(d: int, splits: int):
    """Initial cells: each of the 2d faces of the cube [-1, 1]^d cut into ``splits^(d-1)`` boxes."""
    edges = np.linspace(-1.0, 1.0, splits + 1)
    grid = np.array(np.meshgrid(*[np.arange(splits)] * (d - 1), indexing="ij")).reshape(d - 1, -1).T
    faces = np.repeat(np.arange(2 * d), len(grid))
    lo = np.tile(edges[grid], (2 * d, 1))
    hi = np.tile(edges[grid + 1], (2 * d, 1))
    return faces, lo, hi


def _cell_vertices(faces, lo, hi, d):
    """Unit vertex directions of the cells, shape (n, 2^(d-1), d), and unit centre directions."""
    bits = np.array(list(np.ndindex(*([2] * (d - 1)))), dtype=float)
    others = np.array([[j for j in range(d) if j != k] for k in range(d)])
    axis, sign = faces // 2, np.where(faces % 2 == 0, 1.0, -1.0)

    def lift(box):  # box: (n, m, d-1) on the face -> (n, m, d)
        n, m = box.shape[:2]
        full = np.empty((n, m, d))
        full[np.arange(n)[:, None, None], np.arange(m)[None, :, None], others[axis][:, None, :]] = box
        full[np.arange(n), :, axis] = sign[:, None]
        return full / np.linalg.norm(full, axis=2, keepdims=True)

    V = lift(lo[:, None, :] + bits[None] * (hi - lo)[:, None, :])
    centre = lift(((lo + hi) / 2)[:, None, :])[:, 0]
    return V, centre


def _initial_directions(d: int) -> np.ndarray:
    rng = np.random.default_rng(0)  # fixed: results are reproducible
    R = rng.normal(size=(16 * d, d))
    return np.vstack([np.eye(d), -np.eye(d), R / np.linalg.norm(R, axis=1, keepdims=True)])


def _refine(grasp, system, norm, rel_gap, budget) -> Epsilon:
    """Branch and bound over the sphere of wrench directions (see :func:`epsilon`)."""
    pieces = _Pieces(system)
    d = system.columns.shape[0]
    U = _initial_directions(d)
    h = pieces.h(U, norm)
    u_best, hi, g_star = pieces.local_minimum(U[int(np.argmin(h))], norm)
    faces, lo_box, hi_box = _face_cells(d, 2)
    exact_cells = _CellSolver(pieces, 2 ** (d - 1), norm) if norm == "L1" else None
    retired, rounds, examined = np.inf, 0, 0
    while True:
        rounds += 1
        examined += len(faces)
        V, centre = _cell_vertices(faces, lo_box, hi_box, d)
        hc = pieces.h(centre, norm)
        k = int(np.argmin(hc))
        if hc[k] < hi:
            u, h_u, g = pieces.local_minimum(centre[k], norm)
            if h_u < hi:
                u_best, hi, g_star = u, h_u, g
        bound = np.maximum(pieces.cell_bound(V, centre, norm), (V @ g_star).min(axis=1))
        if exact_cells is not None:
            for i in np.flatnonzero(bound < (1 - rel_gap) * hi):
                bound[i] = max(bound[i], exact_cells.bound(V[i]))
                examined += EXACT_CELL_COST
        target = (1 - rel_gap) * hi
        done = bound >= target
        retired = min(retired, bound[done].min(initial=np.inf))
        lo = min(retired, bound[~done].min(initial=np.inf))
        if done.all() or examined + 2 * np.count_nonzero(~done) > budget:
            break
        faces, lo_box, hi_box = faces[~done], lo_box[~done], hi_box[~done]
        # split every open cell in two across its longest side
        axis = np.argmax(hi_box - lo_box, axis=1)
        mid = (lo_box[np.arange(len(axis)), axis] + hi_box[np.arange(len(axis)), axis]) / 2
        lo2, hi2 = lo_box.copy(), hi_box.copy()
        hi_box[np.arange(len(axis)), axis] = mid
        lo2[np.arange(len(axis)), axis] = mid
        faces = np.concatenate([faces, faces])
        lo_box, hi_box = np.concatenate([lo_box, lo2]), np.concatenate([hi_box, hi2])
    lo = min(lo, hi) * (1 - 1e-12)  # float safety on a bound computed in floating point
    return Epsilon(norm, lo, hi, tuple(u_best), tuple(grasp.center), grasp.length, False, rounds)


def epsilon_of_points(points) -> float:
    """Radius of the largest origin-centred ball inside ``conv(points)`` (qhull); 0 if the origin
    is not interior or the hull is flat."""
    pts = np.asarray(points, dtype=float)
    try:
        eq = ConvexHull(pts).equations
    except (QhullError, ValueError):
        return 0.0
    return max(0.0, float((-eq[:, -1]).min()))


def epsilon_linearised(grasp: Grasp, norm: str = "L1", edges: int = 8) -> float:
    """Epsilon with every spatial friction cone replaced by ``edges`` inscribed edges (the
    linearisation other toolkits use, e.g. Dex-Net's 8 edges), exact for that polytope.

    Point contacts only (no torsion); frictionless contacts keep their normal. The result is a
    lower bound of the exact-cone epsilon. For ``Linf`` the Minkowski sum is enumerated, so keep
    ``(edges + 1) ** contacts`` small.
    """
    _check_norm(norm)
    system = grasp_system(grasp, socp=True)
    theta = 2 * np.pi * np.arange(edges) / edges
    per_contact = []
    for b in system.blocks:
        cols = system.columns[:, list(b.cols)]
        if b.cone == "ray":
            per_contact.append(cols.T)
            continue
        if len(b.cols) > len(b.n):
            raise ValueError("epsilon_linearised handles point and frictionless contacts only")
        n = np.asarray(b.n, dtype=float) / np.linalg.norm(b.n)
        if len(n) == 2:
            t = np.array([[-n[1], n[0]], [n[1], -n[0]]])
        else:
            axis = np.eye(3)[np.argmin(np.abs(n))]
            t1 = np.cross(n, axis)
            t1 /= np.linalg.norm(t1)
            t2 = np.cross(n, t1)
            t = np.cos(theta)[:, None] * t1 + np.sin(theta)[:, None] * t2
        per_contact.append((n + float(b.mu) * t) @ cols.T)
    if norm == "L1":
        return epsilon_of_points(np.vstack([np.zeros(system.columns.shape[0])] + per_contact))
    sums = np.zeros((1, system.columns.shape[0]))
    for g in per_contact:
        with_zero = np.vstack([np.zeros(g.shape[1]), g])
        sums = (sums[:, None, :] + with_zero[None, :, :]).reshape(-1, g.shape[1])
    return epsilon_of_points(sums)

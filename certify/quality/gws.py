"""The grasp wrench space (GWS) of a grasp as the epsilon bounds see it: its generators, its
support points along given directions and the hulls of points of it, in floating point with
error bounds.

Computing the bounds (:mod:`qualgrasp.certify.quality.bounds`) and proving them
(:mod:`qualgrasp.certify.quality.evidence`) build the vertices of an inscribed polytope with the
same functions, so that a vertex the evidence names is the vertex that was computed:

* planar grasps: the generator wrenches with their error bounds
  (:func:`~qualgrasp.certify.core.wrench.planar_generator_arrays`),
  the support point along a direction (:func:`planar_support_choice`, the first generator of each
  contact with the largest ``v . g``) and sums of generators (:func:`sum_rows`);
* spatial grasps with exact cones: the support forces of every contact (:class:`ConicSupport`),
  pulled inside their cones by :data:`SHRINK` and scaled towards the origin by
  :func:`vertex_scale`;
* hulls: their faces oriented about the origin (:func:`surface_faces`, compiled hulls) and their float
  distances.
"""

from __future__ import annotations

import math
from fractions import Fraction
from typing import Sequence

import numpy as np
from scipy.spatial import ConvexHull, QhullError

from .._kernels.conic import SHRINK, support_points
from .._kernels.evidence import support_choices, vertex_sums
from .._kernels.hull import hull_facets, hull_faces, hulls_faces
from .._kernels.jit import kernel_array
from .._kernels.surface import orient_cycle
from ..core import cones
from ..core.grasp import Grasp
from ..core.problem import grasp_system
from ..core.wrench import force_column_errors, grasp_arrays, to_exact

__all__ = ["SHRINK", "surface_faces", "surfaces_faces", "oriented_surface", "hull_rows", "orient_faces",
           "generalised_cross", "face_distances",
           "sum_errors", "planar_support_choice", "planar_support_choices",
           "planar_support_vertices",
           "sum_rows", "sqrt_bounds", "vertex_scale", "ConicSupport"]


# --- surfaces ------------------------------------------------------------------------------------

#: The faces among which :func:`orient_faces` takes the one whose determinant's sign orients the rest.
_SEEDS = 64

def surface_faces(points: np.ndarray) -> np.ndarray | None:
    """Faces of the hull of ``points`` (n, d), ordered outward about an interior origin: each
    float determinant ``det(v_1, ..., v_d)`` not negative in 3-D, and in 6-D oriented as one
    closed surface (:func:`orient_faces`: a sliver face's determinant may round negative; the
    exact check settles it); None when the points span no full-dimensional hull. Compiled hulls
    give them, qhull where those decline: in 3-D (planar grasps)
    :func:`~qualgrasp.certify._kernels.hull.hull_faces`, in other dimensions (6-D, spatial grasps)
    the facets of :func:`~qualgrasp.certify._kernels.hull.hull_facets`, simplices, ordered by
    :func:`orient_faces` (qhull's where they do not close up)."""
    if np.shape(points)[1:] == (3,):  # one set: without the batch's bookkeeping (and its kernel)
        points = kernel_array(points)
        faces = hull_faces(points)
        return faces if len(faces) else _qhull_faces([points])[0]  # as hull_rows falls back
    return surfaces_faces([points])[0]


def surfaces_faces(point_sets) -> list[np.ndarray | None]:
    """:func:`surface_faces` of each of ``point_sets`` (arrays (n_i, d) of one ``d``)."""
    if not point_sets:
        return []
    if np.shape(point_sets[0])[1] == 3:
        vstart = np.cumsum([0] + [len(p) for p in point_sets]).astype(np.int64)
        faces, fstart = hull_rows(np.concatenate(point_sets), vstart)
        return [faces[fstart[s]:fstart[s + 1]] if fstart[s + 1] > fstart[s] else None for s in range(len(point_sets))]
    out = []
    for pts in point_sets:
        pts = kernel_array(pts)
        facets = hull_facets(pts) if pts.ndim == 2 and pts.shape[1] > 3 else np.zeros((0, 0), dtype=np.int64)
        out.append(oriented_surface(pts, facets)[0])
    return out


def oriented_surface(points: np.ndarray, facets: np.ndarray) -> tuple[np.ndarray | None, bool]:
    """The faces :func:`surface_faces` gives for ``points`` from the facets of their compiled hull
    (simplices), ordered by :func:`orient_faces`, or qhull's where they do not close up (rounding
    broke the surface) or there are none; and whether they were found to be one closed oriented cycle (the
    conditions of :func:`qualgrasp.certify.quality.evidence.cycle_check`; False for qhull's, whose
    orientation is each face's own sign, unchecked)."""
    faces, closed = _oriented(points, facets) if len(facets) else (None, False)
    return (faces, True) if closed else (_qhull_faces([points])[0], False)


def hull_rows(V: np.ndarray, vstart: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`surface_faces` of many 3-D sets held flat: set ``s`` is ``V[vstart[s]:vstart[s + 1]]``.
    Returns the faces of all sets one after another (indices local to each set) and ``fstart``,
    set ``s`` owning ``faces[fstart[s]:fstart[s + 1]]`` (none where its points span no hull)."""
    V = kernel_array(V)
    vstart = kernel_array(vstart, np.int64)
    faces, fstart = hulls_faces(V, vstart)
    declined = np.flatnonzero(np.diff(fstart) == 0)
    if not len(declined):
        return faces, fstart
    found = _qhull_faces([V[vstart[s]:vstart[s + 1]] for s in declined])
    if all(f is None for f in found):
        return faces, fstart
    parts = [faces[fstart[s]:fstart[s + 1]] for s in range(len(fstart) - 1)]
    for s, f in zip(declined, found):
        if f is not None:
            parts[s] = f
    return np.concatenate(parts), np.cumsum([0] + [len(f) for f in parts]).astype(np.int64)


def _qhull_faces(point_sets) -> list[np.ndarray | None]:
    """:func:`surface_faces` of each of ``point_sets`` by qhull: qhull runs once per set, the
    orientation once for all (the determinant of each face is computed as for a single set, so
    the faces are the same)."""
    hulls, offset, points = [], 0, []
    for pts in point_sets:
        try:
            hulls.append(np.asarray(ConvexHull(pts).simplices, dtype=np.int64) + offset)
        except (QhullError, ValueError):
            hulls.append(None)
            continue
        points.append(pts)
        offset += len(pts)
    if not points:
        return hulls
    done = [h for h in hulls if h is not None]
    faces = orient_faces(np.concatenate(points), np.concatenate(done))
    starts = np.cumsum([0] + [len(h) for h in done])
    out, q, offset = [], 0, 0
    for h, pts in zip(hulls, point_sets):
        if h is None:
            out.append(None)
            continue
        out.append(faces[starts[q]:starts[q + 1]] - offset)
        offset += len(pts)
        q += 1
    return out


def orient_faces(points: np.ndarray, simplices: np.ndarray) -> np.ndarray:
    """``simplices`` with the first two vertices swapped where needed so that their float
    determinants are not negative: the face with the largest determinant among the first
    :data:`_SEEDS` by its sign, the others
    by propagation across shared ridges (:func:`~qualgrasp.certify._kernels.surface.orient_cycle`),
    so that a sliver face, whose determinant's sign rounding can flip, still closes the cycle (its
    own sign is then the exact check's to settle); each face by its own sign where the simplices
    are not a closed surface."""
    return _oriented(points, simplices)[0]


def _oriented(points: np.ndarray, simplices: np.ndarray) -> tuple[np.ndarray, bool]:
    """:func:`orient_faces` and whether the simplices form a closed surface."""
    faces = np.array(simplices, dtype=np.int64)
    closed = False
    if len(faces) and (faces.shape[1] - 1) * math.log2(max(len(points), 2)) < 62:  # ridge keys fit int64
        det = np.linalg.det(points[faces[:_SEEDS]])  # the seed among the first faces: their largest
        seed = int(np.argmax(np.abs(det)))
        flip, reached = orient_cycle(kernel_array(faces, np.int64), len(points), seed, bool(det[seed] < 0))
        closed = bool(reached.all())
    if not closed:
        flip = np.linalg.det(points[faces]) < 0
    faces[flip, 0], faces[flip, 1] = faces[flip, 1], faces[flip, 0].copy()
    return faces, closed


def generalised_cross(simplices: np.ndarray) -> np.ndarray:
    """Generalised cross product ``n`` of the edges ``v_i - v_1`` (i = 2..d) of simplices
    (F, d, d) of vertex rows, normal to each face (floats).

    ``n_r = (-1)^r det(D without coordinate r)`` with ``D`` the edges, so that the dot product
    ``n·v_1`` equals ``det(v_1, ..., v_d)``.
    """
    D = simplices[:, 1:, :] - simplices[:, :1, :]  # (F, d-1, d)
    d = simplices.shape[2]
    out = np.empty((simplices.shape[0], d))
    for r in range(d):
        minor = np.delete(D, r, axis=2)
        out[:, r] = (-1.0) ** r * (np.linalg.det(minor) if d > 2 else minor[:, 0, 0])
    return out


def face_distances(points: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Signed distance of each face's hyperplane from the origin, ``det / |n|`` (floats; NaN for
    a degenerate face)."""
    S = points[faces]
    n = generalised_cross(S)
    det = np.einsum("fd,fd->f", n, S[:, 0, :])
    norm = np.linalg.norm(n, axis=1)
    return np.divide(det, norm, out=np.full(len(det), np.nan), where=norm > 0)


# --- planar generators and support points -------------------------------------------------------

def sum_errors(E: np.ndarray, mag: np.ndarray, terms: int) -> np.ndarray:
    """Error bound of a float sum of ``terms`` points whose own errors add up to ``E`` and whose
    magnitudes add up to ``mag``."""
    return E + 2 * (terms + 1) * 2.0**-53 * mag


def planar_support_choice(W: np.ndarray, owner: np.ndarray, m: int, v: np.ndarray) -> np.ndarray:
    """The vertex of planar ``support`` evidence along ``v``: for each contact the first of its
    generators (columns of ``W``, ``owner`` sorted) with the largest ``dot(v, g)``, or -1 (the
    origin) when that is not positive (or is NaN).

    The values are rounded in one stated order, ``(v0 g0 + v1 g1) + v2 g2``, each product and
    sum on its own: a tie between generators is then broken the same way on every machine
    (``v @ W`` would leave it to the BLAS library, whose fused multiply-adds vary with the
    processor), so a certificate's re-check finds the vertices its run found."""
    return _first_largest(v[0] * W[0] + v[1] * W[1] + v[2] * W[2], owner, m)


def _first_largest(vals: np.ndarray, owner: np.ndarray, m: int) -> np.ndarray:
    """Per contact the first of its generators (``owner`` sorted) with the largest of ``vals``,
    or -1 when that is not positive, is NaN, or the contact has no generator."""
    out = np.full(m, -1, dtype=np.int64)
    start, end = np.searchsorted(owner, np.arange(m)), np.searchsorted(owner, np.arange(m), side="right")
    for i in np.flatnonzero(end > start):
        seg = vals[start[i]:end[i]]
        best = seg.max()  # NaN when one is NaN, as the kernel takes it
        if best > 0:
            out[i] = start[i] + int(np.argmax(seg == best))
    return out


def planar_support_choices(W, owner, m, dirs: np.ndarray, *, blas: bool = False) -> np.ndarray:
    """The choices of :func:`planar_support_choice` along each row of ``dirs`` (n, m), compiled
    (:func:`~qualgrasp.certify._kernels.evidence.support_choices`, in the same order of
    rounding).

    ``blas``: the choices of builds before 2026-11-28 for the directions whose choice rounding
    can change (ties, values at zero): from the values ``v @ W`` as the BLAS library of the
    machine at hand rounds them, so that the evidence those builds wrote can be re-checked."""
    dirs = np.ascontiguousarray(dirs, dtype=float).reshape(-1, 3)
    R, sure = support_choices(np.ascontiguousarray(W, dtype=float), np.ascontiguousarray(owner, dtype=np.int64),
                              m, dirs)
    if blas:
        for q in np.flatnonzero(~sure):
            R[q] = _first_largest(dirs[q] @ W, owner, m)
    return R


def planar_support_vertices(W, E, owner, m, dirs: np.ndarray, *, blas: bool = False):
    """Float vertices, error bounds and generator choices (rows, -1 for the origin) of planar
    ``support`` evidence along the rows of ``dirs`` (:func:`planar_support_choices`, with
    ``blas`` as there; :func:`sum_rows`); each vertex depends on its own direction only."""
    R = planar_support_choices(W, owner, m, dirs, blas=blas)
    return sum_rows(W, E, R) + (R,)


def sum_rows(W: np.ndarray, E: np.ndarray, R: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Sums of generator rows: for each vertex the sum of the generators ``W`` (3, k) it picks in
    ``R`` (vertices, contacts; -1 picks none), added in order from zero, with the bound of
    :func:`sum_errors` on its error from the generators' own bounds ``E``
    (:func:`~qualgrasp.certify._kernels.evidence.vertex_sums`). Returns ``(V, bounds)``, both
    (vertices, 3); each row depends on its own picks only."""
    R = np.ascontiguousarray(R, dtype=np.int64)
    return vertex_sums(np.ascontiguousarray(W, dtype=float), np.ascontiguousarray(E, dtype=float), R)


def sqrt_bounds(q: Fraction, bits: int = 60) -> tuple[Fraction, Fraction]:
    """Rational bounds of ``sqrt(q)`` (``q >= 0``) to about ``bits`` bits."""
    q = Fraction(q)
    if q <= 0:
        return Fraction(0), Fraction(0)
    num, den = q.numerator, q.denominator
    scale = 1 << (2 * bits)
    r = math.isqrt(num * den * scale)  # sqrt(q) = sqrt(num den scale) / (den 2^bits)
    lo = Fraction(r, den << bits)
    hi = lo if r * r == num * den * scale else Fraction(r + 1, den << bits)
    return lo, hi


# --- spatial support points ---------------------------------------------------------------------

def vertex_scale(i: int) -> float:
    """Scale of the ``i``-th vertex of ``support`` evidence: ``1 - 2^-14 j / 2^16`` with ``j``
    Knuth's multiplicative hash of ``i`` (an exact dyadic number in ``[1 - 2^-14, 1]``)."""
    return 1.0 - ((i * 40503) % 65536) * 2.0**-30


class ConicSupport:
    """Support forces of a spatial grasp's contacts (the vertices of ``support`` evidence).

    Parameters
    ----------
    grasp : Grasp
        A spatial grasp; its conic system (:func:`qualgrasp.certify.core.problem.grasp_system`,
        ``socp=True``) gives the columns of every contact block.
    """

    def __init__(self, grasp: Grasp) -> None:
        system = grasp_system(grasp, socp=True)
        self.grasp = grasp
        self.C = np.ascontiguousarray(system.columns, dtype=float)
        self.absC = np.abs(self.C)
        self.blocks = system.blocks
        self._Cx = None
        P, N, mu, params, c, L = grasp_arrays(grasp)
        models = tuple(ct.model for ct in grasp.contacts)
        self.errors = np.ascontiguousarray(force_column_errors(P[None], N[None], models, c[None], np.array([L]))[0])
        self.data = []
        nb = len(self.blocks)
        self.ray, self.col0, self.m_col = np.zeros(nb, dtype=bool), np.zeros(nb, np.int64), np.full(nb, -1, np.int64)
        self.f_col = np.zeros((nb, 3), dtype=np.int64)
        self.n, self.nh = np.zeros((nb, 3)), np.zeros((nb, 3))
        self.nn, self.mu, self.g, self.gr = np.zeros(nb), np.zeros(nb), np.zeros(nb), np.zeros(nb)
        for i, b in enumerate(self.blocks):
            cols = np.array(b.cols)
            self.col0[i] = cols[0]
            if b.cone == "ray":
                self.data.append((cols, None, None, 0.0, 0.0, 0.0))
                self.ray[i] = True
                self.f_col[i] = cols[0]
                continue
            n = np.asarray(b.n, dtype=float)
            rn = math.sqrt(float(n @ n))
            self.data.append((cols, n, n / rn, float(b.mu), float(b.g), rn))
            self.f_col[i] = cols[:3]
            if len(cols) > 3:
                self.m_col[i] = cols[3]
            self.n[i], self.nh[i], self.mu[i], self.g[i], self.gr[i] = n, n / rn, float(b.mu), float(b.g), float(b.g) / rn
        self.nn = np.einsum("bi,bi->b", self.n, self.n)

    @property
    def Cx(self):
        """Exact columns (built on first use)."""
        if self._Cx is None:
            self._Cx = grasp_system(self.grasp, socp=True, exact=True).columns
        return self._Cx

    def inside(self, b: int, x: np.ndarray) -> bool:
        """Is the block value ``x`` strictly inside block ``b``'s cone? Exact
        (:func:`qualgrasp.certify.core.cones.inside`)."""
        cols, n, nh, mu, g, rn = self.data[b]
        if n is None:
            return bool(x[0] > 0)
        blk = self.blocks[b]
        return cones.inside(blk.cone, list(to_exact(x)), list(to_exact(n)), Fraction(mu), Fraction(g))

    def vertices(self, P: np.ndarray, norm: str, index: np.ndarray, ref: np.ndarray | None = None):
        """Vertices ``index`` of ``support`` evidence along the rows of ``P`` (n, d): the support
        points scaled by :func:`vertex_scale`, as ``(W, EW, X, ok)``: float wrenches (n, d),
        bounds on their distance to the exact ones, the values on every column (0 off the blocks
        they sum) and whether every value was proved inside its cone (a float test with a rigorous
        margin, :func:`~qualgrasp.certify._kernels.conic.support_points`, then the exact test for
        the values it leaves open). Each block's value along ``v``: ``f = n/|n| + SHRINK mu z_t /
        |z|``, ``m = (g / |n|) SHRINK mu z_m / |z|`` with ``z = (a_t, a_m g / |n|)``, ``a`` the
        functional ``C' v``; a ray's value is 1; a fixed float formula, so producer and checker
        compute the same. ``ref`` (L1): the contact to use for each row (-1, the default: the one
        with the largest support value)."""
        P = kernel_array(np.atleast_2d(P))
        index = kernel_array(index, np.int64)
        ref = np.full(len(P), -1, np.int64) if ref is None else kernel_array(ref, np.int64)
        W, EW, X, open_, ok = support_points(
            self.C, self.errors, self.absC, P, index, ref, norm == "L1", self.ray, self.col0, self.f_col,
            self.m_col, self.n, self.nh, self.nn, self.mu, self.g, self.gr)
        for q, b in zip(*np.nonzero(open_ & ok[:, None])):
            if ok[q] and not self.inside(int(b), X[q, self.data[b][0]]):
                ok[q] = False
        return W, EW, X, ok

    def vertex(self, v: np.ndarray, norm: str, index: int, ref: int | None = None):
        """Vertex ``index`` of ``support`` evidence along ``v`` (:meth:`vertices`) as ``(w, err,
        x)``, or None when a value could not be proved inside its cone."""
        W, EW, X, ok = self.vertices(v, norm, np.array([index]), None if ref is None else np.array([ref]))
        return (W[0], EW[0], X[0]) if ok[0] else None

    def vertices_numpy(self, P: np.ndarray, norm: str, index: np.ndarray, ref: np.ndarray | None = None):
        """:meth:`vertices` by the numpy formula of the builds before 2026-11-27 (``C' v`` and
        ``C x`` through BLAS, the normal parts by ``einsum``), for re-checking the evidence they
        wrote: its points are proved points of the GWS like the kernel's, in another rounding,
        which near a tie or a cancellation can move a vertex further than the tolerance."""
        lor, ray = np.flatnonzero(~self.ray), np.flatnonzero(self.ray)
        f_col, m_col, nh, gr, mu = self.f_col[lor], self.m_col[lor], self.nh[lor], self.gr[lor], self.mu[lor]
        N = len(P)
        W, EW, X = np.zeros((N, self.C.shape[0])), np.zeros((N, self.C.shape[0])), np.zeros((N, self.C.shape[1]))
        ok = np.ones(N, dtype=bool)
        for q in range(N):
            a = self.C.T @ P[q]
            c, F = np.empty(len(self.blocks)), np.zeros(self.C.shape[1])
            c[ray], F[self.col0[ray]] = a[self.col0[ray]], 1.0
            if len(lor):
                af = a[f_col]
                an = np.einsum("bi,bi->b", af, nh)
                at = af - an[:, None] * nh
                am = np.where(m_col >= 0, a[m_col] * gr, 0.0)
                nz = np.sqrt(np.einsum("bi,bi->b", at, at) + am * am)
                c[lor] = an + mu * nz
                k = np.divide(SHRINK * mu, nz, out=np.zeros_like(nz), where=nz > 0)
                F[f_col] = nh + k[:, None] * at
                F[m_col[m_col >= 0]] = (k * am * gr)[m_col >= 0]
            if norm == "L1":
                use = np.array([int(np.argmax(c)) if ref is None else int(ref[q])])
            else:
                use = np.flatnonzero(c > 0)
            keep = np.zeros(self.C.shape[1], dtype=bool)
            for b in use:
                keep[self.data[b][0]] = True
            X[q] = np.where(keep, F * vertex_scale(int(index[q])), 0.0)
            ok[q] = all(self.inside(int(b), X[q, self.data[b][0]]) for b in use)
            ax = np.abs(X[q])
            W[q], EW[q] = self.C @ X[q], sum_errors(self.errors @ ax, self.absC @ ax, int(keep.sum()))
        return W, EW, X, ok

    def exact_vertex(self, x: np.ndarray) -> list[Fraction]:
        """The exact wrench of the column values ``x``."""
        Cx = self.Cx
        nz = [(j, Fraction(float(x[j]))) for j in np.flatnonzero(x)]
        return [sum((Cx[r, j] * t for j, t in nz), Fraction(0)) for r in range(Cx.shape[0])]

    def h_bounds(self, u: Sequence[float], norm: str) -> tuple[Fraction, Fraction]:
        """Rigorous bounds ``(lo, hi)`` of ``h(u) / |u|`` (exact columns, integer square roots;
        ``hi < 0`` for a zero ``u``)."""
        ux = [Fraction(float(t)) for t in u]
        Cx = self.Cx
        d = Cx.shape[0]
        a = [sum(Cx[r, j] * ux[r] for r in range(d)) for j in range(Cx.shape[1])]
        terms = []
        for cols, n, nh, mu, g, rn in self.data:
            if n is None:
                t = a[cols[0]]
                terms.append((t, t))
                continue
            dim = len(n)
            nx = [Fraction(float(t)) for t in n]
            af = [a[j] for j in cols[:dim]]
            an = sum(x * y for x, y in zip(af, nx))
            nn = sum(x * x for x in nx)
            tang = nn * sum(x * x for x in af) - an * an
            for j in cols[dim:]:
                tang += (a[j] * Fraction(g)) ** 2
            mu_x = Fraction(mu)
            s_lo, s_hi = sqrt_bounds(tang)
            r_lo, r_hi = sqrt_bounds(nn)
            num_lo, num_hi = an + mu_x * s_lo, an + mu_x * s_hi
            terms.append((num_lo / (r_hi if num_lo >= 0 else r_lo), num_hi / (r_lo if num_hi >= 0 else r_hi)))
        if norm == "L1":
            lo = max(max(t[0] for t in terms), Fraction(0))
            hi = max(max(t[1] for t in terms), Fraction(0))
        else:
            lo = sum(max(t[0], Fraction(0)) for t in terms)
            hi = sum(max(t[1], Fraction(0)) for t in terms)
        u_lo, u_hi = sqrt_bounds(sum(x * x for x in ux))
        if u_lo <= 0:
            return Fraction(0), Fraction(-1)
        return lo / u_hi, hi / u_lo

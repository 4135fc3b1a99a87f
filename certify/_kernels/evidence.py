"""Planar epsilon evidence of many grasps at once, compiled (numba): the generator wrenches of a
batch, the sums of one point per contact polytope (the vertices of ``sums`` evidence) and the
rigorous float checks of many inscribed surfaces; and the vertices of ``support`` evidence
along many directions, with the refinement that picks those directions (:func:`support_refine`).

The arithmetic is that of the per-grasp route (:mod:`qualgrasp.certify.quality.bounds`), so the
floats are the same: the generators by :func:`~.planar.planar_generators`, each sum added
contact by contact from zero as the per-grasp route adds them, and each surface checked by
:func:`~.surface.cycle_code` and :func:`~.surface.face_bounds`. A surface these checks cannot
settle in floats (a face whose sign or distance needs the exact vertices) is reported as
undecided, and its caller takes the per-grasp route.
"""

from __future__ import annotations

import numpy as np

from .hull import face_planes, hull_faces_work, hull_work
from .jit import kernel
from .linalg import ETA, gamma
from .order import stable_smallest
from .planar import planar_generators
from .surface import cycle_code, face_bounds

__all__ = ["generator_rows", "minkowski_sums", "surface_rows", "support_choices", "vertex_sums", "support_refine",
           "support_refine_rows", "REFINED", "ROUNDS_SPENT", "NOT_HERE"]

#: What :func:`support_refine` ends with: the refinement is over, ...
REFINED = 0
#: ... its rounds are spent (call it again to go on), ...
ROUNDS_SPENT = 1
#: ... or the compiled hull declined the vertices (or gave a NaN distance): the caller goes on.
NOT_HERE = 2


@kernel
def generator_rows(P, N, mu, width, c, L, owner, offset, friction):
    """Generator wrenches ``W`` and their error bounds ``E``, both (B, 3, k), of ``B`` planar
    grasps sharing one generator layout (:func:`~.planar.planar_generators` per grasp)."""
    B, k = P.shape[0], owner.shape[0]
    W = np.empty((B, 3, k))
    E = np.empty((B, 3, k))
    for b in range(B):
        planar_generators(P[b], N[b], mu[b], width[b], c[b], L[b], owner, offset, friction, W[b], E[b])
    return W, E


@kernel
def minkowski_sums(W, E, owner, m):
    """Every sum of one point per contact polytope (the origin or one generator of the contact)
    of ``B`` grasps (``W``, ``E`` (B, 3, k), ``owner`` sorted): the points (B, n, 3), bounds on
    their distance to the exact sums (B, n, 3) and the generator chosen per contact (n, m; -1
    for the origin). The first contact's choice varies slowest; each point is added contact by
    contact from zero, and its bound is the sum of the generators' bounds plus ``2 (m + 1) u``
    times the sum of their magnitudes (:func:`qualgrasp.certify.quality.gws.sum_errors`)."""
    B, k = W.shape[0], W.shape[2]
    start = np.zeros(m + 1, dtype=np.int64)
    for j in range(k):
        start[owner[j] + 1] += 1
    n = 1
    for i in range(m):
        start[i + 1] += start[i]
        n *= start[i + 1] - start[i] + 1
    choice = np.empty((n, m), dtype=np.int64)
    for p in range(n):
        rest = p
        for i in range(m - 1, -1, -1):
            size = start[i + 1] - start[i] + 1
            o = rest % size
            rest //= size
            choice[p, i] = -1 if o == 0 else start[i] + o - 1
    pts = np.zeros((B, n, 3))
    err = np.zeros((B, n, 3))
    for b in range(B):
        for p in range(n):
            _pick_sum(W[b], E[b], choice[p], pts[b, p], err[b, p])
    return pts, err, choice


@kernel(inline=True)
def _pick_sum(W, E, picks, v, ev):
    """Into ``v`` and ``ev`` (3,): the sum of the columns of ``W`` (3, k) that ``picks`` (m,;
    -1 picks none) names, added in order from zero, and the bound on its error: the sum of
    their ``E`` plus ``2 (m + 1) u`` times the sum of their magnitudes
    (:func:`qualgrasp.certify.quality.gws.sum_errors`). Adding nothing for the origin is adding
    ``+0.0``: a sum started at ``+0.0`` is never ``-0.0``."""
    factor = 2 * (picks.shape[0] + 1) * 2.0**-53
    for r in range(3):
        s, e, a = 0.0, 0.0, 0.0
        for i in range(picks.shape[0]):
            j = picks[i]
            if j >= 0:
                s = s + W[r, j]
                e = e + E[r, j]
                a = a + abs(W[r, j])
        v[r] = s
        ev[r] = e + factor * a


@kernel
def surface_rows(V, EV, vstart, faces, fstart, perms, psign, tight):
    """The float half of :func:`qualgrasp.certify.quality.evidence.surface_minimum` for many
    surfaces: surface ``s`` has the vertices ``V[vstart[s]:vstart[s + 1]]`` (within ``EV`` of
    the exact ones) and the faces ``faces[fstart[s]:fstart[s + 1]]`` (indices local to its
    vertices). Returns ``(decided, d2_lo, d2_hi)`` per surface: decided when the faces form a
    closed oriented cycle, every face is proved positively oriented, no face is too loosely
    bounded to tell the minimum (``hi > (1 + tight) lo`` with ``lo`` below the least ``hi``)
    and the least ``lo`` is positive; then ``d2_lo <= D^2 <= d2_hi`` for the smallest face
    distance ``D``, the bounds the per-grasp check states."""
    S = vstart.shape[0] - 1
    decided = np.zeros(S, dtype=np.bool_)
    d2_lo = np.zeros(S)
    d2_hi = np.zeros(S)
    for s in range(S):
        Vs = V[vstart[s]:vstart[s + 1]]
        Fs = faces[fstart[s]:fstart[s + 1]]
        if Fs.shape[0] == 0 or cycle_code(Fs, Vs.shape[0]) != 0:
            continue
        ok, lo, hi = face_bounds(Vs, EV[vstart[s]:vstart[s + 1]], Fs, perms, psign)
        if not ok.all():
            continue
        top = hi.min()
        loose = False
        for f in range(Fs.shape[0]):
            if lo[f] < top and hi[f] > lo[f] * (1 + tight):
                loose = True
                break
        least = lo.min()
        if loose or not least > 0.0:
            continue
        decided[s] = True
        d2_lo[s], d2_hi[s] = least, top
    return decided, d2_lo, d2_hi


@kernel
def support_choices(W, owner, m, dirs):
    """The vertex of planar ``support`` evidence along each row of ``dirs`` (n, 3): for each
    contact the first of its generators (columns of ``W`` (3, k), ``owner`` sorted) with the
    largest ``v . g``, or -1 (the origin) when that is not positive, as
    :func:`qualgrasp.certify.quality.gws.planar_support_choice` states it, with the values
    ``v . g`` in its order, ``(v0 g0 + v1 g1) + v2 g2`` (products and sums rounded one by one),
    and -1 for a contact with a NaN value. Returns the choices (n, m) and whether each row is
    sure: any order of the three products and two sums (fused or not) is within ``gamma_3`` of
    the sum of their magnitudes of the exact value, so a row is sure when every contact's
    largest value beats the others, and zero, by more than both errors (a tie, or a value at
    zero, is never sure: its choice is that of the stated order)."""
    n, k = dirs.shape[0], W.shape[1]
    R = np.full((n, m), -1, dtype=np.int64)
    sure = np.ones(n, dtype=np.bool_)
    vals = np.empty(k)
    errs = np.empty(k)
    best = np.empty(m, dtype=np.int64)
    g = 2.0 * gamma(4)
    for q in range(n):
        v0, v1, v2 = dirs[q, 0], dirs[q, 1], dirs[q, 2]
        _choose(W, owner, v0, v1, v2, vals, best, R[q])
        for j in range(k):
            errs[j] = g * (abs(v0 * W[0, j]) + abs(v1 * W[1, j]) + abs(v2 * W[2, j])) + 8 * ETA
        j0 = 0
        while j0 < k and sure[q]:
            i, j1 = owner[j0], j0
            while j1 < k and owner[j1] == i:
                j1 += 1
            top = vals[best[i]] - errs[best[i]]  # below every value the best can take
            clear = top > 0.0
            high = -np.inf  # above every value of the contact
            for j in range(j0, j1):
                if vals[j] != vals[j]:  # a contact with a NaN value (its choice the origin) is never sure
                    clear, high = False, np.inf
                    break
                high = max(high, vals[j] + errs[j])
                if j != best[i] and not vals[j] + errs[j] < top:
                    clear = False
            sure[q] = clear or high < 0.0  # every value of the contact is negative: the origin
            j0 = j1
    return R, sure


@kernel
def _choose(W, owner, v0, v1, v2, vals, best, Rv):
    """The choices of :func:`support_choices` along one direction ``v`` into ``Rv`` (m,; contacts
    without generators are left as they are; -1 for a contact with a NaN value: as numpy's
    maximum, a NaN is the largest value, which is not positive), the values ``v . g`` into
    ``vals`` (k,) and each contact's first generator with the largest value into ``best`` (m,).
    ``owner`` must be sorted (each contact's generators together)."""
    k = W.shape[1]
    for j in range(k):
        vals[j] = v0 * W[0, j] + v1 * W[1, j] + v2 * W[2, j]
    j0 = 0
    while j0 < k:
        i, j1, b, nan = owner[j0], j0, j0, False
        while j1 < k and owner[j1] == i:
            nan = nan or vals[j1] != vals[j1]
            if vals[j1] > vals[b]:
                b = j1
            j1 += 1
        best[i] = b
        Rv[i] = b if vals[b] > 0.0 and not nan else -1
        j0 = j1


@kernel
def vertex_sums(W, E, R):
    """Sums of generators: for each row of ``R`` (n, m; -1 picks none) the sum of the columns
    of ``W`` (3, k) it picks, added in order from zero, and the bound on its error of
    :func:`minkowski_sums`. Returns ``(V, EV)``, both (n, 3)."""
    n = R.shape[0]
    V = np.zeros((n, 3))
    EV = np.zeros((n, 3))
    for q in range(n):
        _pick_sum(W, E, R[q], V[q], EV[q])
    return V, EV


@kernel
def support_refine(W, E, owner, m, u, cut, limit, add, dirs, picks, n, rounds):
    """The refinement of planar ``support`` evidence (its directions and their vertices' generator
    choices), as :func:`qualgrasp.certify.quality.bounds._support_surface` states it, for one
    grasp: the coordinate directions and ``u`` first (on the first call, ``n == 0``), then per
    round the hull of the vertices so far; the refinement is over when every face is at least
    ``cut`` from the origin, ``limit`` directions are kept or no new vertex is found; else the
    normals of the ``2 add`` faces nearest the origin (stable order) are tried, each kept when its
    choice (:func:`support_choices`) is a new one.

    ``dirs`` (cap, 3) and ``picks`` (cap, m) hold the ``n`` directions kept and their choices;
    ``cap`` must be at least ``max(7, limit + 2 add)``. At most ``rounds`` rounds add
    directions in one call. Returns the new ``n``, :data:`REFINED`, :data:`ROUNDS_SPENT` (the
    next call starts with the same hull) or :data:`NOT_HERE`, the faces of the hull of the ``n``
    vertices (:func:`~.hull.hull_faces`; none with :data:`NOT_HERE`), and the vertices and their
    error bounds (:func:`vertex_sums` of the choices)."""
    if n == 0:
        first = np.zeros((7, 3))
        for r in range(3):
            first[r, r] = 1.0
            for c in range(3):
                first[3 + r, c] = -first[r, c]  # -0.0 off the diagonal, as -np.eye(3)
            first[6, r] = u[r]
        n = _fresh(W, owner, m, first, dirs, picks, n)
    V = np.empty((dirs.shape[0], 3))
    EV = np.empty((dirs.shape[0], 3))
    for q in range(n):
        _pick_sum(W, E, picks[q], V[q], EV[q])
    done = 0
    work = hull_work(dirs.shape[0])  # one set of work arrays for every round's hull
    while True:
        P = V[:n].copy()
        faces = hull_faces_work(P, work)
        if faces.shape[0] == 0:
            return n, NOT_HERE, faces, V[:n], EV[:n]
        normal, dist = face_planes(P, faces)
        least = np.inf
        for f in range(dist.shape[0]):
            if dist[f] != dist[f]:
                return n, NOT_HERE, faces[:0], V[:n], EV[:n]
            least = min(least, dist[f])
        if least >= cut or n >= limit:
            return n, REFINED, faces, V[:n], EV[:n]
        if done == rounds:
            return n, ROUNDS_SPENT, faces, V[:n], EV[:n]
        order = stable_smallest(dist, 2 * add)  # no NaN: declined above
        cand = np.empty((order.shape[0], 3))
        for j in range(order.shape[0]):
            cand[j] = normal[order[j]]
        before = n
        n = _fresh(W, owner, m, cand, dirs, picks, n)
        if n == before:
            return n, REFINED, faces, V[:n], EV[:n]
        for q in range(before, n):
            _pick_sum(W, E, picks[q], V[q], EV[q])
        done += 1


@kernel
def support_refine_rows(W, E, owner, m, U, cuts, limit, add, cap, rounds):
    """:func:`support_refine` of every row of a batch ``W``, ``E`` (B, 3, k), one call each from
    its start, row ``b`` along ``U[b]`` down to ``cuts[b]``; ``cap`` and ``rounds`` as for
    :func:`support_refine`. Returns per row its state (:data:`REFINED`, :data:`ROUNDS_SPENT` or
    :data:`NOT_HERE`) and, rows one after another, the directions kept, their
    choices, the vertices and their error bounds (row ``b`` owning
    ``[vstart[b], vstart[b + 1])`` of each), and the faces of their last hull (``fstart``
    likewise; none for :data:`NOT_HERE`): ``state, D, R, V, EV, vstart, F, fstart``."""
    B = W.shape[0]
    state = np.empty(B, dtype=np.int64)
    vstart = np.zeros(B + 1, dtype=np.int64)
    fstart = np.zeros(B + 1, dtype=np.int64)
    dirs, picks = np.empty((cap, 3)), np.empty((cap, m), dtype=np.int64)
    # room for 32 directions a row (10 contacts use about 21), grown to twice the rows used when a
    # row would not fit; the results are views, not copies
    D, R = np.empty((32 * B + cap, 3)), np.empty((32 * B + cap, m), dtype=np.int64)
    V, EV = np.empty((32 * B + cap, 3)), np.empty((32 * B + cap, 3))
    F = np.empty((64 * B + 2 * cap, 3), dtype=np.int64)
    for b in range(B):
        n, st, faces, v, ev = support_refine(W[b], E[b], owner, m, U[b], cuts[b], limit, add, dirs, picks, 0, rounds)
        state[b] = st
        a, f = vstart[b], fstart[b]
        if a + n > D.shape[0]:  # room for twice as many
            D, R, V, EV = _grown(D, a, 2 * (a + n)), _grown(R, a, 2 * (a + n)), _grown(V, a, 2 * (a + n)), \
                _grown(EV, a, 2 * (a + n))
        if f + faces.shape[0] > F.shape[0]:
            F = _grown(F, f, 2 * (f + faces.shape[0]))
        D[a:a + n] = dirs[:n]
        R[a:a + n] = picks[:n]
        V[a:a + n] = v
        EV[a:a + n] = ev
        F[f:f + faces.shape[0]] = faces
        vstart[b + 1] = a + n
        fstart[b + 1] = f + faces.shape[0]
    nv, nf = vstart[B], fstart[B]
    return state, D[:nv], R[:nv], V[:nv], EV[:nv], vstart, F[:nf], fstart


@kernel
def _grown(a, used, size):
    """A copy of ``a`` (n, c) with ``size`` rows, its first ``used`` rows kept."""
    out = np.empty((size, a.shape[1]), dtype=a.dtype)
    out[:used] = a[:used]
    return out


@kernel
def _fresh(W, owner, m, cand, dirs, picks, n):
    """Append to ``dirs`` and ``picks`` (``n`` kept) each row of ``cand`` whose choice is not
    among those kept, in order; the new ``n``."""
    R = np.full((cand.shape[0], m), -1, dtype=np.int64)
    vals, best = np.empty(W.shape[1]), np.empty(m, dtype=np.int64)
    for j in range(cand.shape[0]):
        _choose(W, owner, cand[j, 0], cand[j, 1], cand[j, 2], vals, best, R[j])
        new = True
        for q in range(n):
            same = True
            for i in range(m):
                if picks[q, i] != R[j, i]:
                    same = False
                    break
            if same:
                new = False
                break
        if new:
            dirs[n] = cand[j]
            picks[n] = R[j]
            n += 1
    return n

"""Planar epsilon evidence of many grasps at once, compiled (numba): the generator wrenches of a
batch, the sums of one point per contact polytope (the vertices of ``sums`` evidence) and the
rigorous float checks of many inscribed surfaces; and the vertices of ``support`` evidence
along many directions.

The arithmetic is that of the per-grasp route (:mod:`qualgrasp.certify.quality.bounds`), so the
floats are the same: the generators by :func:`~.planar.planar_generators`, each sum added
contact by contact from zero as the per-grasp route adds them, and each surface checked by
:func:`~.surface.cycle_code` and :func:`~.surface.face_bounds`. A surface these checks cannot
settle in floats (a face whose sign or distance needs the exact vertices) is reported as
undecided, and its caller takes the per-grasp route.
"""

from __future__ import annotations

import numpy as np

from .jit import kernel
from .linalg import ETA, gamma
from .planar import planar_generators
from .surface import cycle_code, face_bounds

__all__ = ["generator_rows", "minkowski_sums", "surface_rows", "support_choices", "vertex_sums"]


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


@kernel
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
    :func:`qualgrasp.certify.quality.gws.planar_support_choice` states it. Returns the choices
    (n, m) and whether each row is sure: its dot products are computed here in one order, and
    any order of the three products and two sums (fused or not) is within ``gamma_3`` of the
    sum of their magnitudes of the exact value, so a row is sure when every contact's largest
    value beats the others, and zero, by more than both errors (a tie, or a value at zero, is
    never sure)."""
    n, k = dirs.shape[0], W.shape[1]
    R = np.full((n, m), -1, dtype=np.int64)
    sure = np.ones(n, dtype=np.bool_)
    vals = np.empty(k)
    errs = np.empty(k)
    g = 2.0 * gamma(4)
    for q in range(n):
        v0, v1, v2 = dirs[q, 0], dirs[q, 1], dirs[q, 2]
        for j in range(k):
            a, b, c = v0 * W[0, j], v1 * W[1, j], v2 * W[2, j]
            vals[j] = a + b + c
            errs[j] = g * (abs(a) + abs(b) + abs(c)) + 8 * ETA
        j0 = 0
        while j0 < k:
            i = owner[j0]
            j1 = j0
            best = j0
            while j1 < k and owner[j1] == i:
                if vals[j1] > vals[best]:
                    best = j1
                j1 += 1
            top = vals[best] - errs[best]  # below every value the best can take
            clear = True
            high = -np.inf  # above every value of the contact
            for j in range(j0, j1):
                high = max(high, vals[j] + errs[j])
                if j != best and not vals[j] + errs[j] < top:
                    clear = False
            if high < 0.0:
                R[q, i] = -1  # every value of the contact is negative
            elif clear and top > 0.0:
                R[q, i] = best
            else:
                sure[q] = False
            j0 = j1
    return R, sure


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

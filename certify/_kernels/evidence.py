"""Planar epsilon evidence of many grasps at once, compiled (numba): the generator wrenches of a
batch, the sums of one point per contact polytope (the vertices of ``sums`` evidence) and the
rigorous float checks of many inscribed surfaces.

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
from .planar import planar_generators
from .surface import cycle_code, face_bounds

__all__ = ["generator_rows", "minkowski_sums", "surface_rows"]


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
    factor = 2 * (m + 1) * 2.0**-53
    pts = np.zeros((B, n, 3))
    err = np.zeros((B, n, 3))
    for b in range(B):
        for p in range(n):
            for r in range(3):
                s, e, a = 0.0, 0.0, 0.0
                for i in range(m):
                    j = choice[p, i]
                    if j >= 0:
                        s = s + W[b, r, j]
                        e = e + E[b, r, j]
                        a = a + abs(W[b, r, j])
                    else:  # the origin, added as the per-grasp route adds it
                        s = s + 0.0
                        e = e + 0.0
                        a = a + 0.0
                pts[b, p, r] = s
                err[b, p, r] = e + factor * a
    return pts, err, choice


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

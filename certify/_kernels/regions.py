"""The bound of :mod:`qualgrasp.certify.regions._branch`, compiled (numba).

For each item ``b`` (a cell of wrench directions, a contact and a piece of its region): the
minimum over the vertex combinations ``(y, q, n)`` (4 each) of ``sum_g W[c, g] F_g`` with
``F_g = (R_g n) . (L y_f + y_tau perp(q - c)) - y_tau ow_g``, ``R_g n = n + fm_g perp(n)``,
``perp(x) = (-x_1, x_0)``, for each candidate combination ``c``, minus ``gamma * scale[b]`` (the
rigorous rounding bound). Plain IEEE arithmetic (no fast-math), so the error analysis of the
caller holds whatever the order of the sums.

The cells' corner directions ``y`` (:func:`cell_corners`: copies, no arithmetic), the vertices
``q`` and ``n`` of the pieces (:func:`piece_vertices`) and ``scale`` (:func:`bound_scales`) are
compiled too, the last two each the expression the caller once evaluated over numpy
arrays, term for term in the same order, so the numbers are the same; the cosines and sines of the
normals' angles stay numpy's (the caller's), whose results the kernels take as given.
"""

from __future__ import annotations

import numpy as np

from .jit import kernel

__all__ = ["piece_bounds", "piece_vertices", "bound_scales", "cell_corners"]


@kernel
def piece_bounds(Y, Q, N, contact, fm, ow, weights, cmask, cand, scale, cx, cy, L, gamma):
    """Lower bounds ``lb`` (B,) and the candidate giving each (``cand[b] >= 0``: that one only).

    Y (B, 4, 3), Q (B, 4, 2), N (B, 4, 2); contact (B,); fm, ow (k, G); weights (k, C, G);
    cmask (k, C) bool; cand (B,) int (-1: best over the candidates); scale (B,).
    """
    B = Y.shape[0]
    G = fm.shape[1]
    C = weights.shape[1]
    lb = np.empty(B)
    best = np.empty(B, dtype=np.int64)
    F = np.empty((64, G))
    for b in range(B):
        i = contact[b]
        r = 0
        for iy in range(4):
            yx, yy, yt = Y[b, iy, 0], Y[b, iy, 1], Y[b, iy, 2]
            for iq in range(4):
                vx = L * yx - yt * (Q[b, iq, 1] - cy)
                vy = L * yy + yt * (Q[b, iq, 0] - cx)
                for jn in range(4):
                    nx, ny = N[b, jn, 0], N[b, jn, 1]
                    for g in range(G):
                        rx = nx - fm[i, g] * ny
                        ry = ny + fm[i, g] * nx
                        F[r, g] = rx * vx + ry * vy - yt * ow[i, g]
                    r += 1
        top = -np.inf
        arg = -1
        for c in range(C):
            if cand[b] >= 0 and c != cand[b]:
                continue
            if not cmask[i, c]:
                continue
            low = np.inf
            for r in range(64):
                acc = 0.0
                for g in range(G):
                    w = weights[i, c, g]
                    if w != 0.0:
                        acc += w * F[r, g]
                if acc < low:
                    low = acc
            low -= gamma * scale[b]
            if low > top:
                top = low
                arg = c
        lb[b] = top
        best[b] = arg
    return lb, best


@kernel
def piece_vertices(P0, P1, E, h, s0, s1, ua, ub, scale, exact, normal, rel):
    """Point and normal vertices (B, 4, 2) of pieces: piece ``b`` covers the chord ``P0 + s (P1 -
    P0)`` for ``s`` in ``[s0, s1]`` (pushed out by ``rel`` at an end of an arc with ``h > 0``),
    widened by ``+-h`` along ``E``; its normals lie between the unit vectors ``ua`` and ``ub``
    (B, 2), inside ``(1 - rel)`` of them and the chord ``scale`` (B,) times them (``exact`` rows:
    ``normal`` itself at every vertex). Corner ``(s0, -h), (s0, h), (s1, -h), (s1, h)`` for the
    points, ``(1 - rel) ua, (1 - rel) ub, scale ua, scale ub`` for the normals; the numbers are
    those of the same expressions over numpy arrays, term for term."""
    B = P0.shape[0]
    Q = np.empty((B, 4, 2))
    N = np.empty((B, 4, 2))
    inner = 1 - rel
    for b in range(B):
        ext = rel if h[b] > 0 else 0.0
        lo = s0[b] - ext if s0[b] <= 0 else s0[b]
        hi = s1[b] + ext if s1[b] >= 1 else s1[b]
        for c in range(4):
            s = lo if c < 2 else hi
            w = h[b] if c % 2 else -h[b]
            for r in range(2):
                Q[b, c, r] = (P0[b, r] + s * (P1[b, r] - P0[b, r])) + w * E[b, r]
        for r in range(2):
            if exact[b]:
                for c in range(4):
                    N[b, c, r] = normal[b, r]
            else:
                N[b, 0, r] = inner * ua[b, r]
                N[b, 1, r] = inner * ub[b, r]
                N[b, 2, r] = scale[b] * ua[b, r]
                N[b, 3, r] = scale[b] * ub[b, r]
    return Q, N


@kernel
def _corner_max(A, b, k):
    """The largest ``abs(A[b, c, k])`` over the four corners ``c``."""
    return max(max(abs(A[b, 0, k]), abs(A[b, 1, k])), max(abs(A[b, 2, k]), abs(A[b, 3, k])))


@kernel
def bound_scales(Y, N, P0, P1, E, h, s0, s1, contact, fm, ow, cx, cy, L, rel):
    """The ``scale`` of :func:`piece_bounds` (B,): the expression of the bound over absolute
    values, bounded above, from the corners ``Y`` (B, 4, 3) and ``N`` (B, 4, 2) and the pieces'
    chords as :func:`piece_vertices` takes them (``|s|`` widened by ``1e-7`` and ``h`` by ``2 rel``
    for the points' ends), the largest over the contact's generators (padded ones included)."""
    B, G = Y.shape[0], fm.shape[1]
    out = np.empty(B)
    widen = 1 + 2 * rel
    for b in range(B):
        i = contact[b]
        y0, y1, y2 = _corner_max(Y, b, 0), _corner_max(Y, b, 1), _corner_max(Y, b, 2)
        sm = max(abs(s0[b]), abs(s1[b])) * 1.0000001
        hh = h[b] * widen
        qa0 = (abs(P0[b, 0]) + sm * (abs(P1[b, 0]) + abs(P0[b, 0]))) + hh * abs(E[b, 0])
        qa1 = (abs(P0[b, 1]) + sm * (abs(P1[b, 1]) + abs(P0[b, 1]))) + hh * abs(E[b, 1])
        vs = (L * y0 + y2 * (qa1 + abs(cy))) + (L * y1 + y2 * (qa0 + abs(cx)))
        ns = _corner_max(N, b, 0) + _corner_max(N, b, 1)
        top = -np.inf
        for g in range(G):
            v = (ns * (1 + abs(fm[i, g]))) * vs + y2 * abs(ow[i, g])
            if v > top:
                top = v
        out[b] = top
    return out


@kernel
def cell_corners(face, box, axes, signs):
    """Corner directions (B, 4, 3) of cells on the faces of the cube: cell ``b`` lies on face
    ``face[b]``, the plane ``x[axes[f]] = signs[f]``, over ``box[b]`` = ``lo0, hi0, lo1, hi1`` of
    the two other coordinates in axis order; corners ``(lo0, lo1), (lo0, hi1), (hi0, lo1), (hi0,
    hi1)``."""
    B = face.shape[0]
    V = np.zeros((B, 4, 3))
    for b in range(B):
        ax = axes[face[b]]
        f0 = 1 if ax == 0 else 0
        f1 = 1 if ax == 2 else 2
        for c in range(4):
            V[b, c, ax] = signs[face[b]]
            V[b, c, f0] = box[b, 0] if c < 2 else box[b, 1]
            V[b, c, f1] = box[b, 2] if c % 2 == 0 else box[b, 3]
    return V

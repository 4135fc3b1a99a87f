"""The bound of :mod:`qualgrasp.certify.regions._branch`, compiled (numba).

For each item ``b`` (a cell of wrench directions, a contact and a piece of its region): the
minimum over the vertex combinations ``(y, q, n)`` (4 each) of ``sum_g W[c, g] F_g`` with
``F_g = (R_g n) . (L y_f + y_tau perp(q - c)) - y_tau ow_g``, ``R_g n = n + fm_g perp(n)``,
``perp(x) = (-x_1, x_0)``, for each candidate combination ``c``, minus ``gamma * scale[b]`` (the
rigorous rounding bound). Plain IEEE arithmetic (no fast-math), so the error analysis of the
caller holds whatever the order of the sums.
"""

from __future__ import annotations

import numpy as np

from .jit import kernel

__all__ = ["piece_bounds"]


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

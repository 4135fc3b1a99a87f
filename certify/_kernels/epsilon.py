"""The exact Ferrari-Canny epsilon of planar grasps, compiled (numba): the minimum of the
support function over a finite set of directions holding every facet normal of the grasp wrench
space (see :func:`planar_epsilon`)."""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["planar_epsilon_one", "planar_epsilon"]


@njit(cache=True)
def _support_planar(Wb, owner, best, u0, u1, u2, linf):
    """Support function of the planar GWS at ``u``: per contact the largest ``u . g`` over its
    generators (at least 0), combined by max (L1) or sum (L-infinity). ``best`` is a work
    array with one entry per contact."""
    m = best.shape[0]
    for i in range(m):
        best[i] = 0.0
    for j in range(Wb.shape[1]):
        v = Wb[0, j] * u0 + Wb[1, j] * u1 + Wb[2, j] * u2
        if v > best[owner[j]]:
            best[owner[j]] = v
    out = 0.0
    for i in range(m):
        out = out + best[i] if linf else max(out, best[i])
    return out


@njit(cache=True)
def planar_epsilon_one(Wb, owner, m, linf):
    """Epsilon and direction of one planar grasp (see :func:`planar_epsilon`)."""
    k = Wb.shape[1]
    if linf:
        n = k
        for a in range(k):
            for c in range(a + 1, k):
                if owner[a] == owner[c]:
                    n += 1
        E = np.empty((n, 3))
        e = 0
        for a in range(k):
            E[e, 0], E[e, 1], E[e, 2] = Wb[0, a], Wb[1, a], Wb[2, a]
            e += 1
        for a in range(k):
            for c in range(a + 1, k):
                if owner[a] == owner[c]:
                    E[e, 0] = Wb[0, a] - Wb[0, c]
                    E[e, 1] = Wb[1, a] - Wb[1, c]
                    E[e, 2] = Wb[2, a] - Wb[2, c]
                    e += 1
    else:
        # facets of conv(0 and the generators): the grasp is in closure, so the origin is
        # interior and no facet passes through it; triples of generators suffice
        n = k
        E = np.empty((n, 3))
        for a in range(k):
            E[a, 0], E[a, 1], E[a, 2] = Wb[0, a], Wb[1, a], Wb[2, a]
    scale = 0.0
    for a in range(n):
        scale = max(scale, abs(E[a, 0]) + abs(E[a, 1]) + abs(E[a, 2]))
    tiny = 1e-12 * max(1.0, scale * scale)
    work = np.empty(m)
    arg = np.zeros(3)
    best = np.inf
    for a in range(n):
        for c in range(a + 1, n):
            if linf:  # normal of a pair of edges
                best = _candidate(Wb, owner, work, linf, E[a, 0], E[a, 1], E[a, 2],
                                  E[c, 0], E[c, 1], E[c, 2], tiny, best, arg)
                continue
            for q in range(c + 1, n):  # normal of a triple of points
                best = _candidate(Wb, owner, work, linf,
                                  E[c, 0] - E[a, 0], E[c, 1] - E[a, 1], E[c, 2] - E[a, 2],
                                  E[q, 0] - E[a, 0], E[q, 1] - E[a, 1], E[q, 2] - E[a, 2],
                                  tiny, best, arg)
    return best, arg


@njit(cache=True)
def _candidate(Wb, owner, work, linf, x0, x1, x2, y0, y1, y2, tiny, best, arg):
    """Evaluate the support function at both unit normals ``+-(x cross y)``; return the least
    value so far (``arg`` holds its direction)."""
    u0 = x1 * y2 - x2 * y1
    u1 = x2 * y0 - x0 * y2
    u2 = x0 * y1 - x1 * y0
    nu = np.sqrt(u0 * u0 + u1 * u1 + u2 * u2)
    if nu <= tiny:
        return best
    u0, u1, u2 = u0 / nu, u1 / nu, u2 / nu
    for sgn in (1.0, -1.0):
        h = _support_planar(Wb, owner, work, sgn * u0, sgn * u1, sgn * u2, linf)
        if h < best:
            best = h
            arg[0], arg[1], arg[2] = sgn * u0, sgn * u1, sgn * u2
    return best


@njit(cache=True)
def planar_epsilon(W, owner, m, linf):
    """Exact Ferrari-Canny epsilon of planar grasps (B, 3, k generators; ``owner`` maps
    generators to the ``m`` contacts, grasps in force closure): the minimum of the support
    function over a set of directions holding every facet normal of the GWS (both orientations).
    L1: normals of the triples of generators (the origin is interior, so no facet contains it).
    L-infinity (Minkowski sum of the
    per-contact polytopes ``conv(0, generators)``): cross products of pairs of their edges (the
    generators, and differences of generators of one contact). Returns epsilon (B,) and the
    minimising unit direction (B, 3)."""
    B = W.shape[0]
    eps = np.empty(B)
    arg = np.empty((B, 3))
    for b in range(B):
        eps[b], arg[b] = planar_epsilon_one(W[b], owner, m, linf)
    return eps, arg

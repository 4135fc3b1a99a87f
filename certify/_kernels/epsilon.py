"""The exact Ferrari-Canny epsilon of planar grasps, compiled (numba): the minimum of the
support function over a finite set of directions holding every facet normal of the grasp wrench
space.

Two routes: :func:`planar_epsilon` enumerates the candidate normals (triples of generators for
L1, pairs of edges for L-infinity), ``O(k^4)`` and ``O(k^3)`` for ``k`` generators, the fastest
for a handful of contacts; :func:`linf_sweep` finds the L-infinity candidates by a sweep around
the great circle orthogonal to each edge, ``O(k^2 log k)`` in all. The L1 route for many
generators is the convex hull (:mod:`qualgrasp.certify.quality.bounds`), whose faces nearest the
origin :func:`hull_minima` evaluates.
"""

from __future__ import annotations

import numpy as np

from .jit import kernel
from .order import stable_argsort

__all__ = ["planar_epsilon_one", "planar_epsilon", "planar_edges", "linf_sweep", "support_rows", "hull_minima"]


@kernel
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


@kernel
def planar_edges(Wb, owner):
    """Edge directions of the per-contact polytopes ``conv(0, generators of the contact)``: every
    generator, then the difference of every pair of generators of one contact (a superset of the
    edges), as rows ``(n, 3)``."""
    k = Wb.shape[1]
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
    return E


@kernel
def planar_epsilon_one(Wb, owner, m, linf):
    """Epsilon and direction of one planar grasp (see :func:`planar_epsilon`)."""
    k = Wb.shape[1]
    # L-infinity: normals of pairs of edges. L1: facets of conv(0 and the generators); the grasp
    # is in closure, so the origin is interior and no facet passes through it: normals of
    # triples of generators suffice
    E = planar_edges(Wb, owner) if linf else np.ascontiguousarray(Wb.T)
    n = E.shape[0]
    scale = 0.0
    for a in range(n):
        scale = max(scale, abs(E[a, 0]) + abs(E[a, 1]) + abs(E[a, 2]))
    tiny = 1e-12 * max(1.0, scale * scale)
    work = np.empty((2, m))
    arg = np.zeros(3)
    grouped = True  # each contact's generators together, in contact order (as generator_layout lays them)
    for j in range(1, k):
        grouped = grouped and owner[j - 1] <= owner[j]
    if linf:
        return _pair_normals(Wb, owner, work, linf, grouped, E, tiny, np.inf, arg), arg
    best = np.inf
    D = np.empty((n, 3))
    for a in range(n):  # the triples (a, c, q), c < q after a: the pairs of their differences from a
        for c in range(a + 1, n):
            D[c - a - 1, 0] = E[c, 0] - E[a, 0]
            D[c - a - 1, 1] = E[c, 1] - E[a, 1]
            D[c - a - 1, 2] = E[c, 2] - E[a, 2]
        best = _pair_normals(Wb, owner, work, linf, grouped, D[:n - a - 1], tiny, best, arg)
    return best, arg


@kernel
def _pair_normals(Wb, owner, work, linf, grouped, D, tiny, best, arg):
    """Evaluate the support function at both unit normals ``+-(x cross y)``, ``+`` first, of
    each pair ``x = D[a]``, ``y = D[c]`` (``a < c``, in that order) whose cross product is longer
    than ``tiny``; return the least of ``best`` and their values (``arg`` is set to the
    direction of each value below the least so far). ``work`` is (2, contacts); ``grouped``: ``owner`` is sorted
    (:func:`_support_both_below` may then stop early). One loop over all pairs, with the normal
    compiled into it (:func:`_unit_cross`): a call per pair costs a third more time."""
    n = D.shape[0]
    for a in range(n):
        x0, x1, x2 = D[a, 0], D[a, 1], D[a, 2]
        for c in range(a + 1, n):
            ok, u0, u1, u2 = _unit_cross(x0, x1, x2, D[c, 0], D[c, 1], D[c, 2], tiny)
            if not ok:
                continue
            if grouped:
                plus, minus = _support_both_below(Wb, owner, u0, u1, u2, linf, best)
            else:
                plus, minus = _support_both(Wb, owner, work[0], work[1], u0, u1, u2, linf)
            if plus < best:
                best = plus
                arg[0], arg[1], arg[2] = u0, u1, u2
            if minus < best:
                best = minus
                arg[0], arg[1], arg[2] = -u0, -u1, -u2
    return best


@kernel(inline=True)
def _unit_cross(x0, x1, x2, y0, y1, y2, tiny):
    """``(True, x cross y / |x cross y|)``, or ``(False, 0, 0, 0)`` when ``|x cross y| <= tiny``:
    a candidate facet normal of two edges."""
    u0 = x1 * y2 - x2 * y1
    u1 = x2 * y0 - x0 * y2
    u2 = x0 * y1 - x1 * y0
    nu = np.sqrt(u0 * u0 + u1 * u1 + u2 * u2)
    if nu <= tiny:
        return False, 0.0, 0.0, 0.0
    return True, u0 / nu, u1 / nu, u2 / nu


@kernel
def _support_both(Wb, owner, best, worst, u0, u1, u2, linf):
    """:func:`_support_planar` at ``u`` and at ``-u`` in one pass over the generators. The
    products at ``-u`` are those at ``u`` negated, exactly (rounding to nearest is symmetric), so
    both values are what :func:`_support_planar` gives. ``best`` and ``worst`` are work arrays
    with one entry per contact."""
    m = best.shape[0]
    for i in range(m):
        best[i] = 0.0
        worst[i] = 0.0
    for j in range(Wb.shape[1]):
        v = Wb[0, j] * u0 + Wb[1, j] * u1 + Wb[2, j] * u2
        if v > best[owner[j]]:
            best[owner[j]] = v
        if -v > worst[owner[j]]:
            worst[owner[j]] = -v
    plus, minus = 0.0, 0.0
    for i in range(m):
        plus = plus + best[i] if linf else max(plus, best[i])
        minus = minus + worst[i] if linf else max(minus, worst[i])
    return plus, minus


@kernel
def _support_both_below(Wb, owner, u0, u1, u2, linf, bound):
    """:func:`_support_both` for generators grouped by contact in contact order (``owner``
    sorted), combining each contact's value as soon as its generators are done, and stopping
    once both values are at least ``bound``: then both are at most the full values, which are
    not below ``bound`` either, since the combined values only grow (each contact's value is at
    least 0, and adding it or taking a maximum never lowers a float). The full values are
    :func:`_support_both`'s: a contact without generators would add ``+0.0``, which changes
    no sum started at ``+0.0``."""
    plus, minus = 0.0, 0.0
    bp, bm = 0.0, 0.0
    for j in range(Wb.shape[1]):
        if j > 0 and owner[j] != owner[j - 1]:
            plus = plus + bp if linf else max(plus, bp)
            minus = minus + bm if linf else max(minus, bm)
            if plus >= bound and minus >= bound:
                return plus, minus
            bp, bm = 0.0, 0.0
        v = Wb[0, j] * u0 + Wb[1, j] * u1 + Wb[2, j] * u2
        if v > bp:
            bp = v
        if -v > bm:
            bm = -v
    plus = plus + bp if linf else max(plus, bp)
    minus = minus + bm if linf else max(minus, bm)
    return plus, minus


@kernel
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


@kernel
def support_rows(Wb, owner, m, U, linf):
    """Support function of the planar GWS (generators ``Wb`` (3, k)) at each row of ``U``."""
    work = np.empty(m)
    out = np.empty(U.shape[0])
    for r in range(U.shape[0]):
        out[r] = _support_planar(Wb, owner, work, U[r, 0], U[r, 1], U[r, 2], linf)
    return out


@kernel
def _insert(top_val, top_u, val, u0, u1, u2):
    """Insert a candidate into the list of the best ones, sorted by value (ascending)."""
    K = top_val.shape[0]
    if not val < top_val[K - 1]:
        return
    i = K - 1
    while i > 0 and top_val[i - 1] > val:
        top_val[i] = top_val[i - 1]
        top_u[i, 0], top_u[i, 1], top_u[i, 2] = top_u[i - 1, 0], top_u[i - 1, 1], top_u[i - 1, 2]
        i -= 1
    top_val[i] = val
    top_u[i, 0], top_u[i, 1], top_u[i, 2] = u0, u1, u2


@kernel
def _pseudo_angle(x, y):
    """A number in [0, 4) increasing with the angle of ``(x, y)`` (no trigonometry)."""
    p = x / (abs(x) + abs(y))
    return 3.0 + p if y < 0.0 else 1.0 - p


@kernel
def _hull2(xs, ys, idx, n, out, delta):
    """Counter-clockwise convex hull (Andrew's monotone chain) of the ``n`` 2-D points
    ``(xs[idx[i]], ys[idx[i]])``; writes hull positions (into ``idx``) to ``out`` and returns
    their count (1 when all points coincide). Robust to rounding: points within ``delta``
    (in the 1-norm) of an earlier one are merged into it, and vertices whose turn is within
    ``1e-12`` of the product of the adjacent edge lengths are dropped as collinear, so that no
    edge is a rounding artefact with an arbitrary normal."""
    kept = 0
    for i in range(n):  # merge near-duplicates (n is a handful)
        dup = False
        for j in range(kept):
            if abs(xs[idx[i]] - xs[idx[j]]) + abs(ys[idx[i]] - ys[idx[j]]) <= delta:
                dup = True
                break
        if not dup:
            idx[kept] = idx[i]
            kept += 1
    n = kept
    if n == 1:
        return 1
    for i in range(1, n):  # insertion sort by (x, y)
        j = i
        while j > 0 and (xs[idx[j - 1]] > xs[idx[j]] or
                         (xs[idx[j - 1]] == xs[idx[j]] and ys[idx[j - 1]] > ys[idx[j]])):
            idx[j - 1], idx[j] = idx[j], idx[j - 1]
            j -= 1
    h = 0
    for i in range(n):  # lower hull
        while h >= 2 and _turns_right(xs, ys, out[h - 2], out[h - 1], idx[i]):
            h -= 1
        out[h] = idx[i]
        h += 1
    low = h + 1
    for i in range(n - 2, -1, -1):  # upper hull
        while h >= low and _turns_right(xs, ys, out[h - 2], out[h - 1], idx[i]):
            h -= 1
        out[h] = idx[i]
        h += 1
    h -= 1  # the first point closes the chain
    return max(h, 2) if n >= 2 else 1


@kernel
def _turns_right(xs, ys, o, a, b):
    """Does ``o -> a -> b`` turn clockwise or go straight (within 1e-12 relative)?"""
    ax, ay = xs[a] - xs[o], ys[a] - ys[o]
    bx, by = xs[b] - xs[o], ys[b] - ys[o]
    cross = ax * by - ay * bx
    return cross <= 1e-12 * (abs(ax) + abs(ay)) * (abs(bx) + abs(by))


@kernel
def linf_sweep(Wb, owner, m, E, first, last, top_val, top_u):
    """Candidate facet normals of the planar L-infinity GWS on the great circles orthogonal to
    the edges ``E[first:last]``, the best ones kept in ``top_val`` / ``top_u`` (updated).

    The GWS is the Minkowski sum of the per-contact polytopes ``P_i = conv(0, generators of i)``
    (``owner`` maps generators to contacts and must be sorted). Each facet normal is orthogonal
    to two edges, so it lies on the circle ``u(t) = cos t a + sin t b`` orthogonal to one of
    them, ``e``, at an angle where the maximiser of ``u . x`` over the vertices of another
    polytope (or of the same one) changes: there ``u`` is orthogonal to ``e`` and to the edge
    between the two maximisers. On the circle the support of ``P_i`` is the 2-D support of its
    vertices projected on ``(a, b)``: the maximiser is a vertex of their 2-D hull, and it changes
    at the outward normals of the hull's edges. All these breakpoints of all contacts are sorted
    (by a pseudo-angle) and swept, keeping the sum of the current maximisers, so that
    ``h(u(t))`` costs O(1) per breakpoint: ``O(k log k)`` per circle. At each breakpoint the
    candidate ``u = +-(e x e') / |e x e'|`` (``e'`` the hull edge, oriented along ``u(t)``)
    enters the list when its swept value is among the best; the caller evaluates the support
    function directly at the listed directions (the swept value only ranks them), so the result
    is the minimum of ``h`` over a set of unit normals holding every facet normal, as
    :func:`planar_epsilon_one` computes it.
    """
    k = Wb.shape[1]
    start = np.zeros(m + 1, dtype=np.int64)
    for j in range(k):
        start[owner[j] + 1] += 1
    rmax = 0
    for i in range(m):
        rmax = max(rmax, start[i + 1])
        start[i + 1] += start[i]
    scale = 0.0
    for a in range(E.shape[0]):
        scale = max(scale, abs(E[a, 0]) + abs(E[a, 1]) + abs(E[a, 2]))
    tiny = 1e-12 * max(1.0, scale * scale)
    delta = 1e-12 * scale
    xs = np.zeros(k + 1)  # projected generators; position k is the origin
    ys = np.zeros(k + 1)
    idx = np.empty(rmax + 1, dtype=np.int64)
    hull = np.empty(2 * rmax + 4, dtype=np.int64)
    maxev = m * (rmax + 1)
    ev_key = np.empty(maxev)
    ev_nx = np.empty(maxev)
    ev_ny = np.empty(maxev)
    ev_dA = np.empty(maxev)
    ev_dB = np.empty(maxev)
    ev_e = np.empty((maxev, 3))
    for a in range(first, last):
        e0, e1, e2 = E[a, 0], E[a, 1], E[a, 2]
        ne = np.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
        if ne * ne <= tiny:
            continue
        h0, h1, h2 = e0 / ne, e1 / ne, e2 / ne
        # a basis (av, bv) of the plane orthogonal to e
        if abs(h0) <= abs(h1) and abs(h0) <= abs(h2):
            x0, x1, x2 = 0.0, h2, -h1  # h x (1, 0, 0)
        elif abs(h1) <= abs(h2):
            x0, x1, x2 = -h2, 0.0, h0  # h x (0, 1, 0)
        else:
            x0, x1, x2 = h1, -h0, 0.0  # h x (0, 0, 1)
        nx_ = np.sqrt(x0 * x0 + x1 * x1 + x2 * x2)
        a0, a1, a2 = x0 / nx_, x1 / nx_, x2 / nx_
        b0 = h1 * a2 - h2 * a1
        b1 = h2 * a0 - h0 * a2
        b2 = h0 * a1 - h1 * a0
        for j in range(k):
            xs[j] = a0 * Wb[0, j] + a1 * Wb[1, j] + a2 * Wb[2, j]
            ys[j] = b0 * Wb[0, j] + b1 * Wb[1, j] + b2 * Wb[2, j]
        nev = 0
        SA, SB = 0.0, 0.0
        for i in range(m):
            n = start[i + 1] - start[i] + 1
            idx[0] = k
            for q in range(1, n):
                idx[q] = start[i] + q - 1
            nh = _hull2(xs, ys, idx, n, hull, delta)
            if nh < 2:
                continue  # every point projects on the origin: the contact adds 0
            # outward normal of the edge hull[t] -> hull[t+1] (counter-clockwise): (dy, -dx);
            # between the normals of the edges into and out of hull[t+1], it is the maximiser
            top, init = -1.0, k
            for t in range(nh):
                p, q = hull[t], hull[(t + 1) % nh]
                dx, dy = xs[q] - xs[p], ys[q] - ys[p]
                if dx == 0.0 and dy == 0.0:
                    continue
                key = _pseudo_angle(dy, -dx)
                if key > top:
                    top, init = key, q
                ev_key[nev] = key
                ev_nx[nev], ev_ny[nev] = dy, -dx
                ev_dA[nev], ev_dB[nev] = dx, dy
                for r in range(3):
                    ev_e[nev, r] = (0.0 if q == k else Wb[r, q]) - (0.0 if p == k else Wb[r, p])
                nev += 1
            SA += xs[init]  # the maximiser on the arc through pseudo-angle 0
            SB += ys[init]
        order = stable_argsort(ev_key[:nev])
        for q in order:
            SA += ev_dA[q]
            SB += ev_dB[q]
            c, s_ = ev_nx[q], ev_ny[q]
            nn = np.sqrt(c * c + s_ * s_)
            c, s_ = c / nn, s_ / nn
            val = SA * c + SB * s_
            if not val < top_val[top_val.shape[0] - 1]:
                continue
            ok, u0, u1, u2 = _unit_cross(e0, e1, e2, ev_e[q, 0], ev_e[q, 1], ev_e[q, 2], tiny)
            if not ok:
                continue
            w0, w1, w2 = c * a0 + s_ * b0, c * a1 + s_ * b1, c * a2 + s_ * b2
            if u0 * w0 + u1 * w1 + u2 * w2 < 0.0:
                u0, u1, u2 = -u0, -u1, -u2
            _insert(top_val, top_u, val, u0, u1, u2)


@kernel
def hull_minima(W, owner, m, faces, fstart, top):
    """Planar L1 epsilon of many grasps from their generators' hulls (``W`` (B, 3, k), grasp ``b``
    owning ``faces[fstart[b]:fstart[b + 1]]``, indices into its generators): per face, its
    vertices in ascending order ``a < b < c``, the normal ``(g_b - g_a) x (g_c - g_a)`` made
    unit by ``sqrt((n0^2 + n1^2) + n2^2)`` and turned so that its offset
    ``(n0 a0 + n1 a1) + n2 a2`` is not negative; the support function evaluated at the normals
    of the ``top`` faces of least offset (stable order; faces of zero normal left out), its
    least value and direction (the first of equal values) per grasp. A grasp without a face of
    non-zero normal gets ``inf``."""
    B = W.shape[0]
    eps = np.full(B, np.inf)
    arg = np.zeros((B, 3))
    work = np.empty(m)
    for b in range(B):
        F = fstart[b + 1] - fstart[b]
        U = np.empty((F, 3))
        off = np.empty(F)
        g = 0
        for f in range(fstart[b], fstart[b + 1]):
            i0, i1, i2 = faces[f, 0], faces[f, 1], faces[f, 2]
            if i1 < i0:
                i0, i1 = i1, i0
            if i2 < i1:
                i1, i2 = i2, i1
                if i1 < i0:
                    i0, i1 = i1, i0
            a0, a1, a2 = W[b, 0, i0], W[b, 1, i0], W[b, 2, i0]
            p0, p1, p2 = W[b, 0, i1] - a0, W[b, 1, i1] - a1, W[b, 2, i1] - a2
            q0, q1, q2 = W[b, 0, i2] - a0, W[b, 1, i2] - a1, W[b, 2, i2] - a2
            n0 = p1 * q2 - p2 * q1
            n1 = p2 * q0 - p0 * q2
            n2 = p0 * q1 - p1 * q0
            norm = np.sqrt(n0 * n0 + n1 * n1 + n2 * n2)
            if not norm > 0.0:
                continue
            n0, n1, n2 = n0 / norm, n1 / norm, n2 / norm
            o = n0 * a0 + n1 * a1 + n2 * a2
            if o < 0.0:
                n0, n1, n2, o = -n0, -n1, -n2, -o
            U[g, 0], U[g, 1], U[g, 2] = n0, n1, n2
            off[g] = abs(o)
            g += 1
        if g == 0:
            continue
        near = stable_argsort(off[:g])
        for r in range(min(top, g)):
            u = U[near[r]]
            h = _support_planar(W[b], owner, work, u[0], u[1], u[2], False)
            if r == 0 or h < eps[b] or (h != h and eps[b] == eps[b]):  # as np.argmin: the first NaN, else least
                eps[b] = h
                arg[b, 0], arg[b, 1], arg[b, 2] = u[0], u[1], u[2]
    return eps, arg

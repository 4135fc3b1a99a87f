"""Compiled kernels (numba) for the hot paths: many small closure programmes at once.

* :func:`lp_enumerate`: the polyhedral min-weight LP by exact basis enumeration (the method of
  :mod:`qualgrasp.certify.solvers.enumeration`), one compiled loop per grasp.
* :func:`socp_dual_barrier`: the spatial closure SOCP solved through its dual, a barrier method
  in the ``d = 6`` dual variables (see :mod:`qualgrasp.certify.solvers.barrier`).

Kernels take plain float arrays and return plain arrays; the decisions (closure, Farkas,
degenerate, fallback) are made by the callers, so that there is one rule for every route.
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["lp_enumerate", "solve_small"]


@njit(cache=True)
def solve_small(A, b):
    """Solve ``A x = b`` by Gaussian elimination with partial pivoting (A is copied).

    Returns ``(x, det)``; ``det`` is 0 (and ``x`` meaningless) when a pivot vanishes.
    """
    n = A.shape[0]
    M = A.copy()
    x = b.copy()
    det = 1.0
    for c in range(n):
        p = c
        best = abs(M[c, c])
        for r in range(c + 1, n):
            if abs(M[r, c]) > best:
                best = abs(M[r, c])
                p = r
        if best == 0.0:
            return x, 0.0
        if p != c:
            for j in range(n):
                M[c, j], M[p, j] = M[p, j], M[c, j]
            x[c], x[p] = x[p], x[c]
            det = -det
        det *= M[c, c]
        for r in range(c + 1, n):
            f = M[r, c] / M[c, c]
            if f != 0.0:
                for j in range(c, n):
                    M[r, j] -= f * M[c, j]
                x[r] -= f * x[c]
    for c in range(n - 1, -1, -1):
        s = x[c]
        for j in range(c + 1, n):
            s -= M[c, j] * x[j]
        x[c] = s / M[c, c]
    return x, det


@njit(cache=True)
def _lu(M, piv):
    """In-place LU factorisation with partial pivoting; returns the determinant (0 if singular)."""
    n = M.shape[0]
    det = 1.0
    for c in range(n):
        p = c
        best = abs(M[c, c])
        for r in range(c + 1, n):
            if abs(M[r, c]) > best:
                best = abs(M[r, c])
                p = r
        piv[c] = p
        if best == 0.0:
            return 0.0
        if p != c:
            for j in range(n):
                tmp = M[c, j]
                M[c, j] = M[p, j]
                M[p, j] = tmp
            det = -det
        det *= M[c, c]
        inv = 1.0 / M[c, c]
        for r in range(c + 1, n):
            M[r, c] *= inv
            f = M[r, c]
            if f != 0.0:
                for j in range(c + 1, n):
                    M[r, j] -= f * M[c, j]
    return det


@njit(cache=True)
def _lu_solve(LU, piv, x):
    """Solve ``A x = b`` in place (``x`` holds ``b``) from :func:`_lu`'s factors of ``A``."""
    n = LU.shape[0]
    for c in range(n):
        p = piv[c]
        if p != c:
            tmp = x[c]
            x[c] = x[p]
            x[p] = tmp
    for r in range(n):
        s = x[r]
        for j in range(r):
            s -= LU[r, j] * x[j]
        x[r] = s
    for r in range(n - 1, -1, -1):
        s = x[r]
        for j in range(r + 1, n):
            s -= LU[r, j] * x[j]
        x[r] = s / LU[r, r]


@njit(cache=True)
def _lu_solve_t(LU, piv, x):
    """Solve ``A' x = b`` in place from :func:`_lu`'s factors of ``A`` (``P A = L U``)."""
    n = LU.shape[0]
    for r in range(n):  # U' w = b
        s = x[r]
        for j in range(r):
            s -= LU[j, r] * x[j]
        x[r] = s / LU[r, r]
    for r in range(n - 1, -1, -1):  # L' v = w
        s = x[r]
        for j in range(r + 1, n):
            s -= LU[j, r] * x[j]
        x[r] = s
    for c in range(n - 1, -1, -1):  # x = P' v
        p = piv[c]
        if p != c:
            tmp = x[c]
            x[c] = x[p]
            x[p] = tmp


@njit(cache=True)
def lp_enumerate(W, combos, feas):
    """Min-weight LPs ``max t : W lam = 0, 1'lam = 1, lam >= t`` by basis enumeration.

    Parameters
    ----------
    W : float array, shape (B, d, k)
    combos : int array, shape (nS, d)
        All ``d``-subsets of ``range(k)``.
    feas : float
        Relative feasibility slack for basic solutions.

    Returns
    -------
    t : (B,) optimal margin, ``-inf`` when infeasible
    lam : (B, k) optimal weights
    y : (B, d) dual direction (``W' y <= t*``; for infeasible problems ``W' y = -1``)
    has_y : (B,) bool, False when no dual basis was found
    """
    B, d, k = W.shape
    nS = combos.shape[0]
    n = d + 1
    t_out = np.full(B, -np.inf)
    lam_out = np.full((B, k), np.nan)
    y_out = np.zeros((B, d))
    has_y = np.zeros(B, dtype=np.bool_)
    M = np.empty((n, n))
    piv = np.empty(n, dtype=np.int64)
    prim = np.empty(n)
    dual = np.empty(n)
    w1 = np.empty(d)
    for b in range(B):
        wmax = 0.0
        for i in range(d):
            s = 0.0
            for j in range(k):
                s += W[b, i, j]
                wmax = max(wmax, abs(W[b, i, j]))
            w1[i] = s
        best_t = -np.inf
        best_z = np.inf
        for si in range(nS):
            had = 1.0
            nc = float(k * k)
            for i in range(d):
                M[i, 0] = w1[i]
                nc += w1[i] * w1[i]
            M[d, 0] = k
            had *= np.sqrt(nc)
            for c in range(d):
                nc = 1.0
                for i in range(d):
                    v = W[b, i, combos[si, c]]
                    M[i, c + 1] = v
                    nc += v * v
                M[d, c + 1] = 1.0
                had *= np.sqrt(nc)
            det = _lu(M, piv)
            if abs(det) <= 1e-13 * had:
                continue
            for i in range(n):
                prim[i] = 0.0
                dual[i] = 0.0
            prim[d] = 1.0
            dual[0] = 1.0
            _lu_solve(M, piv, prim)
            _lu_solve_t(M, piv, dual)
            t = prim[0]
            ok = True
            for c in range(d):
                if prim[c + 1] < -feas * (1.0 + abs(t)):
                    ok = False
                    break
            if ok and t > best_t:
                best_t = t
                for j in range(k):
                    lam_out[b, j] = t
                for c in range(d):
                    lam_out[b, combos[si, c]] += prim[c + 1]
            z = dual[d]
            ynorm = 0.0
            for i in range(d):
                ynorm += dual[i] * dual[i]
            scale = 1.0 + abs(z) + np.sqrt(ynorm) * wmax
            if z < best_z:
                ok = True
                for j in range(k):
                    s = 0.0
                    for i in range(d):
                        s -= W[b, i, j] * dual[i]
                    if s > z + feas * scale:
                        ok = False
                        break
                if ok:
                    best_z = z
                    for i in range(d):
                        y_out[b, i] = -dual[i]
                    has_y[b] = True
        t_out[b] = best_t
        if best_t == -np.inf:
            # No equilibrium with unit weight: W' y = -1 is consistent; solve the normal equations.
            G = np.zeros((d, d))
            g = np.zeros(d)
            for i in range(d):
                for j in range(d):
                    s = 0.0
                    for c in range(k):
                        s += W[b, i, c] * W[b, j, c]
                    G[i, j] = s
                g[i] = -w1[i]
            yy, det = solve_small(G, g)
            has_y[b] = det != 0.0
            if has_y[b]:
                for i in range(d):
                    y_out[b, i] = yy[i]
    return t_out, lam_out, y_out, has_y


@njit(cache=True)
def _lp_planar_one(Wb, combos, feas, dual_below, C, D, buf, lam, y):
    """:func:`lp_planar` for one generator matrix ``Wb`` (3, k); fills ``lam`` and ``y`` and
    returns ``(t, has_y)``. ``C``, ``D``, ``buf`` are work arrays (k, k, 3), (k, k) and
    (k + 2 nS,). The dual bases are scanned only when ``t < dual_below``."""
    k = Wb.shape[1]
    nS = combos.shape[0]
    w10, w11, w12, wmax = 0.0, 0.0, 0.0, 0.0
    norms = buf[:k]
    dens = buf[k:k + nS]
    ts = buf[k + nS:k + 2 * nS]
    for j in range(k):
        w10 += Wb[0, j]
        w11 += Wb[1, j]
        w12 += Wb[2, j]
        wmax = max(wmax, abs(Wb[0, j]), abs(Wb[1, j]), abs(Wb[2, j]))
        norms[j] = 1.0 + Wb[0, j] ** 2 + Wb[1, j] ** 2 + Wb[2, j] ** 2
    for a in range(k):
        for c in range(a + 1, k):
            x0 = Wb[1, a] * Wb[2, c] - Wb[2, a] * Wb[1, c]
            x1 = Wb[2, a] * Wb[0, c] - Wb[0, a] * Wb[2, c]
            x2 = Wb[0, a] * Wb[1, c] - Wb[1, a] * Wb[0, c]
            C[a, c, 0], C[a, c, 1], C[a, c, 2] = x0, x1, x2
            C[c, a, 0], C[c, a, 1], C[c, a, 2] = -x0, -x1, -x2
            D[a, c] = w10 * x0 + w11 * x1 + w12 * x2
            D[c, a] = -D[a, c]
    n0 = k * k + w10 ** 2 + w11 ** 2 + w12 ** 2
    best_t = -np.inf
    for j in range(k):
        lam[j] = np.nan
    for si in range(nS):
        i, j, l = combos[si, 0], combos[si, 1], combos[si, 2]
        # basis (i, j, l): Cramer's rule, singular relative to the Hadamard bound of its 4x4 matrix
        det = Wb[0, i] * C[j, l, 0] + Wb[1, i] * C[j, l, 1] + Wb[2, i] * C[j, l, 2]
        den = k * det - (D[j, l] - D[i, l] + D[i, j])
        if abs(den) <= 1e-13 * np.sqrt(norms[i] * norms[j] * norms[l] * n0):
            dens[si] = 0.0
            continue
        t = det / den
        dens[si], ts[si] = den, t
        s0 = -D[j, l] / den
        s1 = D[i, l] / den
        s2 = -D[i, j] / den
        lim = -feas * (1.0 + abs(t))
        if s0 >= lim and s1 >= lim and s2 >= lim and t > best_t:
            best_t = t
            for c in range(k):
                lam[c] = t
            lam[i] += s0
            lam[j] += s1
            lam[l] += s2
    has_y = False
    y[0], y[1], y[2] = 0.0, 0.0, 0.0
    if best_t >= dual_below:
        return best_t, has_y
    best_z = np.inf
    for si in range(nS):
        den, t = dens[si], ts[si]
        if den == 0.0 or not t < best_z:  # z = t for the matching dual basis
            continue
        i, j, l = combos[si, 0], combos[si, 1], combos[si, 2]
        y0 = (C[j, l, 0] + C[l, i, 0] + C[i, j, 0]) / den
        y1 = (C[j, l, 1] + C[l, i, 1] + C[i, j, 1]) / den
        y2 = (C[j, l, 2] + C[l, i, 2] + C[i, j, 2]) / den
        scale = 1.0 + abs(t) + np.sqrt(y0 * y0 + y1 * y1 + y2 * y2) * wmax
        ok = True
        for c in range(k):
            if Wb[0, c] * y0 + Wb[1, c] * y1 + Wb[2, c] * y2 > t + feas * scale:
                ok = False
                break
        if ok:
            best_z = t
            y[0], y[1], y[2] = y0, y1, y2
            has_y = True
    if best_t == -np.inf:
        # No equilibrium with unit weight: W' y = -1 is consistent; solve the normal equations
        # G y = -w1 (G = W W') by Cramer's rule.
        g00 = g01 = g02 = g11 = g12 = g22 = 0.0
        for c in range(k):
            a0, a1, a2 = Wb[0, c], Wb[1, c], Wb[2, c]
            g00 += a0 * a0
            g01 += a0 * a1
            g02 += a0 * a2
            g11 += a1 * a1
            g12 += a1 * a2
            g22 += a2 * a2
        c00 = g11 * g22 - g12 * g12
        c01 = g02 * g12 - g01 * g22
        c02 = g01 * g12 - g11 * g02
        det = g00 * c00 + g01 * c01 + g02 * c02
        has_y = det != 0.0
        if has_y:
            c11 = g00 * g22 - g02 * g02
            c12 = g01 * g02 - g00 * g12
            c22 = g00 * g11 - g01 * g01
            y[0] = -(c00 * w10 + c01 * w11 + c02 * w12) / det
            y[1] = -(c01 * w10 + c11 * w11 + c12 * w12) / det
            y[2] = -(c02 * w10 + c12 * w11 + c22 * w12) / det
    return best_t, has_y


@njit(cache=True)
def lp_planar(W, combos, feas, dual_below=np.inf):
    """:func:`lp_enumerate` for ``d = 3`` (planar wrenches) in closed form.

    For a basis ``S = (i, j, l)`` with ``det = w_i . (w_j x w_l)`` and ``D_ab = w1 . (w_a x w_b)``
    (``w1`` the sum of the generators), Cramer's rule gives the basic solution
    ``t = det / (k det - g)`` with ``g = D_jl - D_il + D_ij``, weights above ``t`` equal to
    ``s = -(D_jl, -D_il, D_ij) / (k det - g)``, and the dual ``y = (c_jl + c_li + c_ij) /
    (k det - g)`` with ``c_ab = w_a x w_b`` and ``z = t``. Cross products are computed once per
    pair, so a basis costs a few dozen flops. The dual bases (needed only for a verdict against
    closure) are scanned only where ``t* < dual_below``.
    """
    B, d, k = W.shape
    t_out = np.full(B, -np.inf)
    lam_out = np.full((B, k), np.nan)
    y_out = np.zeros((B, 3))
    has_y = np.zeros(B, dtype=np.bool_)
    C = np.empty((k, k, 3))
    D = np.empty((k, k))
    buf = np.empty(k + 2 * combos.shape[0])
    for b in range(B):
        t_out[b], has_y[b] = _lp_planar_one(W[b], combos, feas, dual_below, C, D, buf, lam_out[b],
                                            y_out[b])
    return t_out, lam_out, y_out, has_y


@njit(cache=True)
def _pivot_basis(C, R, chosen, used):
    """:func:`pivot_basis` into ``chosen`` with work arrays ``R`` (d, k) and ``used`` (k,)."""
    d, k = C.shape
    for i in range(d):
        for j in range(k):
            R[i, j] = C[i, j]
    for j in range(k):
        used[j] = False
    for step in range(d):
        best, arg = -1.0, 0
        for j in range(k):
            if used[j]:
                continue
            acc = 0.0
            for i in range(d):
                acc += R[i, j] * R[i, j]
            if acc > best:
                best, arg = acc, j
        chosen[step] = arg
        used[arg] = True
        nrm = np.sqrt(best)
        if nrm == 0.0:
            continue
        for j in range(k):
            if not used[j]:
                acc = 0.0
                for i in range(d):
                    acc += R[i, arg] * R[i, j]
                acc /= nrm * nrm
                for i in range(d):
                    R[i, j] -= acc * R[i, arg]


@njit(cache=True)
def pivot_basis(C):
    """Indices of ``d`` columns of ``C`` (d, k) chosen greedily as in QR with column pivoting:
    at each step the column with the largest norm orthogonal to those already chosen (first
    such index on ties). A well-conditioned basis for the exact correction of a certificate."""
    d, k = C.shape
    chosen = np.empty(d, dtype=np.int64)
    _pivot_basis(C, np.empty((d, k)), chosen, np.empty(k, dtype=np.bool_))
    return chosen


@njit(cache=True)
def pivot_bases(Cs):
    """:func:`pivot_basis` for a batch of matrices (B, d, k)."""
    B, d, _ = Cs.shape
    out = np.empty((B, d), dtype=np.int64)
    for b in range(B):
        out[b] = pivot_basis(Cs[b])
    return out


_U = 2.0**-53


@njit(cache=True)
def _gamma(n):
    return n * _U / (1.0 - n * _U)


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
def _planar_epsilon_one(Wb, owner, m, linf):
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
        eps[b], arg[b] = _planar_epsilon_one(W[b], owner, m, linf)
    return eps, arg


# --- planar batch: one compiled pass per grasp ---------------------------------------------


@njit(cache=True)
def _planar_generators(P, N, mu, c, L, owner, sgn, W, E):
    """Generator wrenches ``W`` (3, k) of one planar grasp, with the arithmetic of
    :func:`qualgrasp.certify.wrench.generator_columns` (same operations, same order, so the same floats),
    and bounds ``E`` on their distance to the exact values on the same data:
    forces exact for a frictionless generator and within ``gamma_2 (|n_x| + mu |n_y|)`` (resp.
    ``y``) for a friction edge ``n +- mu t``; torque within ``gamma_10 (|dx| a_y + |dy| a_x) / L``
    with ``a`` those force magnitudes (``gamma_n = n u / (1 - n u)``, Higham)."""
    k = owner.shape[0]
    for j in range(k):
        i = owner[j]
        nx, ny = N[i, 0], N[i, 1]
        if sgn[j] != 0:
            sm = sgn[j] * mu[i]
            fx = nx + sm * (-ny)
            fy = ny + sm * nx
            ax = abs(nx) + mu[i] * abs(ny)
            ay = abs(ny) + mu[i] * abs(nx)
            E[0, j] = _gamma(2) * ax
            E[1, j] = _gamma(2) * ay
        else:
            fx, fy = nx, ny
            ax, ay = abs(nx), abs(ny)
            E[0, j] = 0.0
            E[1, j] = 0.0
        rx = P[i, 0] - c[0]
        ry = P[i, 1] - c[1]
        W[0, j] = fx
        W[1, j] = fy
        W[2, j] = (rx * fy - ry * fx) / L
        E[2, j] = _gamma(10) * (abs(rx) * ay + abs(ry) * ax) / L


@njit(cache=True)
def _thin(Wb):
    """Conservative test that ``Wb`` (3, k) may be numerically rank deficient:
    ``det(G) / trace(G)^3 < 1e-12`` for ``G = W W'``, true whenever ``sigma_min / sigma_max
    < 1e-6`` (``lambda_min >= det / trace^2``, ``lambda_max <= trace``)."""
    k = Wb.shape[1]
    g00 = g01 = g02 = g11 = g12 = g22 = 0.0
    for c in range(k):
        a0, a1, a2 = Wb[0, c], Wb[1, c], Wb[2, c]
        g00 += a0 * a0
        g01 += a0 * a1
        g02 += a0 * a2
        g11 += a1 * a1
        g12 += a1 * a2
        g22 += a2 * a2
    tr = g00 + g11 + g22
    det = g00 * (g11 * g22 - g12 * g12) - g01 * (g01 * g22 - g12 * g02) + g02 * (g01 * g12 - g11 * g02)
    return not (tr > 0.0 and det >= 1e-12 * tr * tr * tr)


@njit(cache=True)
def _cross_unit(a, b):
    y0 = a[1] * b[2] - a[2] * b[1]
    y1 = a[2] * b[0] - a[0] * b[2]
    y2 = a[0] * b[1] - a[1] * b[0]
    nrm = np.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
    return np.array([y0, y1, y2]) / nrm if nrm > 0.0 else np.zeros(3)


@njit(cache=True)
def null_direction(C):
    """A unit vector orthogonal to the columns of ``C`` (3, k <= 2): their cross product when
    they span a plane (to within 1e-12 relative), else the cross product of the longer column
    with the coordinate axis least aligned with it."""
    a = C[:, 0]
    if C.shape[1] == 2:
        b = C[:, 1]
        y = _cross_unit(a, b)
        na = np.sqrt(a[0] ** 2 + a[1] ** 2 + a[2] ** 2)
        nb = np.sqrt(b[0] ** 2 + b[1] ** 2 + b[2] ** 2)
        c = a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]
        if np.sqrt(c[0] ** 2 + c[1] ** 2 + c[2] ** 2) > 1e-12 * na * nb:
            return y
        if nb > na:
            a = b
    axis = np.zeros(3)
    axis[np.argmin(np.abs(a))] = 1.0
    return _cross_unit(a, axis)


@njit(cache=True)
def _classify(Wb, Eb, combos, feas, margin, residual_tol, C, D, buf, R, used, lam, y, basis,
              rays, first, zeros2, zeros1, no_tight):
    """Verdict of one planar generator matrix, settled only where the per-grasp rules of
    :func:`qualgrasp.certify.closure.decide` give it without exact arithmetic and the certificate is proved
    by the float re-check: 1 closure (``lam``, ``basis``), 2 strict Farkas (``y``), 3 null-space
    Farkas (``y``, fewer than 3 generators), 0 not settled. Returns ``(code, t)``. The block
    layout of the re-check (every generator a ray: ``rays`` 0, ``first`` 0..k-1, ``zeros2``
    (k, 2), ``zeros1`` (k,), ``no_tight`` (k,) False) is passed in, not allocated per grasp."""
    k = Wb.shape[1]
    if k < 3:
        yy = null_direction(Wb)
        y[0], y[1], y[2] = yy[0], yy[1], yy[2]
        return (3 if verify_null_general(Wb, Eb, y) else 0), -np.inf
    t, has_y = _lp_planar_one(Wb, combos, feas, DUAL_BELOW, C, D, buf, lam, y)
    if _thin(Wb):
        return 0, t
    if t >= margin:
        _pivot_basis(Wb, R[:, :Wb.shape[1]], basis, used)
        ok = verify_interior_general(Wb, Eb, rays[:k], first[:k], zeros2[:k], zeros1[:k],
                                     zeros1[:k], lam, basis, residual_tol)
        return (1 if ok else 0), t
    if not has_y:
        return 0, t
    norm = np.sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2])
    if not (norm > 0.0 and np.isfinite(norm)):
        return 0, t
    y[0], y[1], y[2] = y[0] / norm, y[1] / norm, y[2] / norm
    scale = 0.0
    for j in range(k):
        for i in range(3):
            scale = max(scale, abs(Wb[i, j]))
    for j in range(k):
        a = Wb[0, j] * y[0] + Wb[1, j] * y[1] + Wb[2, j] * y[2]
        if abs(a) <= 1e-7 * scale or not a < -1e-9 * scale:
            return 0, t  # tight contacts or no strict separation: per-grasp path
    ok = verify_farkas_general(Wb, Eb, rays[:k], first[:k], zeros2[:k], zeros1[:k], zeros1[:k], y,
                               no_tight[:k], 0.0)
    return (2 if ok else 0), t


#: The LP's dual bases are scanned only below this optimum (a verdict against closure, or a
#: near-degenerate one, needs the dual direction; a clear closure does not).
DUAL_BELOW = 1e-3


@njit(cache=True)
def planar_batch(P, N, mu, c, L, owner, sgn, combos, owner_f, combos_f, form_same, margin, feas,
                 residual_tol, quality):
    """Certify a batch of planar grasps sharing one contact pattern, in one compiled pass.

    ``P``, ``N`` (B, m, 2), ``mu`` (B, m), ``c`` (B, 2), ``L`` (B,); ``owner``/``sgn`` the
    force generators' contacts and edge signs, ``owner_f`` the form (frictionless) generators;
    ``combos``/``combos_f`` their 3-subsets. For force and form closure: verdict codes (see
    :func:`_classify`), margins, weights, bases and directions; with ``quality`` the exact L1
    and L-infinity epsilon of the force-closure grasps.
    """
    B, m = mu.shape
    k, kf = owner.shape[0], owner_f.shape[0]
    code = np.zeros(B, dtype=np.int64)
    code_f = np.zeros(B, dtype=np.int64)
    t = np.zeros(B)
    t_f = np.zeros(B)
    lam = np.zeros((B, k))
    lam_f = np.zeros((B, kf))
    basis = np.zeros((B, 3), dtype=np.int64)
    basis_f = np.zeros((B, 3), dtype=np.int64)
    y = np.zeros((B, 3))
    y_f = np.zeros((B, 3))
    eps = np.zeros((B, 2))
    W = np.empty((3, k))
    E = np.empty((3, k))
    Wf = np.empty((3, kf))
    Ef = np.empty((3, kf))
    kk = max(k, kf)
    C = np.empty((kk, kk, 3))
    D = np.empty((kk, kk))
    buf = np.empty(kk + 2 * max(combos.shape[0], combos_f.shape[0]))
    R = np.empty((3, kk))
    used = np.empty(kk, dtype=np.bool_)
    rays = np.zeros(kk, dtype=np.int64)  # also the edge signs of frictionless generators
    first = np.arange(kk)
    zeros2 = np.zeros((kk, 2))
    zeros1 = np.zeros(kk)
    no_tight = np.zeros(kk, dtype=np.bool_)
    for b in range(B):
        _planar_generators(P[b], N[b], mu[b], c[b], L[b], owner, sgn, W, E)
        code[b], t[b] = _classify(W, E, combos, feas, margin, residual_tol, C, D, buf, R, used,
                                  lam[b], y[b], basis[b], rays, first, zeros2, zeros1, no_tight)
        if form_same:
            code_f[b], t_f[b] = code[b], t[b]
            lam_f[b, :] = lam[b, :kf]
            basis_f[b, :] = basis[b, :]
            y_f[b, :] = y[b, :]
        else:
            _planar_generators(P[b], N[b], mu[b], c[b], L[b], owner_f, rays[:kf], Wf, Ef)
            code_f[b], t_f[b] = _classify(Wf, Ef, combos_f, feas, margin, residual_tol, C, D, buf,
                                          R, used, lam_f[b], y_f[b], basis_f[b], rays, first,
                                          zeros2, zeros1, no_tight)
        if quality and code[b] == 1:
            eps[b, 0] = _planar_epsilon_one(W, owner, m, False)[0]
            eps[b, 1] = _planar_epsilon_one(W, owner, m, True)[0]
    return code, t, lam, basis, y, code_f, t_f, lam_f, basis_f, y_f, eps


# --- spatial closure SOCP through its dual: a barrier method in the wrench directions --------


@njit(cache=True)
def _cholesky_solve(H, rhs, out):
    """Solve ``H out = rhs`` for a symmetric positive definite ``H`` (d, d) in place of a copy;
    return False when ``H`` is not numerically positive definite."""
    d = H.shape[0]
    Lw = np.zeros((d, d))
    for i in range(d):
        for j in range(i + 1):
            acc = H[i, j]
            for q in range(j):
                acc -= Lw[i, q] * Lw[j, q]
            if i == j:
                if acc <= 0.0:
                    return False
                Lw[i, i] = np.sqrt(acc)
            else:
                Lw[i, j] = acc / Lw[j, j]
    for i in range(d):
        acc = rhs[i]
        for q in range(i):
            acc -= Lw[i, q] * out[q]
        out[i] = acc / Lw[i, i]
    for i in range(d - 1, -1, -1):
        acc = out[i]
        for q in range(i + 1, d):
            acc -= Lw[q, i] * out[q]
        out[i] = acc / Lw[i, i]
    return True


@njit(cache=True)
def _barrier_terms(y, Pm, T, rk, kappa, K, q, u, psi, Ty):
    """Affine parts ``u_b = z(y) - p_b . y``, ``T_b y`` and ``psi_b`` (``u^2 - kappa^2 |T y|^2``
    for cones, ``u`` for rays) at ``y``; False when ``y`` is not strictly feasible."""
    nb, rmax, d = T.shape
    z = 1.0
    for i in range(d):
        z += q[i] * y[i]
    z /= K
    for b in range(nb):
        s = 0.0
        for i in range(d):
            s += Pm[b, i] * y[i]
        u[b] = z - s
        if rk[b] == 0:
            psi[b] = u[b]
            if not u[b] > 0.0:
                return False
            continue
        n2 = 0.0
        for r in range(rk[b]):
            acc = 0.0
            for i in range(d):
                acc += T[b, r, i] * y[i]
            Ty[b, r] = acc
            n2 += acc * acc
        psi[b] = u[b] * u[b] - kappa[b] * kappa[b] * n2
        if not (u[b] > 0.0 and psi[b] > 0.0):
            return False
    return True


@njit(cache=True)
def socp_dual_barrier(Pm, T, rk, kappa, exit_below, gap_tol, max_newton):
    """The spatial closure SOCP (see :mod:`qualgrasp.certify.problem`) through its dual, by a barrier method.

    Per contact block ``b`` the support of its unit-normal-force wrenches along ``y`` is
    ``c_b(y) = p_b . y + kappa_b norm(T_b y)`` (``p_b`` the normal-force column, ``T_b`` the
    tangential ones, ``kappa_b`` the friction coefficient; rays have no ``T`` and
    ``kappa = 1``). Weak duality gives ``t* = min over y of z(y)`` subject to ``c_b(y) <= z(y)``,
    with ``z(y) = (1 + q . y) / K``, ``K = sum 1/kappa_b``, ``q = sum p_b / kappa_b``: an SOCP
    in the ``d`` wrench coordinates only, strictly feasible at ``y = 0``. Newton's method on
    ``tau z - sum log(u_b^2 - kappa_b^2 |T_b y|^2) - sum_rays log(u_b)`` follows the central path
    (``u_b = z - p_b . y``); at each centre the gradient condition yields primal forces
    ``x_n,b = alpha_b - (sum(alpha) - 1) / (K kappa_b)``, ``x_t,b = beta_b`` with
    ``alpha = 2 u / (tau psi)``, ``beta = 2 kappa^2 T y / (tau psi)`` (``1 / (tau u)`` for rays),
    strictly inside every cone and with total normal force 1; they are then projected exactly
    onto equilibrium in the least-squares sense. It stops when ``z(y) <= exit_below`` (a
    strictly separating ``y``: not in closure), or when the gap ``z - t`` is below ``gap_tol``.

    Returns ``(status, t, z, y, x_n, x_t)``: status 0 converged (``t`` the primal margin of
    the forces, ``z`` the dual bound), 1 separated early (``t = z``), 2 failed.
    """
    nb, rmax, d = T.shape
    K = 0.0
    q = np.zeros(d)
    for b in range(nb):
        K += 1.0 / kappa[b]
        for i in range(d):
            q[i] += Pm[b, i] / kappa[b]
    g = np.empty((nb, d))  # gradient of u_b
    for b in range(nb):
        for i in range(d):
            g[b, i] = q[i] / K - Pm[b, i]
    nu = 0.0
    for b in range(nb):
        nu += 2.0 if rk[b] > 0 else 1.0
    y = np.zeros(d)
    u = np.empty(nb)
    psi = np.empty(nb)
    Ty = np.zeros((nb, max(rmax, 1)))
    y2 = np.empty(d)
    u2 = np.empty(nb)
    psi2 = np.empty(nb)
    Ty2 = np.zeros((nb, max(rmax, 1)))
    grad = np.empty(d)
    H = np.empty((d, d))
    step = np.empty(d)
    xn = np.zeros(nb)
    xt = np.zeros((nb, max(rmax, 1)))
    tau = nu
    newton = 0
    _barrier_terms(y, Pm, T, rk, kappa, K, q, u, psi, Ty)
    while newton < max_newton:
        # centring at tau
        while newton < max_newton:
            newton += 1
            for i in range(d):
                grad[i] = tau * q[i] / K
                for j in range(d):
                    H[i, j] = 0.0
            for b in range(nb):
                if rk[b] == 0:
                    for i in range(d):
                        grad[i] -= g[b, i] / u[b]
                        for j in range(d):
                            H[i, j] += g[b, i] * g[b, j] / (u[b] * u[b])
                    continue
                kk = kappa[b] * kappa[b]
                dpsi = np.zeros(d)
                for i in range(d):
                    acc = 2.0 * u[b] * g[b, i]
                    for r in range(rk[b]):
                        acc -= 2.0 * kk * T[b, r, i] * Ty[b, r]
                    dpsi[i] = acc
                for i in range(d):
                    grad[i] -= dpsi[i] / psi[b]
                    for j in range(d):
                        h2 = 2.0 * g[b, i] * g[b, j]
                        for r in range(rk[b]):
                            h2 -= 2.0 * kk * T[b, r, i] * T[b, r, j]
                        H[i, j] += -h2 / psi[b] + dpsi[i] * dpsi[j] / (psi[b] * psi[b])
            for i in range(d):
                H[i, i] += 1e-14 * (1.0 + H[i, i])
                grad[i] = -grad[i]
            if not _cholesky_solve(H, grad, step):
                return 2, 0.0, 0.0, y, xn, xt
            dec = 0.0
            for i in range(d):
                dec += grad[i] * step[i]  # Newton decrement squared (grad holds -gradient)
            if dec < 1e-14:
                break
            # damped Newton far from the centre (backtracking on the barrier function, strictly
            # feasible), full steps close to it, where the decrease is below float resolution
            phi0 = _phi(y, tau, q, K, u, psi, rk)
            s = 1.0
            while True:
                for i in range(d):
                    y2[i] = y[i] + s * step[i]
                if _barrier_terms(y2, Pm, T, rk, kappa, K, q, u2, psi2, Ty2):
                    if dec < 0.1 or _phi(y2, tau, q, K, u2, psi2, rk) <= phi0 - 0.25 * s * dec:
                        break
                s *= 0.5
                if s < 1e-12:
                    break
            if s < 1e-12:
                break
            for i in range(d):
                y[i] = y2[i]
            for b in range(nb):
                u[b], psi[b] = u2[b], psi2[b]
                for r in range(rk[b]):
                    Ty[b, r] = Ty2[b, r]
            if dec < 1e-8:  # centred enough: the gap is governed by nu / tau
                break
        z = 1.0
        for i in range(d):
            z += q[i] * y[i]
        z /= K
        if z <= exit_below:
            return 1, z, z, y, xn, xt
        # primal forces from the centring condition
        asum = 0.0
        for b in range(nb):
            if rk[b] == 0:
                xn[b] = 1.0 / (tau * u[b])
            else:
                xn[b] = 2.0 * u[b] / (tau * psi[b])
                for r in range(rk[b]):
                    xt[b, r] = 2.0 * kappa[b] * kappa[b] * Ty[b, r] / (tau * psi[b])
            asum += xn[b]
        for b in range(nb):
            xn[b] -= (asum - 1.0) / (K * kappa[b])
        if nu / tau < gap_tol:
            break
        tau *= 20.0
    if newton >= max_newton:
        return 2, 0.0, 0.0, y, xn, xt
    z = 1.0
    for i in range(d):
        z += q[i] * y[i]
    z /= K
    t = _equilibrate(Pm, T, rk, kappa, xn, xt)
    return 0, t, z, y, xn, xt


@njit(cache=True)
def _equilibrate(Pm, T, rk, kappa, xn, xt):
    """Project the forces onto equilibrium (least-squares correction), rescale them to total
    normal force 1 and return their margin ``min_b slack_b`` (``kappa x_n - |x_t|``; ``x_n`` for
    rays)."""
    nb, _, d = T.shape
    r = np.zeros(d)
    G = np.zeros((d, d))
    for b in range(nb):
        for i in range(d):
            r[i] += Pm[b, i] * xn[b]
            for j in range(d):
                G[i, j] += Pm[b, i] * Pm[b, j]
        for k in range(rk[b]):
            for i in range(d):
                r[i] += T[b, k, i] * xt[b, k]
                for j in range(d):
                    G[i, j] += T[b, k, i] * T[b, k, j]
    lam = np.empty(d)
    if _cholesky_solve(G, r, lam):
        for b in range(nb):
            acc = 0.0
            for i in range(d):
                acc += Pm[b, i] * lam[i]
            xn[b] -= acc
            for k in range(rk[b]):
                acc = 0.0
                for i in range(d):
                    acc += T[b, k, i] * lam[i]
                xt[b, k] -= acc
    total = 0.0
    for b in range(nb):
        total += xn[b]
    t = np.inf
    for b in range(nb):
        xn[b] /= total
        n2 = 0.0
        for k in range(rk[b]):
            xt[b, k] /= total
            n2 += xt[b, k] * xt[b, k]
        slack = xn[b] if rk[b] == 0 else kappa[b] * xn[b] - np.sqrt(n2)
        t = min(t, slack)
    return t


@njit(cache=True)
def _phi(y, tau, q, K, u, psi, rk):
    z = 1.0
    for i in range(y.shape[0]):
        z += q[i] * y[i]
    out = tau * z / K
    for b in range(u.shape[0]):
        out -= np.log(psi[b])
    return out


@njit(cache=True)
def world_values(to_values, x):
    """Certificate values ``to_values @ x`` for a batch (B, ncert, nvar) x (B, nvar), summed in
    variable order: the per-grasp and columnar paths share it, so their values are identical."""
    B, n, k = to_values.shape
    out = np.empty((B, n))
    for b in range(B):
        for i in range(n):
            acc = 0.0
            for j in range(k):
                acc += to_values[b, i, j] * x[b, j]
            out[b, i] = acc
    return out


# --- rigorous float re-check for any dimension (spatial certificates) ------------------------


@njit(cache=True)
def _residual_bound(C, E, x):
    """Upper bound on ``max |C_exact x|`` (exact columns within ``E`` of ``C``) and scales."""
    d, k = C.shape
    rmax, xsum, cmax = 0.0, 0.0, 0.0
    for j in range(k):
        xsum += abs(x[j])
    for i in range(d):
        acc, err = 0.0, 0.0
        for j in range(k):
            acc += C[i, j] * x[j]
            err += (E[i, j] + _gamma(k + 2) * abs(C[i, j])) * abs(x[j])
            cmax = max(cmax, abs(C[i, j]))
        rmax = max(rmax, abs(acc) + err)
    return rmax, xsum, cmax


@njit(cache=True)
def _correction_bound(C, E, basis, rmax):
    """Bound on ``max |C_B_exact^-1 r|`` for any exact residual ``|r| <= rmax`` (and a proof
    that ``C_B`` is invertible), from :func:`_inverse_norm_bound` on the basis columns and their
    error bounds. Returns ``inf`` when not proved."""
    d = C.shape[0]
    M = np.empty((d, d))
    EM = np.empty((d, d))
    for i in range(d):
        for c in range(d):
            M[i, c] = C[i, basis[c]]
            EM[i, c] = E[i, basis[c]]
    inv = _inverse_norm_bound(M, EM)
    if not inv < np.inf:
        return np.inf
    return inv * rmax * (1.0 + 4 * d * _U)


@njit(cache=True)
def verify_interior_general(C, E, kind, cols, n, mu, torsion, x, basis, residual_tol):
    """Rigorous float proof that values ``x`` over certificate columns ``C`` (d, k) certify
    closure: exact residual bounded, basis invertible, exact correction bounded by ``delta``, and
    every contact's corrected force strictly inside its cone with room to spare. Blocks are given
    by ``kind`` (0 ray, 1 point, 2 soft), ``cols`` (their first column; a point block has
    ``dim`` columns, soft ``dim + 1``), ``n`` (stored normals), ``mu``, ``torsion``. A cone's
    slack ``mu f_n - |f_t|`` (with ``|(f_t, m |n| / g)|`` for soft) moves by at most
    ``(1 + mu) |df| (+ |n| |dm| / g)`` under a correction, which is what must fit."""
    rmax, xsum, cmax = _residual_bound(C, E, x)
    if rmax > residual_tol * max(1.0, xsum) * max(1.0, cmax):
        return False
    delta = _correction_bound(C, E, basis, rmax)
    if not np.isfinite(delta):
        return False
    d = C.shape[0]
    inb = np.zeros(C.shape[1], dtype=np.bool_)
    for c in range(d):
        inb[basis[c]] = True
    dim = n.shape[1]
    for b in range(kind.shape[0]):
        j0 = cols[b]
        if kind[b] == 0:
            if not x[j0] > (delta if inb[j0] else 0.0):
                return False
            continue
        nn, fn, ff, df2 = 0.0, 0.0, 0.0, 0.0
        for i in range(dim):
            nn += n[b, i] * n[b, i]
            fn += x[j0 + i] * n[b, i]
            ff += x[j0 + i] * x[j0 + i]
            if inb[j0 + i]:
                df2 += delta * delta
        rn = np.sqrt(nn)
        fn /= rn
        t2 = max(ff - fn * fn, 0.0)
        dm = 0.0
        if kind[b] == 2:
            t2 += (x[j0 + dim] * rn / torsion[b]) ** 2
            if inb[j0 + dim]:
                dm = delta * rn / torsion[b]
        slack = mu[b] * fn - np.sqrt(t2)
        err = 1e-13 * (1.0 + mu[b]) * (np.sqrt(ff) + abs(x[j0 + dim]) * rn / torsion[b] if kind[b] == 2 else np.sqrt(ff))
        if not slack - err - (1.0 + mu[b]) * np.sqrt(df2) - dm > 0.0:
            return False
    return True


@njit(cache=True)
def verify_farkas_general(C, E, kind, cols, n, mu, torsion, y, tight, shift):
    """Rigorous float proof that ``y``, moved by at most ``shift`` (the exact projection off the
    ``tight`` blocks, see :func:`projection_bound`), strictly separates every other contact's
    cone: for each such block the polar value ``a_n + mu |a_t|`` of ``a = C_b' y`` plus its float
    error, the column errors and the shift (``a`` moves by at most ``|C_b| shift``; the polar
    value is Lipschitz ``1 + mu`` in ``a``) stays negative."""
    d, k = C.shape
    dim = n.shape[1]
    a = np.empty(dim + 1)
    for b in range(kind.shape[0]):
        if tight[b]:
            continue
        j0 = cols[b]
        width = 1 if kind[b] == 0 else (dim if kind[b] == 1 else dim + 1)
        ea2 = 0.0
        for c in range(width):
            acc, err, cn = 0.0, 0.0, 0.0
            for i in range(d):
                acc += C[i, j0 + c] * y[i]
                err += (E[i, j0 + c] + _gamma(d + 2) * abs(C[i, j0 + c])) * abs(y[i])
                cn += (abs(C[i, j0 + c]) + E[i, j0 + c]) ** 2
            a[c] = acc
            err += np.sqrt(cn) * shift
            ea2 += err * err
        if kind[b] == 0:
            value, scale = a[0], abs(a[0])
        else:
            nn, an, aa = 0.0, 0.0, 0.0
            for i in range(dim):
                nn += n[b, i] * n[b, i]
                an += a[i] * n[b, i]
                aa += a[i] * a[i]
            rn = np.sqrt(nn)
            an /= rn
            t2 = max(aa - an * an, 0.0)
            if kind[b] == 2:
                t2 += (a[dim] * torsion[b] / rn) ** 2
            value = an + mu[b] * np.sqrt(t2)
            scale = np.sqrt(aa) + (abs(a[dim]) * torsion[b] if kind[b] == 2 else 0.0)
        bound = 1e-13 * (1.0 + mu[b]) * scale + (1.0 + mu[b]) * np.sqrt(ea2)
        if not value + bound < 0.0:
            return False
    return True


@njit(cache=True)
def _inverse_norm_bound(M, EM):
    """Upper bound on ``norm_inf(M_exact^-1)`` for a square ``M_exact`` within ``EM`` of ``M``,
    from an approximate inverse ``R``: ``norm(I - R M_exact) <= alpha < 1`` gives
    ``norm(M_exact^-1) <= norm(R) / (1 - alpha)``; ``inf`` when not proved."""
    k = M.shape[0]
    LU = M.copy()
    piv = np.empty(k, dtype=np.int64)
    if _lu(LU, piv) == 0.0:
        return np.inf
    R = np.empty((k, k))
    col = np.empty(k)
    for c in range(k):
        for i in range(k):
            col[i] = 1.0 if i == c else 0.0
        _lu_solve(LU, piv, col)
        for i in range(k):
            R[i, c] = col[i]
    alpha, rnorm = 0.0, 0.0
    for i in range(k):
        row_z, row_r = 0.0, 0.0
        for c in range(k):
            acc, err = 1.0 if i == c else 0.0, 0.0
            for q in range(k):
                acc -= R[i, q] * M[q, c]
                err += abs(R[i, q]) * (EM[q, c] + _gamma(k + 2) * abs(M[q, c]))
            row_z += abs(acc) + err
            row_r += abs(R[i, c])
        alpha = max(alpha, row_z)
        rnorm = max(rnorm, row_r)
    alpha *= 1.0 + 4 * k * _U
    if not alpha < 1.0:
        return np.inf
    return rnorm * (1.0 + 4 * k * _U) / (1.0 - alpha)


@njit(cache=True)
def projection_bound(C, E, y):
    """Upper bound on the norm of the exact projection of ``y`` onto the span of the exact
    columns (within ``E`` of ``C``, fewer columns than rows): ``|C' y| / sigma_min(C)``, with
    ``sigma_min(C)^2 = lambda_min(G) >= 1 / norm_inf(G^-1)`` for the Gram matrix ``G = C' C``
    (symmetric) bounded by :func:`_inverse_norm_bound`, every error accounted for; ``inf`` when
    not proved."""
    d, k = C.shape
    gnorm2 = 0.0
    for j in range(k):
        acc, err = 0.0, 0.0
        for i in range(d):
            acc += C[i, j] * y[i]
            err += (E[i, j] + _gamma(d + 2) * abs(C[i, j])) * abs(y[i])
        gnorm2 += (abs(acc) + err) ** 2
    gnorm = np.sqrt(gnorm2) * (1.0 + 4 * _U)
    G = np.empty((k, k))
    EG = np.empty((k, k))
    for a in range(k):
        for c in range(k):
            acc, err = 0.0, 0.0
            for i in range(d):
                acc += C[i, a] * C[i, c]
                err += (abs(C[i, a]) * E[i, c] + E[i, a] * abs(C[i, c]) + E[i, a] * E[i, c]
                        + _gamma(d + 2) * abs(C[i, a] * C[i, c]))
            G[a, c] = acc
            EG[a, c] = err
    inv = _inverse_norm_bound(G, EG)
    if not np.isfinite(inv):
        return np.inf
    return gnorm / (np.sqrt(1.0 / inv) * (1.0 - 4 * _U)) * (1.0 + 4 * _U)


@njit(cache=True)
def verify_null_general(C, E, y):
    """Rigorous float proof, for fewer columns than rows, that the exact projection of ``y``
    off the columns' span is within ``1e-6 |y|`` of ``y`` (so non-zero), as the exact checker
    requires (see :func:`projection_bound`)."""
    ny = 0.0
    for i in range(y.shape[0]):
        ny += y[i] * y[i]
    return projection_bound(C, E, y) <= 1e-6 * np.sqrt(ny) * (1.0 - 8 * _U)


@njit(cache=True)
def barrier_batch(Pm, T, rk, kappa, exit_below, gap_tol, max_newton):
    """:func:`socp_dual_barrier` over a batch (B, nb, ...): statuses, margins, directions, forces."""
    B, nb, rmax, d = T.shape
    status = np.empty(B, dtype=np.int64)
    t = np.empty(B)
    y = np.empty((B, d))
    xn = np.empty((B, nb))
    xt = np.empty((B, nb, max(rmax, 1)))
    for b in range(B):
        st, tb, _, yb, xnb, xtb = socp_dual_barrier(Pm[b], T[b], rk, kappa[b], exit_below, gap_tol,
                                                    max_newton)
        status[b], t[b] = st, tb
        y[b], xn[b], xt[b] = yb, xnb, xtb
    return status, t, y, xn, xt


@njit(cache=True)
def polar_values(C, kind, cols, n, mu, torsion, y):
    """Float polar value ``a_n + mu |a_t|`` (``a_n`` for rays) of each block for the functional
    ``a = C_b' y``: the largest ``y . w`` over the block's unit-normal-force wrenches (the same
    formula for every route: see :func:`qualgrasp.certify.certificates.polar_values`)."""
    d = C.shape[0]
    dim = n.shape[1]
    out = np.empty(kind.shape[0])
    a = np.empty(dim + 1)
    for b in range(kind.shape[0]):
        j0 = cols[b]
        width = 1 if kind[b] == 0 else (dim if kind[b] == 1 else dim + 1)
        for c in range(width):
            acc = 0.0
            for i in range(d):
                acc += C[i, j0 + c] * y[i]
            a[c] = acc
        if kind[b] == 0:
            out[b] = a[0]
            continue
        nn, an = 0.0, 0.0
        for i in range(dim):
            nn += n[b, i] * n[b, i]
        rn = np.sqrt(nn)
        for i in range(dim):
            an += a[i] * n[b, i] / rn
        t2 = 0.0
        for i in range(dim):
            ti = a[i] - an * n[b, i] / rn
            t2 += ti * ti
        if kind[b] == 2:
            t2 += (a[dim] * torsion[b]) ** 2
        out[b] = an + mu[b] * np.sqrt(t2)
    return out


@njit(cache=True)
def farkas_direction(C, kind, cols, n, mu, torsion, y, rel):
    """The rule of :func:`qualgrasp.certify.closure.farkas_certificate`, compiled: ``(ok, y, tight)``.

    ``y`` is normalised; if every block's polar value is below ``-1e-9 scale`` (``scale`` the
    largest ``abs(C)``) it is a strict certificate. Otherwise blocks whose functional
    ``C_b' y`` is at most ``rel scale`` in absolute value are tight, ``y`` is projected off the
    span of their columns (QR, columns with ``abs(R_ii) > 1e-12 scale``) and normalised again
    (refused if the projection leaves less than half of it), and every other block must be
    strictly separated."""
    d = C.shape[0]
    dim = n.shape[1]
    nb = kind.shape[0]
    tight = np.zeros(nb, dtype=np.bool_)
    out = np.zeros(d)
    ss = 0.0
    for i in range(d):
        ss += y[i] * y[i]
    norm = np.sqrt(ss)
    if not (np.isfinite(norm) and norm > 0.0):
        return False, out, tight
    for i in range(d):
        out[i] = y[i] / norm
    scale = 0.0
    for i in range(d):
        for j in range(C.shape[1]):
            scale = max(scale, abs(C[i, j]))
    pv = polar_values(C, kind, cols, n, mu, torsion, out)
    if pv.max() < -1e-9 * scale:
        return True, out, tight
    width = np.empty(nb, dtype=np.int64)
    ntc = 0
    for b in range(nb):
        width[b] = 1 if kind[b] == 0 else (dim if kind[b] == 1 else dim + 1)
        big = 0.0
        for c in range(width[b]):
            acc = 0.0
            for i in range(d):
                acc += C[i, cols[b] + c] * out[i]
            big = max(big, abs(acc))
        if big <= rel * scale:
            tight[b] = True
            ntc += width[b]
    if ntc > 0:
        T = np.empty((d, ntc))
        c0 = 0
        for b in range(nb):
            if tight[b]:
                for c in range(width[b]):
                    T[:, c0] = C[:, cols[b] + c]
                    c0 += 1
        Q, R = np.linalg.qr(T)
        proj = out.copy()
        for c in range(min(d, ntc)):
            if abs(R[c, c]) > 1e-12 * scale:
                dot = 0.0
                for i in range(d):
                    dot += Q[i, c] * out[i]
                for i in range(d):
                    proj[i] -= Q[i, c] * dot
        ss = 0.0
        for i in range(d):
            ss += proj[i] * proj[i]
        norm = np.sqrt(ss)
        if norm < 0.5:
            return False, out, tight
        for i in range(d):
            out[i] = proj[i] / norm
        pv = polar_values(C, kind, cols, n, mu, torsion, out)
    for b in range(nb):
        if not tight[b] and not pv[b] < -1e-9 * scale:
            return False, out, tight
    return True, out, tight


@njit(cache=True)
def squeeze_direction(C, cols):
    """The direction orthogonal to the columns ``cols`` of ``C`` (6, k) of two point contacts,
    and whether they span exactly 5 dimensions (smallest singular value at most ``1e-12``,
    next one above ``1e-6``, of the largest): see :mod:`qualgrasp.certify.solvers.squeeze`."""
    T = np.empty((C.shape[0], cols.shape[0]))
    for c in range(cols.shape[0]):
        T[:, c] = C[:, cols[c]]
    U, sv, _ = np.linalg.svd(T)
    ok = sv[-1] <= 1e-12 * sv[0] and sv[-2] > 1e-6 * sv[0]
    return ok, U[:, -1].copy()


@njit(cache=True)
def certify_rows(C, E, kind, first, N, mu, torsion, values, y, closure, farkas, scale,
                 residual_tol):
    """Per row of a batch (B, d, k): for ``closure`` rows choose the basis and prove the
    interior certificate ``values``; for ``farkas`` rows check the strict separation rule of
    :func:`qualgrasp.certify.closure.farkas_certificate` (every polar value below ``-1e-9 scale``) and prove
    it. Returns codes (1 closure, 2 strict Farkas, 0 not settled) and the bases."""
    B, d, k = C.shape
    code = np.zeros(B, dtype=np.int64)
    basis = np.zeros((B, d), dtype=np.int64)
    R = np.empty((d, k))
    used = np.empty(k, dtype=np.bool_)
    none = np.zeros(kind.shape[0], dtype=np.bool_)
    for b in range(B):
        if closure[b]:
            _pivot_basis(C[b], R, basis[b], used)
            if verify_interior_general(C[b], E[b], kind, first, N[b], mu[b], torsion[b], values[b],
                                       basis[b], residual_tol):
                code[b] = 1
        elif farkas[b]:
            pv = polar_values(C[b], kind, first, N[b], mu[b], torsion[b], y[b])
            strict = True
            for q in range(pv.shape[0]):
                if not pv[q] < -1e-9 * scale[b]:
                    strict = False
            if strict and verify_farkas_general(C[b], E[b], kind, first, N[b], mu[b], torsion[b],
                                                y[b], none, 0.0):
                code[b] = 2
    return code, basis


@njit(cache=True)
def null_rows(C, E, y):
    """:func:`verify_null_general` for every row of a batch: 3 where proved, else 0."""
    out = np.zeros(C.shape[0], dtype=np.int64)
    for b in range(C.shape[0]):
        if verify_null_general(C[b], E[b], y[b]):
            out[b] = 3
    return out

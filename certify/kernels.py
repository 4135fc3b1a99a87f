"""Compiled kernels (numba) for the hot paths: many small closure programmes at once.

* :func:`lp_enumerate`: the polyhedral min-weight LP by exact basis enumeration (the method of
  :mod:`certify.solvers.enumeration`), one compiled loop per grasp.
* :func:`socp_dual_barrier`: the spatial closure SOCP solved through its dual, a barrier method
  in the ``d = 6`` dual variables (see :mod:`certify.solvers.barrier`).

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
def lp_planar(W, combos, feas):
    """:func:`lp_enumerate` for ``d = 3`` (planar wrenches) in closed form.

    For a basis ``S = (i, j, l)`` with ``det = w_i . (w_j x w_l)`` and ``D_ab = w1 . (w_a x w_b)``
    (``w1`` the sum of the generators), Cramer's rule gives the basic solution
    ``t = det / (k det - g)`` with ``g = D_jl - D_il + D_ij``, weights above ``t`` equal to
    ``s = -(D_jl, -D_il, D_ij) / (k det - g)``, and the dual ``y = (c_jl + c_li + c_ij) /
    (k det - g)`` with ``c_ab = w_a x w_b`` and ``z = t``. Cross products are computed once per
    pair, so a basis costs a few dozen flops. Primal bases are scanned first; the dual only when
    the optimum is not clearly positive.
    """
    B, d, k = W.shape
    nS = combos.shape[0]
    t_out = np.full(B, -np.inf)
    lam_out = np.full((B, k), np.nan)
    y_out = np.zeros((B, 3))
    has_y = np.zeros(B, dtype=np.bool_)
    C = np.empty((k, k, 3))
    D = np.empty((k, k))
    w1 = np.empty(3)
    for b in range(B):
        wmax = 0.0
        for i in range(3):
            s = 0.0
            for j in range(k):
                s += W[b, i, j]
                wmax = max(wmax, abs(W[b, i, j]))
            w1[i] = s
        for a in range(k):
            for c in range(a + 1, k):
                x0 = W[b, 1, a] * W[b, 2, c] - W[b, 2, a] * W[b, 1, c]
                x1 = W[b, 2, a] * W[b, 0, c] - W[b, 0, a] * W[b, 2, c]
                x2 = W[b, 0, a] * W[b, 1, c] - W[b, 1, a] * W[b, 0, c]
                C[a, c, 0] = x0
                C[a, c, 1] = x1
                C[a, c, 2] = x2
                C[c, a, 0] = -x0
                C[c, a, 1] = -x1
                C[c, a, 2] = -x2
                D[a, c] = w1[0] * x0 + w1[1] * x1 + w1[2] * x2
                D[c, a] = -D[a, c]
        best_t = -np.inf
        best_z = np.inf
        for si in range(nS):
            i, j, l = combos[si, 0], combos[si, 1], combos[si, 2]
            det = W[b, 0, i] * C[j, l, 0] + W[b, 1, i] * C[j, l, 1] + W[b, 2, i] * C[j, l, 2]
            g = D[j, l] - D[i, l] + D[i, j]
            den = k * det - g
            # relative singularity test on the 4x4 basis matrix (Hadamard bound)
            ni = 1.0 + W[b, 0, i] ** 2 + W[b, 1, i] ** 2 + W[b, 2, i] ** 2
            nj = 1.0 + W[b, 0, j] ** 2 + W[b, 1, j] ** 2 + W[b, 2, j] ** 2
            nl = 1.0 + W[b, 0, l] ** 2 + W[b, 1, l] ** 2 + W[b, 2, l] ** 2
            n0 = k * k + w1[0] ** 2 + w1[1] ** 2 + w1[2] ** 2
            if abs(den) <= 1e-13 * np.sqrt(ni * nj * nl * n0):
                continue
            t = det / den
            s0 = -D[j, l] / den
            s1 = D[i, l] / den
            s2 = -D[i, j] / den
            lim = -feas * (1.0 + abs(t))
            if s0 >= lim and s1 >= lim and s2 >= lim and t > best_t:
                best_t = t
                for c in range(k):
                    lam_out[b, c] = t
                lam_out[b, i] += s0
                lam_out[b, j] += s1
                lam_out[b, l] += s2
            if t < best_z:  # z = t for the matching dual basis
                y0 = (C[j, l, 0] + C[l, i, 0] + C[i, j, 0]) / den
                y1 = (C[j, l, 1] + C[l, i, 1] + C[i, j, 1]) / den
                y2 = (C[j, l, 2] + C[l, i, 2] + C[i, j, 2]) / den
                scale = 1.0 + abs(t) + np.sqrt(y0 * y0 + y1 * y1 + y2 * y2) * wmax
                ok = True
                for c in range(k):
                    if W[b, 0, c] * y0 + W[b, 1, c] * y1 + W[b, 2, c] * y2 > t + feas * scale:
                        ok = False
                        break
                if ok:
                    best_z = t
                    y_out[b, 0] = y0
                    y_out[b, 1] = y1
                    y_out[b, 2] = y2
                    has_y[b] = True
        t_out[b] = best_t
        if best_t == -np.inf:
            G = np.zeros((3, 3))
            gg = np.zeros(3)
            for r in range(3):
                for q in range(3):
                    s = 0.0
                    for c in range(k):
                        s += W[b, r, c] * W[b, q, c]
                    G[r, q] = s
                gg[r] = -w1[r]
            yy, det = solve_small(G, gg)
            has_y[b] = det != 0.0
            if has_y[b]:
                for r in range(3):
                    y_out[b, r] = yy[r]
    return t_out, lam_out, y_out, has_y


@njit(cache=True)
def pivot_basis(C):
    """Indices of ``d`` columns of ``C`` (d, k) chosen greedily as in QR with column pivoting:
    at each step the column with the largest norm orthogonal to those already chosen (first
    such index on ties). A well-conditioned basis for the exact correction of a certificate."""
    d, k = C.shape
    R = C.copy()
    chosen = np.empty(d, dtype=np.int64)
    used = np.zeros(k, dtype=np.bool_)
    for step in range(d):
        best, arg = -1.0, 0
        for j in range(k):
            if used[j]:
                continue
            s = 0.0
            for i in range(d):
                s += R[i, j] * R[i, j]
            if s > best:
                best, arg = s, j
        chosen[step] = arg
        used[arg] = True
        nrm = np.sqrt(best)
        if nrm == 0.0:
            continue
        q = R[:, arg] / nrm
        for j in range(k):
            if not used[j]:
                s = 0.0
                for i in range(d):
                    s += q[i] * R[i, j]
                for i in range(d):
                    R[i, j] -= s * q[i]
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
def thin_planar(W):
    """True where the generator matrix (B, 3, k) may be numerically rank deficient: a cheap,
    conservative test, ``det(G) / trace(G)^3 < 1e-12`` for ``G = W W'``, which holds whenever
    ``sigma_min / sigma_max < 1e-6`` (``lambda_min >= det / trace^2``, ``lambda_max <= trace``)."""
    B, d, k = W.shape
    out = np.empty(B, dtype=np.bool_)
    G = np.empty((3, 3))
    for b in range(B):
        for i in range(3):
            for j in range(3):
                s = 0.0
                for c in range(k):
                    s += W[b, i, c] * W[b, j, c]
                G[i, j] = s
        tr = G[0, 0] + G[1, 1] + G[2, 2]
        det = (G[0, 0] * (G[1, 1] * G[2, 2] - G[1, 2] * G[2, 1])
               - G[0, 1] * (G[1, 0] * G[2, 2] - G[1, 2] * G[2, 0])
               + G[0, 2] * (G[1, 0] * G[2, 1] - G[1, 1] * G[2, 0]))
        out[b] = not (tr > 0.0 and det >= 1e-12 * tr * tr * tr)
    return out


@njit(cache=True)
def verify_planar(W, E, kind, lam, basis, y, residual_tol):
    """Rigorous floating-point re-check of planar generator certificates (B rows).

    ``W`` (B, 3, k) are the generator wrenches computed in floating point from the grasp data and
    ``E`` (B, 3, k) bounds on their distance to the exact values (see
    :func:`certify.fastpath.generator_error`). For ``kind == 1`` (interior) the check bounds the
    exact residual ``W lam``, proves ``W_B`` invertible with an approximate inverse ``R``
    (``norm(I - R W_B) < 1``), bounds the exact correction ``norm(W_B^-1 r)`` and requires every
    corrected weight to stay positive: the same statement as the exact checker, proved with
    error bounds (Higham's gamma_n) instead of rationals. For ``kind == 2`` (strict Farkas) it
    requires ``w_j . y + error < 0`` for every generator. Returns 1 (proved) or -1 (not proved
    here: the exact checker decides).
    """
    B, d, k = W.shape
    out = np.empty(B, dtype=np.int64)
    R = np.empty((3, 3))
    for b in range(B):
        if kind[b] == 2:
            res = 1
            for j in range(k):
                s, err = 0.0, 0.0
                for i in range(3):
                    s += W[b, i, j] * y[b, i]
                    err += (E[b, i, j] + _gamma(4) * abs(W[b, i, j])) * abs(y[b, i])
                if not (s + err * (1.0 + 4 * _U) < 0.0):
                    res = -1
                    break
            out[b] = res
            continue
        # residual with its error bound
        rmax, scale_l, wmax = 0.0, 0.0, 0.0
        for j in range(k):
            scale_l += abs(lam[b, j])
        for i in range(3):
            s, err = 0.0, 0.0
            for j in range(k):
                s += W[b, i, j] * lam[b, j]
                err += (E[b, i, j] + _gamma(k + 2) * abs(W[b, i, j])) * abs(lam[b, j])
                wmax = max(wmax, abs(W[b, i, j]))
            rmax = max(rmax, abs(s) + err)
        if rmax > residual_tol * max(1.0, scale_l) * max(1.0, wmax):
            out[b] = -1  # only the exact checker refutes
            continue
        # approximate inverse of the basis by cofactors
        i0, i1, i2 = basis[b, 0], basis[b, 1], basis[b, 2]
        a00, a01, a02 = W[b, 0, i0], W[b, 0, i1], W[b, 0, i2]
        a10, a11, a12 = W[b, 1, i0], W[b, 1, i1], W[b, 1, i2]
        a20, a21, a22 = W[b, 2, i0], W[b, 2, i1], W[b, 2, i2]
        det = a00 * (a11 * a22 - a12 * a21) - a01 * (a10 * a22 - a12 * a20) + a02 * (a10 * a21 - a11 * a20)
        if det == 0.0:
            out[b] = -1
            continue
        R[0, 0] = (a11 * a22 - a12 * a21) / det
        R[0, 1] = (a02 * a21 - a01 * a22) / det
        R[0, 2] = (a01 * a12 - a02 * a11) / det
        R[1, 0] = (a12 * a20 - a10 * a22) / det
        R[1, 1] = (a00 * a22 - a02 * a20) / det
        R[1, 2] = (a02 * a10 - a00 * a12) / det
        R[2, 0] = (a10 * a21 - a11 * a20) / det
        R[2, 1] = (a01 * a20 - a00 * a21) / det
        R[2, 2] = (a00 * a11 - a01 * a10) / det
        alpha, rnorm = 0.0, 0.0
        for i in range(3):
            row_z, row_r = 0.0, 0.0
            for c in range(3):
                s, err = 1.0 if i == c else 0.0, 0.0
                for q in range(3):
                    wq = W[b, q, basis[b, c]]
                    s -= R[i, q] * wq
                    err += abs(R[i, q]) * (E[b, q, basis[b, c]] + _gamma(5) * abs(wq))
                row_z += abs(s) + err
                row_r += abs(R[i, c])
            alpha = max(alpha, row_z)
            rnorm = max(rnorm, row_r)
        alpha *= 1.0 + 8 * _U
        if not alpha < 1.0:
            out[b] = -1
            continue
        delta = rnorm * (1.0 + 8 * _U) / (1.0 - alpha) * rmax * (1.0 + 8 * _U)
        res = 1
        for j in range(k):
            need = 0.0
            for c in range(3):
                if basis[b, c] == j:
                    need = delta
            if not lam[b, j] > need:
                res = -1
                break
        out[b] = res
    return out


@njit(cache=True)
def _support_planar(W, b, owner, m, u0, u1, u2, linf):
    """Support function of the planar GWS at ``u``: per contact the largest ``u . g`` over its
    generators (at least 0), combined by max (L1) or sum (L-infinity)."""
    k = W.shape[2]
    best = np.zeros(m)
    for j in range(k):
        v = W[b, 0, j] * u0 + W[b, 1, j] * u1 + W[b, 2, j] * u2
        if v > best[owner[j]]:
            best[owner[j]] = v
    if linf:
        return best.sum()
    return best.max()


@njit(cache=True)
def _candidate(W, b, owner, m, linf, x, y, tiny, eps, arg):
    """Evaluate the support function at both unit normals ``+-(x cross y)``; keep the least."""
    u0 = x[1] * y[2] - x[2] * y[1]
    u1 = x[2] * y[0] - x[0] * y[2]
    u2 = x[0] * y[1] - x[1] * y[0]
    nu = np.sqrt(u0 * u0 + u1 * u1 + u2 * u2)
    if nu <= tiny:
        return
    u0, u1, u2 = u0 / nu, u1 / nu, u2 / nu
    for sgn in (1.0, -1.0):
        h = _support_planar(W, b, owner, m, sgn * u0, sgn * u1, sgn * u2, linf)
        if h < eps[b]:
            eps[b] = h
            arg[b, 0], arg[b, 1], arg[b, 2] = sgn * u0, sgn * u1, sgn * u2


@njit(cache=True)
def planar_epsilon(W, owner, m, linf):
    """Exact Ferrari-Canny epsilon of planar grasps (B, 3, k generators; ``owner`` maps
    generators to the ``m`` contacts): the minimum of the support function over a set of
    directions holding every facet normal of the GWS (both orientations). L1: normals of the
    triples of points among the generators and the origin. L-infinity (Minkowski sum of the
    per-contact polytopes ``conv(0, generators)``): cross products of pairs of their edges (the
    generators, and differences of generators of one contact). Returns epsilon (B,) and the
    minimising unit direction (B, 3)."""
    B, _, k = W.shape
    eps = np.full(B, np.inf)
    arg = np.zeros((B, 3))
    if linf:
        ne = k
        for a in range(k):
            for c in range(a + 1, k):
                if owner[a] == owner[c]:
                    ne += 1
        E = np.empty((ne, 3))
    else:
        E = np.empty((k + 1, 3))
    for b in range(B):
        if linf:
            e = 0
            for a in range(k):
                for i in range(3):
                    E[e, i] = W[b, i, a]
                e += 1
            for a in range(k):
                for c in range(a + 1, k):
                    if owner[a] == owner[c]:
                        for i in range(3):
                            E[e, i] = W[b, i, a] - W[b, i, c]
                        e += 1
            n = e
        else:
            for i in range(3):
                E[0, i] = 0.0
            for a in range(k):
                for i in range(3):
                    E[a + 1, i] = W[b, i, a]
            n = k + 1
        scale = 0.0
        for a in range(n):
            scale = max(scale, abs(E[a, 0]) + abs(E[a, 1]) + abs(E[a, 2]))
        tiny = 1e-12 * max(1.0, scale * scale)
        for a in range(n):
            for c in range(a + 1, n):
                if linf:  # normal of a pair of edges
                    _candidate(W, b, owner, m, linf, E[a], E[c], tiny, eps, arg)
                    continue
                for q in range(c + 1, n):  # normal of a triple of points
                    _candidate(W, b, owner, m, linf, E[c] - E[a], E[q] - E[a], tiny, eps, arg)
    return eps, arg


@njit(cache=True)
def verify_null_planar(W, E, y):
    """Rigorous float re-check of null-space Farkas directions for planar generator matrices
    with fewer columns than rows (B, 3, k <= 2): proves that the exact projection of ``y`` off
    the columns' span is within ``1e-6 norm(y)`` of ``y`` (hence non-zero), as the exact checker
    requires, by ``norm(y - y_p) <= norm(W' y) / sigma_min(W)`` with both sides bounded
    rigorously (``sigma_min^2 >= det(W'W) / trace(W'W)`` for two columns). Returns 1 or -1."""
    B, d, k = W.shape
    out = np.empty(B, dtype=np.int64)
    for b in range(B):
        ny = 0.0
        for i in range(d):
            ny += y[b, i] * y[b, i]
        ny = np.sqrt(ny) * (1.0 - 4 * _U)
        gnorm2, efro2 = 0.0, 0.0
        for j in range(k):
            s, err = 0.0, 0.0
            for i in range(d):
                s += W[b, i, j] * y[b, i]
                err += (E[b, i, j] + _gamma(4) * abs(W[b, i, j])) * abs(y[b, i])
                efro2 += E[b, i, j] * E[b, i, j]
            gnorm2 += (abs(s) + err) ** 2
        gnorm = np.sqrt(gnorm2) * (1.0 + 4 * _U)
        if k == 1:
            s2 = 0.0
            for i in range(d):
                s2 += W[b, i, 0] * W[b, i, 0]
            smin = np.sqrt(s2 * (1.0 - _gamma(6)))
        else:
            g00, g01, g11 = 0.0, 0.0, 0.0
            for i in range(d):
                g00 += W[b, i, 0] * W[b, i, 0]
                g01 += W[b, i, 0] * W[b, i, 1]
                g11 += W[b, i, 1] * W[b, i, 1]
            det = g00 * g11 - g01 * g01
            err = _gamma(8) * (g00 * g11 + g01 * g01)
            tr = (g00 + g11) * (1.0 + _gamma(4))
            smin = np.sqrt(max(det - err, 0.0) / tr) * (1.0 - 4 * _U) if tr > 0 else 0.0
        smin -= np.sqrt(efro2) * (1.0 + 4 * _U)
        out[b] = 1 if smin > 0.0 and gnorm / smin <= 1e-6 * ny * (1.0 - 8 * _U) else -1
    return out

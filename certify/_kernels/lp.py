"""The polyhedral min-weight LP ``max t : W lam = 0, 1'lam = 1, lam >= t`` by exact basis
enumeration, compiled (numba): the method of :mod:`qualgrasp.certify.solvers.enumeration`, one
loop per grasp, and its closed form for planar wrenches (``d = 3``)."""

from __future__ import annotations

import numpy as np

from .jit import kernel
from .linalg import lu_factor, lu_solve, lu_solve_t, solve_small

__all__ = ["lp_enumerate", "lp_planar_one", "lp_planar"]


@kernel
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
            det = lu_factor(M, piv)
            if abs(det) <= 1e-13 * had:
                continue
            for i in range(n):
                prim[i] = 0.0
                dual[i] = 0.0
            prim[d] = 1.0
            dual[0] = 1.0
            lu_solve(M, piv, prim)
            lu_solve_t(M, piv, dual)
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


@kernel
def lp_planar_one(Wb, combos, feas, dual_below, C, D, buf, lam, y):
    """:func:`lp_planar` for one generator matrix ``Wb`` (3, k); fills ``lam`` and ``y`` and
    returns ``(t, has_y)``. ``combos`` must be every 3-subset of ``range(k)`` in the order of
    :func:`itertools.combinations` (:func:`qualgrasp.certify.solvers.enumeration.bases`: the
    primal scan runs over them as nested loops). ``C``, ``D``, ``buf`` are work arrays
    (k, k, 3), (k, k) and (k + 2 nS,). The dual bases are scanned only when ``t < dual_below``."""
    k = Wb.shape[1]
    nS = combos.shape[0]
    if nS != k * (k - 1) * (k - 2) // 6:  # the scan below writes one entry of buf per 3-subset
        raise ValueError("combos must be bases(k, 3): every 3-subset of the generators")
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
    si = 0  # the bases (i, j, l) in the order of combos, nested: what stays fixed is read once
    for i in range(k):
        wi0, wi1, wi2 = Wb[0, i], Wb[1, i], Wb[2, i]
        for j in range(i + 1, k):
            dij, nij = D[i, j], norms[i] * norms[j]
            for l in range(j + 1, k):
                s, si = si, si + 1
                # Cramer's rule, singular relative to the Hadamard bound of its 4x4 matrix
                det = wi0 * C[j, l, 0] + wi1 * C[j, l, 1] + wi2 * C[j, l, 2]
                den = k * det - (D[j, l] - D[i, l] + dij)
                if abs(den) <= 1e-13 * np.sqrt(nij * norms[l] * n0):
                    dens[s] = 0.0
                    continue
                t = det / den
                dens[s], ts[s] = den, t
                s0 = -D[j, l] / den
                s1 = D[i, l] / den
                s2 = -dij / den
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


@kernel
def lp_planar(W, combos, feas, dual_below=np.inf):
    """:func:`lp_enumerate` for ``d = 3`` (planar wrenches) in closed form.

    For a basis ``S = (i, j, l)`` with ``det = w_i . (w_j x w_l)`` and ``D_ab = w1 . (w_a x w_b)``
    (``w1`` the sum of the generators), Cramer's rule gives the basic solution
    ``t = det / (k det - g)`` with ``g = D_jl - D_il + D_ij``, weights above ``t`` equal to
    ``s = -(D_jl, -D_il, D_ij) / (k det - g)``, and the dual ``y = (c_jl + c_li + c_ij) /
    (k det - g)`` with ``c_ab = w_a x w_b`` and ``z = t``. Cross products are computed once per
    pair, so a basis costs a few dozen flops. The dual bases (needed only for a verdict against
    closure) are scanned only where ``t* < dual_below``. ``combos`` must be
    :func:`qualgrasp.certify.solvers.enumeration.bases` of ``(k, 3)`` (see :func:`lp_planar_one`).
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
        t_out[b], has_y[b] = lp_planar_one(W[b], combos, feas, dual_below, C, D, buf, lam_out[b],
                                            y_out[b])
    return t_out, lam_out, y_out, has_y

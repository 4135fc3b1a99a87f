"""Small dense linear algebra, compiled (numba): factorisations, solves, bases and rigorous
bounds on inverses (the floating-point half of the certificate checks).

``U`` is the unit roundoff of float64 and :func:`gamma` Higham's ``gamma_n = n u / (1 - n u)``,
the factor bounding the accumulated rounding of ``n`` operations.
"""

from __future__ import annotations

import numpy as np

from .jit import kernel

__all__ = ["U", "gamma", "solve_small", "lu_factor", "lu_solve", "lu_solve_t", "cholesky_solve",
           "pivot_basis_into", "pivot_basis", "inverse_norm_bound", "projection_bound", "cross_unit",
           "null_direction", "thin", "world_values", "U", "ETA", "gamma"]

U = 2.0**-53
#: The smallest subnormal: the absolute error a rounding can add when its result underflows.
ETA = 2.0**-1074


@kernel
def gamma(n):
    return n * U / (1.0 - n * U)


@kernel
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


@kernel
def lu_factor(M, piv):
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


@kernel
def lu_solve(LU, piv, x):
    """Solve ``A x = b`` in place (``x`` holds ``b``) from :func:`lu_factor`'s factors of ``A``."""
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


@kernel
def lu_solve_t(LU, piv, x):
    """Solve ``A' x = b`` in place from :func:`lu_factor`'s factors of ``A`` (``P A = L U``)."""
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


@kernel
def cholesky_solve(H, rhs, out):
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


@kernel
def pivot_basis_into(C, R, chosen, used):
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


@kernel
def pivot_basis(C):
    """Indices of ``d`` columns of ``C`` (d, k) chosen greedily as in QR with column pivoting:
    at each step the column with the largest norm orthogonal to those already chosen (first
    such index on ties). A well-conditioned basis for the exact correction of a certificate."""
    d, k = C.shape
    chosen = np.empty(d, dtype=np.int64)
    pivot_basis_into(C, np.empty((d, k)), chosen, np.empty(k, dtype=np.bool_))
    return chosen


@kernel
def inverse_norm_bound(M, EM):
    """Upper bound on ``norm_inf(M_exact^-1)`` for a square ``M_exact`` within ``EM`` of ``M``,
    from an approximate inverse ``R``: ``norm(I - R M_exact) <= alpha < 1`` gives
    ``norm(M_exact^-1) <= norm(R) / (1 - alpha)``; ``inf`` when not proved."""
    k = M.shape[0]
    LU = M.copy()
    piv = np.empty(k, dtype=np.int64)
    if lu_factor(LU, piv) == 0.0:
        return np.inf
    R = np.empty((k, k))
    col = np.empty(k)
    for c in range(k):
        for i in range(k):
            col[i] = 1.0 if i == c else 0.0
        lu_solve(LU, piv, col)
        for i in range(k):
            R[i, c] = col[i]
    alpha, rnorm = 0.0, 0.0
    for i in range(k):
        row_z, row_r = 0.0, 0.0
        for c in range(k):
            acc, err = 1.0 if i == c else 0.0, 0.0
            for q in range(k):
                acc -= R[i, q] * M[q, c]
                err += abs(R[i, q]) * (EM[q, c] + gamma(k + 2) * abs(M[q, c]))
            row_z += abs(acc) + err
            row_r += abs(R[i, c])
        alpha = max(alpha, row_z)
        rnorm = max(rnorm, row_r)
    alpha *= 1.0 + 4 * k * U
    if not alpha < 1.0:
        return np.inf
    return rnorm * (1.0 + 4 * k * U) / (1.0 - alpha)


@kernel
def projection_bound(C, E, y):
    """Upper bound on the norm of the exact projection of ``y`` onto the span of the exact
    columns (within ``E`` of ``C``, fewer columns than rows): ``|C' y| / sigma_min(C)``, with
    ``sigma_min(C)^2 = lambda_min(G) >= 1 / norm_inf(G^-1)`` for the Gram matrix ``G = C' C``
    (symmetric) bounded by :func:`inverse_norm_bound`, every error accounted for; ``inf`` when
    not proved."""
    d, k = C.shape
    gnorm2 = 0.0
    for j in range(k):
        acc, err = 0.0, 0.0
        for i in range(d):
            acc += C[i, j] * y[i]
            err += (E[i, j] + gamma(d + 2) * abs(C[i, j])) * abs(y[i])
        gnorm2 += (abs(acc) + err) ** 2
    gnorm = np.sqrt(gnorm2) * (1.0 + 4 * U)
    G = np.empty((k, k))
    EG = np.empty((k, k))
    for a in range(k):
        for c in range(k):
            acc, err = 0.0, 0.0
            for i in range(d):
                acc += C[i, a] * C[i, c]
                err += (abs(C[i, a]) * E[i, c] + E[i, a] * abs(C[i, c]) + E[i, a] * E[i, c]
                        + gamma(d + 2) * abs(C[i, a] * C[i, c]))
            G[a, c] = acc
            EG[a, c] = err
    inv = inverse_norm_bound(G, EG)
    if not np.isfinite(inv):
        return np.inf
    return gnorm / (np.sqrt(1.0 / inv) * (1.0 - 4 * U)) * (1.0 + 4 * U)


@kernel
def cross_unit(a, b):
    y0 = a[1] * b[2] - a[2] * b[1]
    y1 = a[2] * b[0] - a[0] * b[2]
    y2 = a[0] * b[1] - a[1] * b[0]
    nrm = np.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
    return np.array([y0, y1, y2]) / nrm if nrm > 0.0 else np.zeros(3)


@kernel
def null_direction(C):
    """A unit vector orthogonal to the columns of ``C`` (3, k <= 2): their cross product when
    they span a plane (to within 1e-12 relative), else the cross product of the longer column
    with the coordinate axis least aligned with it."""
    a = C[:, 0]
    if C.shape[1] == 2:
        b = C[:, 1]
        y = cross_unit(a, b)
        na = np.sqrt(a[0] ** 2 + a[1] ** 2 + a[2] ** 2)
        nb = np.sqrt(b[0] ** 2 + b[1] ** 2 + b[2] ** 2)
        c = a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]
        if np.sqrt(c[0] ** 2 + c[1] ** 2 + c[2] ** 2) > 1e-12 * na * nb:
            return y
        if nb > na:
            a = b
    axis = np.zeros(3)
    axis[np.argmin(np.abs(a))] = 1.0
    return cross_unit(a, axis)


@kernel
def thin(Wb):
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


@kernel
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

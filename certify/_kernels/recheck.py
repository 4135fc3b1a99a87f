"""Rigorous floating-point re-checks of certificates, compiled (numba).

Columns ``C`` come with bounds ``E`` on their distance to the exact columns of the same float
data; every rounding of the check itself is bounded with :func:`~.linalg.gamma`. A check that
passes proves what the exact rational checker (:mod:`qualgrasp.certify.core.certificates`) would
prove; one that fails proves nothing (the caller then uses the exact checker). Cone blocks are
given as arrays ``(cone, first, width, n, mu, g)`` (:func:`qualgrasp.certify.core.problem.block_arrays`).
"""

from __future__ import annotations

import numpy as np

from ..core.cones import RAY
from .cones import polar_values
from .jit import kernel
from .linalg import U, gamma, inverse_norm_bound, pivot_basis_into, projection_bound

__all__ = ["residual_bound", "correction_bound", "verify_interior_general", "verify_farkas_general",
           "verify_null_general", "certify_rows", "null_rows"]


@kernel
def residual_bound(C, E, x):
    """Upper bound on ``max |C_exact x|`` (exact columns within ``E`` of ``C``) and scales."""
    d, k = C.shape
    rmax, xsum, cmax = 0.0, 0.0, 0.0
    for j in range(k):
        xsum += abs(x[j])
    for i in range(d):
        acc, err = 0.0, 0.0
        for j in range(k):
            acc += C[i, j] * x[j]
            err += (E[i, j] + gamma(k + 2) * abs(C[i, j])) * abs(x[j])
            cmax = max(cmax, abs(C[i, j]))
        rmax = max(rmax, abs(acc) + err)
    return rmax, xsum, cmax


@kernel
def correction_bound(C, E, basis, rmax):
    """Bound on ``max |C_B_exact^-1 r|`` for any exact residual ``|r| <= rmax`` (and a proof
    that ``C_B`` is invertible), from :func:`inverse_norm_bound` on the basis columns and their
    error bounds. Returns ``inf`` when not proved."""
    d = C.shape[0]
    M = np.empty((d, d))
    EM = np.empty((d, d))
    for i in range(d):
        for c in range(d):
            M[i, c] = C[i, basis[c]]
            EM[i, c] = E[i, basis[c]]
    inv = inverse_norm_bound(M, EM)
    if not inv < np.inf:
        return np.inf
    return inv * rmax * (1.0 + 4 * d * U)


@kernel
def verify_interior_general(C, E, cone, first, width, n, mu, g, x, basis, residual_tol):
    """Rigorous float proof that values ``x`` over certificate columns ``C`` (d, k) certify
    closure: exact residual bounded, basis invertible, exact correction bounded by ``delta``, and
    every block's corrected value strictly inside its cone with room to spare. A Lorentz block's
    slack ``mu f_n - norm((f_t, m |n| / g))`` moves by at most ``(1 + mu) |df| + |n| |dm| / g``
    under a correction, which is what must fit."""
    rmax, xsum, cmax = residual_bound(C, E, x)
    if rmax > residual_tol * max(1.0, xsum) * max(1.0, cmax):
        return False
    delta = correction_bound(C, E, basis, rmax)
    if not np.isfinite(delta):
        return False
    d = C.shape[0]
    inb = np.zeros(C.shape[1], dtype=np.bool_)
    for c in range(d):
        inb[basis[c]] = True
    dim = n.shape[1]
    for b in range(cone.shape[0]):
        j0 = first[b]
        if cone[b] == RAY:
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
        dm, size = 0.0, np.sqrt(ff)
        for c in range(dim, width[b]):  # moment columns
            t2 += (x[j0 + c] * rn / g[b]) ** 2
            size += abs(x[j0 + c]) * rn / g[b]
            if inb[j0 + c]:
                dm += delta * rn / g[b]
        slack = mu[b] * fn - np.sqrt(t2)
        err = 1e-13 * (1.0 + mu[b]) * size
        if not slack - err - (1.0 + mu[b]) * np.sqrt(df2) - dm > 0.0:
            return False
    return True


@kernel
def verify_farkas_general(C, E, cone, first, width, n, mu, g, y, tight, shift):
    """Rigorous float proof that ``y``, moved by at most ``shift`` (the exact projection off the
    ``tight`` blocks, see :func:`~.linalg.projection_bound`), strictly separates every other
    block's cone: for each such block the polar value of ``a = C_b' y``
    (:func:`~.cones.polar_value`) plus its float error, the column errors and the shift (``a``
    moves by at most ``|C_b| shift``; the polar value is Lipschitz ``1 + mu`` in ``a``, with
    moment columns weighted by ``g / |n|``) stays negative."""
    d, k = C.shape
    dim = n.shape[1]
    a = np.empty(k)
    for b in range(cone.shape[0]):
        if tight[b]:
            continue
        j0 = first[b]
        ea2 = 0.0
        for c in range(width[b]):
            acc, err, cn = 0.0, 0.0, 0.0
            for i in range(d):
                acc += C[i, j0 + c] * y[i]
                err += (E[i, j0 + c] + gamma(d + 2) * abs(C[i, j0 + c])) * abs(y[i])
                cn += (abs(C[i, j0 + c]) + E[i, j0 + c]) ** 2
            a[c] = acc
            err += np.sqrt(cn) * shift
            ea2 += err * err
        if cone[b] == RAY:
            value, scale, lip = a[0], abs(a[0]), 1.0
        else:
            nn, an, aa = 0.0, 0.0, 0.0
            for i in range(dim):
                nn += n[b, i] * n[b, i]
                an += a[i] * n[b, i]
                aa += a[i] * a[i]
            rn = np.sqrt(nn)
            an /= rn
            t2 = max(aa - an * an, 0.0)
            scale, lip = np.sqrt(aa), 1.0
            for c in range(dim, width[b]):
                t2 += (a[c] * g[b] / rn) ** 2
                scale += abs(a[c]) * g[b] / rn
                lip = max(lip, g[b] / rn)
            value = an + mu[b] * np.sqrt(t2)
        bound = 1e-13 * (1.0 + mu[b]) * scale + (1.0 + mu[b]) * lip * np.sqrt(ea2)
        if not value + bound < 0.0:
            return False
    return True


@kernel
def verify_null_general(C, E, y):
    """Rigorous float proof, for fewer columns than rows, that the exact projection of ``y``
    off the columns' span is within ``1e-6 |y|`` of ``y`` (so non-zero), as the exact checker
    requires (see :func:`projection_bound`)."""
    ny = 0.0
    for i in range(y.shape[0]):
        ny += y[i] * y[i]
    return projection_bound(C, E, y) <= 1e-6 * np.sqrt(ny) * (1.0 - 8 * U)


@kernel
def certify_rows(C, E, cone, first, width, N, mu, g, values, y, closure, farkas, scale,
                 residual_tol):
    """Per row of a batch (B, d, k): for ``closure`` rows choose the basis and prove the
    interior certificate ``values``; for ``farkas`` rows check the strict separation rule of
    :func:`qualgrasp.certify.core.closure.farkas_certificate` (every polar value below ``-1e-9 scale``) and prove
    it. Returns codes (1 closure, 2 strict Farkas, 0 not settled) and the bases."""
    B, d, k = C.shape
    code = np.zeros(B, dtype=np.int64)
    basis = np.zeros((B, d), dtype=np.int64)
    R = np.empty((d, k))
    used = np.empty(k, dtype=np.bool_)
    none = np.zeros(cone.shape[0], dtype=np.bool_)
    for b in range(B):
        if closure[b]:
            pivot_basis_into(C[b], R, basis[b], used)
            if verify_interior_general(C[b], E[b], cone, first, width, N[b], mu[b], g[b], values[b],
                                       basis[b], residual_tol):
                code[b] = 1
        elif farkas[b]:
            pv = polar_values(C[b], cone, first, width, N[b], mu[b], g[b], y[b])
            strict = True
            for q in range(pv.shape[0]):
                if not pv[q] < -1e-9 * scale[b]:
                    strict = False
            if strict and verify_farkas_general(C[b], E[b], cone, first, width, N[b], mu[b], g[b],
                                                y[b], none, 0.0):
                code[b] = 2
    return code, basis


@kernel
def null_rows(C, E, y):
    """:func:`verify_null_general` for every row of a batch: 3 where proved, else 0."""
    out = np.zeros(C.shape[0], dtype=np.int64)
    for b in range(C.shape[0]):
        if verify_null_general(C[b], E[b], y[b]):
            out[b] = 3
    return out

"""Cone tests in floating point, compiled (numba): the formulas of :mod:`qualgrasp.certify.core.cones`.

Cone blocks are given as arrays ``(cone, first, width, n, mu, g)``
(:func:`qualgrasp.certify.core.problem.block_arrays`): the cone shape code (:data:`~qualgrasp.certify.core.cones.RAY`
or :data:`~qualgrasp.certify.core.cones.LORENTZ`), the block's first certificate column and its
number of columns, its stored normal (zeros for rays), friction coefficient and moment length
(a Lorentz block's columns beyond the dimension of ``n`` are moment columns weighted by ``g``).
"""

from __future__ import annotations

import numpy as np

from ..core.cones import RAY
from .jit import kernel

__all__ = ["functional", "polar_value", "polar_values", "farkas_direction", "squeeze_direction"]


@kernel
def functional(C, first, width, y, a):
    """``a[c] = y . C[:, first + c]`` for the ``width`` columns of one block."""
    for c in range(width):
        acc = 0.0
        for i in range(C.shape[0]):
            acc += C[i, first + c] * y[i]
        a[c] = acc


@kernel
def polar_value(a, cone, width, n, mu, g):
    """Polar value ``a_n + mu norm((a_t, a_m g / |n|))`` of the functional ``a`` (values on the
    block's ``width`` columns) on one block, ``a[0]`` for a ray: the largest ``y . w`` over the
    block's unit-normal-force wrenches."""
    if cone == RAY:
        return a[0]
    dim = n.shape[0]
    nn = 0.0
    for i in range(dim):
        nn += n[i] * n[i]
    rn = np.sqrt(nn)
    an = 0.0
    for i in range(dim):
        an += a[i] * n[i] / rn
    t2 = 0.0
    for i in range(dim):
        ti = a[i] - an * n[i] / rn
        t2 += ti * ti
    for c in range(dim, width):  # moment columns (a soft finger's torsion)
        t2 += (a[c] * g / rn) ** 2
    return an + mu * np.sqrt(t2)


@kernel
def polar_values(C, cone, first, width, n, mu, g, y):
    """:func:`polar_value` of every block for the functional ``a = C_b' y`` (the same formula
    for every route: see :mod:`qualgrasp.certify.core.cones`)."""
    out = np.empty(cone.shape[0])
    a = np.empty(C.shape[1])
    for b in range(cone.shape[0]):
        functional(C, first[b], width[b], y, a)
        out[b] = polar_value(a, cone[b], width[b], n[b], mu[b], g[b])
    return out


@kernel
def _project_off_tight(C, first, width, tight, scale, v):
    """Project ``v`` in place off the span of the tight blocks' columns of ``C``: modified
    Gram-Schmidt over those columns in order, keeping the directions whose remaining norm is above
    ``1e-12 scale`` (the rank the columns have at that tolerance). Written as loops: numba compiles
    ``np.linalg.qr`` and slice assignments slowly, and this runs on a first call."""
    d = C.shape[0]
    basis = np.empty((d, d))
    rank = np.int64(0)  # an int literal would have numba compile _remove_components for it too
    q = np.empty(d)
    for b in range(first.shape[0]):
        if not tight[b]:
            continue
        for c in range(width[b]):
            if rank == d:
                break
            for i in range(d):
                q[i] = C[i, first[b] + c]
            _remove_components(basis, rank, q)
            nq = 0.0
            for i in range(d):
                nq += q[i] * q[i]
            nq = np.sqrt(nq)
            if nq > 1e-12 * scale:
                for i in range(d):
                    basis[i, rank] = q[i] / nq
                rank += 1
    _remove_components(basis, rank, v)


@kernel
def _remove_components(basis, rank, v):
    """Subtract from ``v``, in place and in order, its component along each of the first ``rank``
    orthonormal columns of ``basis`` (modified Gram-Schmidt)."""
    for r in range(rank):
        dot = 0.0
        for i in range(v.shape[0]):
            dot += basis[i, r] * v[i]
        for i in range(v.shape[0]):
            v[i] -= dot * basis[i, r]


@kernel
def farkas_direction(C, cone, first, width, n, mu, g, y, rel):
    """The rule of :func:`qualgrasp.certify.core.closure.farkas_certificate`, compiled: ``(ok, y,
    tight)``.

    ``y`` is normalised; if every block's polar value is below ``-1e-9 scale`` (``scale`` the
    largest ``abs(C)``) it is a strict certificate. Otherwise blocks whose functional
    ``C_b' y`` is at most ``rel scale`` in absolute value are tight, ``y`` is projected off the
    span of their columns (Gram-Schmidt, directions above ``1e-12 scale``) and normalised again
    (refused if the projection leaves less than half of it), and every other block must be
    strictly separated."""
    d = C.shape[0]
    nb = cone.shape[0]
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
    pv = polar_values(C, cone, first, width, n, mu, g, out)
    if pv.max() < -1e-9 * scale:
        return True, out, tight
    ntc = 0
    a = np.empty(C.shape[1])
    for b in range(nb):
        functional(C, first[b], width[b], out, a)
        big = 0.0
        for c in range(width[b]):
            big = max(big, abs(a[c]))
        if big <= rel * scale:
            tight[b] = True
            ntc += width[b]
    if ntc > 0:
        proj = np.empty(d)
        for i in range(d):
            proj[i] = out[i]
        _project_off_tight(C, first, width, tight, scale, proj)
        ss = 0.0
        for i in range(d):
            ss += proj[i] * proj[i]
        norm = np.sqrt(ss)
        if norm < 0.5:
            return False, out, tight
        for i in range(d):
            out[i] = proj[i] / norm
        pv = polar_values(C, cone, first, width, n, mu, g, out)
    for b in range(nb):
        if not tight[b] and not pv[b] < -1e-9 * scale:
            return False, out, tight
    return True, out, tight


@kernel
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

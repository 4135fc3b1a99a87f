"""Rigorous floating-point checks of epsilon evidence (numba): the faces of an inscribed surface
and the support function of a planar GWS, with error bounds instead of rationals (the float half
of :mod:`qualgrasp.certify.quality.evidence`; the exact half decides whatever these cannot).

Vertex coordinates ``V`` come with bounds ``EV`` on their distance to the exact values. A
determinant computed from floats by Leibniz's formula (a signed sum of products of ``d - 1``
entries) is within ``perm(|D| + E) - perm(|D|) + gamma * perm(|D| + E)`` of the exact one,
``perm`` the permanent (the same sum without signs): each product moves by at most the
difference of the products of the enlarged and the plain magnitudes, and rounding adds
Higham's ``gamma_n`` of the sum of magnitudes.
"""

from __future__ import annotations

import functools
from itertools import permutations

import numpy as np

from .jit import kernel
from .linalg import U, gamma
from .order import radix_argsort, stable_argsort

__all__ = ["face_bounds", "face_bounds_laplace", "leibniz_tables", "planar_h_bounds", "cycle_code", "orient_cycle",
           "TRIANGLES_MAX"]


@functools.lru_cache(maxsize=None)
def leibniz_tables(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Permutations of ``range(n)`` (rows) and their signs, for :func:`face_bounds`; computed once
    per ``n`` and shared (callers pass them on, never change them)."""
    perms = np.array(list(permutations(range(n))), dtype=np.int64).reshape(-1, n)
    signs = np.array([(-1.0) ** sum(p[i] > p[j] for i in range(n) for j in range(i + 1, n))
                      for p in perms])
    return perms, signs


@kernel
def _cofactors(D, ED, M, PA, PE):
    """Every minor of the last ``k`` rows of ``D`` (m, d), ``m = d - 1``, on every set of ``k``
    columns (a bit mask ``S``): ``M[S]`` its determinant, ``PA[S]`` and ``PE[S]`` the permanents of
    ``|D|`` and ``|D| + ED`` on it, each expanded along its first row (Laplace), the smaller minors
    shared. The maximal ones (all columns but ``r``) are the cofactors of the generalised cross
    product. Evaluated this way each product of ``m`` entries passes through at most
    ``m - 1 + m (m - 1) / 2`` roundings, fewer than the ``m + m!`` of Leibniz's sum that
    :func:`face_bounds` bounds, so its bound holds for these values too."""
    m, d = D.shape
    for S in range(1, 1 << d):
        k = 0
        for c in range(d):
            k += (S >> c) & 1
        if k > m:
            continue
        row = m - k
        if k == 1:
            c = 0
            while not (S >> c) & 1:
                c += 1
            M[S], PA[S], PE[S] = D[row, c], abs(D[row, c]), abs(D[row, c]) + ED[row, c]
            continue
        s, pa, pe, i = 0.0, 0.0, 0.0, 0
        for c in range(d):
            if (S >> c) & 1:
                rest = S ^ (1 << c)
                term = D[row, c] * M[rest]
                s = s + term if i % 2 == 0 else s - term
                pa += abs(D[row, c]) * PA[rest]
                pe += (abs(D[row, c]) + ED[row, c]) * PE[rest]
                i += 1
        M[S], PA[S], PE[S] = s, pa, pe


@kernel
def face_bounds(V, EV, faces, perms, psign):
    """For every face (row of ``faces``, ``d`` vertex indices into ``V`` (nv, d)): whether its
    determinant ``det(v_1, ..., v_d)`` is proved positive, and rigorous lower and upper bounds
    of its squared distance from the origin, ``det^2 / |n|^2`` (``n`` the generalised cross
    product of ``v_2 - v_1, ..., v_d - v_1``, for which ``n . v_1 = det``), for the exact
    vertices within ``EV`` of ``V``. ``perms``/``psign``: :func:`leibniz_tables` of ``d - 1``;
    each cofactor is Leibniz's sum (:func:`face_bounds_laplace` gives the same bounds with shared
    minors, for ``d > 3``).
    Returns ``(ok, dist2_lo, dist2_hi)``; ``dist2_lo`` is 0 where ``ok`` is False."""
    F, d = faces.shape
    ok, lo, hi = np.zeros(F, dtype=np.bool_), np.zeros(F), np.full(F, np.inf)
    D, ED, n, en = np.empty((d - 1, d)), np.empty((d - 1, d)), np.empty(d), np.empty(d)
    g = 3.0 * gamma(d + perms.shape[0] + 2)
    spatial3 = d == 3 and _pair_table(perms, psign)
    for f in range(F):
        i0 = _edges(V, EV, faces, f, D, ED)
        if spatial3:
            _normal3(D, ED, g, n, en)
        else:
            _leibniz_normal(D, ED, perms, psign, g, n, en)
        ok[f], lo[f], hi[f] = _distance_bounds(V, EV, i0, n, en)
    return ok, lo, hi


@kernel
def face_bounds_laplace(V, EV, faces, perms, psign):
    """:func:`face_bounds` with every cofactor from minors shared by all of them
    (:func:`_cofactors`): the same bound (``perms`` sets its constant), about ``(d - 1)!`` fewer
    products in 6-D."""
    F, d = faces.shape
    ok, lo, hi = np.zeros(F, dtype=np.bool_), np.zeros(F), np.full(F, np.inf)
    D, ED, n, en = np.empty((d - 1, d)), np.empty((d - 1, d)), np.empty(d), np.empty(d)
    g = 3.0 * gamma(d + perms.shape[0] + 2)
    M, PA, PE = np.zeros(1 << d), np.zeros(1 << d), np.zeros(1 << d)
    full = (1 << d) - 1
    for f in range(F):
        i0 = _edges(V, EV, faces, f, D, ED)
        _cofactors(D, ED, M, PA, PE)
        for r in range(d):
            S = full ^ (1 << r)
            n[r] = M[S] if r % 2 == 0 else -M[S]
            en[r] = (PE[S] - PA[S]) + g * PE[S]
        ok[f], lo[f], hi[f] = _distance_bounds(V, EV, i0, n, en)
    return ok, lo, hi


@kernel(inline=True)
def _edges(V, EV, faces, f, D, ED):
    """Into ``D`` and ``ED``: the edges ``v_q - v_1`` of face ``f`` and bounds on their distance to
    the exact ones (the vertices' own and the subtraction's rounding); returns ``v_1``'s index."""
    d = faces.shape[1]
    i0 = faces[f, 0]
    for q in range(1, d):
        j = faces[f, q]
        for r in range(d):
            D[q - 1, r] = V[j, r] - V[i0, r]
            ED[q - 1, r] = EV[j, r] + EV[i0, r] + U * (abs(V[j, r]) + abs(V[i0, r]))
    return i0


@kernel
def _leibniz_normal(D, ED, perms, psign, g, n, en):
    """Into ``n`` and ``en``: each cofactor ``n_r = (-1)^r det(D without column r)`` by Leibniz's
    sum, and its error bound ``perm(|D| + ED) - perm(|D|) + g perm(|D| + ED)``."""
    d = D.shape[1]
    for r in range(d):
        s, pa_sum, pe_sum = 0.0, 0.0, 0.0
        for t in range(perms.shape[0]):
            prod, pa, pe = psign[t], 1.0, 1.0
            for q in range(d - 1):
                c = perms[t, q]
                col = c if c < r else c + 1
                x = D[q, col]
                prod *= x
                pa *= abs(x)
                pe *= abs(x) + ED[q, col]
            s += prod
            pa_sum += pa
            pe_sum += pe
        n[r] = s if r % 2 == 0 else -s
        en[r] = (pe_sum - pa_sum) + g * pe_sum


@kernel
def _pair_table(perms, psign):
    """Whether ``perms``/``psign`` are :func:`leibniz_tables` of 2: ``(0, 1)`` with +1, ``(1, 0)``
    with -1."""
    return (perms.shape[0] == 2 and perms.shape[1] == 2 and perms[0, 0] == 0 and perms[0, 1] == 1
            and perms[1, 0] == 1 and perms[1, 1] == 0 and psign[0] == 1.0 and psign[1] == -1.0)


@kernel(inline=True)
def _normal3(D, ED, g, n, en):
    """:func:`_leibniz_normal` of a face in 3-D with the table of :func:`leibniz_tables` of 2,
    written out: the same operations in the same order (each sum from ``0.0``, each product from
    the sign or ``1.0``), so the same floats, without the table's loops (the planar surfaces'
    checks spend most of their time here)."""
    for r in range(3):
        c0 = 1 if r == 0 else 0  # the loop's column map (c if c < r else c + 1) of c = 0 and 1
        c1 = 1 if r == 2 else 2
        a0, a1, b0, b1 = D[0, c0], D[0, c1], D[1, c0], D[1, c1]
        s = 0.0 + (1.0 * a0) * b1
        s = s + (-1.0 * a1) * b0
        pa = 0.0 + (1.0 * abs(a0)) * abs(b1)
        pa = pa + (1.0 * abs(a1)) * abs(b0)
        pe = 0.0 + (1.0 * (abs(a0) + ED[0, c0])) * (abs(b1) + ED[1, c1])
        pe = pe + (1.0 * (abs(a1) + ED[0, c1])) * (abs(b0) + ED[1, c0])
        n[r] = s if r % 2 == 0 else -s
        en[r] = (pe - pa) + g * pe


@kernel(inline=True)
def _distance_bounds(V, EV, i0, n, en):
    """From the normal ``n`` (within ``en``) of a face through ``v_1 = V[i0]``: whether
    ``det = n . v_1`` is proved positive, and bounds of ``det^2 / |n|^2``."""
    d = n.shape[0]
    det, edet, mag = 0.0, 0.0, 0.0
    for r in range(d):
        a, ea = V[i0, r], EV[i0, r]
        det += n[r] * a
        big = (abs(n[r]) + en[r]) * (abs(a) + ea)
        edet += big - abs(n[r]) * abs(a)
        mag += big
    edet = (edet + 3.0 * gamma(2 * d + 2) * mag) * (1.0 + 4 * U)
    nn_hi, nn_lo = 0.0, 0.0
    for r in range(d):
        up = abs(n[r]) + en[r]
        dn = max(0.0, abs(n[r]) - en[r])
        nn_hi += up * up
        nn_lo += dn * dn
    nn_hi *= 1.0 + gamma(d + 4)
    nn_lo *= 1.0 - gamma(d + 4)
    d_lo, d_hi = det - edet, det + edet
    ok, lo, hi = False, 0.0, np.inf
    if d_lo > 0.0 and nn_hi > 0.0:
        ok = True
        lo = d_lo * d_lo / nn_hi * (1.0 - gamma(4))
    if nn_lo > 0.0:
        hi = d_hi * d_hi / nn_lo * (1.0 + gamma(4))
    return ok, lo, hi


@kernel
def planar_h_bounds(W, EW, owner, m, u, linf):
    """Rigorous bounds ``(lo, hi)`` of ``h(u) / |u|`` for the exact generators within ``EW`` of
    ``W`` (3, k): per contact the largest ``u . g`` (at least 0), combined by max (L1) or sum
    (L-infinity); ``(0, -1)`` for a zero ``u``."""
    k = W.shape[1]
    best_lo = np.zeros(m)
    best_hi = np.zeros(m)
    for j in range(k):
        v, err = 0.0, 0.0
        for r in range(3):
            v += W[r, j] * u[r]
            err += (EW[r, j] + gamma(4) * abs(W[r, j])) * abs(u[r])
        i = owner[j]
        best_lo[i] = max(best_lo[i], v - err)
        best_hi[i] = max(best_hi[i], v + err)
    h_lo, h_hi = 0.0, 0.0
    for i in range(m):
        if linf:
            h_lo += best_lo[i]
            h_hi += best_hi[i]
        else:
            h_lo = max(h_lo, best_lo[i])
            h_hi = max(h_hi, best_hi[i])
    if linf:
        h_lo *= 1.0 - gamma(m + 1)
        h_hi *= 1.0 + gamma(m + 1)
    uu = u[0] * u[0] + u[1] * u[1] + u[2] * u[2]
    if uu <= 0.0:
        return 0.0, -1.0
    r_lo = np.sqrt(uu * (1.0 - gamma(4))) * (1.0 - 2 * U)
    r_hi = np.sqrt(uu * (1.0 + gamma(4))) * (1.0 + 2 * U)
    return h_lo / r_hi * (1.0 - 2 * U), h_hi / r_lo * (1.0 + 2 * U)


@kernel
def _ridge_keys(faces, nv, keys, sgn):
    """Into ``keys`` and ``sgn`` (F * d): each ridge of ``faces`` (face ``f`` without its ``k``-th
    vertex, at ``f * d + k``) as an integer in base ``nv`` of its sorted vertices, and its sign,
    ``(-1)^k`` times the parity of sorting them. Returns 0, or 1 for an index out of range, 2 for a
    face repeating a vertex."""
    F, d = faces.shape
    r = np.empty(d - 1, dtype=np.int64)
    for f in range(F):
        for q in range(d):
            v = faces[f, q]
            if v < 0 or v >= nv:
                return 1
            for p in range(q):
                if faces[f, p] == v:
                    return 2
        for k in range(d):
            c = 0
            for q in range(d):
                if q != k:
                    r[c] = faces[f, q]
                    c += 1
            parity = 0
            for i in range(1, d - 1):  # insertion sort, counting swaps
                j = i
                while j > 0 and r[j - 1] > r[j]:
                    r[j - 1], r[j] = r[j], r[j - 1]
                    parity += 1
                    j -= 1
            key = 0
            for i in range(d - 1):
                key = key * nv + r[i]
            keys[f * d + k] = key
            s = 1 if k % 2 == 0 else -1
            sgn[f * d + k] = s if parity % 2 == 0 else -s
    return 0


@kernel
def _paired(keys):
    """The ridges sorted by key, or an empty array when a ridge is not in exactly two faces."""
    order = radix_argsort(keys)
    n = keys.shape[0]
    if n % 2:
        return order[:0]
    for i in range(0, n, 2):
        a, b = order[i], order[i + 1]
        if keys[a] != keys[b] or (i + 2 < n and keys[order[i + 2]] == keys[a]):
            return order[:0]
    return order


#: Most vertices of a triangulated surface :func:`cycle_code` checks by :func:`_closed_triangles`
#: (an ``nv`` by ``nv`` table of directed edges); larger ones are sorted.
TRIANGLES_MAX = 128


@kernel
def _closed_triangles(faces, nv):
    """Whether the triangles ``faces`` (F, 3) on ``nv`` vertices form a closed oriented cycle, as
    :func:`cycle_code` returning 0 states it, without sorting (time linear in ``F`` once an ``nv``
    by ``nv`` table is cleared): every index in range, no face repeating a vertex, and each edge of
    a face, directed along the face's vertex order (``a -> b -> c -> a``), in no other face in that
    direction and in one face in the other.
    That is :func:`cycle_code`'s condition: the sign of ridge ``k`` (:func:`_ridge_keys`) is +1
    exactly when the edge it leaves, so directed, goes from the smaller index to the larger, so
    two faces sharing a ridge have opposite signs exactly when they run along it in opposite
    directions."""
    F = faces.shape[0]
    for f in range(F):
        a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
        if min(a, b, c) < 0 or max(a, b, c) >= nv or a == b or b == c or a == c:
            return False
    seen = np.zeros((nv, nv), dtype=np.bool_)
    for f in range(F):
        for k in range(3):
            u, v = faces[f, k], faces[f, (k + 1) % 3]
            if seen[u, v]:
                return False
            seen[u, v] = True
    for f in range(F):
        for k in range(3):
            if not seen[faces[f, (k + 1) % 3], faces[f, k]]:
                return False
    return True


@kernel
def cycle_code(faces, nv):
    """Whether ``faces`` (F, d) on ``nv`` vertices form a closed oriented cycle: 0 yes; 1 an
    index out of range; 2 a face repeating a vertex; 3 a ridge not in exactly two faces; 4 two
    faces sharing a ridge with the same orientation. Ridges (a face without its ``k``-th
    vertex, sign ``(-1)^k`` times the parity of sorting the rest) are encoded as integers in
    base ``nv`` (the caller keeps ``nv^(d-1)`` below ``2^62``)."""
    F, d = faces.shape
    if d == 3 and 0 < nv <= TRIANGLES_MAX and _closed_triangles(faces, nv):
        return 0
    keys = np.empty(F * d, dtype=np.int64)
    sgn = np.empty(F * d, dtype=np.int64)
    code = _ridge_keys(faces, nv, keys, sgn)
    if code:
        return code
    order = stable_argsort(keys)  # the merge sort the planar kernels compile anyway
    n = F * d
    if n % 2:
        return 3
    for i in range(0, n, 2):
        a, b = order[i], order[i + 1]
        if keys[a] != keys[b] or (i + 2 < n and keys[order[i + 2]] == keys[a]):
            return 3
        if sgn[a] + sgn[b] != 0:
            return 4
    return 0


@kernel
def orient_cycle(faces, nv, seed, flip_seed):
    """Which faces of a closed surface to turn over (swap two vertices of) so that every two
    faces sharing a ridge are oppositely oriented (:func:`cycle_code`), the face ``seed`` turned
    over when ``flip_seed``: propagated from it across the ridges, so the orientation is decided
    once, not by a sign of each face. Returns ``(flip, reached)``: nothing is reached when a ridge
    is not in exactly two faces, an index is out of range or repeated in a face, or the surface
    cannot be oriented; only the seed's piece when the surface has more than one (so the faces
    form one closed oriented surface exactly when all are reached)."""
    F, d = faces.shape
    flip = np.zeros(F, dtype=np.bool_)
    reached = np.zeros(F, dtype=np.bool_)
    keys = np.empty(F * d, dtype=np.int64)
    sgn = np.empty(F * d, dtype=np.int64)
    if F == 0 or _ridge_keys(faces, nv, keys, sgn):
        return flip, reached
    order = _paired(keys)
    if order.shape[0] < F * d:
        return flip, reached
    partner = np.empty(F * d, dtype=np.int64)
    for i in range(0, F * d, 2):
        partner[order[i]], partner[order[i + 1]] = order[i + 1], order[i]
    stack = np.empty(F, dtype=np.int64)
    stack[0], top = seed, 1
    flip[seed], reached[seed] = flip_seed, True
    while top:
        top -= 1
        f = stack[top]
        for k in range(d):
            a = f * d + k
            b = partner[a]
            g = b // d
            # opposite induced signs after turning: turned faces negate every ridge's sign
            turn = flip[f] != (sgn[a] == sgn[b])
            if not reached[g]:
                flip[g] = turn
                reached[g] = True
                stack[top] = g
                top += 1
            elif flip[g] != turn:  # a loop of faces that cannot be oriented
                return flip, np.zeros(F, dtype=np.bool_)
    return flip, reached

"""Planar grasps in one compiled pass per grasp (numba): generator wrenches with error bounds,
the closure LP in closed form, certificates re-checked in floating point, and the exact planar
epsilon (:func:`planar_batch`, the columnar path of :mod:`qualgrasp.certify.batch.fastpath`)."""

from __future__ import annotations

import numpy as np

from .epsilon import planar_epsilon_one
from .jit import kernel
from .linalg import ETA, U, gamma, null_direction, pivot_basis_into, projection_bound, thin
from .cones import farkas_direction
from .lp import lp_planar_one
from .recheck import verify_farkas_general, verify_interior_general, verify_null_general

__all__ = ["DUAL_BELOW", "planar_generators", "planar_batch", "thin_screen", "pair_null_rows"]

#: The LP's dual bases are scanned only below this optimum (a verdict against closure, or a
#: near-degenerate one, needs the dual direction; a clear closure does not).
DUAL_BELOW = 1e-3


@kernel
def planar_generators(P, N, mu, width, c, L, owner, offset, friction, W, E):
    """Generator wrenches ``W`` (3, k) of one planar grasp, with the arithmetic of
    :func:`qualgrasp.certify.core.wrench.generator_columns` (same operations, same order, so the same
    floats), and bounds ``E`` on their distance to the exact values on the same data.

    Generator ``j`` of contact ``i = owner[j]`` is the force ``f = n + (friction_j mu_i) t``
    at ``q = p + (offset_j width_i) t`` (``t = (-n_y, n_x)``), its wrench
    ``(f, ((q - c) x f) / L)``. Bounds (``gamma_k = k u / (1 - k u)``, Higham; ``eta`` the
    smallest subnormal, the absolute error of a product that underflows): the force is exact
    when ``friction_j = 0`` and within ``gamma_2 (|n| + |s t|) + 2 eta`` per component otherwise
    (``s = friction_j mu_i``); the lever ``r = q - c`` within ``gamma_1 |r|`` (of the computed
    ``r``) when ``offset_j = 0`` and ``gamma_4 (|p| + |o t| + |c|) + 2 eta`` otherwise
    (``o = offset_j width_i``); the torque within ``(|r_x| e_fy + (|f_y| + e_fy) e_rx + |r_y| e_fx
    + (|f_x| + e_fx) e_ry + gamma_4 (|r_x f_y| + |r_y f_x|) + 4 eta) (1 + 2u) / L + eta``. The
    bounds are computed in floating point; the factor ``1 + 2u`` and the slack of ``gamma_4``
    over the torque's three roundings cover the rounding of the bound itself."""
    k = owner.shape[0]
    for j in range(k):
        i = owner[j]
        nx, ny = N[i, 0], N[i, 1]
        tx, ty = -ny, nx
        if friction[j] != 0.0:
            sm = friction[j] * mu[i]
            fx = nx + sm * tx
            fy = ny + sm * ty
            efx = gamma(2) * (abs(nx) + abs(sm * tx)) + 2 * ETA
            efy = gamma(2) * (abs(ny) + abs(sm * ty)) + 2 * ETA
        else:
            fx, fy = nx, ny
            efx, efy = 0.0, 0.0
        if offset[j] != 0.0:
            so = offset[j] * width[i]
            rx = (P[i, 0] + so * tx) - c[0]
            ry = (P[i, 1] + so * ty) - c[1]
            erx = gamma(4) * (abs(P[i, 0]) + abs(so * tx) + abs(c[0])) + 2 * ETA
            ery = gamma(4) * (abs(P[i, 1]) + abs(so * ty) + abs(c[1])) + 2 * ETA
        else:
            rx = P[i, 0] - c[0]
            ry = P[i, 1] - c[1]
            erx, ery = gamma(1) * abs(rx), gamma(1) * abs(ry)
        W[0, j] = fx
        W[1, j] = fy
        W[2, j] = (rx * fy - ry * fx) / L
        E[0, j] = efx
        E[1, j] = efy
        E[2, j] = (abs(rx) * efy + (abs(fy) + efy) * erx + abs(ry) * efx + (abs(fx) + efx) * ery
                   + gamma(4) * (abs(rx * fy) + abs(ry * fx)) + 4 * ETA) * (1.0 + 2 * U) / L + ETA


@kernel
def _classify(Wb, Eb, combos, feas, margin, residual_tol, C, D, buf, R, used, lam, y, basis,
              rays, first, ones, zeros2, zeros1, no_tight):
    """Verdict of one planar generator matrix, settled only where the per-grasp rules of
    :func:`qualgrasp.certify.core.closure.decide` give it without exact arithmetic and the certificate is proved
    by the float re-check: 1 closure (``lam``, ``basis``), 2 strict Farkas (``y``), 3 null-space
    Farkas (``y``, fewer than 3 generators), 0 not settled. A strictly separating dual direction
    is a certificate whatever the rank (``decide`` tries it before the rank test), so thin
    matrices are left unsettled only when they have none. Returns ``(code, t)``. The block
    layout of the re-check (every generator a ray: ``rays`` 0, ``first`` 0..k-1, ``ones`` (k,)
    widths, ``zeros2`` (k, 2), ``zeros1`` (k,), ``no_tight`` (k,) False) is passed in, not
    allocated per grasp."""
    k = Wb.shape[1]
    if k < 3:
        yy = null_direction(Wb)
        y[0], y[1], y[2] = yy[0], yy[1], yy[2]
        return (3 if verify_null_general(Wb, Eb, y) else 0), -np.inf
    t, has_y = lp_planar_one(Wb, combos, feas, DUAL_BELOW, C, D, buf, lam, y)
    if t >= margin:
        if thin(Wb):
            return 0, t  # closure needs full rank: the per-grasp path decides
        pivot_basis_into(Wb, R[:, :Wb.shape[1]], basis, used)
        ok = verify_interior_general(Wb, Eb, rays[:k], first[:k], ones[:k], zeros2[:k], zeros1[:k],
                                     zeros1[:k], lam, basis, residual_tol)
        return (1 if ok else 0), t
    if not has_y:
        return 0, t
    norm = np.sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2])
    if not (norm > 0.0 and np.isfinite(norm)):
        return 0, t
    y0, y1, y2 = y[0], y[1], y[2]  # the solver's direction, kept for the rows left unsettled
    y[0], y[1], y[2] = y[0] / norm, y[1] / norm, y[2] / norm
    scale = 0.0
    for j in range(k):
        for i in range(3):
            scale = max(scale, abs(Wb[i, j]))
    ok = True
    for j in range(k):
        a = Wb[0, j] * y[0] + Wb[1, j] * y[1] + Wb[2, j] * y[2]
        if abs(a) <= 1e-7 * scale or not a < -1e-9 * scale:
            ok = False  # tight contacts or no strict separation: per-grasp path
            break
    if ok:
        ok = verify_farkas_general(Wb, Eb, rays[:k], first[:k], ones[:k], zeros2[:k], zeros1[:k],
                                   zeros1[:k], y, no_tight[:k], 0.0)
    if not ok:
        y[0], y[1], y[2] = y0, y1, y2
    return (2 if ok else 0), t


@kernel
def planar_batch(P, N, mu, width, c, L, owner, offset, friction, combos, owner_f, offset_f,
                 friction_f, combos_f, form_same, margin, feas, residual_tol, quality):
    """Certify a batch of planar grasps sharing one contact pattern, in one compiled pass.

    ``P``, ``N`` (B, m, 2), ``mu``, ``width`` (B, m), ``c`` (B, 2), ``L`` (B,);
    ``owner``/``offset``/``friction`` the force generators' layout (see
    :func:`planar_generators`), ``owner_f``/``offset_f``/``friction_f`` the form (frictionless)
    generators'; ``combos``/``combos_f`` their 3-subsets. For force and form closure: verdict codes (see
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
    rays = np.zeros(kk, dtype=np.int64)
    first = np.arange(kk)
    ones = np.ones(kk, dtype=np.int64)
    zeros2 = np.zeros((kk, 2))
    zeros1 = np.zeros(kk)
    no_tight = np.zeros(kk, dtype=np.bool_)
    for b in range(B):
        planar_generators(P[b], N[b], mu[b], width[b], c[b], L[b], owner, offset, friction, W, E)
        code[b], t[b] = _classify(W, E, combos, feas, margin, residual_tol, C, D, buf, R, used,
                                  lam[b], y[b], basis[b], rays, first, ones, zeros2, zeros1, no_tight)
        if form_same:
            code_f[b], t_f[b] = code[b], t[b]
            lam_f[b, :] = lam[b, :kf]
            basis_f[b, :] = basis[b, :]
            y_f[b, :] = y[b, :]
        else:
            planar_generators(P[b], N[b], mu[b], width[b], c[b], L[b], owner_f, offset_f, friction_f,
                              Wf, Ef)
            code_f[b], t_f[b] = _classify(Wf, Ef, combos_f, feas, margin, residual_tol, C, D, buf,
                                          R, used, lam_f[b], y_f[b], basis_f[b], rays, first, ones,
                                          zeros2, zeros1, no_tight)
        if quality and code[b] == 1:
            eps[b, 0] = planar_epsilon_one(W, owner, m, False)[0]
            eps[b, 1] = planar_epsilon_one(W, owner, m, True)[0]
    return code, t, lam, basis, y, code_f, t_f, lam_f, basis_f, y_f, eps


@kernel
def _two_prod(a, b):
    """``a b = p + e`` exactly (Dekker's product; no overflow or underflow, see :func:`_in_range`)."""
    p = a * b
    c = 134217729.0 * a
    ah = c - (c - a)
    al = a - ah
    c = 134217729.0 * b
    bh = c - (c - b)
    bl = b - bh
    return p, ((ah * bh - p) + ah * bl + al * bh) + al * bl


@kernel
def _in_range(x):
    """Zero, or of a magnitude whose products of four stay far from underflow and overflow."""
    a = abs(x)
    return a == 0.0 or (a > 2.0 ** -100 and a < 2.0 ** 100)


@kernel
def _cross_terms(a, b, c, d, out, at):
    """The exact ``a d - b c`` as 4 floats ``out[at:at+4]``."""
    p, e = _two_prod(a, d)
    q, f = _two_prod(b, c)
    out[at], out[at + 1], out[at + 2], out[at + 3] = p, e, -q, -f


@kernel
def _minor_nonzero(P, N, i, j, l, rt, mt, terms):
    """Rigorous float proof that the exact determinant of the columns ``(n_x, n_y, p x n)`` of
    contacts ``i, j, l`` is not zero: its 96 terms are exact products
    (:func:`_two_prod`), summed by the cascade of Ogita, Rump and Oishi (Sum2), whose result is
    within ``u |s| + gamma_{n-1}^2 sum |terms|`` of the exact sum ``s``; beyond twice that bound
    the sum cannot be zero."""
    idx = (i, j, l)
    for a in range(3):
        c = idx[a]
        _cross_terms(P[c, 0], P[c, 1], N[c, 0], N[c, 1], rt, 4 * a)  # p x n = px ny - py nx
        b1, b2 = idx[(a + 1) % 3], idx[(a + 2) % 3]
        _cross_terms(N[b1, 0], N[b1, 1], N[b2, 0], N[b2, 1], mt, 4 * a)  # n_b1 x n_b2
    n = 0
    for a in range(3):  # det = sum over a of r_a (n_b1 x n_b2), cyclic
        for u in range(4):
            for v in range(4):
                p, e = _two_prod(rt[4 * a + u], mt[4 * a + v])
                terms[n], terms[n + 1] = p, e
                n += 2
    s = terms[0]
    sigma = 0.0
    total = abs(terms[0])
    for m in range(1, n):
        x = terms[m]
        t = s + x
        z = t - s
        sigma += (s - (t - z)) + (x - z)
        s = t
        total += abs(x)
    g = gamma(n - 1)
    return abs(s + sigma) > 2.0 * g * g * total * (1.0 + gamma(n))


@kernel
def _full_rank(P, N, owner):
    """Proof in floats that the exact frictionless generators (one per contact, ``owner``) have
    rank 3 (some 3 x 3 minor of ``(n_x, n_y, p x n)`` not zero; a row operation away from the
    wrenches, whatever the center and length); False when not proved."""
    k = owner.shape[0]
    for j in range(k):
        i = owner[j]
        if not (_in_range(P[i, 0]) and _in_range(P[i, 1]) and _in_range(N[i, 0]) and _in_range(N[i, 1])):
            return False
    rt = np.empty(12)
    mt = np.empty(12)
    terms = np.empty(96)
    for a in range(k):
        for b in range(a + 1, k):
            for c in range(b + 1, k):
                if _minor_nonzero(P, N, owner[a], owner[b], owner[c], rt, mt, terms):
                    return True
    return False


@kernel
def _at_most_two(P, N, width, owner, one_each):
    """Proof that the exact generators (no friction edges: forces along the normals) have rank
    at most 2: every normal parallel to the first (``n_i x n_0 = 0`` exactly, by comparing
    error-free products: the force rows are then proportional), or, with one generator per
    contact (``one_each``: no pad offsets), at most two distinct contacts (point, normal and
    width equal as floats: equal generators)."""
    i0 = owner[0]
    a, b = N[i0, 0], N[i0, 1]
    parallel = not (a == 0.0 and b == 0.0) and _in_range(a) and _in_range(b)
    second = -1
    two = one_each
    for j in range(1, owner.shape[0]):
        i = owner[j]
        if parallel:
            if not (_in_range(N[i, 0]) and _in_range(N[i, 1])):
                parallel = False
            else:
                p, e = _two_prod(a, N[i, 1])
                q, f = _two_prod(b, N[i, 0])
                parallel = p == q and e == f
        if two and i != i0 and not _same_contact(P, N, width, i, i0):
            if second < 0:
                second = i
            elif i != second and not _same_contact(P, N, width, i, second):
                two = False
        if not (parallel or two):
            return False
    return True


@kernel
def _same_contact(P, N, width, i, j):
    return (P[i, 0] == P[j, 0] and P[i, 1] == P[j, 1] and N[i, 0] == N[j, 0] and N[i, 1] == N[j, 1]
            and width[i] == width[j])


@kernel
def pair_null_rows(W, E, Y):
    """For matrices ``W`` (B, 3, k) whose exact generators have rank at most 2, does the exact
    checker accept ``Y[b]`` as orthogonal to all of them? 1 proved (two generators proved
    independent in floats: the rank is 2 and their span is the generators'; the exact
    projection of ``y`` onto it is within ``1e-6 |y|``, :func:`projection_bound`), 0 refuted (a
    generator's functional on ``y`` alone is beyond twice that), -1 undecided."""
    B, d, k = W.shape
    out = np.full(B, -1, dtype=np.int64)
    C2 = np.empty((3, 2))
    E2 = np.empty((3, 2))
    g = gamma(5)
    for b in range(B):
        y = Y[b]
        ny = np.sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2])
        found = False
        for a in range(k):
            for c in range(a + 1, k):
                for i in range(3):
                    C2[i, 0], C2[i, 1] = W[b, i, a], W[b, i, c]
                    E2[i, 0], E2[i, 1] = E[b, i, a], E[b, i, c]
                bound = projection_bound(C2, E2, y)
                if np.isfinite(bound):
                    found = True
                    if bound <= 1e-6 * ny * (1.0 - 8 * U):
                        out[b] = 1
                    break
            if found:
                break
        if out[b] == 1:
            continue
        for j in range(k):  # |projection| >= |c . y| / |c| for any one generator c
            acc, err, nc = 0.0, 0.0, 0.0
            for i in range(3):
                acc += W[b, i, j] * y[i]
                err += (E[b, i, j] + g * abs(W[b, i, j])) * abs(y[i])
                nc += (abs(W[b, i, j]) + E[b, i, j]) ** 2
            nc = np.sqrt(nc) * (1 + 4 * U)
            if (abs(acc) - err) * (1 - 4 * U) > 2e-6 * ny * (1 + 4 * U) * nc:
                out[b] = 0
                break
    return out


@kernel
def thin_screen(W, E, Y, T, margin, rel, P, N, width, owner, no_friction, no_offset):
    """The columnar part of the rule for numerically rank-deficient planar generator matrices
    (``qualgrasp.certify.batch.fastpath``): for each of the ``B`` matrices ``W`` (B, 3, k) with
    error bounds ``E``, the solver's direction ``Y`` (B, 3) and optimum ``T`` (B,):

    * where ``T < margin`` and ``Y`` is not zero, the Farkas rule of
      :func:`qualgrasp.certify.core.closure.farkas_from_arrays` (same kernel, every generator a
      ray): ``ok``, its direction ``yf`` and tight generators ``tight``, and for a strict
      direction its rigorous float re-check ``proved``;
    * with generators without friction edges (``no_friction``; ``owner`` their contacts),
      ``at_most_two``: rank at most 2 proved (:func:`_at_most_two`); without pad offsets as
      well (``no_offset``), ``full``: rank 3 of the exact generators proved in floats
      (:func:`_full_rank`), sought only where rank at most 2 is not proved (which excludes it).
    """
    B, d, k = W.shape
    ok = np.zeros(B, dtype=np.bool_)
    proved = np.zeros(B, dtype=np.bool_)
    full = np.zeros(B, dtype=np.bool_)
    parallel = np.zeros(B, dtype=np.bool_)
    yf = np.zeros((B, 3))
    tight = np.zeros((B, k), dtype=np.bool_)
    rays = np.zeros(k, dtype=np.int64)
    first = np.arange(k)
    ones = np.ones(k, dtype=np.int64)
    n0 = np.zeros((k, 2))
    z = np.zeros(k)
    for b in range(B):
        if T[b] < margin and (Y[b, 0] != 0.0 or Y[b, 1] != 0.0 or Y[b, 2] != 0.0):
            ok[b], yy, tt = farkas_direction(W[b], rays, first, ones, n0, z, z, Y[b], rel)
            yf[b, :] = yy
            tight[b, :] = tt
            if ok[b] and not tt.any():
                proved[b] = verify_farkas_general(W[b], E[b], rays, first, ones, n0, z, z, yf[b], tt, 0.0)
        # rank at most 2 first: its proof is linear in the generators, and rules out rank 3,
        # whose search over minors is cubic (every minor of collinear contacts is zero)
        if no_friction:
            parallel[b] = _at_most_two(P[b], N[b], width[b], owner, no_offset)
        if no_friction and no_offset and not parallel[b]:
            full[b] = _full_rank(P[b], N[b], owner)
    return ok, yf, tight, proved, full, parallel

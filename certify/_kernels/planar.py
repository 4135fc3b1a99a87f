"""Planar grasps in one compiled pass per grasp (numba): generator wrenches with error bounds,
the closure LP in closed form, certificates re-checked in floating point, and the exact planar
epsilon (:func:`planar_batch`, the columnar path of :mod:`qualgrasp.certify.batch.fastpath`)."""

from __future__ import annotations

import numpy as np

from .epsilon import planar_epsilon_one
from .jit import kernel
from .linalg import ETA, U, gamma, null_direction, pivot_basis_into, thin
from .lp import lp_planar_one
from .recheck import verify_farkas_general, verify_interior_general, verify_null_general

__all__ = ["DUAL_BELOW", "planar_generators", "planar_batch"]

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
    Farkas (``y``, fewer than 3 generators), 0 not settled. Returns ``(code, t)``. The block
    layout of the re-check (every generator a ray: ``rays`` 0, ``first`` 0..k-1, ``ones`` (k,)
    widths, ``zeros2`` (k, 2), ``zeros1`` (k,), ``no_tight`` (k,) False) is passed in, not
    allocated per grasp."""
    k = Wb.shape[1]
    if k < 3:
        yy = null_direction(Wb)
        y[0], y[1], y[2] = yy[0], yy[1], yy[2]
        return (3 if verify_null_general(Wb, Eb, y) else 0), -np.inf
    t, has_y = lp_planar_one(Wb, combos, feas, DUAL_BELOW, C, D, buf, lam, y)
    if thin(Wb):
        return 0, t
    if t >= margin:
        pivot_basis_into(Wb, R[:, :Wb.shape[1]], basis, used)
        ok = verify_interior_general(Wb, Eb, rays[:k], first[:k], ones[:k], zeros2[:k], zeros1[:k],
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
    ok = verify_farkas_general(Wb, Eb, rays[:k], first[:k], ones[:k], zeros2[:k], zeros1[:k],
                               zeros1[:k], y, no_tight[:k], 0.0)
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

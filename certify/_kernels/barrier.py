"""The spatial closure SOCP through its dual, by a barrier method in the ``d = 6`` wrench
coordinates, compiled (numba): see :func:`socp_dual_barrier` and
:mod:`qualgrasp.certify.solvers.barrier`."""

from __future__ import annotations

import numpy as np

from .jit import kernel
from .linalg import cholesky_solve

__all__ = ["socp_dual_barrier", "barrier_batch"]


@kernel(inline=True)
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


@kernel
def socp_dual_barrier(Pm, T, rk, kappa, exit_below, gap_tol, max_newton):
    """The spatial closure SOCP (see :mod:`qualgrasp.certify.core.problem`) through its dual, by a barrier method.

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
            if not cholesky_solve(H, grad, step):
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


@kernel
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
    if cholesky_solve(G, r, lam):
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


@kernel(inline=True)
def _phi(y, tau, q, K, u, psi, rk):
    z = 1.0
    for i in range(y.shape[0]):
        z += q[i] * y[i]
    out = tau * z / K
    for b in range(u.shape[0]):
        out -= np.log(psi[b])
    return out


@kernel
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

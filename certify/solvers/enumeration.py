"""Exact, vectorised solution of the polyhedral min-weight LP by basis enumeration.

The LP ``max t : W lam = 0, 1'lam = 1, lam >= t`` has ``k + 1`` variables and ``d + 1``
equalities, so a vertex leaves at most ``d`` weights strictly above ``t``. For each set ``S`` of
``d`` generators the square system

    [W 1   W_S] [t  ]   [0]
    [ k    1' ] [s_S] = [1]          (lam = t 1 + s on S, lam = t elsewhere)

gives a basic solution; the transposed system gives the matching dual ``(y, z)`` with
``w_i . y = z`` on ``S`` and ``k z - (W 1) . y = 1``. Then ``t*`` is the largest ``t`` of a
primal-feasible basis (``s_S >= 0``) and equals the smallest ``z`` of a dual-feasible one
(``W' y <= z``). One matrix inverse per basis yields both. With ``k`` generators in ``d``
dimensions there are ``k choose d`` bases: 4 to 56 in the plane with up to 8 generators.

When no basis is primal feasible the equality system ``W lam = 0, 1'lam = 1`` has no solution,
which happens exactly when ``W' y = -1`` is solvable: that ``y`` separates strictly.
"""

from __future__ import annotations

from itertools import combinations

import numpy as np

from ..problem import ClosureProblem
from . import Solution

__all__ = ["enumerate_lp", "solve_enumeration", "EnumerationSolver"]

_FEAS = 1e-12  # feasibility slack on basic solutions, relative to their scale


def enumerate_lp(W: np.ndarray):
    """Solve a batch of min-weight LPs exactly.

    Parameters
    ----------
    W : ndarray, shape (B, d, k)
        Generator columns of ``B`` problems of the same size.

    Returns
    -------
    t : ndarray, shape (B,)
        Optimal margin, ``-inf`` where infeasible.
    lam : ndarray, shape (B, k)
        Optimal weights (NaN where infeasible).
    y : ndarray, shape (B, d)
        Dual direction with ``W' y <= t*`` (scaled so that ``k z - (W 1) . y = 1``); for
        infeasible problems ``W' y = -1``. NaN where no dual basis was found.
    """
    W = np.asarray(W, dtype=float)
    B, d, k = W.shape
    S = np.array(list(combinations(range(k), d)), dtype=int)
    M = np.empty((B, len(S), d + 1, d + 1))
    M[:, :, :d, 0] = W.sum(axis=2)[:, None, :]
    M[:, :, :d, 1:] = np.moveaxis(W[:, :, S], 1, 2)
    M[:, :, d, 0] = k
    M[:, :, d, 1:] = 1.0
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        det = np.linalg.det(M)  # singular bases are expected; they are masked next
    hadamard = np.prod(np.linalg.norm(M, axis=-2), axis=-1)
    ok = np.abs(det) > 1e-13 * hadamard
    M[~ok] = np.eye(d + 1)
    inv = np.linalg.inv(M)

    t_all = inv[..., 0, d]
    s_all = inv[..., 1:, d]
    primal = ok & np.all(s_all >= -_FEAS * (1 + np.abs(t_all))[..., None], axis=-1)
    y_all = -inv[..., 0, :d]
    z_all = inv[..., 0, d]
    Wy = np.einsum("bdk,bsd->bsk", W, y_all)
    scale = 1 + np.abs(z_all) + np.linalg.norm(y_all, axis=-1) * np.abs(W).max(axis=(1, 2))[:, None]
    dual = ok & np.all(Wy <= (z_all + _FEAS * scale)[..., None], axis=-1)

    rows = np.arange(B)
    tp = np.where(primal, t_all, -np.inf)
    best = np.argmax(tp, axis=1)
    t = tp[rows, best]
    lam = np.full((B, k), np.nan)
    feasible = np.isfinite(t)
    lam[feasible] = t[feasible, None]
    Sb = S[best]
    sb = s_all[rows, best]
    for j in range(d):
        lam[rows[feasible], Sb[feasible, j]] += sb[feasible, j]

    zd = np.where(dual, z_all, np.inf)
    bestd = np.argmin(zd, axis=1)
    y = np.where(np.isfinite(zd[rows, bestd])[:, None], y_all[rows, bestd], np.nan)
    if not feasible.all():
        # No equilibrium with unit weight: W' y = -1 is consistent; take its least-squares solution.
        for b in np.flatnonzero(~feasible):
            y[b] = np.linalg.lstsq(W[b].T, -np.ones(k), rcond=None)[0]
    return t, lam, y


def solve_enumeration(problem: ClosureProblem) -> Solution:
    """Solve one polyhedral closure programme by enumeration."""
    if problem.cones:
        raise ValueError("enumeration solves polyhedral programmes only")
    t, lam, y = enumerate_lp(problem.columns[None])
    if not np.isfinite(t[0]):
        return Solution("infeasible", -np.inf, None, y[0])
    return Solution("optimal", float(t[0]), lam[0], None if np.isnan(y[0]).any() else y[0])


class EnumerationSolver:
    """Solver object wrapping :func:`solve_enumeration` (polyhedral programmes only)."""

    def solve(self, problem: ClosureProblem) -> Solution:
        return solve_enumeration(problem)

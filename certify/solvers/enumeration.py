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

from functools import lru_cache
from itertools import chain, combinations
from math import comb

import numpy as np

from .._kernels.lp import lp_enumerate, lp_planar
from ..core.problem import ClosureProblem
from .base import Solution

__all__ = ["FEAS", "bases", "enumerate_lp", "solve_enumeration", "EnumerationSolver"]

#: Feasibility slack on basic solutions, relative to their scale.
FEAS = 1e-12


@lru_cache(maxsize=64)
def bases(k: int, d: int) -> np.ndarray:
    """All ``d``-subsets of ``range(k)`` as an int array (nS, d), in the order of
    :func:`itertools.combinations`. Kept per size: a grasp-by-grasp run asks for the same
    thousands of bases for every grasp (the kernels only read them; do not write to it).

    Examples
    --------
    >>> bases(4, 3).tolist()
    [[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]]
    """
    flat = chain.from_iterable(combinations(range(k), d))
    return np.fromiter(flat, dtype=np.int64, count=comb(k, d) * d).reshape(-1, d)


def enumerate_lp(W: np.ndarray):
    """Solve a batch of min-weight LPs exactly (compiled kernels of :mod:`qualgrasp.certify._kernels.lp`).

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
    W = np.ascontiguousarray(W, dtype=float)
    _, d, k = W.shape
    kernel = lp_planar if d == 3 else lp_enumerate
    t, lam, y, has_y = kernel(W, bases(k, d), FEAS)
    y[~has_y] = np.nan
    return t, lam, y


def solve_enumeration(problem: ClosureProblem) -> Solution:
    """Solve one polyhedral closure programme by enumeration."""
    if problem.cones:
        raise ValueError("enumeration solves polyhedral programmes only")
    t, lam, y = enumerate_lp(problem.columns[None])
    y = None if np.isnan(y[0]).any() else y[0]
    if not np.isfinite(t[0]):
        return Solution("infeasible", -np.inf, None, y)
    return Solution("optimal", float(t[0]), lam[0], y)


class EnumerationSolver:
    """Solver object wrapping :func:`solve_enumeration` (polyhedral programmes only)."""

    def solve(self, problem: ClosureProblem) -> Solution:
        return solve_enumeration(problem)

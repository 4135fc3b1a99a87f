"""The polyhedral closure LP through scipy's ``linprog`` (HiGHS): a baseline for benchmarks.

``max t : W lam = 0, 1'lam = 1, lam - t >= 0`` with variables ``(lam, t)``; the duals of the
equality rows (HiGHS marginals) give the Farkas-oriented direction. An infeasible programme has
no duals from HiGHS; then ``W' y = -1`` is solvable and its least-squares solution separates.
Cones are not handled.
"""

from __future__ import annotations

import numpy as np

from ..errors import SolverError
from ..core.problem import ClosureProblem
from .base import Solution

__all__ = ["LinprogSolver"]


class LinprogSolver:
    """Solve polyhedral closure programmes with ``scipy.optimize.linprog`` (HiGHS)."""

    def solve(self, problem: ClosureProblem) -> Solution:
        from scipy.optimize import linprog  # a benchmark's method: scipy.optimize stays out of certify's start-up

        if problem.cones:
            raise ValueError("linprog solves polyhedral programmes only")
        d, k = problem.columns.shape
        c = np.zeros(k + 1)
        c[-1] = -1.0
        A_eq = np.zeros((d + 1, k + 1))
        A_eq[:d, :k] = problem.columns
        A_eq[d, :k] = 1.0
        b_eq = np.zeros(d + 1)
        b_eq[d] = 1.0
        A_ub = np.hstack([-np.eye(k), np.ones((k, 1))])  # t - lam <= 0
        res = linprog(c, A_ub=A_ub, b_ub=np.zeros(k), A_eq=A_eq, b_eq=b_eq,
                      bounds=[(None, None)] * (k + 1), method="highs")
        if res.status == 0:
            return Solution("optimal", float(res.x[-1]), res.x[:k], res.eqlin.marginals[:d])
        if res.status == 2:
            y = np.linalg.lstsq(problem.columns.T, -np.ones(k), rcond=None)[0]
            return Solution("infeasible", -np.inf, None, y)
        raise SolverError(f"linprog failed: {res.message}")

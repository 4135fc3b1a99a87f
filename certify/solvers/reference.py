"""The readable reference formulation of the closure programme, in cvxpy (CLARABEL backend).

This is the programme of :mod:`qualgrasp.certify.core.problem` written as it reads::

    maximise t
    subject to  columns @ x == 0, normal @ x == 1,
                x[rays] >= t, SOC(kappa * x_n - t, x_tan) for every cone block

With ``parametric=True`` (default) one cvxpy problem per structure is built with Parameters and
re-solved (DPP); with ``parametric=False`` the problem is rebuilt for every call, as naive code does.
"""

from __future__ import annotations

import warnings

import cvxpy as cp
import numpy as np

from ..errors import SolverError
from ..core.problem import ClosureProblem
from .base import Solution

__all__ = ["CvxpySolver"]

_OPTIONS = dict(tol_gap_abs=1e-10, tol_gap_rel=1e-10, tol_feas=1e-10)


def _build(problem: ClosureProblem, parametric: bool):
    d, nvar = problem.columns.shape
    x, t = cp.Variable(nvar), cp.Variable()
    columns = cp.Parameter((d, nvar)) if parametric else problem.columns
    kappa = cp.Parameter(len(problem.cones), nonneg=True) if parametric and problem.cones else None
    equilibrium = columns @ x == 0
    constraints = [equilibrium, problem.normal @ x == 1]
    if problem.rays:
        constraints.append(x[list(problem.rays)] >= t)
    for j, (start, size, mu) in enumerate(problem.cones):
        k = kappa[j] if kappa is not None else mu
        constraints.append(cp.SOC(k * x[start] - t, x[start + 1:start + size]))
    return cp.Problem(cp.Maximize(t), constraints), x, t, equilibrium, columns, kappa


class CvxpySolver:
    """Reference route: the closure programme in cvxpy, solved by CLARABEL."""

    def __init__(self, parametric: bool = True) -> None:
        self.parametric = parametric
        self._built: dict[tuple, tuple] = {}

    def solve(self, problem: ClosureProblem) -> Solution:
        key = problem.structure
        if not self.parametric:
            built = _build(problem, False)
        elif key in self._built:
            built = self._built[key]
        else:
            built = self._built[key] = _build(problem, True)
        prob, x, t, equilibrium, columns, kappa = built
        if self.parametric:
            columns.value = problem.columns
            if kappa is not None:
                kappa.value = np.array([mu for _, _, mu in problem.cones])
        try:
            with warnings.catch_warnings():
                # "Solution may be inaccurate": the status says so and is handled below.
                warnings.simplefilter("ignore", UserWarning)
                prob.solve(solver=cp.CLARABEL, **_OPTIONS)
        except cp.error.SolverError as err:
            raise SolverError(f"cvxpy/CLARABEL failed: {err}") from None
        # cvxpy's dual of `columns @ x == 0` is the multiplier of `columns @ x` in the Lagrangian
        # of the minimisation of -t; its negative is the Farkas-oriented direction.
        y = equilibrium.dual_value
        if prob.status in (cp.OPTIMAL, cp.OPTIMAL_INACCURATE):
            return Solution("optimal", float(t.value), np.asarray(x.value), -np.asarray(y))
        if prob.status in (cp.INFEASIBLE, cp.INFEASIBLE_INACCURATE):
            y = -np.asarray(y)
            return Solution("infeasible", -np.inf, None, y / np.linalg.norm(y))
        raise SolverError(f"cvxpy returned status {prob.status}")

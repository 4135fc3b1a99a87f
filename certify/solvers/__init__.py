"""Solver routes for the closure programme of :mod:`qualgrasp.certify.problem`.

Three routes solve the same programme and return a :class:`Solution`:

* ``"reference"``: :class:`CvxpySolver`, the readable cvxpy formulation (CLARABEL backend).
* ``"fast"``: exact vertex enumeration for small polyhedral problems (vectorised numpy, the
  planar case) and :class:`ClarabelSolver`, clarabel's own API with prebuilt sparse structure,
  for the rest.

A solver instance caches prebuilt problems by sparsity structure, so reuse one instance across
many grasps; nothing is cached globally.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..problem import ClosureProblem

__all__ = ["Solution", "make_solver", "FastSolver"]


@dataclass(frozen=True, eq=False)
class Solution:
    """Outcome of one closure programme.

    Attributes
    ----------
    status : {'optimal', 'infeasible'}
        ``infeasible`` when no equilibrium with unit total normal force exists at all.
    t : float
        Optimal margin ``t*`` (``-inf`` when infeasible).
    x : ndarray or None
        Optimal variables (solver coordinates).
    y : ndarray or None
        Dual direction of the equilibrium rows, oriented as a Farkas direction: every achievable
        wrench ``w`` has ``y . w <= t* (sum of normal forces)``; when ``t* < 0`` (or infeasible)
        ``y`` is a strict separating direction.
    """

    status: str
    t: float
    x: np.ndarray | None
    y: np.ndarray | None


#: Barrier solutions with ``abs(t) <`` this are re-solved by clarabel.
BARRIER_NEAR_ZERO = 1e-5


class FastSolver:
    """Exact enumeration for small polyhedral programmes, the compiled dual barrier method for
    cones and large polyhedral programmes, clarabel's API for the rest (programmes whose barrier
    solution is within :data:`BARRIER_NEAR_ZERO` of the closure boundary, where the
    interior-point solver's sharper duals tell tight contacts apart), except where the
    closed-form squeeze direction of two point contacts proves ``t* = 0``
    (:func:`qualgrasp.certify.solvers.squeeze.squeeze_solution`)."""

    #: Largest number of bases (``k choose d``) enumerated before handing over to clarabel.
    max_bases = 64

    def __init__(self) -> None:
        from .barrier import BarrierSolver
        from .clarabel_direct import ClarabelSolver

        self._clarabel = ClarabelSolver()
        self._barrier = BarrierSolver()

    def solve(self, problem: ClosureProblem) -> Solution:
        from math import comb

        from .enumeration import solve_enumeration

        if problem.cones or comb(problem.nvar, problem.d) > self.max_bases:
            sol = self._barrier.solve(problem)
            if sol is not None and abs(sol.t) >= BARRIER_NEAR_ZERO:
                return sol
            return self.solve_near_boundary(problem)
        sol = solve_enumeration(problem)
        if sol.y is not None or (sol.status == "optimal" and sol.t > 0):
            return sol
        # A verdict against closure needs a dual direction, and no dual basis survived the
        # feasibility tolerance (numerically tied bases): the interior-point route has one.
        return self._clarabel.solve(problem)

    def solve_near_boundary(self, problem: ClosureProblem) -> Solution:
        """What :meth:`solve` does with a programme whose barrier solution is within
        :data:`BARRIER_NEAR_ZERO` of the boundary (or did not converge): the squeeze rule,
        else clarabel."""
        from .squeeze import squeeze_solution

        return squeeze_solution(problem) or self._clarabel.solve(problem)


def make_solver(method: str = "fast"):
    """A solver instance for ``method`` in ``{'fast', 'reference', 'clarabel', 'enumeration',
    'linprog'}``."""
    if method == "fast":
        return FastSolver()
    if method == "reference":
        from .reference import CvxpySolver

        return CvxpySolver()
    if method == "clarabel":
        from .clarabel_direct import ClarabelSolver

        return ClarabelSolver()
    if method == "enumeration":
        from .enumeration import EnumerationSolver

        return EnumerationSolver()
    if method == "linprog":
        from .linprog import LinprogSolver

        return LinprogSolver()
    raise ValueError(f"unknown method {method!r}; use 'fast' or 'reference'")

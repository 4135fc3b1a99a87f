"""The fast route: exact enumeration, the compiled dual barrier method, the squeeze rule and
clarabel, each where it is best (see :class:`FastSolver`)."""

from __future__ import annotations

from math import comb

from ..problem import ClosureProblem
from .barrier import BarrierSolver
from .base import BARRIER_NEAR_ZERO, Solution
from .clarabel_direct import ClarabelSolver
from .enumeration import solve_enumeration
from .squeeze import squeeze_solution

__all__ = ["FastSolver"]


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
        self._clarabel = ClarabelSolver()
        self._barrier = BarrierSolver()

    def solve(self, problem: ClosureProblem) -> Solution:
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
        return squeeze_solution(problem) or self._clarabel.solve(problem)

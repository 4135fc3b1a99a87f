"""The fast route: exact enumeration, the compiled dual barrier method, the squeeze rule and
clarabel, each where it is best (see :class:`FastSolver`)."""

from __future__ import annotations

from math import comb

from ..core.problem import ClosureProblem
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

    #: Largest number of bases (``k choose d``) of a spatial programme (``d = 6``) enumerated
    #: before handing over to the barrier method.
    max_bases = 64
    #: The same for planar programmes (``d = 3``), whose 3 x 3 bases are cheap: up to 30
    #: generators (10 friction pads, 15 point contacts) are solved exactly by enumeration.
    max_planar_bases = 4096

    @classmethod
    def enumerates(cls, nvar: int, d: int) -> bool:
        """Whether a polyhedral programme of ``nvar`` generators in ``d`` wrench dimensions is
        solved by enumerating its bases (the rule the columnar path follows too)."""
        return comb(nvar, d) <= (cls.max_planar_bases if d == 3 else cls.max_bases)

    def __init__(self) -> None:
        self._clarabel = ClarabelSolver()
        self._barrier = BarrierSolver()

    def solve(self, problem: ClosureProblem) -> Solution:
        if problem.cones or not self.enumerates(problem.nvar, problem.d):
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

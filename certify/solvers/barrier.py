"""Spatial closure programmes through their dual, by the compiled barrier method of
:func:`qualgrasp.certify._kernels.barrier.socp_dual_barrier`: a few dozen Newton steps in the ``d = 6`` wrench
coordinates, tens of microseconds per grasp, no solver library call."""

from __future__ import annotations

import numpy as np

from .._kernels.barrier import socp_dual_barrier
from ..core.problem import ClosureProblem
from .base import Solution

__all__ = ["BarrierSolver", "barrier_arrays", "EXIT_BELOW", "GAP_TOL"]

#: Stop as soon as the dual bound ``z(y)`` falls below this: ``y`` separates strictly.
EXIT_BELOW = -1e-6
#: Duality gap bound ``nu / tau`` at which the central path is left.
GAP_TOL = 1e-9
MAX_NEWTON = 400


def barrier_arrays(problem: ClosureProblem):
    """``(Pm, T, rk, kappa, blocks)`` of :func:`socp_dual_barrier` for ``problem``: one block per
    ray (``kappa = 1``, no tangential columns) then per cone; ``blocks`` lists their
    ``(start, size)`` in the problem's variables."""
    blocks = [(r, 1, 1.0) for r in problem.rays] + list(problem.cones)
    d = problem.d
    rmax = max([size - 1 for _, size, _ in problem.cones] + [1])
    Pm = np.zeros((len(blocks), d))
    T = np.zeros((len(blocks), rmax, d))
    rk = np.zeros(len(blocks), dtype=np.int64)
    kappa = np.ones(len(blocks))
    for b, (start, size, mu) in enumerate(blocks):
        Pm[b] = problem.columns[:, start]
        if size > 1:
            T[b, : size - 1] = problem.columns[:, start + 1:start + size].T
            rk[b], kappa[b] = size - 1, mu
    return Pm, T, rk, kappa, [(start, size) for start, size, _ in blocks]


class BarrierSolver:
    """Closure programmes with cones, by the compiled dual barrier method.

    ``solve`` returns None when the method did not converge (the caller falls back to an
    interior-point solver).
    """

    def solve(self, problem: ClosureProblem) -> Solution | None:
        Pm, T, rk, kappa, blocks = barrier_arrays(problem)
        status, t, z, y, xn, xt = socp_dual_barrier(Pm, T, rk, kappa, EXIT_BELOW, GAP_TOL, MAX_NEWTON)
        if status == 2:
            return None
        if status == 1:
            return Solution("optimal", float(t), None, y)
        x = np.zeros(problem.nvar)
        for b, (start, size) in enumerate(blocks):
            x[start] = xn[b]
            x[start + 1:start + size] = xt[b, : size - 1]
        return Solution("optimal", float(t), x, y)

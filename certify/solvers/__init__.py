"""Solver routes for the closure programme of :mod:`qualgrasp.certify.core.problem`.

Every route solves the same programme and returns a :class:`Solution`
(:func:`make_solver` by name):

* ``"fast"`` (:class:`FastSolver`): exact basis enumeration for small polyhedral programmes
  (compiled), the compiled dual barrier method for cones and large LPs, the closed-form squeeze
  rule and clarabel near the closure boundary;
* ``"reference"``: the readable cvxpy formulation (CLARABEL backend), the route the others are
  tested against;
* ``"clarabel"``, ``"enumeration"``, ``"linprog"``: single methods, for benchmarks.

A solver instance caches prebuilt problems by sparsity structure, so reuse one instance across
many grasps; nothing is cached globally.
"""

from __future__ import annotations

from typing import Literal, get_args

from ..errors import ArgumentError
from .base import BARRIER_NEAR_ZERO, Solution
from .clarabel_direct import ClarabelSolver
from .enumeration import EnumerationSolver
from .fast import FastSolver
from .linprog import LinprogSolver

__all__ = ["Solution", "BARRIER_NEAR_ZERO", "make_solver", "FastSolver", "Method", "METHODS"]

#: A solver route (:func:`make_solver`).
Method = Literal["fast", "reference", "clarabel", "enumeration", "linprog", "reference-rebuilt"]
METHODS: tuple[str, ...] = get_args(Method)


def make_solver(method: Method = "fast"):
    """A solver instance for ``method`` in ``{'fast', 'reference', 'clarabel', 'enumeration',
    'linprog'}`` (``'reference-rebuilt'``: the reference formulation rebuilt for every problem,
    as naive cvxpy code does, for benchmarks).

    Raises
    ------
    ArgumentError
        Unknown ``method``.
    """
    if method == "fast":
        return FastSolver()
    if method in ("reference", "reference-rebuilt"):
        # cvxpy takes about 1.5 s to import and only this route needs it: imported on demand, so
        # that every command and the fast route start without it
        from .reference import CvxpySolver

        return CvxpySolver(parametric=method == "reference")
    if method == "clarabel":
        return ClarabelSolver()
    if method == "enumeration":
        return EnumerationSolver()
    if method == "linprog":
        return LinprogSolver()
    raise ArgumentError(f"unknown method {method!r}; use 'fast', 'reference', 'clarabel', 'enumeration' "
                     "or 'linprog'")

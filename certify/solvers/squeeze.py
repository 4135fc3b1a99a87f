"""The squeeze rule: a closed-form dual direction on the closure boundary.

A common way for a spatial grasp to sit exactly on the closure boundary (``t* = 0``) is a pair of
point contacts that squeeze the object: forces along the line through them balance, every other
contact carries nothing, and no wrench about that line can be resisted. The columns
``(e, (p - c) x e / L)`` of two point contacts at distinct points span exactly a 5-dimensional
subspace of wrench space, orthogonal to one direction ``y`` (the twist about the line through
them). If ``y`` or ``-y`` strictly separates every other contact's cone, it is a Farkas direction
with those two contacts tight, and ``t* = 0``.

An interior-point solution near ``t* = 0`` tells tight contacts apart only to the solver's
accuracy, at a few hundred microseconds a grasp; this rule gives the direction in closed form, so
:class:`qualgrasp.certify.solvers.FastSolver` tries it before handing a near-boundary programme to clarabel.
"""

from __future__ import annotations

from itertools import combinations

import numpy as np

from .._kernels.cones import farkas_direction, squeeze_direction
from ..core.cones import LORENTZ
from ..core.problem import ClosureProblem, block_arrays
from .base import Solution

__all__ = ["squeeze_solution", "squeeze_farkas"]


def squeeze_solution(problem: ClosureProblem) -> Solution | None:
    """``t* = 0`` with the squeeze direction of the first pair of point contacts (in index order)
    that gives a Farkas certificate (:func:`qualgrasp.certify.core.closure.farkas_certificate`) with exactly
    that pair tight; None if no pair does, or the system is not spatial.

    ``x`` is not returned: a verdict against closure does not use it.
    """
    C, blocks, _ = problem.system
    if C.shape[0] != 6:
        return None
    y = squeeze_farkas(np.ascontiguousarray(C, dtype=float), *block_arrays(blocks, 3))
    return None if y is None else Solution("optimal", 0.0, None, y)


def squeeze_farkas(C, cone, first, width, n, mu, g) -> np.ndarray | None:
    """The rule on a spatial certificate system given as block arrays
    (:func:`qualgrasp.certify.core.problem.block_arrays`): the squeeze direction ``y`` (or ``-y``) of the first
    pair of point blocks (Lorentz cones without moment columns) for which :func:`qualgrasp.certify.core.closure.farkas_certificate` gives a certificate
    with exactly that pair tight, else None."""
    points = np.flatnonzero((cone == LORENTZ) & (width == 3))
    for a, b in combinations(points, 2):
        cols = np.concatenate([first[a] + np.arange(3), first[b] + np.arange(3)])
        ok, y = squeeze_direction(C, cols)
        if not ok:
            continue
        for signed in (y, -y):
            good, _, tight = farkas_direction(C, cone, first, width, n, mu, g, signed, 1e-7)
            if good and tight[a] and tight[b] and tight.sum() == 2:
                return signed
    return None

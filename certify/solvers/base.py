"""What every solver route returns: :class:`Solution`, and the barrier method's hand-over
threshold."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Solution", "BARRIER_NEAR_ZERO"]


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

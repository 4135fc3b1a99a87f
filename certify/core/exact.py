"""Exact rational linear algebra for small dense matrices (d <= 6 rows).

Matrices are sequences of rows of :class:`fractions.Fraction` (or numpy object arrays of them).
Every float is a dyadic rational, so these routines decide ranks, solve systems and project
vectors exactly on the float data, with no rounding and no tolerance. :func:`rank` also takes
Python integers (exact scaled values, as built by
:func:`qualgrasp.certify.core.wrench.planar_generator_rank`).
"""

from __future__ import annotations

import math
from fractions import Fraction
from typing import Sequence

__all__ = ["row_echelon", "rank", "solve", "independent_columns", "project_out", "dyadic_integers", "unit_direction"]

Matrix = Sequence[Sequence[Fraction]]


def dyadic_integers(values) -> tuple[list[int], int]:
    """The floats ``values`` times ``2**s``, for the least ``s >= 0`` making them all integers:
    ``(integers, s)``. Integer arithmetic on them is exact and much cheaper than
    :class:`~fractions.Fraction` (and than a fixed scale such as ``2**1074``).

    Examples
    --------
    >>> dyadic_integers([0.75, -2.0, 3.0])
    ([3, -8, 12], 2)
    """
    ratios = [float(v).as_integer_ratio() for v in values]
    s = max((den.bit_length() - 1 for _, den in ratios), default=0)
    return [num << (s - den.bit_length() + 1) for num, den in ratios], s


def _pivots(R: list[list]):
    """Walk the columns of ``R`` (modified in place) for Gaussian elimination: for each column
    with a non-zero entry at or below the next pivot row ``r``, swap that row up to ``r`` and
    yield ``(r, c)``; the caller eliminates before the walk goes on."""
    r = 0
    for c in range(len(R[0]) if R else 0):
        p = next((i for i in range(r, len(R)) if R[i][c] != 0), None)
        if p is None:
            continue
        R[r], R[p] = R[p], R[r]
        yield r, c
        r += 1
        if r == len(R):
            return


def row_echelon(A: Matrix) -> tuple[list[list[Fraction]], list[int]]:
    """Reduced row echelon form of ``A`` and its pivot columns."""
    R = [list(row) for row in A]
    pivots: list[int] = []
    for r, c in _pivots(R):
        inv = 1 / R[r][c]
        R[r] = [v * inv for v in R[r]]
        for i in range(len(R)):
            if i != r and R[i][c] != 0:
                f = R[i][c]
                R[i] = [a - f * b for a, b in zip(R[i], R[r])]
        pivots.append(c)
    return R, pivots


def rank(A: Matrix) -> int:
    """Exact rank of ``A`` (Fractions or integers).

    Each row is scaled to integers (by the least common multiple of its denominators: the rank
    is unchanged) and eliminated without fractions, which is much cheaper than elimination over
    :class:`~fractions.Fraction`.

    Examples
    --------
    >>> from fractions import Fraction as F
    >>> rank([[F(1, 3), F(2, 3)], [F(1, 2), F(1)]]), rank([[1, 2, 3], [0, 1, 0]])
    (1, 2)
    """
    R = []
    for row in A:
        den = math.lcm(*(getattr(v, "denominator", 1) for v in row)) if len(row) else 1
        R.append([int(v * den) for v in row])
    found = 0
    for r, c in _pivots(R):
        g = R[r][c]
        for i in range(r + 1, len(R)):
            f = R[i][c]
            if f != 0:
                R[i] = [a * g - b * f for a, b in zip(R[i], R[r])]
        found = r + 1
    return found


def solve(A: Matrix, b: Sequence[Fraction]) -> list[Fraction] | None:
    """Solution of the square system ``A x = b``, or None when ``A`` is singular."""
    n = len(A)
    aug = [list(row) + [bi] for row, bi in zip(A, b)]
    R, pivots = row_echelon(aug)
    if pivots != list(range(n)):
        return None
    return [R[i][n] for i in range(n)]


def independent_columns(A: Matrix) -> list[int]:
    """Indices of a maximal set of linearly independent columns of ``A`` (its pivot columns)."""
    return row_echelon(A)[1]


def project_out(y: Sequence[Fraction], A: Matrix) -> list[Fraction]:
    """Component of ``y`` orthogonal to the column space of ``A``: ``y - B (B'B)^{-1} B'y``."""
    cols = independent_columns(A)
    if not cols:
        return list(y)
    B = [[row[j] for j in cols] for row in A]
    k = len(cols)
    BtB = [[sum(B[r][i] * B[r][j] for r in range(len(B))) for j in range(k)] for i in range(k)]
    Bty = [sum(B[r][i] * y[r] for r in range(len(B))) for i in range(k)]
    c = solve(BtB, Bty)
    assert c is not None  # B has independent columns, so B'B is invertible
    return [y[r] - sum(B[r][i] * c[i] for i in range(k)) for r in range(len(B))]


def unit_direction(v: Sequence[Fraction | int]) -> tuple[float, ...]:
    """The exact non-zero vector ``v`` rounded to a float unit vector: each component divided
    exactly by the largest magnitude, rounded once, then normalised in floats. Depends only on the
    direction of ``v`` (any positive multiple gives the same floats), so that two routes reaching
    the same exact direction by different scalings state the same certificate.

    Examples
    --------
    >>> unit_direction([3, 0, -4])
    (0.6, 0.0, -0.8)
    >>> unit_direction([Fraction(3, 7), 0, Fraction(-4, 7)])
    (0.6, 0.0, -0.8)
    """
    m = max(abs(Fraction(a)) for a in v)
    if m == 0:
        raise ValueError("the zero vector has no direction")
    u = [float(Fraction(a) / m) for a in v]
    n = math.sqrt(math.fsum(a * a for a in u))
    return tuple(a / n for a in u)


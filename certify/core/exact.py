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


def _integers(values) -> tuple[list[int], int]:
    """Rationals (Fractions or integers) ``values`` times the least common multiple ``den`` of
    their denominators: ``(integers, den)``."""
    den = math.lcm(*(v.denominator for v in values)) if len(values) else 1
    return [v.numerator * (den // v.denominator) for v in values], den


def _pivot_columns(A: Matrix) -> list[int]:
    """Pivot columns of ``A``'s row echelon form, by elimination without fractions: each row is
    scaled to integers (:func:`_integers`; the column dependencies are unchanged), which is much
    cheaper than elimination over :class:`~fractions.Fraction`."""
    R = [_integers(row)[0] for row in A]
    pivots = []
    for r, c in _pivots(R):
        g = R[r][c]
        for i in range(r + 1, len(R)):
            f = R[i][c]
            if f != 0:
                R[i] = [a * g - b * f for a, b in zip(R[i], R[r])]
        pivots.append(c)
    return pivots


def rank(A: Matrix) -> int:
    """Exact rank of ``A`` (Fractions or integers), eliminated without fractions.

    Examples
    --------
    >>> from fractions import Fraction as F
    >>> rank([[F(1, 3), F(2, 3)], [F(1, 2), F(1)]]), rank([[1, 2, 3], [0, 1, 0]])
    (1, 2)
    """
    return len(_pivot_columns(A))


def solve(A: Matrix, b: Sequence[Fraction]) -> list[Fraction] | None:
    """Solution of the square system ``A x = b``, or None when ``A`` is singular."""
    n = len(A)
    aug = [list(row) + [bi] for row, bi in zip(A, b)]
    R, pivots = row_echelon(aug)
    if pivots != list(range(n)):
        return None
    return [R[i][n] for i in range(n)]


def independent_columns(A: Matrix) -> list[int]:
    """Indices of a maximal set of linearly independent columns of ``A`` (its pivot columns,
    the first independent column each time, whatever the elimination).

    Examples
    --------
    >>> independent_columns([[1, 2, 0], [2, 4, 1]])
    [0, 2]
    """
    return _pivot_columns(A)


def _gram_solve(G: list[list[int]], b: list[int]) -> tuple[int, list[int]]:
    """``(det G, det G * G^{-1} b)`` of a positive definite integer matrix ``G``, exactly, by
    fraction-free (Bareiss) elimination: its pivots are the leading principal minors, positive,
    and every division is exact (the second result is integer by Cramer's rule)."""
    k = len(G)
    M = [list(row) + [bi] for row, bi in zip(G, b)]
    prev = 1
    for p in range(k):
        for i in range(p + 1, k):
            M[i] = [0] * (p + 1) + [(M[i][j] * M[p][p] - M[i][p] * M[p][j]) // prev for j in range(p + 1, k + 1)]
        prev = M[p][p]
    det = prev
    z = [0] * k
    for i in reversed(range(k)):
        z[i] = (det * M[i][k] - sum(M[i][j] * z[j] for j in range(i + 1, k))) // M[i][i]
    return det, z


def project_out(y: Sequence[Fraction], A: Matrix) -> list[Fraction]:
    """Component of ``y`` orthogonal to the column space of ``A``: ``y - B (B'B)^{-1} B'y``
    with ``B`` independent columns of ``A``, exactly.

    Evaluated in integers: scaling each column of ``B``, and ``y``, to integers
    (:func:`_integers`) changes neither the column space nor the projection's direction, and
    ``det(B'B) y - B adj(B'B) B'y`` is an integer vector (:func:`_gram_solve`); the exact rationals
    are that over ``det(B'B)`` and ``y``'s scale.

    Examples
    --------
    >>> from fractions import Fraction as F
    >>> project_out([F(1), F(2), F(3)], [[1, 0], [0, 1], [0, 0]])
    [Fraction(0, 1), Fraction(0, 1), Fraction(3, 1)]
    >>> project_out([F(1), F(1)], [[F(1, 3)], [F(-1, 3)]])
    [Fraction(1, 1), Fraction(1, 1)]
    """
    cols = independent_columns(A)
    if not cols:
        return list(y)
    B = [_integers([row[j] for row in A])[0] for j in cols]  # columns
    Y, scale = _integers(y)
    d, k = len(Y), len(B)
    G = [[sum(B[i][r] * B[j][r] for r in range(d)) for j in range(k)] for i in range(k)]
    det, z = _gram_solve(G, [sum(B[i][r] * Y[r] for r in range(d)) for i in range(k)])
    return [Fraction(det * Y[r] - sum(B[i][r] * z[i] for i in range(k)), det * scale) for r in range(d)]


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


"""Contact cones: the admissible values of one contact on its certificate columns.

Every cone block of a closure programme (:mod:`qualgrasp.certify.core.problem`) has one of two shapes,
declared by the contact models (:mod:`qualgrasp.certify.models`):

``ray``
    One column; admissible values ``v >= 0`` (a frictionless contact's normal force, or the
    weight of a generator of a polyhedral cone).
``lorentz``
    ``dim`` world-axis force columns, then optional moment columns (a soft finger's torsion):
    admissible values ``(f, m)`` with ``norm((f_t, m |n| / g)) <= mu f_n``, where ``f_n = f . n /
    |n|``, ``f_t = f - f_n n / |n|``, ``n`` the stored normal and ``g`` the block's moment length.

The tests below are written once, with sums, products and comparisons only, so they run the
same on floats and, exactly, on :class:`fractions.Fraction` (the certificate checker); the
compiled kernels (:mod:`qualgrasp.certify._kernels.cones`) evaluate the same formulas in floating
point. Both shapes' *polar* test ``a_n + mu norm((a_t, a_m g / |n|)) < 0`` says that the
functional ``a`` (``y . w`` on each column) is negative on the whole cone: the support of the
block's unit-normal-force wrenches along ``y``, also the piece of the support function that
epsilon uses.
"""

from __future__ import annotations

import math
from typing import Sequence

__all__ = ["CONES", "RAY", "LORENTZ", "cone_code", "inside", "polar", "slack"]

#: Cone shapes, in the order of their integer codes (used by the compiled kernels).
CONES = ("ray", "lorentz")
RAY, LORENTZ = 0, 1


def cone_code(name: str) -> int:
    """Integer code of a cone shape (``'ray'`` 0, ``'lorentz'`` 1)."""
    return CONES.index(name)


def _dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def inside(cone: str, v: Sequence, n: Sequence = (), mu=0, g=0) -> bool:
    """Is ``v`` (values on the block's columns) strictly inside the cone? Exact on Fractions:
    ``mu^2 f_n^2 |n|^2 > |n|^2 |f_t|^2 + (m |n|^2 / g)^2`` with ``f_n > 0``, squared."""
    if cone == "ray":
        return v[0] > 0
    dim = len(n)
    f = v[:dim]
    fn, nn, ff = _dot(f, n), _dot(n, n), _dot(f, f)
    tang = nn * ff - fn * fn  # nn * |f_t|^2
    for m in v[dim:]:
        tang += (m * nn / g) ** 2
    return fn > 0 and tang < mu * mu * fn * fn


def polar(cone: str, a: Sequence, n: Sequence = (), mu=0, g=0) -> bool:
    """Is ``a`` (the functional ``y @ w`` on the block's columns) in the cone's strict polar,
    ``a_n + mu norm((a_t, a_m g / |n|)) < 0``? Exact on Fractions (squared)."""
    if cone == "ray":
        return a[0] < 0
    dim = len(n)
    an, nn = _dot(a[:dim], n), _dot(n, n)
    tang = nn * _dot(a[:dim], a[:dim]) - an * an  # nn * |a_t|^2
    for am in a[dim:]:
        tang += (am * g) ** 2
    return an < 0 and mu * mu * tang < an * an


def slack(cone: str, v: Sequence[float], n: Sequence = (), mu=0.0, g=0.0) -> tuple[float, float]:
    """Float ``(slack, normal force)``: ``mu f_n - norm((f_t, m |n| / g))`` and ``f_n`` (``v[0]``
    twice for a ray): the block's term of the min-weight margin."""
    if cone == "ray":
        return float(v[0]), float(v[0])
    dim = len(n)
    rn = math.sqrt(float(_dot(n, n)))
    nhat = [float(x) / rn for x in n]
    f = [float(x) for x in v[:dim]]
    fn = _dot(f, nhat)
    t2 = sum((fi - fn * ni) ** 2 for fi, ni in zip(f, nhat))
    for m in v[dim:]:
        t2 += (float(m) * rn / float(g)) ** 2
    return float(mu) * fn - math.sqrt(t2), fn

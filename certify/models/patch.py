"""Contact patch (spatial): a flat patch of radius ``radius`` (for a patch of another shape, the
disc of the same area) pressed on the object with uniform pressure, Coulomb friction ``mu``.

Each area element resists sliding up to ``mu`` times its normal force, so the patch transmits a
force ``f`` and a moment ``m`` about the normal with ``norm((f_t, m / g)) <= mu f_n``, a soft
finger whose torsional length follows from the patch: under uniform pressure ``p = f_n / (pi
a^2)`` the largest moment is ``integral of mu p r dA = (2 a / 3) mu f_n``, so ``g = 2 radius / 3``
(exactly two thirds, in exact arithmetic too). This couples force and moment conservatively (the
exact limit surface of a uniformly pressed disc lies outside this ellipsoid, touching it on both
axes). A patch of radius 0 is a point contact; ``mu = 0`` is frictionless.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np

from .base import Param, register
from .point import MU
from .soft import Soft

__all__ = ["Patch", "PATCH"]


class Patch(Soft):
    """The soft finger's cone, its torsional length derived from the patch's radius."""

    name = "patch"
    params = (MU, Param("radius", "patch radius", positive=True))
    extra = ("radius",)
    description = "contact patch of radius `radius` under uniform pressure: a soft finger with torsion 2 radius / 3"

    def moment_lengths(self, values):
        radius = values["radius"]
        exact = isinstance(radius, Fraction) or np.asarray(radius).dtype == object
        return (radius * Fraction(2, 3) if exact else 2.0 * np.asarray(radius, dtype=float) / 3.0,)

    def patch_params(self, mu, area, torsion):
        return {"mu": mu, "radius": math.sqrt(area / math.pi)} if area > 0 else None  # the disc of its area


PATCH = register(Patch())

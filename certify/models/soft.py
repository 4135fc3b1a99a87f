"""Soft finger (spatial): a point contact with friction that also resists a torsional moment
``m`` about the normal, ``norm((f_t, m / torsion)) <= mu f_n`` with ``torsion`` a length (the
torsional coefficient)."""

from __future__ import annotations

from .base import ContactModel, Param, register
from .point import MU

__all__ = ["Soft"]


class Soft(ContactModel):
    name = "soft"
    dims = (3,)
    params = (MU, Param("torsion", "torsional length", positive=True))
    reductions = (("mu", "frictionless"),)
    forces = "axes"
    extra = ("torsion",)
    cone = "lorentz"
    description = "soft finger: norm((f_t, m / torsion)) <= mu f_n (spatial)"

    def patch_params(self, mu, area, torsion):
        return {"mu": mu, "torsion": torsion} if torsion > 0 else None  # torsion from the patch's points


SOFT = register(Soft())

"""Point contact with Coulomb friction: ``norm(f_t) <= mu f_n``.

In the plane the friction cone is exactly its two edges ``n + mu t`` and ``n - mu t`` (no
approximation); in space it is the exact Lorentz cone (no linearisation). ``mu = 0`` is a
frictionless contact.
"""

from __future__ import annotations

from .base import MAX_MU, ContactModel, Generator, Param, register

__all__ = ["Point", "POINT", "MU"]

#: The friction coefficient parameter, shared by the models with Coulomb friction.
MU = Param("mu", "friction coefficient", high=MAX_MU, length=False)


class Point(ContactModel):
    name = "point"
    dims = (2, 3)
    params = (MU,)
    reductions = (("mu", "frictionless"),)
    forces = "axes"
    cone = "lorentz"
    description = "point contact with Coulomb friction: norm(f_t) <= mu f_n"

    def generators(self, dim: int, variant: int = 0):
        if dim != 2:
            return None  # the spatial friction cone has no finite generators
        return (Generator(0.0, 1.0), Generator(0.0, -1.0))

    def patch_params(self, mu, area, torsion):
        return {"mu": mu}  # the patch as its centroid


POINT = register(Point())

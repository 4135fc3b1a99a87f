"""Frictionless point contact: the finger can only push along the inward normal, ``f = l n``,
``l >= 0``."""

from __future__ import annotations

from .base import ContactModel, Generator, register

__all__ = ["Frictionless", "FRICTIONLESS"]


class Frictionless(ContactModel):
    name = "frictionless"
    dims = (2, 3)
    forces = "normal"
    cone = "ray"
    description = "frictionless point contact: force l n, l >= 0"

    def generators(self, dim: int, variant: int = 0):
        return (Generator(0.0, 0.0),)

    def frictionless(self):
        return self.name, {}, 0


FRICTIONLESS = register(Frictionless())

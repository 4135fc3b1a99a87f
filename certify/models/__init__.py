"""Contact models as objects, registered by name (see :mod:`qualgrasp.certify.models.base`).

Built in, in code order: ``frictionless``, ``point``, ``soft``, ``pad``, ``patch``. A new model is one
module declaring a :class:`ContactModel` subclass and registering an instance, plus its import
here.

Examples
--------
>>> from qualgrasp.certify import models
>>> models.names()
('frictionless', 'point', 'soft', 'pad', 'patch')
>>> models.get("pad").generators(2, variant=1)[0]
Generator(offset=0.5, friction=1.0)
"""

from typing import Literal

from .base import (MAX_LENGTH, MAX_MU, MIN_LENGTH, ContactModel, Generator, Param, frictionless_names, get,
                   models, names, offset_lengths, register)
from . import frictionless, point, soft, pad, patch  # noqa: E402,F401  (registration, in code order)
from .frictionless import FRICTIONLESS
from .point import POINT

__all__ = ["ModelName", "ContactModel", "Param", "Generator", "register", "get", "names", "models",
           "offset_lengths", "frictionless_names", "FRICTIONLESS", "POINT", "MAX_MU", "MAX_LENGTH", "MIN_LENGTH"]

#: The name of a built-in contact model, as validation accepts it (a model registered later with
#: :func:`register` is accepted too, by its name).
ModelName = Literal["frictionless", "point", "soft", "pad", "patch"]

"""The grasp model: contacts with inward normals and contact models, a reference point and a length.

Conventions
-----------
* Coordinates are in the user's length unit (pixels for grasps synthesised from images, x = column,
  y = row). A grasp is planar (2 coordinates) or spatial (3); all its contacts share the dimension.
* ``n`` is the **inward** normal: it points into the object. Normals of any non-zero finite length
  are accepted and normalised to unit length on construction (a normal is a direction; image
  gradients rarely come out unit length); a normal already unit to within ``1e-12`` is kept as
  given, so that exact data (``n = -p`` on the unit circle) stays exact. A normal shorter than
  ``1e-9`` is rejected as zero.
* Contact models: ``frictionless`` (force ``l n``, ``l >= 0``); ``point`` with Coulomb friction
  coefficient ``mu`` (``norm(f_t) <= mu f_n``); ``soft`` (spatial only) which adds a torsional
  moment ``m`` about ``n`` with ``norm((f_t, m / torsion)) <= mu f_n``, ``torsion`` being a length.
  A ``point`` or ``soft`` contact with ``mu == 0`` can only push along ``n`` and is stored as
  ``frictionless``.
* ``center`` (reference point of torques) defaults to the centroid of the contact points and
  ``length`` (characteristic length dividing torques) to the largest distance from ``center`` to a
  contact, or 1 when that distance is zero. Closure verdicts and the min-weight margin do not depend
  on either; quality measures such as epsilon do. The values used are always reported.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any, Mapping, Sequence

import numpy as np

from .errors import GraspError

__all__ = ["MODELS", "Contact", "Grasp", "grasp_from_dict", "grasp_to_dict"]

MODELS = ("frictionless", "point", "soft")
_MIN_NORMAL = 1e-9


def _vector(value: Any, what: str) -> tuple[float, ...]:
    try:
        vec = tuple(float(v) for v in value)
    except (TypeError, ValueError):
        raise GraspError(f"{what} must be a list of 2 or 3 numbers, got {value!r}") from None
    if len(vec) not in (2, 3):
        raise GraspError(f"{what} must have 2 (planar) or 3 (spatial) coordinates, got {len(vec)}")
    if not all(math.isfinite(v) for v in vec):
        raise GraspError(f"{what} has a NaN or infinite coordinate: {list(vec)}")
    return vec


def _scalar(value: Any, what: str) -> float:
    if isinstance(value, bool):
        raise GraspError(f"{what} must be a number, got {value!r}")
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise GraspError(f"{what} must be a number, got {value!r}") from None
    if not math.isfinite(x):
        raise GraspError(f"{what} must be finite, got {value!r}")
    return x


@dataclass(frozen=True)
class Contact:
    """A contact between a finger and the object.

    Parameters
    ----------
    p : sequence of float
        Contact point, 2 or 3 coordinates.
    n : sequence of float
        Inward normal (into the object); normalised to unit length.
    model : {'frictionless', 'point', 'soft'}
        Contact model.
    mu : float
        Coulomb friction coefficient (``point`` and ``soft``), ``>= 0``.
    torsion : float, optional
        Torsional length of a ``soft`` contact, ``> 0``, in the unit of ``p``.
    """

    p: tuple[float, ...]
    n: tuple[float, ...]
    model: str = "frictionless"
    mu: float = 0.0
    torsion: float | None = None

    def __post_init__(self) -> None:
        p = _vector(self.p, "contact point p")
        n = _vector(self.n, "normal n")
        if len(p) != len(n):
            raise GraspError(f"contact point p has {len(p)} coordinates but normal n has {len(n)}")
        norm = math.sqrt(sum(v * v for v in n))
        if norm < _MIN_NORMAL:
            raise GraspError(f"normal n is zero (length {norm:.3g}); give the inward surface normal")
        if self.model not in MODELS:
            raise GraspError(f"unknown contact model {self.model!r}; use one of {', '.join(MODELS)}")
        mu = _scalar(self.mu, "friction coefficient mu")
        if mu < 0:
            raise GraspError(f"friction coefficient mu must be >= 0, got {mu}")
        model, torsion = self.model, self.torsion
        if model == "frictionless" and mu != 0:
            raise GraspError("a frictionless contact takes no mu; use model 'point' for friction")
        if model == "soft":
            if len(p) != 3:
                raise GraspError("soft contacts are spatial only; a planar contact has no torsion")
            if torsion is None:
                raise GraspError("a soft contact needs its torsional length 'torsion' (> 0)")
            torsion = _scalar(torsion, "torsional length torsion")
            if torsion <= 0:
                raise GraspError(f"torsional length must be > 0, got {torsion}")
        elif torsion is not None:
            raise GraspError(f"'torsion' applies to soft contacts only, not to {model!r}")
        if mu == 0:
            model, torsion = "frictionless", None
        object.__setattr__(self, "p", p)
        if abs(norm - 1.0) > 1e-12:  # re-normalising a unit normal would only add rounding
            n = tuple(v / norm for v in n)
        object.__setattr__(self, "n", n)
        object.__setattr__(self, "model", model)
        object.__setattr__(self, "mu", mu)
        object.__setattr__(self, "torsion", torsion)

    @property
    def dim(self) -> int:
        return len(self.p)


@dataclass(frozen=True)
class Grasp:
    """A set of contacts on one object, with the reference point and length used for torques.

    Parameters
    ----------
    contacts : sequence of Contact
        At least one contact; all of the same dimension.
    center : sequence of float, optional
        Reference point of torques. Default: centroid of the contact points.
    length : float, optional
        Characteristic length dividing torques, ``> 0``. Default: largest distance from ``center``
        to a contact point (1 if that is zero).
    id : str, optional
        The grasp's identifier in a grasp set.
    meta : mapping, optional
        Extra fields carried through unchanged (for example region ids).
    """

    contacts: tuple[Contact, ...]
    center: tuple[float, ...] | None = None
    length: float | None = None
    id: Any = None
    meta: Mapping[str, Any] = field(default_factory=dict, compare=False)

    def __post_init__(self) -> None:
        contacts = tuple(self.contacts)
        if not contacts:
            raise GraspError("a grasp needs at least one contact")
        if not all(isinstance(c, Contact) for c in contacts):
            raise GraspError("contacts must be Contact objects")
        dims = {c.dim for c in contacts}
        if len(dims) > 1:
            raise GraspError(f"contacts mix dimensions {sorted(dims)}; a grasp is planar or spatial")
        dim = dims.pop()
        points = np.array([c.p for c in contacts])
        if self.center is None:
            center = tuple(float(v) for v in points.mean(axis=0))
        else:
            center = _vector(self.center, "center")
            if len(center) != dim:
                raise GraspError(f"center has {len(center)} coordinates, the contacts have {dim}")
        if self.length is None:
            reach = float(np.max(np.linalg.norm(points - np.array(center), axis=1)))
            length = reach if reach > 0 else 1.0
        else:
            length = _scalar(self.length, "length")
            if length <= 0:
                raise GraspError(f"length must be > 0, got {length}")
        object.__setattr__(self, "contacts", contacts)
        object.__setattr__(self, "center", center)
        object.__setattr__(self, "length", length)

    @property
    def dim(self) -> int:
        """Number of coordinates: 2 (planar) or 3 (spatial)."""
        return self.contacts[0].dim

    @property
    def wrench_dim(self) -> int:
        """Dimension of the wrench space: 3 (planar) or 6 (spatial)."""
        return 3 if self.dim == 2 else 6

    @property
    def points(self) -> np.ndarray:
        """Contact points, shape ``(m, dim)``."""
        return np.array([c.p for c in self.contacts])

    @property
    def normals(self) -> np.ndarray:
        """Unit inward normals, shape ``(m, dim)``."""
        return np.array([c.n for c in self.contacts])

    @property
    def frictionless(self) -> bool:
        """True when every contact is frictionless (form and force closure coincide)."""
        return all(c.model == "frictionless" for c in self.contacts)

    def as_frictionless(self) -> "Grasp":
        """The same grasp with every contact treated as frictionless (for form closure)."""
        contacts = tuple(Contact(c.p, c.n) for c in self.contacts)
        return replace(self, contacts=contacts)


def _contact_from_dict(d: Any, i: int) -> Contact:
    if not isinstance(d, Mapping):
        raise GraspError(f"contact {i} must be an object with keys p, n, model, mu, torsion")
    unknown = set(d) - {"p", "n", "model", "mu", "torsion"}
    if unknown:
        raise GraspError(f"contact {i} has unknown key(s) {sorted(unknown)}")
    for key in ("p", "n"):
        if key not in d:
            raise GraspError(f"contact {i} has no {key!r}")
    mu = d.get("mu")
    model = d.get("model", "frictionless" if mu is None else "point")
    try:
        return Contact(d["p"], d["n"], model, 0.0 if mu is None else mu, d.get("torsion"))
    except GraspError as err:
        raise GraspError(f"contact {i}: {err}") from None


def grasp_from_dict(d: Any) -> Grasp:
    """Build a :class:`Grasp` from the grasp-set schema.

    ``{"id": "g1", "contacts": [{"p": [x, y], "n": [nx, ny], "model": "point", "mu": 0.5}],
    "center": [cx, cy], "length": 1.0}``; ``center``, ``length`` and ``id`` are optional, 3
    coordinates for spatial grasps, ``torsion`` for soft contacts. A contact without ``model`` is
    ``point`` when it has ``mu`` and ``frictionless`` otherwise. Other top-level keys are kept in
    ``meta``.
    """
    if not isinstance(d, Mapping):
        raise GraspError("a grasp must be a JSON object with a 'contacts' list")
    contacts = d.get("contacts")
    if not isinstance(contacts, Sequence) or isinstance(contacts, (str, bytes)):
        raise GraspError("a grasp needs a 'contacts' list")
    meta = {k: v for k, v in d.items() if k not in ("id", "contacts", "center", "length")}
    return Grasp(
        tuple(_contact_from_dict(c, i) for i, c in enumerate(contacts)),
        center=d.get("center"),
        length=d.get("length"),
        id=d.get("id"),
        meta=meta,
    )


def grasp_to_dict(grasp: Grasp) -> dict[str, Any]:
    """The grasp-set schema of ``grasp`` (inverse of :func:`grasp_from_dict`)."""
    contacts = []
    for c in grasp.contacts:
        item: dict[str, Any] = {"p": list(c.p), "n": list(c.n), "model": c.model}
        if c.model != "frictionless":
            item["mu"] = c.mu
        if c.torsion is not None:
            item["torsion"] = c.torsion
        contacts.append(item)
    out: dict[str, Any] = {}
    if grasp.id is not None:
        out["id"] = grasp.id
    out.update(contacts=contacts, center=list(grasp.center), length=grasp.length)
    out.update(grasp.meta)
    return out

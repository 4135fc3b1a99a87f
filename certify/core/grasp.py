"""The grasp model: contacts with inward normals and contact models, a reference point and a length.

Conventions
-----------
* Coordinates are in the user's length unit (pixels for grasps synthesised from images, x = column,
  y = row). A grasp is planar (2 coordinates) or spatial (3); all its contacts share the dimension.
* ``n`` is the **inward** normal: it points into the object. Normals of any non-zero finite length
  are accepted and normalised to unit length on construction (a normal is a direction; image
  gradients rarely come out unit length); a normal already unit to within ``1e-12`` is kept as
  given, so that exact data (``n = -p`` on the unit circle) stays exact.
* Contact models are registered objects (:mod:`qualgrasp.certify.models`): ``frictionless``
  (force ``l n``, ``l >= 0``); ``point`` with Coulomb friction coefficient ``mu``
  (``norm(f_t) <= mu f_n``); ``soft`` (spatial) which adds a torsional moment ``m`` about ``n``
  with ``norm((f_t, m / torsion)) <= mu f_n``, ``torsion`` a length; ``pad`` (planar), a flat pad
  of width ``width`` with friction ``mu``. A contact whose parameters make it a simpler model is
  stored as that model (``mu == 0``: frictionless; a pad of width 0: point).
* ``center`` (reference point of torques) defaults to the centroid of the contact points and
  ``length`` (characteristic length dividing torques) to the largest distance from ``center`` to a
  contact, or 1 when that distance is zero. Closure verdicts and the min-weight margin do not depend
  on either; quality measures such as epsilon do. The values used are always reported.

Every rule and message is :mod:`qualgrasp.certify.core.validation`'s, for contacts built here, grasps
read from JSON and columns read from Parquet alike.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Mapping

import numpy as np

from .. import models as registry
from ..models import ModelName
from ..errors import GraspError
from .arguments import require
from .validation import (Checked, CheckedGrasps, GraspData, check_contact, check_contacts, contact_data,
                         grasp_data, check_grasps, grasp_geometry, grasp_rules, number, numbers, param_names)

__all__ = ["Contact", "Grasp", "grasp_from_dict", "grasp_to_dict", "grasps_from_checked"]


@dataclass(frozen=True, init=False)
class Contact:
    """A contact between a finger and the object.

    Parameters
    ----------
    p : sequence of float
        Contact point, 2 or 3 coordinates (the user's length unit).
    n : sequence of float
        Inward normal (into the object); normalised to unit length.
    model : str
        A registered contact model (:mod:`qualgrasp.certify.models`): ``'frictionless'``
        (default), ``'point'``, ``'soft'`` or ``'pad'``.
    mu : float, optional
        Coulomb friction coefficient (``point``, ``soft``, ``pad``), ``>= 0``.
    torsion : float, optional
        Torsional length of a ``soft`` contact, ``> 0``, in the unit of ``p``.
    **params : float
        Other model parameters, e.g. ``width`` of a ``pad`` (``>= 0``, unit of ``p``).

    Attributes
    ----------
    p, n : tuple of float
        The point and the stored unit normal.
    model : str
        The effective model (after reductions such as ``mu == 0`` meaning frictionless).
    params : tuple of (str, float)
        The model's parameters, in its declared order.

    Raises
    ------
    GraspError
        A value breaks a rule of :mod:`qualgrasp.certify.core.validation` (the message names it).

    Examples
    --------
    >>> from qualgrasp.certify import Contact
    >>> Contact((0, 1), (0, -2), "point", 0.5)
    Contact(p=(0.0, 1.0), n=(0.0, -1.0), model='point', params=(('mu', 0.5),))
    >>> Contact((0, 1), (0, -1), "pad", mu=0.5, width=0.0).model  # a pad of width 0 is a point
    'point'
    """

    p: tuple[float, ...]
    n: tuple[float, ...]
    model: str
    params: tuple[tuple[str, float], ...]

    def __init__(self, p, n, model: ModelName | str | None = "frictionless", mu: float | None = None,
                 torsion: float | None = None, **params: float) -> None:
        unknown = sorted(set(params) - set(param_names()))
        if unknown:
            raise GraspError(f"unknown contact parameter(s) {unknown}; the models take "
                             f"{', '.join(param_names())}")
        value = {"p": p, "n": n, "model": model, "mu": mu, "torsion": torsion, **params}
        fast = check_contact(value)  # the usual contact, by the same rules without arrays
        if fast is not None:
            for name, v in zip(("p", "n", "model", "params"), fast):
                object.__setattr__(self, name, v)
            return
        checked = check_contacts(contact_data([value]))
        if checked.error[0] is not None:
            raise GraspError(str(checked.error[0]))
        _set_contact(self, checked, 0)

    @property
    def dim(self) -> int:
        """Number of coordinates: 2 (planar) or 3 (spatial)."""
        return len(self.p)

    def param(self, name: str, default: Any = None) -> Any:
        """The value of parameter ``name``, or ``default`` when the model does not take it."""
        return dict(self.params).get(name, default)

    @property
    def mu(self) -> float:
        """Friction coefficient (0 for a frictionless contact)."""
        return float(self.param("mu", 0.0))

    @property
    def torsion(self) -> float | None:
        """Torsional length of a soft contact, else None."""
        return self.param("torsion")

    @property
    def contact_model(self) -> registry.ContactModel:
        """The registered model object."""
        return registry.get(self.model)


def _set_contact(contact: Contact, checked: Checked, j: int) -> None:
    dim = int(checked.dim[j])
    model = registry.get(int(checked.model[j]))
    object.__setattr__(contact, "p", tuple(float(v) for v in checked.p[j, :dim]))
    object.__setattr__(contact, "n", tuple(float(v) for v in checked.n[j, :dim]))
    object.__setattr__(contact, "model", model.name)
    object.__setattr__(contact, "params",
                       tuple((name, float(checked.params[name][j])) for name in model.param_names))


def _checked_of(contacts) -> Checked:
    """The :class:`Checked` arrays of valid contacts (no rule is re-applied)."""
    k = len(contacts)
    p, n = np.zeros((k, 3)), np.zeros((k, 3))
    dim = np.array([c.dim for c in contacts], dtype=np.int64)
    for j, c in enumerate(contacts):
        p[j, : c.dim], n[j, : c.dim] = c.p, c.n
    params = {name: np.array([float(c.param(name, 0.0)) for c in contacts]) for name in param_names()}
    model = np.array([registry.get(c.model).code for c in contacts], dtype=np.int64)
    variant = np.zeros(k, dtype=np.int64)
    for m in registry.models():
        rows = model == m.code
        if rows.any():
            variant[rows] = m.variant({name: params[name][rows] for name in m.param_names})
    return Checked(np.full(k, None, dtype=object), p, n, dim, model, params, variant)


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
    id : str or int, optional
        The grasp's identifier in a grasp set.
    meta : mapping, optional
        Extra fields carried through unchanged (for example region ids).

    Raises
    ------
    GraspError
        No contact, mixed dimensions, a bad ``center`` or ``length``.

    Examples
    --------
    >>> from qualgrasp.certify import Contact, Grasp
    >>> g = Grasp((Contact((0, 0), (1, 0)), Contact((4, 0), (-1, 0)), Contact((2, 3), (0, -1))))
    >>> g.center, round(g.length, 4)
    ((2.0, 1.0), 2.2361)
    """

    contacts: tuple[Contact, ...]
    center: tuple[float, ...] | None = None
    length: float | None = None
    id: Any = None
    meta: Mapping[str, Any] = field(default_factory=dict, compare=False)

    def __post_init__(self) -> None:
        contacts = tuple(self.contacts)
        if not all(isinstance(c, Contact) for c in contacts):
            raise GraspError("contacts must be Contact objects")
        geometry = grasp_geometry([c.p for c in contacts], self.center, self.length)  # the usual grasp
        center, length = geometry if geometry is not None else self._checked_geometry(contacts)
        object.__setattr__(self, "contacts", contacts)
        object.__setattr__(self, "center", center)
        object.__setattr__(self, "length", length)

    def _checked_geometry(self, contacts: tuple[Contact, ...]) -> tuple[tuple[float, ...], float]:
        """``center`` and ``length`` by the grasp rules on arrays, which word any problem."""
        data = GraspData(np.array([len(contacts)]), np.zeros((1, 3)), np.full(1, -1), np.full(1, np.nan),
                         np.zeros(1, dtype=bool), [None], [None], [{}])
        if self.center is not None:
            vec = numbers(self.center)
            if vec is None or not 2 <= len(vec) <= 3:
                raise GraspError(f"center: expected 2 (planar) or 3 (spatial) finite numbers, got {self.center!r}")
            data.center[0, : len(vec)], data.clen[0] = vec, len(vec)
            data.raw[(0, "center")] = list(vec)
        if self.length is not None:
            x = number(self.length)
            if x is None:
                raise GraspError(f"length: expected a number, got {self.length!r}")
            data.length[0], data.length_given[0] = x, True
        checked = grasp_rules(data, _checked_of(contacts))
        if checked.error[0] is not None:
            raise GraspError(str(checked.error[0]))
        dim = int(checked.dim[0])
        return tuple(float(v) for v in checked.center[0, :dim]), float(checked.length[0])

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
        return all(c.contact_model.is_frictionless for c in self.contacts)


def grasps_from_checked(checked: CheckedGrasps, rows, ids=None, meta=None) -> list[Grasp]:
    """:class:`Grasp` objects of the valid ``rows`` of checked grasp arrays (no rule is applied
    again: the arrays come from :func:`qualgrasp.certify.core.validation.check_grasps`)."""
    out = []
    c = checked.contacts
    for i in rows:
        contacts = []
        for j in range(checked.offsets[i], checked.offsets[i + 1]):
            contact = object.__new__(Contact)
            _set_contact(contact, c, j)
            contacts.append(contact)
        dim = int(checked.dim[i])
        grasp = object.__new__(Grasp)
        for name, value in (("contacts", tuple(contacts)),
                            ("center", tuple(float(v) for v in checked.center[i, :dim])),
                            ("length", float(checked.length[i])),
                            ("id", None if ids is None else ids[i]),
                            ("meta", {} if meta is None else meta[i])):
            object.__setattr__(grasp, name, value)
        out.append(grasp)
    return out


def grasp_from_dict(d: Any) -> Grasp:
    """Build a :class:`Grasp` from the grasp-set schema.

    ``{"id": "g1", "contacts": [{"p": [x, y], "n": [nx, ny], "model": "point", "mu": 0.5}],
    "center": [cx, cy], "length": 1.0}``; ``center``, ``length`` and ``id`` are optional, 3
    coordinates for spatial grasps, the model's parameters (``mu``, ``torsion``, ``width``) as
    keys of a contact. A contact without ``model`` is ``point`` when it has ``mu`` and
    ``frictionless`` otherwise. Other keys of a contact are ignored; other top-level keys are kept
    in ``meta``.

    Parameters
    ----------
    d : mapping
        One grasp of a grasp set, as parsed JSON.

    Returns
    -------
    Grasp

    Raises
    ------
    GraspError
        The value breaks a rule (the message names the field, e.g. ``contacts[1].mu``).

    Examples
    --------
    >>> from qualgrasp.certify import grasp_from_dict
    >>> g = grasp_from_dict({"id": "g1", "contacts": [
    ...     {"p": [1, 0], "n": [-1, 0], "model": "pad", "mu": 0.5, "width": 0.2},
    ...     {"p": [-1, 0], "n": [1, 0], "model": "pad", "mu": 0.5, "width": 0.2}]})
    >>> [c.model for c in g.contacts], g.length
    (['pad', 'pad'], 1.0)
    """
    data, contacts = grasp_data([d])
    checked = check_grasps(data, contacts)
    if checked.error[0] is not None:
        raise GraspError(str(checked.error[0]))
    return grasps_from_checked(checked, [0], data.ids, data.meta)[0]


def grasp_to_dict(grasp: Grasp) -> dict[str, Any]:
    """The grasp-set schema of ``grasp`` (inverse of :func:`grasp_from_dict`).

    Parameters
    ----------
    grasp : Grasp

    Returns
    -------
    dict
        ``id`` (when set), ``contacts`` (``p``, ``n``, ``model`` and the model's parameters),
        ``center``, ``length`` and the ``meta`` fields.

    Examples
    --------
    >>> from qualgrasp.certify import Contact, Grasp, grasp_to_dict
    >>> grasp_to_dict(Grasp((Contact((0, 0), (1, 0)),), id="g"))["contacts"]
    [{'p': [0.0, 0.0], 'n': [1.0, 0.0], 'model': 'frictionless'}]
    """
    require(grasp, Grasp, "grasp")
    contacts = []
    for c in grasp.contacts:
        item: dict[str, Any] = {"p": list(c.p), "n": list(c.n), "model": c.model}
        item.update(c.params)
        contacts.append(item)
    out: dict[str, Any] = {}
    if grasp.id is not None:
        out["id"] = grasp.id
    out.update(contacts=contacts, center=list(grasp.center), length=grasp.length)
    out.update(grasp.meta)
    return out

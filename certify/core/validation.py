"""Validation of grasp data: one set of rules and messages, whichever way grasps come in.

Grasps arrive as Python values (:class:`qualgrasp.certify.Contact` and
:class:`qualgrasp.certify.Grasp` keywords, JSON Lines parsed by :func:`json.loads`) or as Arrow
columns (Parquet, in-memory tables). Both are turned into the same arrays, :class:`ContactData`
(one row per contact) and :class:`GraspData` (one row per grasp), by a *reader* that only checks
types: :func:`contact_data` and :func:`grasp_data` for Python values (numbers must be numbers:
no string, boolean or mapping is coerced), :mod:`qualgrasp.certify.files.columns` for Arrow. Every rule
on the values is then applied here, vectorised, by :func:`check_contacts` and :func:`check_grasps`,
with the same messages for every source. A message names the field and the problem:
``contacts[2].p: expected 2 or 3 finite numbers, got "abc"``.

Rules and documented limits
---------------------------
* ``p`` and ``n``: 2 (planar) or 3 (spatial) finite numbers each, as many for both; coordinates
  at most :data:`~qualgrasp.certify.models.MAX_LENGTH` in absolute value; ``n`` not shorter than
  :data:`MIN_NORMAL`. Normals are normalised to unit length, except one already unit to within
  ``1e-12`` (kept as given, so exact data stays exact); the length is computed without overflow.
* ``model``: a registered model (:mod:`qualgrasp.certify.models`) that exists in the contact's
  dimension. Without ``model``, a contact with ``mu`` is ``point``, otherwise ``frictionless``.
* The model's parameters are required and must lie in their ranges
  (:class:`qualgrasp.certify.models.Param`); a parameter of another model may only be 0 (it then
  means nothing). Reductions then apply (``mu = 0``: frictionless; a pad of width 0: point).
* A grasp has 1 to :data:`MAX_CONTACTS` contacts of one dimension; ``center`` (optional) has
  that many finite coordinates, at most ``MAX_LENGTH`` in absolute value; ``length``
  (optional) is a finite number in ``[MIN_LENGTH, MAX_GRASP_LENGTH]``. Defaults: ``center`` the
  centroid of the contact points (their sum in contact order over their count), ``length`` the
  largest distance from ``center`` to a contact point, or 1 when the contacts coincide (up to
  the rounding of their centroid); a default length
  outside ``[MIN_LENGTH, MAX_GRASP_LENGTH]`` is an error (the contacts are too close together
  for the tolerances: give ``length`` or rescale), so a grasp's results always read back.
* ``id`` (optional) is a string or an integer.
* Other keys of a contact are ignored; other top-level keys of a grasp are kept (``meta``).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from numbers import Integral, Real
from typing import Any, Mapping, Sequence

import numpy as np

from .. import models as registry
from ..models import MAX_LENGTH, MIN_LENGTH

__all__ = ["MAX_CONTACTS", "MIN_NORMAL", "ABSENT", "UNKNOWN", "ContactData", "GraspData",
           "Checked", "show", "show_repr", "number", "numbers", "contact_data", "contact_arrays", "grasp_data",
           "check_contacts", "check_contact", "check_grasps", "grasp_geometry", "grasp_rules", "CheckedGrasps",
           "param_names", "TOP_LEVEL", "id_problem"]

#: Most contacts in one grasp (documented limit; a longer row is an error).
MAX_CONTACTS = 10_000
#: A normal shorter than this is zero.
MIN_NORMAL = 1e-9
#: Model code of a contact without ``model`` (resolved by the default rule), and of an unknown name.
ABSENT, UNKNOWN = -2, -1


def show(value: Any, limit: int = 60) -> str:
    """A short rendering of a user's value for messages (JSON where possible)."""
    try:
        text = json.dumps(value, allow_nan=True)
    except (TypeError, ValueError, RecursionError):
        text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def show_repr(value: Any, limit: int = 60) -> str:
    """A short ``repr`` of a value for messages (a row's own Python value, as it was read).

    Examples
    --------
    >>> show_repr("abc"), len(show_repr(list(range(100))))
    ("'abc'", 60)
    """
    try:
        text = repr(value)
    except RecursionError:
        return "(deeply nested value)"
    return text if len(text) <= limit else text[: limit - 3] + "..."


def number(value: Any) -> float | None:
    """``value`` as a float if it is a real number (not a boolean, string or container), else
    None. Integers too large for a float become ``inf`` (rejected later as not finite)."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (Real, np.number)):
        return None
    try:
        return float(value)
    except OverflowError:
        return math.inf if value > 0 else -math.inf


def numbers(value: Any) -> tuple[float, ...] | None:
    """``value`` as a tuple of floats if it is a list, tuple or 1-D numeric array of real
    numbers, else None."""
    if isinstance(value, np.ndarray):
        if value.ndim != 1 or value.dtype.kind not in "iuf":
            return None
        return tuple(float(v) for v in value.astype(float))
    if not isinstance(value, (list, tuple)):
        return None
    out = tuple(number(v) for v in value)
    return None if any(v is None for v in out) else out


@dataclass
class ContactData:
    """Contacts as arrays, one row per contact (``k`` rows), before the value rules.

    ``p``, ``n`` (k, 3) with lengths ``plen``, ``nlen`` (-1: absent); ``model`` codes
    (:data:`ABSENT`, :data:`UNKNOWN`), ``names`` the given model names (for messages);
    ``params`` NaN where not given, ``given`` masks; ``errors`` the reader's message per contact
    (None when it read the contact); ``raw`` given values by ``(row, key)`` for messages."""

    p: np.ndarray
    plen: np.ndarray
    n: np.ndarray
    nlen: np.ndarray
    model: np.ndarray
    names: list
    params: dict[str, np.ndarray]
    given: dict[str, np.ndarray]
    errors: list
    raw: dict = field(default_factory=dict)

    @classmethod
    def empty(cls, k: int) -> "ContactData":
        return cls(np.zeros((k, 3)), np.full(k, -1), np.zeros((k, 3)), np.full(k, -1),
                   np.full(k, ABSENT, dtype=np.int64), [None] * k,
                   {name: np.full(k, np.nan) for name in param_names()},
                   {name: np.zeros(k, dtype=bool) for name in param_names()}, [None] * k)


def param_names() -> tuple[str, ...]:
    """Every registered model's parameter names (the optional keys of a contact), in order."""
    out: list[str] = []
    for model in registry.models():
        out += [p.name for p in model.params if p.name not in out]
    return tuple(out)


def _vector_into(data: ContactData, j: int, key: str, value: Any) -> str | None:
    vec = numbers(value)
    if vec is None or not 2 <= len(vec) <= 3:
        return f"{key}: expected 2 (planar) or 3 (spatial) finite numbers, got {show(value)}"
    arr, lens = (data.p, data.plen) if key == "p" else (data.n, data.nlen)
    arr[j, : len(vec)] = vec
    lens[j] = len(vec)
    data.raw[(j, key)] = value
    return None


def contact_data(values: Sequence[Any]) -> ContactData:
    """Read contacts given as Python values (mappings with keys ``p``, ``n``, ``model`` and the
    models' parameters), checking only types (the value rules are :func:`check_contacts`')."""
    data = ContactData.empty(len(values))
    names = registry.names()
    for j, c in enumerate(values):
        if not isinstance(c, Mapping):
            data.errors[j] = f"expected an object with keys p, n, model, ..., got {show(c)}"
            continue
        error = None
        for key in ("p", "n"):
            if c.get(key) is None:
                error = error or f"{key}: missing ({'the contact point' if key == 'p' else 'the inward normal'})"
            else:
                error = error or _vector_into(data, j, key, c[key])
        model = c.get("model")
        if model is not None:
            if not isinstance(model, str):
                error = error or f"model: expected one of {', '.join(map(repr, names))}, got {show(model)}"
            else:
                data.names[j] = model
                data.model[j] = names.index(model) if model in names else UNKNOWN
        for name in data.params:
            if c.get(name) is None:
                continue
            x = number(c[name])
            if x is None:
                error = error or f"{name}: expected a number, got {show(c[name])}"
                continue
            data.params[name][j] = x
            data.given[name][j] = True
            data.raw[(j, name)] = c[name]
        data.errors[j] = error
    return data


def contact_arrays(p: np.ndarray, n: np.ndarray, model: str | None = None,
                   params: Mapping[str, Any] | None = None) -> ContactData | None:
    """Read contacts given as float arrays ``p`` and ``n`` (k, 2) or (k, 3), one model name (or
    None: the default rule) and one value per parameter (None: not given) for every contact: the
    data :func:`contact_data` reads from the equivalent mappings, without a Python value per
    number. None when a value is not of those types (:func:`contact_data` then says which).

    Examples
    --------
    >>> data = contact_arrays(np.array([[1.0, 0.0]]), np.array([[-1.0, 0.0]]), "point", {"mu": 0.5})
    >>> check_contacts(data).params["mu"].tolist()
    [0.5]
    """
    ok = (isinstance(p, np.ndarray) and isinstance(n, np.ndarray) and p.dtype.kind == "f" and n.dtype.kind == "f"
          and p.ndim == 2 and p.shape == n.shape and p.shape[1] in (2, 3) and (model is None or isinstance(model, str)))
    if not ok:
        return None
    k, d = p.shape
    data = ContactData.empty(k)
    data.p[:, :d], data.n[:, :d] = p, n
    data.plen[:], data.nlen[:] = d, d
    if model is not None:
        names = registry.names()
        data.names = [model] * k
        data.model[:] = names.index(model) if model in names else UNKNOWN
    for name, value in (params or {}).items():
        if value is None:
            continue
        x = number(value)
        if x is None or name not in data.params:
            return None
        data.params[name][:] = x
        data.given[name][:] = True
    return data


@dataclass
class Checked:
    """Contacts after the value rules: ``error`` per contact (None when valid); for valid
    contacts the stored values: ``p``, unit ``n`` (k, 3), ``dim``, effective ``model`` codes
    (after reductions and defaults), ``params`` (0 where the model does not take one) and the
    model ``variant``."""

    error: np.ndarray
    p: np.ndarray
    n: np.ndarray
    dim: np.ndarray
    model: np.ndarray
    params: dict[str, np.ndarray]
    variant: np.ndarray


def _by_column(ufunc: np.ufunc, a: np.ndarray) -> np.ndarray:
    """``ufunc.reduce(a, axis=1)`` of a (k, c) array, c >= 1, computed column by column from left
    to right: the same values (numpy reduces a short row from left to right too, as the scalar
    :func:`_scaled_norm` sums), several times faster than a reduction along a short axis."""
    out = a[:, 0].copy()
    for j in range(1, a.shape[1]):
        ufunc(out, a[:, j], out=out)
    return out


def _plain(value: Any) -> Any:
    """A Python value of an Arrow scalar (``as_py``), other values as they are."""
    return value.as_py() if hasattr(value, "as_py") else value


def _unit_normals(n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Normals as stored (unit, or kept when unit to within 1e-12) and their lengths, without
    overflow for huge components."""
    scale = _by_column(np.maximum, np.abs(n))
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        safe = np.where(scale > 0, scale, 1.0)
        norm = safe * np.sqrt(_by_column(np.add, (n / safe[:, None]) ** 2))
        unit = np.abs(norm - 1.0) <= 1e-12
        plain = np.sqrt(_by_column(np.add, n * n))  # exact rounding as before for ordinary data
        norm = np.where(np.isfinite(plain) & (plain > 1e-150), plain, norm)
        stored = np.where(unit[:, None], n, n / np.where(norm > 0, norm, 1.0)[:, None])
    return stored, norm


def _owners(name: str) -> list[str]:
    """The names of the models taking the parameter ``name``."""
    return [o.name for o in registry.models() if name in o.param_names]


def check_contacts(data: ContactData) -> Checked:
    """Apply the value rules (module docstring) to every contact; messages name the field."""
    k = len(data.plen)
    error = np.array(data.errors, dtype=object) if k else np.zeros(0, dtype=object)
    todo = np.equal(error, None)

    def fail(mask, message) -> None:
        """Record ``message(row)`` for the rows of ``mask`` still without an error."""
        hit = mask & todo
        if not hit.any():  # the usual case, checked first: most of a single contact's checking time
            return
        for j in np.flatnonzero(hit):
            error[j] = message(j)
            todo[j] = False

    def raw(j, key, value):
        return show(data.raw.get((j, key), value))

    plen, nlen = data.plen, data.nlen
    fail(plen < 0, lambda j: "p: missing (the contact point)")
    fail(nlen < 0, lambda j: "n: missing (the inward normal)")
    fail(todo & (nlen != plen),
         lambda j: f"n: contact point p has {plen[j]} coordinates but normal n has {nlen[j]}")
    cols = np.arange(3)[None, :] < plen[:, None]
    p = np.where(cols, data.p, 0.0)
    n = np.where(cols, data.n, 0.0)
    with np.errstate(invalid="ignore"):
        fail(~_by_column(np.logical_and, np.abs(p) <= MAX_LENGTH),  # False for NaN and infinities too
             lambda j: f"p: NaN or infinite coordinate, or one beyond {MAX_LENGTH:g}: expected 2 (planar) "
                       f"or 3 (spatial) finite numbers, got {raw(j, 'p', list(p[j, :plen[j]]))}")
        fail(~_by_column(np.logical_and, np.isfinite(n)),
             lambda j: f"n: NaN or infinite coordinate: expected 2 (planar) or 3 (spatial) finite "
                       f"numbers, got {raw(j, 'n', list(n[j, :plen[j]]))}")
    stored, norm = _unit_normals(np.where(np.isfinite(n), n, 0.0))
    fail(~(norm >= MIN_NORMAL),
         lambda j: f"n: normal n is zero or shorter than {MIN_NORMAL:g} (length {norm[j]:.3g}); "
                   "give the inward surface normal")

    # model: the default rule, then known names existing in the contact's dimension
    model = data.model.copy()
    given = data.given
    model[model == ABSENT] = np.where(given.get("mu", np.zeros(k, bool))[model == ABSENT],
                                      registry.POINT.code, registry.FRICTIONLESS.code)
    names = registry.names()
    fail(model == UNKNOWN, lambda j: f"model: unknown contact model {show(_plain(data.names[j]))}; use "
                                     f"one of {', '.join(map(repr, names))}")
    for m in registry.models():
        fail((model == m.code) & ~np.logical_or.reduce([plen == d for d in m.dims]),  # np.isin: 20 us a call
             lambda j, m=m: f"model: {m.name!r} contacts are {'planar' if m.dims == (2,) else 'spatial'} "
                            f"only ({m.description}); this one has {plen[j]} coordinates")
    # parameters: those of the model required and in range, others absent or 0
    params = {name: np.where(given[name], data.params[name], 0.0) for name in data.params}
    for m in registry.models():
        rows = model == m.code
        for par in m.params:
            fail(rows & ~given[par.name], lambda j, m=m, par=par: f"{par.name}: missing: a {m.name!r} contact "
                                                                  f"needs its {par.description} ({par.requirement()})")
            fail(rows & ~np.isfinite(params[par.name]),
                 lambda j, par=par: f"{par.name}: {par.description} {par.name} must be finite, "
                                    f"got {raw(j, par.name, params[par.name][j])}")
            fail(rows & ~par.admissible(params[par.name]),
                 lambda j, par=par: f"{par.name}: {par.description} {par.name} must be {par.bounds()}, "
                                    f"got {raw(j, par.name, params[par.name][j])}")
        for name in data.params:
            if name in m.param_names:
                continue
            fail(rows & given[name] & (params[name] != 0),
                 lambda j, m=m, name=name: f"{name}: a {m.name} contact takes no {name}; "
                                           f"'{name}' applies to {' and '.join(_owners(name))} "
                                           f"contacts only, not to {m.name!r}")
    valid = error == None  # noqa: E711  (elementwise on an object array)
    model = np.where(valid, model, -1)
    # reductions, until none applies (a pad of width 0 is a point, a point with mu 0 frictionless)
    changed = True
    while changed:
        changed = False
        for m in registry.models():
            for name, target in m.reductions:
                hit = (model == m.code) & (params[name] == 0)
                if hit.any():
                    keep = registry.get(target).param_names
                    for other in m.param_names:
                        if other not in keep:
                            params[other] = np.where(hit, 0.0, params[other])
                    model = np.where(hit, registry.get(target).code, model)
                    changed = True
    variant = np.zeros(k, dtype=np.int64)
    for m in registry.models():
        rows = model == m.code
        if rows.any():
            variant[rows] = m.variant({name: params[name][rows] for name in m.param_names})
    return Checked(error, p, np.where(valid[:, None], stored, 0.0), np.where(valid, plen, 0), model,
                   params, variant)


def check_contact(value: Mapping[str, Any]) -> tuple | None:
    """One contact, given as a mapping, by the rules of :func:`check_contacts` when it meets
    every rule as given: ``(p, n, model, params)`` as :class:`qualgrasp.certify.Contact` stores
    them (the point's floats, the stored unit normal, the model's name, its parameters in its
    order). None for any other contact (a rule fails, or a reduction applies):
    :func:`check_contacts` then decides and words it.

    The same rules in plain Python on scalars: one contact in a few microseconds, against some
    250 for the vectorised rules on arrays of one row. Tests hold the two to the same values,
    bit for bit.

    Examples
    --------
    >>> check_contact({"p": [0, 1], "n": [0, -2], "model": "point", "mu": 0.5})
    ((0.0, 1.0), (0.0, -1.0), 'point', (('mu', 0.5),))
    >>> check_contact({"p": [0, 1], "n": [0, -1], "model": "point", "mu": 0.0}) is None  # frictionless
    True
    """
    # the values are read in contact_data's order (p, then n, then every parameter), so that a
    # value whose conversion raises raises here as it would there
    p = numbers(value.get("p"))
    if p is None or len(p) not in (2, 3):
        return None
    n = numbers(value.get("n"))
    if n is None or len(n) != len(p):
        return None
    given = {key: number(value[key]) for key in param_names() if value.get(key) is not None}
    if not all(math.isfinite(x) and abs(x) <= MAX_LENGTH for x in p) or not all(map(math.isfinite, n)):
        return None
    names, name = registry.names(), value.get("model")
    if name is None:  # the default rule
        name = registry.POINT.name if given.get("mu") is not None else registry.FRICTIONLESS.name
    if not isinstance(name, str) or name not in names:
        return None
    model = registry.get(names.index(name))  # by position, as contact_data finds it
    if len(p) not in model.dims:
        return None
    params = []
    for par in model.params:
        x = given.get(par.name)
        if x is None or not (math.isfinite(x) and bool(par.admissible(np.array([x]))[0])):
            return None
        params.append((par.name, x))
    if any(key not in model.param_names and x != 0 for key, x in given.items()):
        return None  # another model's parameter may only be 0 (a value not a number: None, refused)
    if any(given.get(key, 0.0) == 0 for key, _ in model.reductions):
        return None
    stored = _unit_normal(n)
    return None if stored is None else (p, stored, model.name, tuple(params))


def _unit_normal(n: tuple[float, ...]) -> tuple[float, ...] | None:
    """:func:`_unit_normals` of one finite normal, the same floats; None when it is too short."""
    scaled = _scaled_norm(n)
    plain = math.sqrt(sum(x * x for x in n))
    norm = plain if math.isfinite(plain) and plain > 1e-150 else scaled
    if not norm >= MIN_NORMAL:
        return None
    if abs(scaled - 1.0) <= 1e-12:
        return n
    return tuple(x / (norm if norm > 0 else 1.0) for x in n)


@dataclass
class GraspData:
    """Grasps as arrays, before the value rules: contacts per grasp ``count`` (their rows in
    :class:`ContactData` are consecutive, in grasp order), ``center`` (g, 3) with length
    ``clen`` (-1: not given), ``length`` (NaN: not given), ``ids`` (str, int or None),
    ``errors`` the reader's message per grasp, ``meta`` other top-level keys, ``raw`` values
    for messages."""

    count: np.ndarray
    center: np.ndarray
    clen: np.ndarray
    length: np.ndarray
    length_given: np.ndarray
    ids: list
    errors: list
    meta: list
    raw: dict = field(default_factory=dict)


#: The top-level keys of a grasp (other keys are kept as ``meta`` and carried through).
TOP_LEVEL = ("id", "contacts", "center", "length")


def grasp_data(values: Sequence[Any]) -> tuple[GraspData, ContactData]:
    """Read grasps given as Python values (mappings in the grasp-set schema), checking only
    types; returns the grasp rows and their contacts (see :func:`check_grasps`)."""
    g = len(values)
    data = GraspData(np.zeros(g, dtype=np.int64), np.zeros((g, 3)), np.full(g, -1), np.full(g, np.nan),
                     np.zeros(g, dtype=bool), [None] * g, [None] * g, [{} for _ in range(g)])
    contacts: list = []
    for i, d in enumerate(values):
        if not isinstance(d, Mapping):
            data.errors[i] = f"expected a JSON object with a 'contacts' list, got {show(d)}"
            continue
        gid = d.get("id")
        problem = id_problem(gid)
        if problem:
            data.errors[i] = problem
        elif gid is not None:
            data.ids[i] = gid if isinstance(gid, str) else int(gid)
        data.meta[i] = {k: v for k, v in d.items() if k not in TOP_LEVEL}
        cs = d.get("contacts")
        if not isinstance(cs, (list, tuple)):
            data.errors[i] = data.errors[i] or (
                "contacts: missing (a grasp needs a 'contacts' list)" if cs is None else
                f"contacts: expected a list of contacts, got {show(cs)}")
            continue
        if len(cs) > MAX_CONTACTS:
            data.errors[i] = data.errors[i] or f"contacts: {len(cs)} contacts, more than the limit of {MAX_CONTACTS}"
            continue
        data.count[i] = len(cs)
        contacts.extend(cs)
        if d.get("center") is not None:
            vec = numbers(d["center"])
            if vec is None or not 2 <= len(vec) <= 3:
                data.errors[i] = data.errors[i] or f"center: expected 2 or 3 finite numbers, got {show(d['center'])}"
            else:
                data.center[i, : len(vec)] = vec
                data.clen[i] = len(vec)
                data.raw[(i, "center")] = d["center"]
        if d.get("length") is not None:
            x = number(d["length"])
            if x is None:
                data.errors[i] = data.errors[i] or f"length: expected a number, got {show(d['length'])}"
            else:
                data.length[i] = x
                data.length_given[i] = True
                data.raw[(i, "length")] = d["length"]
    return data, contact_data(contacts)


def id_problem(gid: Any) -> str | None:
    """Why ``gid`` cannot be an id (a string of valid Unicode or an integer; None for none), or
    None when it can.

    Examples
    --------
    >>> id_problem("g1") is None, id_problem(7) is None, id_problem(None) is None
    (True, True, True)
    >>> print(id_problem("a\\ud800b"))
    id: not valid Unicode (it holds a lone surrogate), got "a\ud800b"
    """
    if gid is not None and (isinstance(gid, bool) or not isinstance(gid, (str, Integral))):
        return f"id: expected a string or an integer, got {show(gid)}"
    if isinstance(gid, str) and not _is_unicode(gid):
        return f"id: not valid Unicode (it holds a lone surrogate), got {show(gid)}"
    return None


def _is_unicode(text: str) -> bool:
    """False for a string holding a lone surrogate (JSON allows ``"\\ud800"``; UTF-8 does not)."""
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        return False
    return True


@dataclass
class CheckedGrasps:
    """Grasps after the value rules: ``error`` per grasp (the first problem, prefixed with the
    contact's index), ``dim``, ``center`` (g, 3), ``length``, and the checked contacts with their
    grasp's ``offsets`` (g + 1)."""

    error: np.ndarray
    dim: np.ndarray
    center: np.ndarray
    length: np.ndarray
    contacts: Checked
    offsets: np.ndarray


MAX_GRASP_LENGTH = 4 * MAX_LENGTH
"""Largest ``length`` (given or default): about the largest distance between a center and a
point whose coordinates are within ``MAX_LENGTH`` (``2 sqrt(3) MAX_LENGTH``)."""


def _reach(d: np.ndarray) -> np.ndarray:
    """Euclidean norms of the rows of ``d``, scaled so that neither tiny nor huge coordinates
    underflow or overflow (0 for rows that are not finite)."""
    scale = _by_column(np.maximum, np.abs(d)) if d.size else np.zeros(len(d))
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        safe = np.where(scale > 0, scale, 1.0)
        norm = scale * np.sqrt(_by_column(np.add, (d / safe[:, None]) ** 2))
    return np.where(np.isfinite(norm), norm, 0.0)


def grasp_geometry(points: Sequence[tuple[float, ...]], center: Any = None,
                   length: Any = None) -> tuple[tuple[float, ...], float] | None:
    """The ``center`` and ``length`` of a grasp whose contacts are valid (their ``points``), by
    the rules of :func:`grasp_rules` (given values checked, defaults computed) when the grasp
    meets every rule; None for any other (:func:`grasp_rules` then decides and words it). Plain
    Python on scalars, the same floats: tests hold the two together.

    Examples
    --------
    >>> grasp_geometry([(0.0, 0.0), (4.0, 0.0), (2.0, 3.0)])
    ((2.0, 1.0), 2.23606797749979)
    """
    if not points or any(len(q) != len(points[0]) for q in points):
        return None
    dim = len(points[0])
    if center is None:  # the sum in contact order over the count, as the columns' bincount
        sums = [0.0] * dim
        for q in points:
            for i in range(dim):
                sums[i] += q[i]
        c = tuple(s / len(points) for s in sums)
    else:
        c = numbers(center)
        if c is None or len(c) != dim or not all(math.isfinite(x) and abs(x) <= MAX_LENGTH for x in c):
            return None
    if length is None:
        far = max(_reach_one(tuple(a - b for a, b in zip(q, c))) for q in points)
        size = max(abs(x) for q in points for x in q)
        L = far if far > 8 * 2.0**-53 * size else 1.0
    else:
        L = number(length)
    if L is None or not MIN_LENGTH <= L <= MAX_GRASP_LENGTH:
        return None
    return c, L


def _reach_one(d: tuple[float, ...]) -> float:
    """:func:`_reach` of one row, the same float."""
    norm = _scaled_norm(d)
    return norm if math.isfinite(norm) else 0.0


def _scaled_norm(v: tuple[float, ...]) -> float:
    """The Euclidean norm of ``v`` scaled by its largest magnitude, so that neither tiny nor huge
    coordinates underflow or overflow: the float :func:`_unit_normals` and :func:`_reach` compute
    for one row (their ``safe`` and ``scale`` factors differ only where the sum is 0)."""
    scale = max(abs(x) for x in v)
    safe = scale if scale > 0 else 1.0
    return scale * math.sqrt(sum((x / safe) * (x / safe) for x in v))


def check_grasps(data: GraspData, contacts: ContactData) -> CheckedGrasps:
    """Apply the grasp and contact value rules (module docstring); one message per bad grasp."""
    return grasp_rules(data, check_contacts(contacts))


def grasp_rules(data: GraspData, checked: Checked) -> CheckedGrasps:
    """The grasp rules and defaults on grasps whose contacts are already checked."""
    g = len(data.count)
    offsets = np.concatenate([[0], np.cumsum(data.count)])
    error = np.array(data.errors, dtype=object) if g else np.zeros(0, dtype=object)
    todo = np.equal(error, None)

    def fail(mask, message) -> None:
        for i in np.flatnonzero(mask & todo):
            error[i] = message(i)
            todo[i] = False

    # the first bad contact of each grasp names the grasp's problem
    owner = np.repeat(np.arange(g), data.count)
    bad = np.flatnonzero(checked.error != None)  # noqa: E711
    for j in bad[::-1]:  # reversed, so the first bad contact of a grasp is the one kept
        i = owner[j]
        if todo[i]:
            error[i] = f"contacts[{j - offsets[i]}].{checked.error[j]}"
    for j in bad:
        todo[owner[j]] = False
    fail(data.count == 0, lambda i: "contacts: a grasp needs at least one contact")
    dim = np.zeros(g, dtype=np.int64)
    has = data.count > 0
    dim[has] = checked.dim[offsets[:-1][has]]
    if len(owner):
        mixed = np.zeros(g, dtype=bool)  # a grasp's contacts are consecutive: one reduceat (.at is slow)
        mixed[has] = np.logical_or.reduceat(checked.dim != dim[owner], offsets[:-1][has])
        fail(mixed, lambda i: "contacts: mix dimensions "
                              f"{sorted(set(checked.dim[offsets[i]:offsets[i + 1]].tolist()))}; "
                              "a grasp is planar or spatial")
    given = data.clen >= 0
    fail(given & (data.clen != dim),
         lambda i: f"center: center has {data.clen[i]} coordinates, the contacts have {dim[i]}")
    with np.errstate(invalid="ignore"):
        finite = _by_column(np.logical_and, np.abs(data.center) <= MAX_LENGTH)  # False for NaN and infinities too
        fail(given & ~finite, lambda i: f"center: NaN or infinite coordinate, or one beyond {MAX_LENGTH:g}: "
                                        f"expected {dim[i]} finite numbers, got "
                                        f"{show(data.raw.get((i, 'center'), list(data.center[i, :data.clen[i]])))}")
        L = data.length
        fail(data.length_given & ~((L >= MIN_LENGTH) & (L <= MAX_GRASP_LENGTH)),
             lambda i: f"length: length must be > 0 (at least {MIN_LENGTH:g}), finite and <= "
                       f"{MAX_GRASP_LENGTH:g}, got {show(data.raw.get((i, 'length'), L[i]))}")
    ok = todo
    center = data.center.copy()
    length = data.length.copy()
    need_c = ok & ~given
    if need_c.any():
        # the centroid: the sum of the points in contact order over their count
        p = np.where(np.isfinite(checked.p), checked.p, 0.0)
        sums = np.stack([np.bincount(owner, p[:, q], minlength=g) for q in range(3)], axis=1)
        center[need_c] = sums[need_c] / np.maximum(data.count[need_c], 1)[:, None]
    need_l = ok & ~data.length_given
    if need_l.any():
        far, size = np.zeros(g), np.zeros(g)
        has = data.count > 0
        if has.any():
            far[has] = np.maximum.reduceat(_reach(checked.p - center[owner]), offsets[:-1][has])
            with np.errstate(invalid="ignore"):
                # NaN as 0 and infinity as the largest float, as np.nan_to_num before the maximum would
                top = np.nan_to_num(_by_column(np.fmax, np.abs(checked.p)))
                size[has] = np.maximum.reduceat(top, offsets[:-1][has])
        # contacts that coincide up to the rounding of their centroid: no lever arm to scale
        apart = far > 8 * 2.0**-53 * size
        length[need_l] = np.where(apart[need_l], far[need_l], 1.0)
        with np.errstate(invalid="ignore"):
            fail(need_l & ~((length >= MIN_LENGTH) & (length <= MAX_GRASP_LENGTH)),
                 lambda i: f"contacts: the contacts lie within {length[i]:.3g} of the center, outside the "
                           f"usable range [{MIN_LENGTH:g}, {MAX_GRASP_LENGTH:g}] of the length that divides "
                           "torques: give 'length' or rescale the coordinates")
    return CheckedGrasps(error, np.where(ok, dim, 0), np.where(ok[:, None], center, 0.0),
                         np.where(ok, length, 1.0), checked, offsets)

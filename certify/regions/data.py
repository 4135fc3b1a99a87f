"""Contact regions: sets of possible contacts for the fingers of a planar grasp, and their JSON form.

A **contact region** is where one finger may touch the object, with the finger's contact model
(any registered model with planar generators: ``frictionless``, ``point`` with ``mu``, ``pad``
with ``mu`` and ``width``):

* :class:`StraightRegion` ``(a, b, n)``: a stretch of a straight edge; the finger's point is
  anywhere on the segment ``[a, b]`` and the inward normal is ``n`` there.
* :class:`CurvedRegion` ``(points, normals)``: a stretch of a curve given as a polyline of
  boundary points with their inward normals (as an image outline gives it); the finger is at
  any point of the curve from the first point to the last.

A :class:`RegionTuple` holds one region per finger, an optional ``normal_tol`` (radians: the true
normal at every point may differ from the stated one by up to that angle), the torque
``center`` and ``length`` (as :class:`qualgrasp.certify.Grasp`; defaults: the centroid of the
region points and the largest distance from it to one), and an ``id``.

What a curved region allows between two consecutive points (the reading every verdict rests
on): the curve runs from ``P_j`` to ``P_j+1`` and its normal stays, all along, within the
angular interval spanned by ``N_j``, ``N_j+1`` and the chord's normal (the curve's tangent
must be parallel to the chord somewhere), widened by ``normal_tol`` on each side. The interval
must be narrower than 90 degrees (sample the curve densely enough). Then the tangent stays
within the same angles of the chord, so the curve lies in the parallelogram spanned from
``P_j`` and ``P_j+1`` by its extreme tangent directions; its height above and below the chord
is ``c tan(a_hi) tan(-a_lo) / (tan(a_hi) + tan(-a_lo))`` (``c`` the chord length, ``a_lo <= 0
<= a_hi`` the extreme tangent angles to the chord). :mod:`qualgrasp.certify.regions._branch` works
with that set. A curved region of one point is a point contact (with ``normal_tol``, its normal
varies).

Validation follows :mod:`qualgrasp.certify.core.validation`: numbers must be numbers, the model's
parameters are required and in their ranges, reductions apply (``mu = 0``: frictionless, a pad
of width 0: point), normals are normalised, and every message names the field:
``regions[1].a: expected 2 finite numbers, got "x"``.

JSON (one region tuple per line of a region set)::

    {"id": "r1", "regions": [{"a": [x, y], "b": [x, y], "n": [nx, ny], "model": "point", "mu": 0.5},
                             {"points": [[x, y], ...], "normals": [[nx, ny], ...],
                              "model": "frictionless"}],
     "normal_tol": 0.0, "center": [cx, cy], "length": 1.0}
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from numbers import Integral
from typing import Any, Mapping, Sequence, Union

import numpy as np

from .. import models as registry
from ..errors import GraspError
from ..core.grasp import Contact
from ..models import MAX_LENGTH, MIN_LENGTH
from ..core.validation import check_contacts, contact_arrays, contact_data, number, numbers, param_names, show

__all__ = ["MAX_NORMAL_TOL", "MAX_TURN", "MAX_REGIONS", "MAX_POINTS", "StraightRegion", "CurvedRegion",
           "Region", "RegionTuple", "region_from_dict", "region_to_dict", "tuple_from_dict",
           "tuple_to_dict", "contact_of"]

#: Largest ``normal_tol`` accepted, radians.
MAX_NORMAL_TOL = 0.5
#: Largest angle (radians) the normal may sweep between two consecutive points of a curved
#: region, ``normal_tol`` included on both sides.
MAX_TURN = math.pi / 2
#: Most regions in a tuple, and most points in a curved region (documented limits).
MAX_REGIONS = 64
MAX_POINTS = 100_000


def _model_params(model: str, params: Mapping[str, float]) -> dict[str, float]:
    return {name: float(params.get(name, 0.0)) for name in registry.get(model).param_names}


def _check_model(prefix: str, items: list[dict], names: Mapping[str, str]):
    """Run certify's contact rules on ``items`` (contact dicts); raise with the first message,
    the field renamed by ``names`` (``p`` -> ``a``), prefixed with ``prefix``. Returns Checked."""
    checked = check_contacts(contact_data(items))
    for j, err in enumerate(checked.error):
        if err is None:
            continue
        field, _, rest = str(err).partition(":")
        raise GraspError(f"{prefix}{names.get((j, field), field)}:{rest}")
    if len(items) and (checked.dim != 2).any():
        raise GraspError(f"{prefix}model: regions are planar")
    model = _without_planar_generators(checked)
    if model is not None:
        raise GraspError(f"{prefix}model: {model!r} contacts have no planar generators; "
                         f"regions take {', '.join(_planar_models())}")
    return checked


def _without_planar_generators(checked) -> str | None:
    """The name of a checked contacts' model (and variant) without planar generators, if any."""
    for code in set(checked.model.tolist()):
        model = registry.get(int(code))
        for variant in set(checked.variant[checked.model == code].tolist()):
            if model.generators(2, int(variant)) is None:
                return model.name
    return None


def _checked_lists(points, normals, model, mu, width, prefix: str):
    """``(P, checked)`` of a curved region given as sequences of points and normals; raises
    GraspError naming the first value that breaks a rule."""
    if isinstance(points, np.ndarray):
        points = points.tolist()
    if isinstance(normals, np.ndarray):
        normals = normals.tolist()
    if not isinstance(points, (list, tuple)) or not points:
        raise GraspError(f"{prefix}points: expected a list of at least one [x, y] point, got {show(points)}")
    if len(points) > MAX_POINTS:
        raise GraspError(f"{prefix}points: {len(points)} points, more than the limit of {MAX_POINTS}")
    if not isinstance(normals, (list, tuple)):
        raise GraspError(f"{prefix}normals: expected a list of [nx, ny] normals, got {show(normals)}")
    if len(normals) != len(points):
        raise GraspError(f"{prefix}normals: {len(normals)} normals for {len(points)} points")
    pts = [_point(prefix, f"points[{j}]", p) for j, p in enumerate(points)]
    nrm = []
    for j, v in enumerate(normals):
        vec = numbers(v)
        if vec is None or len(vec) != 2 or not all(math.isfinite(x) for x in vec):
            raise GraspError(f"{prefix}normals[{j}]: expected 2 finite numbers, got {show(v)}")
        nrm.append(vec)
    items = [{"p": list(p), "n": list(v), "model": model, "mu": mu, "width": width} for p, v in zip(pts, nrm)]
    names = {}
    for j in range(len(items)):
        names[(j, "p")], names[(j, " p")] = f"points[{j}]", f"points[{j}]"
        names[(j, "n")] = f"normals[{j}]"
    checked = _check_model(prefix, items, names)
    return np.array(pts, dtype=float).reshape(-1, 2), checked


def _checked_arrays(points, normals, model, mu, width):
    """``(P, checked)`` of a curved region given as float arrays (:func:`contact_arrays`) of 1 to
    :data:`MAX_POINTS` planar contacts that pass every rule, as the reading of lists gives them;
    None otherwise (that reading then states the problem)."""
    data = contact_arrays(points, normals, model, {"mu": mu, "width": width})
    if data is None or not 1 <= len(data.plen) <= MAX_POINTS:
        return None
    checked = check_contacts(data)
    if any(err is not None for err in checked.error) or (checked.dim != 2).any() \
            or _without_planar_generators(checked) is not None:
        return None
    return data.p[:, :2].copy(), checked


def _planar_models() -> list[str]:
    return [repr(m.name) for m in registry.models() if 2 in m.dims and m.generators(2, 0) is not None]


def _point(prefix: str, field: str, value: Any) -> tuple[float, float]:
    vec = numbers(value)
    if vec is None or len(vec) != 2 or not all(math.isfinite(v) for v in vec):
        extra = " (regions are planar; spatial regions are not supported)" if vec is not None and len(vec) == 3 else ""
        raise GraspError(f"{prefix}{field}: expected 2 finite numbers{extra}, got {show(value)}")
    if max(abs(v) for v in vec) > MAX_LENGTH:
        raise GraspError(f"{prefix}{field}: coordinate beyond {MAX_LENGTH:g}, got {show(value)}")
    return vec


def _params_of(prefix: str, d: Mapping[str, Any]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    model = d.get("model")
    if model is not None:
        out["model"] = model
    for name in param_names():
        if d.get(name) is not None:
            out[name] = d[name]
    return out


class _ModelParams:
    """The contact model's parameters of a region, read from ``params``."""

    params: tuple[tuple[str, float], ...]

    @property
    def mu(self) -> float:
        """Friction coefficient (0 when frictionless)."""
        return float(dict(self.params).get("mu", 0.0))

    @property
    def width(self) -> float:
        """Pad width (0 unless a pad)."""
        return float(dict(self.params).get("width", 0.0))

    @property
    def offset_length(self) -> float:
        """The length the model's generator offsets are in units of
        (:meth:`qualgrasp.certify.models.ContactModel.offset_length`: a pad's width), 0 without."""
        values = {name: np.array(value) for name, value in self.params}
        return float(registry.get(self.model).offset_length(values)) if values else 0.0


def _set_model(region: Any, checked) -> None:
    """Store a region's checked model: its registered name and its parameters in the model's order."""
    name = registry.get(int(checked.model[0])).name
    object.__setattr__(region, "model", name)
    object.__setattr__(region, "params", tuple((p, float(checked.params[p][0]))
                                               for p in registry.get(name).param_names))


@dataclass(frozen=True, init=False)
class StraightRegion(_ModelParams):
    """A straight contact region: the finger anywhere on the segment ``[a, b]``, inward normal ``n``.

    Parameters
    ----------
    a, b : sequence of 2 float
        End points (``a == b`` is a single point contact).
    n : sequence of 2 float
        Inward normal (normalised as certify does). It need not be exactly perpendicular to
        ``b - a``; the region is the set of contacts ``(q, n)`` for ``q`` on the segment.
    model : str
        ``'frictionless'`` (default), ``'point'`` or ``'pad'``.
    mu, width : float, optional
        The model's parameters (friction coefficient; pad width, unit of the coordinates).

    Attributes
    ----------
    a, b, n : tuple of float
    model : str
        The effective model (after reductions: ``mu = 0`` is frictionless, a pad of width 0 a
        point).
    params : tuple of (str, float)

    Examples
    --------
    >>> r = StraightRegion((1, -0.5), (1, 0.5), (-2, 0), "point", mu=0.5)
    >>> r.n, r.model, r.length
    ((-1.0, 0.0), 'point', 1.0)
    """

    a: tuple[float, float]
    b: tuple[float, float]
    n: tuple[float, float]
    model: str
    params: tuple[tuple[str, float], ...]

    def __init__(self, a, b, n, model: str | None = "frictionless", mu: float | None = None,
                 width: float | None = None, *, _prefix: str = "") -> None:
        a, b = _point(_prefix, "a", a), _point(_prefix, "b", b)
        nv = numbers(n)
        if nv is None or len(nv) != 2 or not all(math.isfinite(v) for v in nv):
            raise GraspError(f"{_prefix}n: expected 2 finite numbers, got {show(n)}")
        items = [{"p": list(a), "n": list(nv), "model": model, "mu": mu, "width": width},
                 {"p": list(b), "n": list(nv), "model": model, "mu": mu, "width": width}]
        checked = _check_model(_prefix, items, {(0, "p"): "a", (1, "p"): "b"})
        stored = tuple(float(v) for v in checked.n[0, :2])
        object.__setattr__(self, "a", a)
        object.__setattr__(self, "b", b)
        object.__setattr__(self, "n", stored)
        _set_model(self, checked)

    @property
    def length(self) -> float:
        """Length of the segment."""
        return math.hypot(self.b[0] - self.a[0], self.b[1] - self.a[1])

    @property
    def points(self) -> np.ndarray:
        """``(2, 2)`` the end points."""
        return np.array([self.a, self.b], dtype=float)

    def contact(self, p, n=None) -> Contact:
        """The contact of this region's model at ``p`` (normal ``n``, default the region's)."""
        return Contact(p, self.n if n is None else n, self.model, **dict(self.params))


@dataclass(frozen=True, init=False)
class CurvedRegion(_ModelParams):
    """A curved contact region: a polyline of boundary points with their inward normals.

    The finger is anywhere on the curve from the first point to the last; between two
    consecutive points the curve's normal stays within the angles of the two stated normals
    and the chord's normal (module docstring).

    Parameters
    ----------
    points : sequence of [x, y]
        At least one boundary point, in order along the curve.
    normals : sequence of [nx, ny]
        Inward normal at each point (normalised).
    model, mu, width
        As for :class:`StraightRegion`.

    Examples
    --------
    >>> import math
    >>> angles = [0.0, 0.1, 0.2]
    >>> r = CurvedRegion([(math.cos(t), math.sin(t)) for t in angles],
    ...                  [(-math.cos(t), -math.sin(t)) for t in angles], "point", mu=0.4)
    >>> r.points.shape, r.model
    ((3, 2), 'point')
    """

    points: np.ndarray
    normals: np.ndarray
    model: str
    params: tuple[tuple[str, float], ...]

    def __init__(self, points, normals, model: str | None = "frictionless", mu: float | None = None,
                 width: float | None = None, *, _prefix: str = "") -> None:
        # valid float arrays (the boundary's sub-curves) are read without a Python value per number
        P, checked = (_checked_arrays(points, normals, model, mu, width)
                      or _checked_lists(points, normals, model, mu, width, _prefix))
        N = np.ascontiguousarray(checked.n[:, :2], dtype=float)
        P.setflags(write=False)
        N.setflags(write=False)
        object.__setattr__(self, "points", P)
        object.__setattr__(self, "normals", N)
        _set_model(self, checked)

    @property
    def length(self) -> float:
        """Length of the polyline."""
        return float(np.hypot(*np.diff(self.points, axis=0).T).sum()) if len(self.points) > 1 else 0.0

    def contact(self, p, n) -> Contact:
        """The contact of this region's model at ``p`` with normal ``n``."""
        return Contact(p, n, self.model, **dict(self.params))

    def __eq__(self, other) -> bool:
        return (isinstance(other, CurvedRegion) and self.model == other.model and self.params == other.params
                and np.array_equal(self.points, other.points) and np.array_equal(self.normals, other.normals))

    def __hash__(self) -> int:
        return hash((self.model, self.params, self.points.tobytes(), self.normals.tobytes()))


Region = Union[StraightRegion, CurvedRegion]


def contact_of(region: Region, p, n) -> Contact:
    """The contact of ``region``'s model and parameters at ``p`` with normal ``n``."""
    return Contact(p, n, region.model, **dict(region.params))


def _turns(region: CurvedRegion, normal_tol: float, prefix: str) -> None:
    """Check that every arc's normal interval (with the chord's normal and ``normal_tol``) is
    narrower than :data:`MAX_TURN`."""
    P, N = region.points, region.normals
    for j in range(len(P) - 1):
        chord = P[j + 1] - P[j]
        angles = [0.0, _angle(N[j], N[j + 1])]
        if np.hypot(*chord) > 0:
            e = np.array([-chord[1], chord[0]]) / np.hypot(*chord)
            e = e if e @ (N[j] + N[j + 1]) >= 0 else -e
            angles.append(_angle(N[j], e))
        width = max(angles) - min(angles) + 2 * normal_tol
        if not width < MAX_TURN:
            raise GraspError(f"{prefix}normals[{j + 1}]: the curve turns by {math.degrees(width):.1f} degrees "
                             f"between points {j} and {j + 1} (normals, chord and normal_tol), more than "
                             f"{math.degrees(MAX_TURN):.0f}: sample the curve more densely")


def _angle(u, v) -> float:
    """Signed angle from ``u`` to ``v`` (radians)."""
    return math.atan2(u[0] * v[1] - u[1] * v[0], u[0] * v[0] + u[1] * v[1])


@dataclass(frozen=True, init=False)
class RegionTuple:
    """One contact region per finger, with the tolerance on normals and the torque scaling.

    Parameters
    ----------
    regions : sequence of StraightRegion or CurvedRegion
        At least one region.
    normal_tol : float
        Radians in ``[0, MAX_NORMAL_TOL]``: every true normal may differ from the stated one
        by up to this angle.
    center : sequence of 2 float, optional
        Torque reference point; default the centroid of the region points (``a``, ``b`` of
        straight regions, every point of curved ones).
    length : float, optional
        Length dividing torques; default the largest distance from ``center`` to a region point
        (1 when that is 0).
    id : str or int, optional

    Examples
    --------
    >>> t = RegionTuple([StraightRegion((1, -0.2), (1, 0.2), (-1, 0), "point", mu=0.5),
    ...                  StraightRegion((-1, -0.2), (-1, 0.2), (1, 0), "point", mu=0.5)], id="r1")
    >>> t.center, round(t.length, 4)
    ((0.0, 0.0), 1.0198)
    """

    regions: tuple
    normal_tol: float
    center: tuple[float, float]
    length: float
    id: Any

    def __init__(self, regions: Sequence[Region], normal_tol: float = 0.0, center=None, length=None,
                 id: Any = None) -> None:
        regions = tuple(regions)
        if not regions:
            raise GraspError("regions: a region tuple needs at least one region")
        if len(regions) > MAX_REGIONS:
            raise GraspError(f"regions: {len(regions)} regions, more than the limit of {MAX_REGIONS}")
        for i, r in enumerate(regions):
            if not isinstance(r, (StraightRegion, CurvedRegion)):
                raise GraspError(f"regions[{i}]: expected a StraightRegion or a CurvedRegion, got {r!r}")
        tol = number(normal_tol)
        if tol is None or not (0.0 <= tol <= MAX_NORMAL_TOL):
            raise GraspError(f"normal_tol: expected a number of radians in [0, {MAX_NORMAL_TOL}], got {show(normal_tol)}")
        for i, r in enumerate(regions):
            if isinstance(r, CurvedRegion):
                _turns(r, tol, f"regions[{i}].")
            elif 2 * tol >= MAX_TURN:
                raise GraspError(f"normal_tol: {tol} is too wide")
        pts = np.vstack([r.points for r in regions])
        if center is None:
            c = tuple(float(v) for v in pts.sum(axis=0) / len(pts))
        else:
            vec = numbers(center)
            if vec is None or len(vec) != 2 or not all(math.isfinite(v) and abs(v) <= MAX_LENGTH for v in vec):
                raise GraspError(f"center: expected 2 finite numbers, got {show(center)}")
            c = vec
        if length is None:
            reach = float(np.sqrt(((pts - np.array(c)) ** 2).sum(axis=1)).max())
            L = reach if reach > 0 else 1.0
        else:
            L = number(length)
            if L is None or not (MIN_LENGTH <= L <= MAX_LENGTH):
                raise GraspError(f"length: length must be > 0 (at least {MIN_LENGTH:g}), finite and <= "
                                 f"{MAX_LENGTH:g}, got {show(length)}")
        if id is not None and (isinstance(id, bool) or not isinstance(id, (str, Integral))):
            raise GraspError(f"id: expected a string or an integer, got {show(id)}")
        object.__setattr__(self, "regions", regions)
        object.__setattr__(self, "normal_tol", float(tol))
        object.__setattr__(self, "center", tuple(float(v) for v in c))
        object.__setattr__(self, "length", float(L))
        object.__setattr__(self, "id", id if not isinstance(id, Integral) else int(id))

    def __len__(self) -> int:
        return len(self.regions)

    @property
    def straight(self) -> bool:
        """Every region straight."""
        return all(isinstance(r, StraightRegion) for r in self.regions)

    @property
    def points_only(self) -> bool:
        """Every region a single point and ``normal_tol == 0``: the tuple is one grasp."""
        return self.normal_tol == 0 and all(
            (r.a == r.b) if isinstance(r, StraightRegion) else len(r.points) == 1 for r in self.regions)


def region_from_dict(d: Any, index: int | None = None) -> Region:
    """Build a region from its JSON form (module docstring).

    Parameters
    ----------
    d : mapping
        ``{"a", "b", "n", "model", ...}`` (straight) or ``{"points", "normals", "model", ...}``
        (curved); the model's parameters as keys (``mu``, ``width``).
    index : int, optional
        Position in the tuple, for messages (``regions[1].a: ...``).

    Returns
    -------
    StraightRegion or CurvedRegion

    Raises
    ------
    GraspError
        A value breaks a rule; the message names the field.

    Examples
    --------
    >>> region_from_dict({"a": [0, 0], "b": [1, 0], "n": [0, 1], "model": "pad", "mu": 0.5, "width": 0.1})
    StraightRegion(a=(0.0, 0.0), b=(1.0, 0.0), n=(0.0, 1.0), model='pad', params=(('mu', 0.5), ('width', 0.1)))
    >>> region_from_dict({"a": [0, "x"], "b": [1, 0], "n": [0, 1]}, 1)
    Traceback (most recent call last):
    ...
    qualgrasp.certify.errors.GraspError: regions[1].a: expected 2 finite numbers, got [0, "x"]
    """
    prefix = "" if index is None else f"regions[{index}]."
    if not isinstance(d, Mapping):
        raise GraspError(f"{prefix.rstrip('.') or 'region'}: expected an object with keys a, b, n or "
                         f"points, normals, got {show(d)}")
    straight = any(k in d for k in ("a", "b", "n"))
    curved = any(k in d for k in ("points", "normals"))
    if straight == curved:
        raise GraspError(f"{prefix.rstrip('.') or 'region'}: expected a straight region (a, b, n) or a curved "
                         f"one (points, normals), got keys {sorted(map(str, d))}")
    params = _params_of(prefix, d)
    model = params.pop("model", None)
    if "torsion" in params:
        raise GraspError(f"{prefix}torsion: regions are planar; no model with torsion applies")
    if straight:
        for key in ("a", "b", "n"):
            if d.get(key) is None:
                raise GraspError(f"{prefix}{key}: missing")
        return StraightRegion(d["a"], d["b"], d["n"], model, _prefix=prefix, **params)
    for key in ("points", "normals"):
        if d.get(key) is None:
            raise GraspError(f"{prefix}{key}: missing")
    return CurvedRegion(d["points"], d["normals"], model, _prefix=prefix, **params)


def region_to_dict(region: Region) -> dict[str, Any]:
    """The JSON form of a region (inverse of :func:`region_from_dict`).

    Parameters
    ----------
    region : StraightRegion or CurvedRegion

    Returns
    -------
    dict

    Examples
    --------
    >>> region_to_dict(StraightRegion((0, 0), (1, 0), (0, 1), "point", mu=0.5))
    {'a': [0.0, 0.0], 'b': [1.0, 0.0], 'n': [0.0, 1.0], 'model': 'point', 'mu': 0.5}
    """
    if isinstance(region, StraightRegion):
        out: dict[str, Any] = {"a": list(region.a), "b": list(region.b), "n": list(region.n)}
    else:
        out = {"points": region.points.tolist(), "normals": region.normals.tolist()}
    out["model"] = region.model
    out.update(region.params)
    return out


_TOP = ("id", "regions", "normal_tol", "center", "length")


def tuple_from_dict(d: Any) -> RegionTuple:
    """Build a :class:`RegionTuple` from one line of a region set (module docstring).

    Parameters
    ----------
    d : mapping
        ``{"id", "regions": [...], "normal_tol", "center", "length"}``; only ``regions`` is
        required.

    Returns
    -------
    RegionTuple

    Raises
    ------
    GraspError
        The message names the field (``regions[1].mu: ...``).

    Examples
    --------
    >>> t = tuple_from_dict({"id": "r1", "regions": [{"a": [1, 0], "b": [1, 0.5], "n": [-1, 0]},
    ...                                             {"points": [[-1, 0]], "normals": [[1, 0]]}]})
    >>> [type(r).__name__ for r in t.regions], t.id
    (['StraightRegion', 'CurvedRegion'], 'r1')
    """
    if not isinstance(d, Mapping):
        raise GraspError(f"expected a JSON object with a 'regions' list, got {show(d)}")
    rs = d.get("regions")
    if not isinstance(rs, (list, tuple)):
        raise GraspError("regions: missing (a region tuple needs a 'regions' list)" if rs is None else
                         f"regions: expected a list of regions, got {show(rs)}")
    if len(rs) > MAX_REGIONS:
        raise GraspError(f"regions: {len(rs)} regions, more than the limit of {MAX_REGIONS}")
    regions = [region_from_dict(r, i) for i, r in enumerate(rs)]
    tol = d.get("normal_tol", 0.0)
    return RegionTuple(regions, 0.0 if tol is None else tol, d.get("center"), d.get("length"), d.get("id"))


def tuple_to_dict(regions: RegionTuple) -> dict[str, Any]:
    """The JSON form of a region tuple (inverse of :func:`tuple_from_dict`).

    Parameters
    ----------
    regions : RegionTuple

    Returns
    -------
    dict
        ``id`` (when set), ``regions``, ``normal_tol``, ``center``, ``length``.

    Examples
    --------
    >>> t = RegionTuple([StraightRegion((0, 0), (0, 0), (1, 0))], id=3)
    >>> tuple_to_dict(t)
    {'id': 3, 'regions': [{'a': [0.0, 0.0], 'b': [0.0, 0.0], 'n': [1.0, 0.0], 'model': 'frictionless'}], 'normal_tol': 0.0, 'center': [0.0, 0.0], 'length': 1.0}
    """
    out: dict[str, Any] = {}
    if regions.id is not None:
        out["id"] = regions.id
    out.update(regions=[region_to_dict(r) for r in regions.regions], normal_tol=regions.normal_tol,
               center=list(regions.center), length=regions.length)
    return out

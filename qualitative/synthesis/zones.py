"""Zones of freedom (Reuleaux, Nielsen): where a frictionless grasp still lets the object turn or slide.

A planar motion of the object is a rotation about a centre ``c`` with angular velocity ``w`` or a
translation with velocity ``v``. A frictionless contact at ``p`` with inward unit normal ``n``
allows the motion to first order iff the contact point does not move into the finger:

* rotation: ``w * cross(p - c, n) >= 0``, so each contact's **normal line** splits the plane of
  centres into a closed half-plane of allowed positive centres and one of allowed negative ones;
* translation: ``v . n >= 0``.

Intersected over the contacts (no forces involved):

``Z+ = {c : cross(p_i - c, n_i) >= 0 for all i}``, ``Z- = {c : cross(p_i - c, n_i) <= 0 for all i}``,
``T = {v != 0 : v . n_i >= 0 for all i}``.

The grasp is in first-order form closure iff all three are empty; that is the strict positive
spanning of the contact wrenches that :func:`qualgrasp.certify.form_closure` decides with a linear programme
(a free motion is exactly a Farkas direction of that programme).

Conventions
-----------
* Coordinates are those of the contacts (pixels for grasps from images, x = column, y = row).
  ``cross(a, b) = a_x b_y - a_y b_x``. **Sign**: ``+`` means ``w > 0``, a rotation turning +x
  towards +y; on screen, with y pointing down, that is **clockwise** (the paper's ``Omega+``).
* ``Z+`` and ``Z-`` may be unbounded. They are represented **exactly** as half-plane
  intersections: finite vertices plus recession directions (its points at infinity), from which
  :meth:`Zone.polygon` draws a shapely polygon clipped to any box. Centres at infinity are
  translations: a recession direction ``d`` of ``Z+`` is the translation ``(d_y, -d_x)``, one of
  ``Z-`` the translation ``(-d_y, d_x)``; both recession cones are therefore fixed by ``T``.
* ``T`` is an arc of directions on the unit circle: its centre and half-width come from the
  angular-gap rule (the normals fill an arc of width ``2 pi - G``, ``G`` their largest angular gap,
  so ``T`` is the arc of half-width ``(G - pi) / 2`` around that arc's centre; negative means empty).

How it is computed
------------------
Motions are taken up to a positive factor, as points of the oriented projective plane: the twist
``y = (v_x, v_y, w L)`` written about the reference point ``center`` (default the contacts'
centroid), with ``L = length`` (default the largest distance from ``center`` to a contact). A centre
``c`` of sign ``s`` is the twist ``s (u_y, -u_x, 1)`` with ``u = (c - center) / L``; a translation is
``(v, 0)``. Contact ``i`` allows the half-space ``a_i . y >= 0`` with
``a_i = (n_i, cross(u_i, n_i))`` normalised to unit length (``u_i = (p_i - center) / L``). On the unit
sphere of twists the zone of freedom ``F`` is a spherical polygon; ``Z+`` is its upper hemisphere
(``w > 0``), ``Z-`` its lower one and ``T`` its equator. Each zone's vertices are the extreme rays of
the polyhedral cone ``{y : a_i . y >= 0, s y_3 >= 0}`` (pairwise intersections of the bounding
planes that satisfy every constraint), mapped back to centres (``y_3 != 0``) and directions at
infinity (``y_3 = 0``).

**Depth and tolerance.** A zone's depth is ``max over unit y in it of min_i a_i . y`` (for ``Z+``
the extra constraint ``y_3 >= 0`` joins the ``a_i``): the sine of the angular radius of the largest
cap of free motions inside it when positive; when negative, minus the sine of the smallest angle
by which the constraints must be relaxed before it admits a motion. It is evaluated exactly (up to
rounding) by enumerating the finitely many points where the maximum can occur: the ``a_i``, the
midpoints ``a_i + a_j``, the pairwise intersections ``a_i x a_j`` and, for triples, the normal of
the plane through three ``a_i`` (equal values on all three), both signs each. For ``T`` the depth
is ``sin((G - pi) / 2)``. A zone is ``empty`` when its depth is below ``-tol``, ``nonempty`` above
``tol`` and ``degenerate`` in between (empty or non-empty only within rounding of the boundary,
e.g. three normal lines meeting in a point). ``tol`` defaults to ``1e-7``, the margin tolerance of
:class:`qualgrasp.certify.Tolerances`: on grasps built at known distances from the boundary, every grasp
the linear programme calls degenerate has a depth below ``1e-7`` in magnitude
(``tests/test_zones.py`` counts the agreement). The verdict of the grasp is ``closure`` when all
three zones are empty, ``no_closure`` when one is non-empty, else ``degenerate``, like
:class:`qualgrasp.certify.Verdict`. The depths, their signs, and hence the verdicts do not depend on
``center``; their magnitudes do, through the metric on twists (``L``), which is why a grasp set
synthesised from one image uses one ``center`` and ``length``.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from functools import cache

import numpy as np
import shapely
from shapely.geometry import MultiPoint
from shapely.geometry.base import BaseGeometry

from ...certify.core.wrench import cross, wrench

from ..errors import ZoneError

__all__ = ["TOL", "Zone", "Translations", "Zones", "zones", "grasp_zones", "free_depth",
           "twist_constraints", "centre_of"]

TOL = 1e-7
_RAY = 1e-12  # slack accepted when a candidate ray is tested against the constraints (rounding)
_E3 = np.array([0.0, 0.0, 1.0])


@dataclass(frozen=True, eq=False)
class Zone:
    """``Z+`` (``sign = +1``) or ``Z-`` (``sign = -1``): allowed rotation centres, a convex region.

    Attributes
    ----------
    sign : int
        ``+1``: rotations turning +x towards +y (clockwise on screen), ``-1`` the opposite.
    vertices : numpy.ndarray
        ``(v, 2)`` finite vertices (x, y), in the contacts' frame (pixels), sorted around the zone.
    directions : numpy.ndarray
        ``(d, 2)`` unit recession directions: the zone holds ``vertex + t * d`` for ``t >= 0``
        (centres at infinity). Empty for a bounded zone.
    depth : float
        Signed depth (see the module notes): positive when the zone has interior.
    status : str
        ``empty``, ``nonempty`` or ``degenerate`` (within ``tol`` of changing).
    """

    sign: int
    vertices: np.ndarray
    directions: np.ndarray
    depth: float
    status: str

    @property
    def empty(self) -> bool:
        """True when the zone holds no finite centre (exactly, not only robustly)."""
        return len(self.vertices) == 0

    @property
    def bounded(self) -> bool:
        """True when the zone is bounded (or empty)."""
        return len(self.directions) == 0

    def polygon(self, bounds: tuple[float, float, float, float]) -> BaseGeometry:
        """The zone clipped to ``bounds = (xmin, ymin, xmax, ymax)`` as a shapely geometry.

        Exact: a bounded zone is the hull of its vertices; an unbounded one is cut from the box by
        the lines that support its vertices and directions (its edges). A zone without interior
        gives a point or a segment; a zone missing the box gives an empty geometry.
        """
        box = shapely.box(*bounds)
        if self.empty:
            return shapely.Polygon()
        if self.bounded:
            return MultiPoint(self.vertices).convex_hull.intersection(box)
        corners = np.asarray(box.exterior.coords)
        reach = 4.0 * float(np.max(np.linalg.norm(corners[:, None, :] - self.vertices[None], axis=2)))
        edges = _supporting_lines(self.vertices, self.directions)
        if edges is None:  # no interior: a ray, a line or a strip of zero width
            far = [self.vertices + reach * d for d in self.directions]
            return MultiPoint(np.vstack([self.vertices, *far])).convex_hull.intersection(box)
        region = box
        for m, offset in edges:  # keep {x : m . x <= offset}
            t = np.array([-m[1], m[0]])
            foot = offset * m
            region = region.intersection(shapely.Polygon(
                [foot - reach * t, foot + reach * t, foot + reach * t - reach * m, foot - reach * t - reach * m]))
        return region


def _supporting_lines(vertices: np.ndarray, directions: np.ndarray) -> list | None:
    """Edges ``(m, offset)`` (``m . x <= offset`` inside) of ``conv(vertices) + cone(directions)``.

    Candidate lines pass through two vertices or through a vertex along a direction; a candidate
    is an edge when every vertex and every direction lies on its inner side. None when the region
    has no interior.
    """
    scale = 1.0 + float(np.abs(vertices).max())
    inner = vertices.mean(axis=0) + 1e-3 * scale * directions.sum(axis=0)
    lines = [(vertices[i], vertices[j] - vertices[i]) for i, j in itertools.combinations(range(len(vertices)), 2)]
    lines += [(v, d) for v in vertices for d in directions]
    edges = []
    for point, along in lines:
        norm = np.linalg.norm(along)
        if norm < 1e-12 * scale:
            continue
        m = np.array([along[1], -along[0]]) / norm
        if m @ (inner - point) > 0:
            m = -m
        if m @ (inner - point) > -1e-12 * scale:
            continue  # the inner point is on the line: no interior on this side
        if (vertices @ m - m @ point).max() <= 1e-9 * scale and (directions @ m).max() <= 1e-9:
            edges.append((m, float(m @ point)))
    return edges or None


@dataclass(frozen=True, eq=False)
class Translations:
    """``T``: the free translation directions, an arc of the unit circle.

    Attributes
    ----------
    centre : numpy.ndarray
        Unit direction at the middle of the arc (the middle of the smallest arc holding the
        normals); defined even when the arc is empty.
    half_width : float
        Half the arc's angular width, radians, ``(G - pi) / 2`` for ``G`` the largest angular gap
        between the normals; negative when no translation is free. When the normals take exactly
        two opposite directions, ``T`` is the two directions orthogonal to them, of which the arc
        (of half-width 0, status ``degenerate``) shows one; ``Z+`` and ``Z-`` list both.
    depth : float
        ``sin(half_width)``.
    status : str
        ``empty``, ``nonempty`` or ``degenerate``.
    """

    centre: np.ndarray
    half_width: float
    depth: float
    status: str

    @property
    def empty(self) -> bool:
        return self.half_width < 0

    @property
    def ends(self) -> np.ndarray:
        """``(2, 2)`` unit directions at the ends of the arc (meaningless when empty)."""
        a = math.atan2(self.centre[1], self.centre[0])
        h = max(self.half_width, 0.0)
        return np.array([[math.cos(a - h), math.sin(a - h)], [math.cos(a + h), math.sin(a + h)]])


@dataclass(frozen=True, eq=False)
class Zones:
    """The zone of freedom of a set of frictionless contacts.

    Attributes
    ----------
    plus, minus : Zone
        ``Z+`` and ``Z-``.
    translations : Translations
        ``T``.
    depth : float
        Depth of the whole zone of freedom (all three together); negative iff form closure.
    status : str
        ``closure`` (all three zones empty), ``no_closure`` (one is non-empty) or ``degenerate``.
    center : numpy.ndarray
        Reference point of the twists, contacts' frame.
    length : float
        Length scaling angular velocities, contacts' units.
    """

    plus: Zone
    minus: Zone
    translations: Translations
    depth: float
    status: str
    center: np.ndarray
    length: float

    @property
    def empty(self) -> bool | None:
        """True (form closure), False, or None when degenerate."""
        return None if self.status == "degenerate" else self.status == "closure"


# --------------------------------------------------------------------------------------------------
# Input


def _frozen(array) -> np.ndarray:
    array = np.ascontiguousarray(array, dtype=np.float64)
    array.setflags(write=False)
    return array


def _check(points, normals) -> tuple[np.ndarray, np.ndarray]:
    p = np.asarray(points, dtype=np.float64)
    n = np.asarray(normals, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 2 or n.shape != p.shape or len(p) == 0:
        raise ZoneError(f"need (k, 2) points and normals with k >= 1, got shapes {p.shape} and {n.shape}")
    if not (np.isfinite(p).all() and np.isfinite(n).all()):
        raise ZoneError("points and normals must be finite")
    norm = np.linalg.norm(n, axis=1)
    if norm.min() < 1e-9:
        raise ZoneError("a normal is zero; give the inward unit normal of each contact")
    return p, n / norm[:, None]


def twist_constraints(points, normals, center=None, length=None) -> tuple[np.ndarray, np.ndarray, float]:
    """Unit constraint vectors ``a_i`` of the free twists, with the ``center`` and ``length`` used.

    Parameters
    ----------
    points, normals : array_like
        ``(k, 2)`` contact points and inward normals (normalised here).
    center : array_like, optional
        Reference point; default the centroid of the points.
    length : float, optional
        Length scale, ``> 0``; default the largest distance from ``center`` to a point (1 if 0).

    Returns
    -------
    a : numpy.ndarray
        ``(k, 3)`` unit rows; a twist ``y`` is allowed by contact ``i`` iff ``a_i . y >= 0``.
    center : numpy.ndarray
    length : float
    """
    p, n = _check(points, normals)
    c = p.mean(axis=0) if center is None else np.asarray(center, dtype=np.float64)
    if c.shape != (2,) or not np.isfinite(c).all():
        raise ZoneError(f"center must be a finite (x, y) pair, got {center!r}")
    if length is None:
        reach = float(np.linalg.norm(p - c, axis=1).max())
        length = reach if reach > 0 else 1.0
    elif not (math.isfinite(length) and length > 0):
        raise ZoneError(f"length must be finite and > 0, got {length!r}")
    return unit_wrenches(p, n, c, length), c, float(length)


def unit_wrenches(points, normals, center, length) -> np.ndarray:
    """The frictionless contacts' wrenches (certify's :func:`qualgrasp.certify.core.wrench.wrench` of the unit
    inward normals, torques about ``center`` divided by ``length``), each scaled to unit norm:
    the constraint vectors ``a_i`` of the free twists, ``(..., 3)``."""
    a = wrench(np.asarray(points, dtype=np.float64), np.asarray(normals, dtype=np.float64),
               np.asarray(center, dtype=np.float64), length)
    return a / np.linalg.norm(a, axis=-1, keepdims=True)


def centre_of(y: np.ndarray, center: np.ndarray, length: float) -> np.ndarray:
    """The rotation centre (contacts' frame) of twists ``y`` (``(..., 3)``, ``y_3 != 0``)."""
    u = np.stack([-y[..., 1] / y[..., 2], y[..., 0] / y[..., 2]], axis=-1)
    return center + length * u


# --------------------------------------------------------------------------------------------------
# Depth: max over unit y of min_i a_i . y, by enumeration of the points where it can be attained


@cache
def _combos(k: int) -> tuple[np.ndarray, np.ndarray]:
    pairs = np.array(list(itertools.combinations(range(k), 2)), dtype=np.intp).reshape(-1, 2)
    triples = np.array(list(itertools.combinations(range(k), 3)), dtype=np.intp).reshape(-1, 3)
    return pairs, triples


def _unit(v: np.ndarray) -> np.ndarray:
    """Rows normalised; rows too short to have a direction become 0 (their value is then 0)."""
    norm = np.linalg.norm(v, axis=-1, keepdims=True)
    return np.where(norm > 1e-12, v / np.where(norm > 0, norm, 1.0), 0.0)


def _depth(a: np.ndarray) -> np.ndarray:
    """``max over unit y of min_i a_i . y`` for a batch ``a`` of shape ``(B, k, 3)`` (unit rows).

    The maximum of a minimum of linear functions on the sphere is attained where one, two or
    three of them are equal and active (Caratheodory in the plane ``a . y = value``): at ``+-a_i``,
    at ``+-(a_i + a_j)`` (equal norms: the nearest point of a chord), at ``+-(a_i x a_j)`` (value 0)
    or along ``+-(a_j - a_i) x (a_k - a_i)`` for a triple (equal values on all three). A rank-one
    set (all ``a_i`` parallel) is handled by the ``a_i`` themselves and by vectors orthogonal to them.
    """
    B, k, _ = a.shape
    pairs, triples = _combos(k)
    cands = [a]
    if len(pairs):
        ai, aj = a[:, pairs[:, 0]], a[:, pairs[:, 1]]
        cands += [_unit(ai + aj), _unit(cross(ai, aj))]
    if len(triples):
        # equal values on a triple: y normal to the plane through the three points a_i, a_j, a_k
        ai, aj, ak = (a[:, triples[:, m]] for m in range(3))
        cands.append(_unit(cross(aj - ai, ak - ai)))
    # vectors orthogonal to a_0 (one of them non-zero): they cover a rank-one set of constraints
    cands += [_unit(cross(a[:, :1], axis)) for axis in np.eye(3)[[0, 2]]]
    y = np.concatenate(cands, axis=1)
    y = np.concatenate([y, -y], axis=1)
    valid = np.linalg.norm(y, axis=2) > 0.5
    values = np.einsum("bck,bik->bci", y, a).min(axis=2)
    return np.where(valid, values, -np.inf).max(axis=1)


def free_depth(points, normals, center, length) -> np.ndarray:
    """Depth of the whole zone of freedom for a batch of grasps (negative iff form closure).

    Parameters
    ----------
    points, normals : array_like
        ``(B, k, 2)`` contact points and inward unit normals of ``B`` grasps of ``k`` contacts.
    center : array_like
        ``(2,)`` reference point shared by the batch.
    length : float
        Length scale of the batch.

    Returns
    -------
    numpy.ndarray
        ``(B,)`` depths (see the module notes).
    """
    p = np.asarray(points, dtype=np.float64)
    n = np.asarray(normals, dtype=np.float64)
    n = n / np.linalg.norm(n, axis=-1, keepdims=True)
    return _depth(unit_wrenches(p, n, center, length))


# --------------------------------------------------------------------------------------------------
# Exact regions: extreme rays of the cone of free twists


def _extreme_rays(C: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Extreme rays and lineality basis of the cone ``{y in R^3 : C y >= 0}`` (rows of ``C`` unit).

    Returns ``(rays, lines)``: unit extreme rays of the pointed part (the cone minus its lineality
    space) and an orthonormal basis of the lineality space. ``{0}`` gives two empty arrays.
    """
    _, sv, vt = np.linalg.svd(C)
    rank = int(np.sum(sv > 1e-12 * sv[0]))
    lines, Q = vt[rank:], vt[:rank].T  # Q: orthonormal basis of the lineality space's complement
    D = C @ Q  # the constraints within the complement, where the cone is pointed
    if rank == 3:
        i, j = np.triu_indices(len(D), 1)
        cand = cross(D[i], D[j])
    elif rank == 2:
        cand = np.column_stack([-D[:, 1], D[:, 0]])
    else:  # rank 1: a half-line on each side
        cand = np.sign(D[:, :1]) if len(D) else np.zeros((0, 1))
    cand = _unit(cand)
    cand = cand[np.linalg.norm(cand, axis=1) > 0.5]
    cand = np.vstack([cand, -cand])
    ok = (cand @ D.T).min(axis=1) >= -_RAY if len(cand) else np.zeros(0, bool)
    rays = []
    for r in cand[ok]:
        if all(np.linalg.norm(r - s) > 1e-9 for s in rays):
            rays.append(r)
    rays = np.array(rays).reshape(-1, rank) @ Q.T if rays else np.zeros((0, 3))
    return rays, lines


def _zone(a: np.ndarray, sign: int, center: np.ndarray, length: float, tol: float) -> Zone:
    C = np.vstack([a, sign * _E3])
    rays, lines = _extreme_rays(C)
    finite = rays[np.abs(rays[:, 2]) > _RAY] if len(rays) else rays
    ideal = np.vstack([rays[np.abs(rays[:, 2]) <= _RAY], lines, -lines]) if len(rays) or len(lines) else rays
    vertices = centre_of(finite, center, length) if len(finite) else np.zeros((0, 2))
    # a twist (y1, y2, 0) in Z+ is the limit of centres far along d = (-y2, y1); in Z-, along -d
    directions = sign * np.column_stack([-ideal[:, 1], ideal[:, 0]]) if len(ideal) else np.zeros((0, 2))
    directions = _unit(directions)
    directions = directions[np.linalg.norm(directions, axis=1) > 0.5]
    if len(vertices) > 2:
        mid = vertices.mean(axis=0)
        vertices = vertices[np.argsort(np.arctan2(*(vertices - mid).T[::-1]))]
    depth = float(_depth(C[None])[0])
    return Zone(sign, _frozen(vertices), _frozen(directions), depth, _status(depth, tol))


def _translations(normals: np.ndarray, tol: float) -> Translations:
    angles = np.sort(np.arctan2(normals[:, 1], normals[:, 0]))
    gaps = np.diff(np.concatenate([angles, angles[:1] + 2 * np.pi]))
    g = int(np.argmax(gaps))
    gap = float(gaps[g])
    # the normals fill the arc from angles[g + 1] round to angles[g]; T is centred on its middle
    middle = angles[(g + 1) % len(angles)] + (2 * np.pi - gap) / 2
    half = (gap - np.pi) / 2
    depth = math.sin(half)
    return Translations(_frozen([math.cos(middle), math.sin(middle)]), half, depth, _status(depth, tol))


def _status(depth: float, tol: float) -> str:
    if depth < -tol:
        return "empty"
    if depth > tol:
        return "nonempty"
    return "degenerate"


def zones(points, normals, *, center=None, length=None, tol: float = TOL) -> Zones:
    """Zones of freedom ``Z+``, ``Z-`` and ``T`` of frictionless contacts.

    Parameters
    ----------
    points : array_like
        ``(k, 2)`` contact points (x, y), e.g. pixels (x = column, y = row).
    normals : array_like
        ``(k, 2)`` inward normals (into the object); normalised here.
    center : array_like, optional
        Reference point of the twists (default: centroid of the points). Verdicts do not depend on it.
    length : float, optional
        Length scale (default: largest distance from ``center`` to a point).
    tol : float
        Depth band within which a zone is ``degenerate`` (unit-free; default ``1e-7``).

    Returns
    -------
    Zones

    Raises
    ------
    ZoneError
        Malformed input (shapes, non-finite values, zero normal, bad ``center`` or ``length``).
    """
    if not (tol >= 0 and math.isfinite(tol)):
        raise ZoneError(f"tol must be finite and >= 0, got {tol!r}")
    a, c, L = twist_constraints(points, normals, center, length)
    _, n = _check(points, normals)
    plus, minus = _zone(a, 1, c, L, tol), _zone(a, -1, c, L, tol)
    trans = _translations(n, tol)
    statuses = {plus.status, minus.status, trans.status}
    if statuses == {"empty"}:
        status = "closure"
    elif "nonempty" in statuses:
        status = "no_closure"
    else:
        status = "degenerate"
    depth = float(_depth(a[None])[0])
    return Zones(plus, minus, trans, depth, status, _frozen(c), L)


def grasp_zones(grasp, *, tol: float = TOL) -> Zones:
    """:func:`zones` of a planar :class:`qualgrasp.certify.Grasp`, every contact taken as frictionless,
    about the grasp's own ``center`` and ``length``."""
    if grasp.dim != 2:
        raise ZoneError("zones of freedom are planar; this grasp is spatial")
    return zones(grasp.points, grasp.normals, center=grasp.center, length=grasp.length, tol=tol)

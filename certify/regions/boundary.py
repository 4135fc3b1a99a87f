"""Independent contact regions of a grasp on a closed boundary: how far may each finger slide?

The object's boundary is a closed polygon of points ``P_0 .. P_n-1`` with inward normals
``N_0 .. N_n-1`` (positions along it by arc length ``s``, from ``P_0``). An edge ``P_e P_e+1`` is
**straight** when its two normals are equal (within ``1e-9``) and perpendicular to it (within
``1e-9`` relative); consecutive straight edges with the same normal form a **straight run** (a
side of a polygon, however finely sampled). Other edges are curved stretches read as
:mod:`qualgrasp.certify.regions.data` reads curved regions; a zero-length edge across which the
normal turns is a corner.

:func:`independent_regions` finds, for a grasp whose contacts lie on the boundary, the largest
``delta`` such that the regions made of the boundary within arc length ``delta`` on each side of
every contact -- clipped at the contact's **limits**, an arc-length interval it must not leave
(default: the straight run the contact lies on, or its own edge on a curved stretch, so that a
finger never slides over a corner) -- are robust (:func:`qualgrasp.certify.regions.decide.certify_regions`).
A stretch within one straight run is a :class:`~qualgrasp.certify.regions.data.StraightRegion`;
any other is a :class:`~qualgrasp.certify.regions.data.CurvedRegion` through the boundary points,
widened outward to the boundary points around its ends (never beyond a limit: limits on curved
stretches are rounded inward to boundary points), so that every point of the stretch is covered.

Robustness only shrinks as ``delta`` grows (the regions grow), so ``delta`` is found by
bisection, to ``tol`` (boundary units; default ``1e-3`` of the object's size). ``undecided``
verdicts (a budget spent) count as not robust: the ``delta`` returned is certified.

``delta`` is the half-width **before clipping**: a contact near the end of its limits reaches
less far on that side (and a curved stretch reaches the boundary points around it). What the
certificate covers is stated by the **certified extents**, per finger and side the arc length
from the contact to the end of its certified region, and the **certified slide**, the smallest
of them: how far every finger may slide along the boundary either way with closure certified.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from ..core.closure import Verdict, force_closure
from ..errors import GraspError
from ..core.grasp import Contact, Grasp
from .decide import RegionVerdict, certify_regions
from .data import CurvedRegion, RegionTuple, StraightRegion

__all__ = ["Boundary", "IndependentRegions", "independent_regions", "enclosing_diameter", "SEARCH_BUDGET",
           "TOL_FLOOR", "bisection_tol"]

_NORMAL_EQ = 1e-9
#: Default branch-and-bound budget of each region tuple tried by the bisection (work units):
#: smaller than :func:`certify_regions`' default, since a tuple left undecided only makes the
#: certified ``delta`` a little smaller.
SEARCH_BUDGET = 50_000
#: Finest bisection tolerance, fraction of the object's size: at most 30 halvings.
TOL_FLOOR = 1e-9


def enclosing_diameter(points) -> float:
    """Diameter of the minimum enclosing circle of ``points`` (Welzl's algorithm, iterative,
    points in a fixed pseudo-random order).

    Examples
    --------
    >>> enclosing_diameter([(0, 0), (2, 0), (1, 0.5)])
    2.0
    """
    P = np.unique(np.asarray(points, dtype=float).reshape(-1, 2), axis=0)
    P = P[np.random.default_rng(0).permutation(len(P))]

    def circle2(a, b):
        c = (a + b) / 2
        return c, float(np.hypot(*(a - c)))

    def circle3(a, b, c):
        bx, by = b - a
        cx, cy = c - a
        d = 2 * (bx * cy - by * cx)
        if d == 0:
            pairs = [circle2(a, b), circle2(a, c), circle2(b, c)]
            return max(pairs, key=lambda t: t[1])
        ux = (cy * (bx * bx + by * by) - by * (cx * cx + cy * cy)) / d
        uy = (bx * (cx * cx + cy * cy) - cx * (bx * bx + by * by)) / d
        centre = a + np.array([ux, uy])
        return centre, float(np.hypot(ux, uy))

    def inside(circle, p):
        return np.hypot(*(p - circle[0])) <= circle[1] * (1 + 1e-12) + 1e-12

    if len(P) == 0:
        return 0.0
    circ = (P[0], 0.0)
    for i in range(1, len(P)):
        if inside(circ, P[i]):
            continue
        circ = (P[i], 0.0)
        for j in range(i):
            if inside(circ, P[j]):
                continue
            circ = circle2(P[i], P[j])
            for k in range(j):
                if not inside(circ, P[k]):
                    circ = circle3(P[i], P[j], P[k])
    return 2 * circ[1]


@dataclass(frozen=True, eq=False)
class Boundary:
    """A closed boundary polygon with inward normals, parametrised by arc length.

    Parameters
    ----------
    points : array_like, shape (n, 2)
        The boundary points in order (either orientation; the closing point not repeated).
    normals : array_like, shape (n, 2)
        Inward normals at the points (normalised).

    Attributes
    ----------
    points, normals : ndarray
    cum : ndarray, shape (n + 1,)
        Arc length at each point, ``cum[n]`` the perimeter.
    straight : ndarray of bool, shape (n,)
        Edge ``e`` (from point ``e`` to ``e + 1``) is straight.
    run : ndarray of int, shape (n,)
        Straight run of each edge (-1 on curved edges).
    size : float
        Diameter of the minimum enclosing circle.
    """

    points: np.ndarray
    normals: np.ndarray
    cum: np.ndarray
    straight: np.ndarray
    run: np.ndarray
    size: float

    @classmethod
    def of(cls, points, normals) -> "Boundary":
        """Build and check a boundary (see the class docstring)."""
        P = np.asarray(points, dtype=float)
        N = np.asarray(normals, dtype=float)
        if P.ndim != 2 or P.shape[1] != 2 or len(P) < 3 or N.shape != P.shape:
            raise GraspError(f"boundary: expected (n, 2) points and normals with n >= 3, got shapes "
                             f"{P.shape} and {N.shape}")
        if not (np.isfinite(P).all() and np.isfinite(N).all()):
            raise GraspError("boundary: points and normals must be finite")
        norm = np.hypot(N[:, 0], N[:, 1])
        if (norm < 1e-9).any():
            raise GraspError(f"boundary: normal {int(np.argmin(norm))} is zero")
        N = np.where(np.abs(norm - 1)[:, None] <= 1e-12, N, N / norm[:, None])
        n = len(P)
        D = np.roll(P, -1, axis=0) - P
        length = np.hypot(D[:, 0], D[:, 1])
        cum = np.concatenate([[0.0], np.cumsum(length)])
        N1 = np.roll(N, -1, axis=0)
        same = np.abs(N - N1).max(axis=1) <= _NORMAL_EQ
        perp = np.abs((N * D).sum(axis=1)) <= _NORMAL_EQ * length
        straight = same & perp & (length > 0)
        run = np.full(n, -1, dtype=np.int64)
        label = 0
        # runs: maximal sequences of straight edges with the same normal (cyclic)
        start = next((e for e in range(n) if not (straight[e] and straight[e - 1]
                                                  and np.abs(N[e] - N[e - 1]).max() <= _NORMAL_EQ)), 0)
        for q in range(n):
            e = (start + q) % n
            if not straight[e]:
                continue
            prev = (e - 1) % n
            if q > 0 and straight[prev] and np.abs(N[e] - N[prev]).max() <= _NORMAL_EQ and run[prev] >= 0:
                run[e] = run[prev]
            else:
                run[e] = label
                label += 1
        for arr in (P, N, cum, straight, run):
            arr.setflags(write=False)
        return cls(P, N, cum, straight, run, enclosing_diameter(P))

    @property
    def perimeter(self) -> float:
        """Length of the boundary."""
        return float(self.cum[-1])

    def locate(self, p) -> tuple[float, float, int]:
        """Arc length of the boundary point nearest to ``p``, the distance, and its edge."""
        P = self.points
        D = np.roll(P, -1, axis=0) - P
        L2 = (D * D).sum(axis=1)
        t = np.clip(np.where(L2 > 0, ((np.asarray(p, float) - P) * D).sum(axis=1) / np.where(L2 > 0, L2, 1), 0.0), 0, 1)
        near = P + t[:, None] * D
        dist = np.hypot(*(near - np.asarray(p, float)).T)
        e = int(np.argmin(dist))
        return float(self.cum[e] + t[e] * math.sqrt(L2[e])), float(dist[e]), e

    def edge_at(self, s: float) -> int:
        """The edge containing arc length ``s`` (taken modulo the perimeter; a point shared by
        two edges belongs to the later one)."""
        s = s % self.perimeter
        e = int(np.searchsorted(self.cum, s, side="right")) - 1
        return min(max(e, 0), len(self.points) - 1)

    def point_at(self, s: float) -> tuple[float, float]:
        """The boundary point at arc length ``s`` (modulo the perimeter)."""
        s = s % self.perimeter
        e = self.edge_at(s)
        length = self.cum[e + 1] - self.cum[e]
        a, b = self.points[e], self.points[(e + 1) % len(self.points)]
        if length <= 0:
            return tuple(map(float, a))
        t = (s - self.cum[e]) / length
        if t <= 0:
            return tuple(map(float, a))
        if t >= 1:
            return tuple(map(float, b))
        return tuple(float(v) for v in a + t * (b - a))

    def default_limits(self, s: float, edge: int) -> tuple[float, float]:
        """The straight run around ``edge`` (or the edge itself), unwrapped around ``s``."""
        n = len(self.points)
        if self.run[edge] < 0:
            lo, hi = self.cum[edge], self.cum[edge + 1]
        else:
            a = b = edge
            while self.run[(a - 1) % n] == self.run[edge] and edge - (a - 1) < n:
                a -= 1
            while self.run[(b + 1) % n] == self.run[edge] and (b + 1) - a < n:
                b += 1
            lo = self.cum[a % n] + (a // n) * self.perimeter
            hi = self.cum[b % n + 1] + (b // n) * self.perimeter
        return _unwrap(lo, hi, s, self.perimeter)

    def stretch(self, lo: float, hi: float, limits: tuple[float, float], tol_normal: float = 0.0):
        """The region over arc lengths ``[lo, hi]`` (within ``limits``, unwrapped): ``(kind, data,
        covered)``, ``kind`` ``'straight'`` (``data`` = end points and normal) or ``'curved'``
        (``data`` = boundary points and normals), and ``covered`` the arc-length interval
        (unwrapped like ``lo``) from the region's first end to its last: ``(lo, hi)`` on a straight
        run, the boundary points it was widened or rounded to on a curved stretch."""
        n = len(self.points)
        e0 = self._edge_unwrapped(lo, up=True)
        e1 = self._edge_unwrapped(hi, up=False)
        edges = range(e0, e1 + 1)
        run = self.run[e0 % n]
        if run >= 0 and all(self.run[e % n] == run for e in edges):
            return ("straight", (self.point_at(lo), self.point_at(hi), tuple(map(float, self.normals[e0 % n]))),
                    (float(lo), float(hi)))
        # curved: whole edges, from the point at or before lo to the point at or after hi,
        # never beyond the limits (rounded inward to points)
        first = self._vertex_unwrapped(lo, down=True)
        last = self._vertex_unwrapped(hi, down=False)
        lim_lo = self._vertex_unwrapped(limits[0], down=False)
        lim_hi = self._vertex_unwrapped(limits[1], down=True)
        first, last = max(first, lim_lo), min(last, lim_hi)
        if last < first:
            last = first
        idx = [v % n for v in range(first, last + 1)]
        return "curved", (self.points[idx], self.normals[idx]), (self._arc(first), self._arc(last))

    def _arc(self, v: int) -> float:
        """Unwrapped arc length of the unwrapped boundary point index ``v``."""
        n = len(self.points)
        return float(self.cum[v % n] + (v // n) * self.perimeter)

    def _edge_unwrapped(self, s: float, up: bool) -> int:
        """Unwrapped edge index containing ``s``; at a shared point, the edge after (``up``) or
        before it."""
        per, n = self.perimeter, len(self.points)
        k = math.floor(s / per) if up else math.ceil(s / per) - 1  # r in [0, per) or (0, per]
        r = s - k * per
        e = int(np.searchsorted(self.cum, r, side="right" if up else "left")) - 1
        e = min(max(e, 0), n - 1)
        return e + k * n

    def _vertex_unwrapped(self, s: float, down: bool) -> int:
        """Unwrapped index of the boundary point at or before (``down``) / at or after ``s``."""
        per, n = self.perimeter, len(self.points)
        k = math.floor(s / per)
        r = s - k * per
        if down:
            v = int(np.searchsorted(self.cum, r, side="right")) - 1
        else:
            v = int(np.searchsorted(self.cum, r, side="left"))
        return v + k * n


def _unwrap(lo: float, hi: float, s: float, per: float, slack: float = 0.0) -> tuple[float, float]:
    """``(lo, hi)`` shifted by whole perimeters so that ``lo <= s <= hi`` (when possible); a
    contact up to ``slack`` outside the limits (its projection onto the boundary and the limits'
    sample positions differ by rounding, up to a boundary step) widens them to reach it."""
    if hi < lo:
        hi += per
    shift = math.floor((s - lo + slack) / per) * per  # s = lo + per up to rounding: that period
    lo, hi = lo + shift, hi + shift
    if s > hi + slack + 1e-9 * per or s < lo - slack - 1e-9 * per:
        raise GraspError(f"limits ({lo}, {hi}) do not contain the contact's position {s}")
    return min(lo, s), max(hi, s)


@dataclass(frozen=True)
class IndependentRegions:
    """Outcome of :func:`independent_regions`.

    What the certificate covers is stated by ``extents`` and ``slide``; ``delta`` is the search's
    parameter, the half-width of each stretch **before** it is clipped at the contact's limits
    (a contact near the end of its limits reaches less far on that side, and a curved stretch is
    widened to whole boundary samples), so ``delta`` alone does not say how far a finger may
    slide.

    Attributes
    ----------
    status : {'robust', 'not_robust', 'undecided'}
        ``robust``: some ``delta > 0`` is certified; ``not_robust``: the grasp itself is not in
        force closure; ``undecided``: it is (or is degenerate) but no ``delta > 0`` was certified.
    delta : float
        The bisection parameter certified (boundary units): the common half-width, or the
        smallest per-finger one, of the stretches ``[s - delta, s + delta]`` before clipping.
    deltas : tuple of float
        Per finger, its half-width before clipping (all equal to ``delta`` when ``symmetric``).
    delta_fraction : float
        ``delta`` over the object's size (diameter of the boundary's minimum enclosing circle).
    regions : RegionTuple or None
        The certified regions (straight or curved per finger).
    verdict : RegionVerdict or None
        Their verdict, with the certificate.
    grasp_verdict : Verdict
        Certify's verdict on the grasp itself.
    positions : tuple of float
        Arc length of each contact along the boundary.
    limits : tuple of (float, float)
        Each contact's limits (unwrapped around its position).
    size : float
    evaluations : int
        Region tuples certified during the search.
    seconds : float
    extents : tuple of (float, float)
        Per finger, the **certified extents** (boundary units): the arc length along the
        boundary from the contact back to the start of its certified region and on to its end
        (``(before, after)``, in the boundary's order); every placement of each finger within
        its extents is covered by the certificate. ``(0, 0)`` without certified regions.
    slide : float
        The **certified slide** (boundary units): the smallest extent over fingers and sides,
        how far every finger may slide along the boundary either way with closure certified.
    slide_fraction : float
        ``slide`` over the object's size.
    """

    status: str
    delta: float
    deltas: tuple[float, ...]
    delta_fraction: float
    regions: RegionTuple | None
    verdict: RegionVerdict | None
    grasp_verdict: Verdict
    positions: tuple[float, ...]
    limits: tuple[tuple[float, float], ...]
    size: float
    evaluations: int = 0
    seconds: float = 0.0
    extents: tuple[tuple[float, float], ...] = ()
    slide: float = 0.0
    slide_fraction: float = 0.0

    @property
    def certificate(self) -> dict | None:
        """The certificate of the certified regions (None when none is certified)."""
        return None if self.verdict is None else self.verdict.certificate


def _extents(positions, covered, slack: float) -> tuple[tuple[float, float], ...]:
    """Per finger ``(before, after)``: from its position ``s`` to the ends of the covered
    interval ``(start, end)``; ``(0, 0)`` when the interval misses ``s`` by more than ``slack``
    (the certificate then covers no stretch through the contact), rounding below ``slack``
    read as 0."""
    out = []
    for s, (start, end) in zip(positions, covered):
        if not start - slack <= s <= end + slack:
            out.append((0.0, 0.0))
        else:
            out.append((max(0.0, float(s - start)), max(0.0, float(end - s))))
    return tuple(out)


def _contacts(boundary: Boundary, contacts, models) -> list[Contact]:
    if isinstance(contacts, Grasp):
        contacts = list(contacts.contacts)
    elif isinstance(contacts, np.ndarray) or (isinstance(contacts, (list, tuple)) and contacts
                                              and not isinstance(contacts[0], Contact)):
        pts = np.asarray(contacts, dtype=float).reshape(-1, 2)
        if models is None:
            raise GraspError("contacts given as points need their models (models={'model': ..., 'mu': ...})")
        out = []
        for p in pts:
            s, _, e = boundary.locate(p)
            j = e if s - boundary.cum[e] <= boundary.cum[e + 1] - s else (e + 1) % len(boundary.points)
            n = boundary.normals[e] if boundary.straight[e] else boundary.normals[j]
            out.append(Contact(tuple(p), tuple(n)))
        contacts = out
    contacts = list(contacts)
    if not contacts or not all(isinstance(c, Contact) and c.dim == 2 for c in contacts):
        raise GraspError("contacts: expected a planar Grasp, Contacts, or (k, 2) points")
    if models is not None:
        specs = [models] * len(contacts) if isinstance(models, dict) else list(models)
        if len(specs) != len(contacts):
            raise GraspError(f"models: {len(specs)} model specifications for {len(contacts)} contacts")
        contacts = [Contact(c.p, c.n, spec.get("model"), **{k: v for k, v in spec.items() if k != "model"})
                    for c, spec in zip(contacts, specs)]
    return contacts


def bisection_tol(tol: float | None, size: float) -> float:
    """The bisection tolerance of :func:`independent_regions` for an object of ``size``
    (boundary units): ``tol``, or ``1e-3`` of the size when None.

    Raises
    ------
    GraspError
        ``tol`` is not finite or below :data:`TOL_FLOOR` of the size: the bisection takes
        ``log2(size / tol)`` certificates, and below rounding it would not end.

    Examples
    --------
    >>> bisection_tol(None, 200.0)
    0.2
    >>> bisection_tol(1e-300, 200.0)
    Traceback (most recent call last):
    ...
    qualgrasp.certify.errors.GraspError: tol: expected a finite number of at least 1e-09 of the object's size (2e-07 boundary units), got 1e-300
    """
    tol = 1e-3 * size if tol is None else float(tol)
    if not (math.isfinite(tol) and tol >= TOL_FLOOR * size):
        raise GraspError(f"tol: expected a finite number of at least {TOL_FLOOR:g} of the object's size "
                         f"({TOL_FLOOR * size:.3g} boundary units), got {tol:g}")
    return tol


def independent_regions(boundary, normals, contacts, *, limits=None, models=None, tol: float | None = None,
                        symmetric: bool = True, normal_tol: float = 0.0, budget: int = SEARCH_BUDGET,
                        center=None, length=None, on_boundary: float = 1e-6) -> IndependentRegions:
    """The largest independent contact regions of a grasp on a closed boundary (module docstring).

    Parameters
    ----------
    boundary : array_like, shape (n, 2)
        Closed boundary polygon (the closing point not repeated).
    normals : array_like, shape (n, 2)
        Inward normals at the boundary points.
    contacts : Grasp, sequence of Contact, or array_like (k, 2)
        The grasp's contacts, on the boundary (within ``on_boundary`` times the object's size);
        bare points take their normals from the boundary and their models from ``models``.
    limits : sequence of (float, float), optional
        Per contact, the arc-length interval (from ``boundary[0]``, either end may wrap) it must
        not leave. Default: its straight run, or its own edge on a curved stretch.
    models : dict or sequence of dict, optional
        Contact model and parameters (``{"model": "point", "mu": 0.5}``) for every contact, or one
        per contact; default: the contacts' own.
    tol : float, optional
        Bisection tolerance on ``delta`` (boundary units); default ``1e-3`` of the object's size.
    symmetric : bool
        True: one ``delta`` for every finger. False: then grow each finger's ``delta`` in turn
        (in contact order) by bisection, the others fixed, starting from the common one (which
        already maximises the smallest).
    normal_tol : float
        Passed to the region tuples (radians).
    budget : int
        Branch-and-bound budget per region tuple tried (curved stretches, ``normal_tol > 0``;
        default :data:`SEARCH_BUDGET`).
    center, length : optional
        Torque scaling of the tuples (default: those of ``contacts`` when it is a Grasp, else
        certify's defaults). The tuples carry the grasp's id.
    on_boundary : float
        Largest distance of a contact from the boundary, fraction of the object's size.

    Returns
    -------
    IndependentRegions
        ``status``; what the certificate covers, per finger and side (``extents``) and the
        smallest of those (``slide``, ``slide_fraction``); the bisection's half-widths before
        clipping (``delta``, ``deltas``, ``delta_fraction``); the certified ``regions`` and their
        ``verdict`` (with the certificate).

    Raises
    ------
    GraspError
        Bad boundary, a contact off the boundary, limits that do not contain their contact.

    Examples
    --------
    The square ``[-1, 1]^2`` (each corner twice, once per side) and two point contacts with
    friction 0.5 at ``(+-1, 0)``: the fingers' heights may differ by less than ``2 mu``, so each
    may slide by less than ``mu = 0.5``.

    >>> from qualgrasp.certify import Contact, Grasp
    >>> square = [(1, -1), (1, 1), (1, 1), (-1, 1), (-1, 1), (-1, -1), (-1, -1), (1, -1)]
    >>> inward = [(-1, 0), (-1, 0), (0, -1), (0, -1), (1, 0), (1, 0), (0, 1), (0, 1)]
    >>> g = Grasp((Contact((1, 0), (-1, 0), "point", 0.5), Contact((-1, 0), (1, 0), "point", 0.5)))
    >>> r = independent_regions(square, inward, g, tol=1e-4)
    >>> r.status, round(r.delta, 3), round(r.delta_fraction, 3), round(r.slide, 3)
    ('robust', 0.5, 0.177, 0.5)

    Near a corner the stretch is clipped. Both fingers at height 0.8: each stretch
    ``[0.8 - delta, 0.8 + delta]`` is clipped at the corner (height 1), so the fingers' heights
    differ by less than 1 for ``delta`` up to 0.8; but a finger may slide up by 0.2 only (the
    first finger's side runs upwards along the boundary, the second's downwards), and the
    certified slide says so.

    >>> g = Grasp((Contact((1, 0.8), (-1, 0), "point", 0.5), Contact((-1, 0.8), (1, 0), "point", 0.5)))
    >>> r = independent_regions(square, inward, g, tol=1e-4)
    >>> round(r.delta, 3), [tuple(round(v, 3) for v in e) for e in r.extents], round(r.slide, 3)
    (0.8, [(0.8, 0.2), (0.2, 0.8)], 0.2)
    """
    t0 = time.perf_counter()
    B = Boundary.of(boundary, normals)
    cs = _contacts(B, contacts, models)
    if isinstance(contacts, Grasp):  # its torque scaling and id, unless given
        center = contacts.center if center is None else center
        length = contacts.length if length is None else length
    grasp = Grasp(tuple(cs), center=center, length=length, id=contacts.id if isinstance(contacts, Grasp) else None)
    k = len(cs)
    tol = bisection_tol(tol, B.size)
    pos, lims = [], []
    for i, c in enumerate(cs):
        s, dist, e = B.locate(c.p)
        if dist > on_boundary * B.size:
            raise GraspError(f"contacts[{i}]: {list(c.p)} is {dist:.3g} from the boundary (more than "
                             f"{on_boundary:g} of the object's size {B.size:.3g})")
        if limits is None:
            lim = B.default_limits(s, e)
        else:
            if len(limits) != k:
                raise GraspError(f"limits: {len(limits)} intervals for {k} contacts")
            lo, hi = (float(v) for v in limits[i])
            lim = _unwrap(lo, hi, s, B.perimeter, B.perimeter / len(B.points))
        if not (lim[0] - 1e-9 * B.perimeter <= s <= lim[1] + 1e-9 * B.perimeter):
            raise GraspError(f"limits[{i}]: ({lim[0]:.6g}, {lim[1]:.6g}) does not contain the contact "
                             f"(arc length {s:.6g})")
        pos.append(s)
        lims.append((min(lim[0], s), max(lim[1], s)))
    gv = force_closure(grasp)
    cache: dict = {}

    def tuple_at(deltas) -> tuple[RegionTuple, list[tuple[float, float]]]:
        """The region tuple of half-widths ``deltas`` and the arc-length interval each covers."""
        regions, covered = [], []
        for c, s, (lo, hi), d in zip(cs, pos, lims, deltas):
            kind, data, span = B.stretch(max(lo, s - d), min(hi, s + d), (lo, hi))
            params = dict(c.params)
            if kind == "straight":
                regions.append(StraightRegion(*data, c.model, **params))
            else:
                regions.append(CurvedRegion(*data, c.model, **params))
            covered.append(span)
        return RegionTuple(regions, normal_tol, center=grasp.center, length=grasp.length, id=grasp.id), covered

    def certified(deltas) -> RegionVerdict | None:
        key = tuple(round(d, 12) for d in deltas)
        if key not in cache:
            t, covered = tuple_at(deltas)
            v = certify_regions(t, budget=budget)
            cache[key] = (t, v if v.status == "robust" else None, covered)
        return cache[key][1]

    reach = [float(max(s - lo, hi - s)) for s, (lo, hi) in zip(pos, lims)]
    if gv.status != "closure":
        status = "not_robust" if gv.status == "no_closure" else "undecided"
        return IndependentRegions(status, 0.0, (0.0,) * k, 0.0, None, None, gv, tuple(pos), tuple(lims), B.size,
                                  0, time.perf_counter() - t0, ((0.0, 0.0),) * k)

    def bisect(make, lo, hi):
        """Largest certified value in [lo, hi] given ``lo`` certified (or 0), by bisection."""
        if certified(make(hi)) is not None:
            return hi
        while hi - lo > tol:
            mid = (lo + hi) / 2
            if certified(make(mid)) is not None:
                lo = mid
            else:
                hi = mid
        return lo

    dmax = max(reach)
    common = bisect(lambda d: [d] * k, 0.0, dmax)
    if common == 0.0:  # below the tolerance: try smaller
        d = tol
        for _ in range(20):
            d /= 2
            if certified([d] * k) is not None:
                common = bisect(lambda x: [x] * k, d, 2 * d)
                break
    deltas = [common] * k
    if common > 0 and not symmetric:
        for i in range(k):
            if reach[i] > deltas[i]:
                deltas[i] = bisect(lambda d, i=i: deltas[:i] + [d] + deltas[i + 1:], deltas[i], reach[i])
    if min(deltas) <= 0:
        return IndependentRegions("undecided", 0.0, tuple(deltas), 0.0, None, None, gv, tuple(pos), tuple(lims),
                                  B.size, len(cache), time.perf_counter() - t0, ((0.0, 0.0),) * k)
    v = certified(deltas)
    t, _, covered = cache[tuple(round(d, 12) for d in deltas)]
    deltas = [float(d) for d in deltas]
    extents = _extents(pos, covered, 1e-9 * B.perimeter)
    slide = min(min(e) for e in extents)
    return IndependentRegions("robust", min(deltas), tuple(deltas), min(deltas) / B.size if B.size else 0.0,
                              t, v, gv, tuple(pos), tuple(lims), B.size, len(cache), time.perf_counter() - t0,
                              extents, slide, slide / B.size if B.size else 0.0)

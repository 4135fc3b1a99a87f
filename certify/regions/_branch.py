"""Conservative decision for curved regions and for a tolerance on normals, by branch and bound.

**Over-approximation.** A *stretch* of a region is the part of its curve over consecutive arcs
``j0 .. j1 - 1`` (an arc joins two consecutive points of a curved region; a straight region, or a
single point, is one arc). A stretch is over-approximated by what a finger there could be
(:class:`Geometry`):

* its point lies in a rectangle on the chord ``[P_j0, P_j1]``: ``P_j0 + s (P_j1 - P_j0) + h' E``
  with ``0 <= s <= 1`` and ``|h'| <= h`` (``E`` the chord's unit normal). On every arc the
  curve's normal stays within the angles of its end normals and its chord's normal
  (:mod:`qualgrasp.certify.regions.data`'s reading), so over the stretch the tangent stays within
  ``[a_lo, a_hi]`` of the chord (``a_lo <= 0 <= a_hi``, the extreme angles of those normals and
  of the stretch's chord normal, widened by ``normal_tol``): the curve moves forward along the
  chord and stays within ``h = c tan(a_hi) tan(-a_lo) / (tan(a_hi) + tan(-a_lo))`` of it (the
  parallelogram of the extreme tangent lines through both ends, ``c`` the chord's length). A
  straight region's stretch is its segment (``h = 0``). A stretch of several arcs whose normals
  sweep more than :data:`MAX_MERGED` is split first;
* its normal lies in the angular interval ``[psi_lo, psi_hi]`` of those angles, or is one exact
  normal (straight regions and single points with ``normal_tol = 0``).

Every constructed number is widened by a margin (``1e-9`` relative, ``1e-12`` radians) that
absorbs the rounding of the construction (``atan2``, ``cos``, ``sin``, ``tan``, a square root),
so the sets contain the exact ones. A *piece* is a stretch and, for a single arc, a sub-box
``[s0, s1] x [t0, t1]`` of its chord parameter ``s`` and of its normal's fraction ``t`` of
``[psi_lo, psi_hi]``.

**Covering.** The tuple is not robust iff some ``y != 0`` and some choice have ``y . w_g <= 0``
for every generator of every contact. Directions ``y`` are covered by cells: the 6 faces of the
cube ``[-1, 1]^3`` cut into dyadic squares (:data:`FACES`). A cell is **covered** by contact ``i``
when, on each piece of ``i``'s region, a rigorous lower bound of ``max_g y . w_g`` over the cell
and the piece is positive: then every choice of contact ``i`` resists every wrench direction of
the cell. For a unit normal, ``L y . w_g = (R_g n) . (L y_f + y_tau perp(q - c)) - y_tau
offset_g width`` (``R_g n = n + friction_g mu perp(n)``, ``perp`` a quarter turn), which is affine
separately in ``y``, in ``q`` and in ``n``; so its minimum over the cell, the piece's rectangle and
the quadrilateral ``{a n_lo + b n_hi : a, b >= 0, 1 - 1e-9 <= a + b <= 1e-9 + 1 / cos(width / 2)}``
(which contains the piece's arc of unit normals) is attained at vertices, 4 x 4 x 4 of them. The
bound is that minimum, for a fixed convex combination of the generators (one of the candidates of
:func:`candidate_weights`: single generators, pairs, all), evaluated in floating point minus a
rigorous error bound ``gamma_40 * scale`` (Higham's ``gamma_n``, ``scale`` an upper bound of the
same expression over absolute values; compiled: :mod:`qualgrasp.certify._kernels.regions`). All
cells covered: **robust**; the certificate lists each cell with its contact and pieces
(:func:`check_cells` re-checks it: coverage of the faces and of every arc, and every bound).

**Refinement and witnesses.** At an uncovered cell's centre direction ``y_c`` each region's exact
candidate contacts (its given points -- a straight region's ends -- with the given normals, and
those normals turned by just under ``+-normal_tol``) are scored by ``max_g y_c . w_g``. When every
region has one scoring ``<= 0``, that choice is certified with :func:`qualgrasp.certify.force_closure`:
a verified ``no_closure`` is a **witness** (not robust). Otherwise the pieces of the region scoring
best are halved where their bound at ``y_c`` is far below its score and halving improves it (a
stretch at its middle point, a single arc along ``s`` or ``t``); when none is, the cell is split in
four. The **budget** counts work units: one unit is one bound of one piece of one contact on one
cell (64 vertex evaluations per generator; about 10 microseconds with the search around it), and a
candidate witness certified costs :data:`CERTIFY_COST` units. When the budget is spent, or
cells reach the finest size (``2^-40`` of a face) uncovered, the verdict is **undecided**.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any

import numpy as np

from .. import models as registry
from .._kernels.jit import kernel_array
from .._kernels.regions import bound_scales, cell_corners, piece_bounds, piece_vertices
from ..core.certificates import Check, verify
from ..core.closure import force_closure
from ..core.grasp import Contact, Grasp
from .data import RegionTuple, StraightRegion
from ._exact import region_variant

__all__ = ["FACES", "Geometry", "MAX_MERGED", "candidate_weights", "cells_certificate", "bounds", "decide_branch", "check_cells",
           "exact_candidates", "turned", "BranchResult", "DEFAULT_BUDGET", "MIN_CELL", "MIN_PIECE"]

#: The 6 faces of the direction cube: ``(axis, sign)`` (axis 0 ``y_fx``, 1 ``y_fy``, 2 ``y_tau``).
FACES = ((0, 1), (0, -1), (1, 1), (1, -1), (2, 1), (2, -1))
_FACE_AXES = np.array([f[0] for f in FACES], dtype=np.int64)
_FACE_SIGNS = np.array([f[1] for f in FACES], dtype=float)
#: Default budget, in work units (module docstring).
DEFAULT_BUDGET = 200_000
#: Finest cell width (a face is 2 wide) and finest piece width (fractions of an arc).
MIN_CELL = 2.0 ** -40
MIN_PIECE = 2.0 ** -16
_REL = 1e-9   # relative widening of constructed lengths
_ANG = 1e-12  # absolute widening of constructed angles (radians)
_U = 2.0 ** -53
_GAMMA = 40 * _U / (1 - 40 * _U)


# --------------------------------------------------------------------------------------------------
# Geometry of the arcs

#: Widest normal interval (radians, margins and ``normal_tol`` included) of a piece spanning
#: several arcs; wider ranges are split at a point before they are bounded.
MAX_MERGED = math.radians(60)


def _turn(n, angle):
    c, s = math.cos(angle), math.sin(angle)
    return np.array([c * n[0] - s * n[1], s * n[0] + c * n[1]])


def _signed(u, v) -> float:
    return math.atan2(u[0] * v[1] - u[1] * v[0], u[0] * v[0] + u[1] * v[1])


class Geometry:
    """Over-approximations of the stretches ``[j0, j1]`` of the regions' polylines (module
    docstring), as arrays indexed by a stretch id (:meth:`id`), grown on demand.

    Array attributes (one row per stretch): ``region``, ``j0``, ``j1``; ``p0``, ``p1`` the chord;
    ``e`` its unit normal; ``h`` the rectangle's half height; ``exact`` (one exact normal,
    ``normal``) or the normal interval ``psi``; ``splittable_s`` (a single arc of positive
    length, which may be cut along its chord).
    """

    _FIELDS = ("region", "j0", "j1", "p0", "p1", "e", "h", "exact", "normal", "psi", "splittable_s")

    def __init__(self, regions: RegionTuple) -> None:
        self.regions = regions
        self._rows: list[tuple] = []
        self._ids: dict[tuple[int, int, int], int | None] = {}
        self._halves: dict[int, tuple[int, int] | None] = {}

    def arcs(self, i: int) -> int:
        """Number of arcs of region ``i`` (1 for a straight region or a single point)."""
        r = self.regions.regions[i]
        return 1 if isinstance(r, StraightRegion) or len(r.points) == 1 else len(r.points) - 1

    def id(self, i: int, j0: int, j1: int) -> int | None:
        """Id of the stretch of region ``i`` over arcs ``j0 .. j1 - 1``, or None when it spans
        several arcs and its normal interval is wider than :data:`MAX_MERGED` (split it)."""
        key = (i, j0, j1)
        if key not in self._ids:
            row = _stretch(self.regions.regions[i], j0, j1, self.regions.normal_tol)
            if row is None:
                self._ids[key] = None
            else:
                self._ids[key] = len(self._rows)
                self._rows.append((i, j0, j1) + row)
                for f in Geometry._FIELDS:  # stale: the next read builds them again
                    self.__dict__.pop(f, None)
        return self._ids[key]

    def halves(self, g: int) -> tuple[int, int] | None:
        """Ids of the two halves of stretch ``g`` (several arcs, cut at its middle arc), None
        when one cannot be bounded."""
        if g not in self._halves:
            i, j0, j1 = self._rows[g][:3]
            mid = (j0 + j1) // 2
            ids = (self.id(i, j0, mid), self.id(i, mid, j1))
            self._halves[g] = None if None in ids else ids
        return self._halves[g]

    def ranges(self, i: int) -> list[int]:
        """Ids of a partition of region ``i`` into the fewest halvings that can be bounded."""
        out: list[int] = []
        todo = [(0, self.arcs(i))]
        while todo:
            j0, j1 = todo.pop()
            g = self.id(i, j0, j1)
            if g is None:
                mid = (j0 + j1) // 2
                todo += [(mid, j1), (j0, mid)]
            else:
                out.append(g)
        return out

    def __getattr__(self, name: str) -> np.ndarray:
        # called only when the arrays are not instance attributes: built once per growth of the rows
        if name not in Geometry._FIELDS:
            raise AttributeError(name)
        cols = list(zip(*self._rows))
        shapes = {"p0": 2, "p1": 2, "e": 2, "normal": 2, "psi": 2}
        dtypes = {"region": np.int64, "j0": np.int64, "j1": np.int64, "exact": bool, "splittable_s": bool}
        for f, c in zip(Geometry._FIELDS, cols):
            shape = (-1, shapes[f]) if f in shapes else (-1,)
            self.__dict__[f] = np.array(c, dtype=dtypes.get(f, float)).reshape(shape)
        return self.__dict__[name]


def _stretch(r, j0: int, j1: int, tol: float):
    """``(p0, p1, e, h, exact, normal, psi, splittable_s)`` of arcs ``j0 .. j1 - 1`` of region
    ``r``, or None (several arcs, too wide a normal interval)."""
    if isinstance(r, StraightRegion):
        a, b, n = np.array(r.a), np.array(r.b), np.array(r.n)
        psi = math.atan2(n[1], n[0])
        return (a, b, np.zeros(2), 0.0, tol == 0, n, (psi - tol - _ANG, psi + tol + _ANG), bool((a != b).any()))
    P, N = r.points, r.normals
    if len(P) == 1:
        psi = math.atan2(N[0][1], N[0][0])
        return (P[0], P[0], np.zeros(2), 0.0, tol == 0, N[0], (psi - tol - _ANG, psi + tol + _ANG), False)
    p0, p1 = P[j0], P[j1]
    chord = p1 - p0
    c = math.hypot(chord[0], chord[1])
    if c == 0:
        if j1 - j0 > 1:
            return None
        psi = math.atan2(N[j0][1], N[j0][0])  # a corner: one point, the normal turns from N_j0 to N_j1
        turn = _signed(N[j0], N[j1])
        return (p0, p1, np.zeros(2), 0.0, False, N[j0],
                (psi + min(0.0, turn) - tol - _ANG, psi + max(0.0, turn) + tol + _ANG), False)
    e = np.array([-chord[1], chord[0]]) / c
    if e @ N[j0:j1 + 1].sum(axis=0) < 0:
        e = -e
    angles = [0.0] + [_signed(e, N[j]) for j in range(j0, j1 + 1)]
    for j in range(j0, j1):  # every arc's chord normal is attained on it
        d = P[j + 1] - P[j]
        if d[0] or d[1]:
            ej = np.array([-d[1], d[0]])
            angles.append(_signed(e, ej if ej @ (N[j] + N[j + 1]) >= 0 else -ej))
    lo = min(angles) - tol - _ANG
    hi = max(angles) + tol + _ANG
    if j1 - j0 > 1 and hi - lo > MAX_MERGED:
        return None
    t1, t2 = math.tan(hi + _ANG), math.tan(-lo + _ANG)
    h = c * t1 * t2 / (t1 + t2)
    h = h * (1 + _REL) + c * _REL + 8 * _U * (np.abs(p0).max() + np.abs(p1).max())
    psi = math.atan2(e[1], e[0])
    return (p0, p1, e, h, False, e, (psi + lo, psi + hi), j1 - j0 == 1)


# --------------------------------------------------------------------------------------------------
# Generators and their convex combinations

def _generators(region):
    gens = registry.get(region.model).generators(2, region_variant(region))
    fm = np.array([g.friction * region.mu for g in gens])
    ow = np.array([g.offset * region.offset_length for g in gens])
    return fm, ow


def candidate_weights(count: int) -> np.ndarray:
    """Convex combinations of ``count`` generators tried by the bound: each generator alone, each
    pair's mean, and (more than two) the mean of all. Shape ``(C, count)``; exact dyadic weights."""
    rows = [np.eye(count)[g] for g in range(count)]
    for g in range(count):
        for h in range(g + 1, count):
            w = np.zeros(count)
            w[[g, h]] = 0.5
            rows.append(w)
    if count > 2:
        rows.append(np.full(count, 1.0 / count))
    return np.array(rows)


@dataclass(frozen=True)
class _Model:
    """Generator data of every region, padded to ``G`` generators and ``C`` candidates."""

    fm: np.ndarray      # (k, G)
    ow: np.ndarray      # (k, G)
    gmask: np.ndarray   # (k, G)
    weights: np.ndarray  # (k, C, G)
    cmask: np.ndarray   # (k, C)


def _model(regions: RegionTuple) -> _Model:
    data = [_generators(r) for r in regions.regions]
    G = max(len(fm) for fm, _ in data)
    cands = [candidate_weights(len(fm)) for fm, _ in data]
    C = max(len(c) for c in cands)
    k = len(data)
    fm, ow, gm = np.zeros((k, G)), np.zeros((k, G)), np.zeros((k, G), dtype=bool)
    W, cm = np.zeros((k, C, G)), np.zeros((k, C), dtype=bool)
    for i, ((f, o), c) in enumerate(zip(data, cands)):
        fm[i, :len(f)], ow[i, :len(o)], gm[i, :len(f)] = f, o, True
        W[i, :len(c), :c.shape[1]], cm[i, :len(c)] = c, True
    return _Model(fm, ow, gm, W, cm)


# --------------------------------------------------------------------------------------------------
# The bound

def cell_vertices(face: np.ndarray, box: np.ndarray) -> np.ndarray:
    """``(B, 4, 3)`` corner directions of cells: ``face`` (B,) indices into :data:`FACES`,
    ``box`` (B, 4) ``lo0, hi0, lo1, hi1`` of the two free coordinates (in axis order)."""
    return cell_corners(kernel_array(face, np.int64), kernel_array(box), _FACE_AXES, _FACE_SIGNS)


def _normal_corners(arcs: Geometry, arc: np.ndarray, t0, t1):
    """The normals' bounding unit vectors ``ua``, ``ub`` (B, 2) of pieces and their chord scale
    (B,) (:func:`~qualgrasp.certify._kernels.regions.piece_vertices` takes them; the cosines and
    sines are numpy's)."""
    lo, hi = arcs.psi[arc, 0], arcs.psi[arc, 1]
    a = lo + t0 * (hi - lo) - _ANG
    b = lo + t1 * (hi - lo) + _ANG
    half = (b - a) / 2
    scale = (1.0 / np.cos(half)) * (1 + _REL)
    return np.stack([np.cos(a), np.sin(a)], axis=1), np.stack([np.cos(b), np.sin(b)], axis=1), scale


def bounds(regions: RegionTuple, arcs: Geometry, model: _Model, contact, arc, face, box, s0, s1, t0, t1,
           Y: np.ndarray | None = None, cand: np.ndarray | None = None):
    """Rigorous lower bounds, per item, of ``L max_g y @ w_g`` over a cell and a piece.

    Items are ``(contact, arc, cell face, cell box, piece s0 s1 t0 t1)`` arrays of one length
    ``B``; ``Y`` (B, 4, 3) replaces the cell's corners (the analysis uses the centre direction);
    ``cand`` (B,) evaluates only that candidate combination. Returns ``(bound, candidate)``:
    the best bound over the candidates and which one gave it.
    """
    Y = kernel_array(cell_vertices(face, box) if Y is None else Y)
    P0, P1, E, h = arcs.p0[arc], arcs.p1[arc], arcs.e[arc], arcs.h[arc]
    s0, s1 = kernel_array(s0), kernel_array(s1)
    contact = kernel_array(contact, np.int64)
    Q, Nv = piece_vertices(P0, P1, E, h, s0, s1, *_normal_corners(arcs, arc, t0, t1), arcs.exact[arc],
                           arcs.normal[arc], _REL)
    cx, cy = (float(v) for v in regions.center)
    L = float(regions.length)
    # rounding: every term of the exact expression is bounded in absolute value by ``scale``
    # (the same expression over absolute values, bounded above), so each value is within
    # gamma_40 scale of its float (Higham's gamma_n; the depth of the expression is below 25)
    scale = bound_scales(Y, Nv, P0, P1, E, h, s0, s1, contact, model.fm, model.ow, cx, cy, L, _REL)
    which = np.full(len(contact), -1, dtype=np.int64) if cand is None else kernel_array(cand, np.int64)
    return piece_bounds(Y, Q, Nv, contact, model.fm, model.ow, model.weights, model.cmask, which, scale,
                        cx, cy, L, _GAMMA)


def _centre_values(regions, arcs, model, contact, arc, yc, s0, s1, t0, t1):
    """Float ``L max_g y_c . w_g`` at the piece's centre point and normal (no rigour needed)."""
    sm = (s0 + s1) / 2
    q = arcs.p0[arc] + sm[:, None] * (arcs.p1[arc] - arcs.p0[arc])
    lo, hi = arcs.psi[arc, 0], arcs.psi[arc, 1]
    ang = lo + (t0 + t1) / 2 * (hi - lo)
    n = np.stack([np.cos(ang), np.sin(ang)], axis=1)
    n[arcs.exact[arc]] = arcs.normal[arc][arcs.exact[arc]]
    cx, cy = regions.center
    L = regions.length
    v = np.stack([L * yc[:, 0] - yc[:, 2] * (q[:, 1] - cy), L * yc[:, 1] + yc[:, 2] * (q[:, 0] - cx)], axis=1)
    fm, ow = model.fm[contact], model.ow[contact]
    Rx, Ry = n[:, 0:1] - fm * n[:, 1:2], n[:, 1:2] + fm * n[:, 0:1]
    F = Rx * v[:, 0:1] + Ry * v[:, 1:2] - yc[:, 2:3] * ow
    F = np.where(model.gmask[contact], F, -np.inf)
    spread_s = np.abs(yc[:, 2]) * np.hypot(*(arcs.p1[arc] - arcs.p0[arc]).T) * (s1 - s0) + 2 * arcs.h[arc] * np.abs(yc[:, 2])
    spread_t = (hi - lo) * (t1 - t0) * np.hypot(v[:, 0], v[:, 1])
    spread_t = np.where(arcs.exact[arc], 0.0, spread_t)
    return F.max(axis=1), spread_s, spread_t


# --------------------------------------------------------------------------------------------------
# Exact candidate choices (witnesses)

def turned(n, angle: float):
    """``n`` turned by ``angle`` (radians, counter-clockwise), as a tuple."""
    return tuple(float(v) for v in _turn(np.asarray(n, dtype=float), angle))


def _inside_tol(tol: float) -> float:
    """The turn used for candidate normals: just inside ``tol`` (see :func:`normal_within`)."""
    return tol - tol * _REL - 1e-12 if tol > 4e-12 else 0.0


def exact_candidates(regions: RegionTuple):
    """Per region, its exact candidate contacts ``(point, normal, descriptor)``: the given
    points (a straight region's ends) with the given normal and, with ``normal_tol``, that normal
    turned by just under ``+-normal_tol``."""
    turn = _inside_tol(regions.normal_tol)
    out = []
    for r in regions.regions:
        if isinstance(r, StraightRegion):
            pts = [(r.a, r.n, {"s": 0.0}), (r.b, r.n, {"s": 1.0})] if r.a != r.b else [(r.a, r.n, {"s": 0.0})]
        else:
            pts = [(tuple(map(float, p)), tuple(map(float, n)), {"point": j}) for j, (p, n) in enumerate(zip(r.points, r.normals))]
        cands = []
        for p, n, desc in pts:
            cands.append((p, tuple(n), dict(desc, turn=0)))
            if turn > 0:
                for sign in (-1, 1):
                    cands.append((p, turned(n, sign * turn), dict(desc, turn=sign)))
        out.append(cands)
    return out


def _candidate_wrenches(regions: RegionTuple, cands) -> list[np.ndarray]:
    """Generator wrenches (n_cand, G, 3) of each region's candidate contacts."""
    cx, cy = regions.center
    L = regions.length
    out = []
    for r, cs in zip(regions.regions, cands):
        fm, ow = _generators(r)
        P = np.array([c[0] for c in cs], dtype=float)
        N = np.array([c[1] for c in cs], dtype=float)
        T = np.stack([-N[:, 1], N[:, 0]], axis=1)
        F = N[:, None, :] + fm[None, :, None] * T[:, None, :]
        Q = P[:, None, :] + ow[None, :, None] * T[:, None, :]
        tau = ((Q[..., 0] - cx) * F[..., 1] - (Q[..., 1] - cy) * F[..., 0]) / L
        out.append(np.concatenate([F, tau[..., None]], axis=-1))
    return out


# --------------------------------------------------------------------------------------------------
# The search

@dataclass
class BranchResult:
    """Outcome of :func:`decide_branch`."""

    status: str                      # robust, not_robust, undecided
    cells: list = field(default_factory=list)
    witness: Grasp | None = None
    verdict: Any = None
    choice: list | None = None
    reason: str | None = None
    work: int = 0
    geometry: Any = None
    pending: list = field(default_factory=list)


def _initial_cells(geo: Geometry, k: int):
    """24 cells (each face in 2 x 2), every region in its fewest boundable stretches. A cell is
    ``(face, box, pieces)``, ``pieces`` rows ``contact, stretch id, s0, s1, t0, t1`` sorted by
    contact (never modified in place: children share them)."""
    rows = [[i, g, 0.0, 1.0, 0.0, 1.0] for i in range(k) for g in geo.ranges(i)]
    pieces = np.array(rows, dtype=float)
    cells = []
    for f in range(6):
        for lo0 in (-1.0, 0.0):
            for lo1 in (-1.0, 0.0):
                cells.append((f, np.array([lo0, lo0 + 1.0, lo1, lo1 + 1.0]), pieces))
    return cells


#: Work units charged for certifying a candidate witness with force_closure.
CERTIFY_COST = 500


def decide_branch(regions: RegionTuple, budget: int = DEFAULT_BUDGET, batch_items: int = 4096) -> BranchResult:
    """Branch and bound over direction cells and pieces (module docstring)."""
    arcs = Geometry(regions)
    model = _model(regions)
    k = len(regions.regions)
    L = regions.length
    cands = exact_candidates(regions)
    cwrench = _candidate_wrenches(regions, cands)
    cscale = [1e-12 * (1 + np.abs(w).max()) for w in cwrench]
    queue = deque(_initial_cells(arcs, k))
    covered: list = []
    stuck = 0
    work = 0
    tried: set = set()
    failures: list[str] = []
    while queue:
        batch, n_items = [], 0
        while queue and (not batch or n_items + len(queue[0][2]) <= batch_items):
            cell = queue.popleft()
            batch.append(cell)
            n_items += len(cell[2])
        if work + n_items > budget:
            return BranchResult("undecided", reason=f"budget of {budget} work units spent with "
                                f"{len(batch) + len(queue)} direction cells still uncovered ({len(covered)} covered)",
                                work=work, cells=covered, pending=list(batch) + list(queue))
        work += n_items
        it = _items(batch, k)
        corners = cell_vertices(np.array([b[0] for b in batch]), np.array([b[1] for b in batch]))  # once per cell
        lb, best = bounds(regions, arcs, model, it["contact"], it["arc"], None, None,
                          it["s0"], it["s1"], it["t0"], it["t1"], Y=corners[it["cell"]])
        good = lb > 0
        group_good = np.logical_and.reduceat(good, it["group_start"])
        covering = {}
        for g in np.flatnonzero(group_good):
            covering.setdefault(int(it["group_cell"][g]), int(it["group_contact"][g]))
        for c, i in covering.items():
            f, box, pieces = batch[c]
            a, b = it["cell_start"][c], it["cell_start"][c + 1]  # the cell's items, one per piece
            sel = pieces[:, 0] == i
            covered.append((f, box, i, np.column_stack([pieces[sel][:, 1:], best[a:b][sel]])))
        open_cells = np.array([c for c in range(len(batch)) if c not in covering], dtype=np.int64)
        if not len(open_cells):
            continue
        # the centre directions of the open cells, and every region's best exact candidate there
        yc_all = corners.mean(axis=1)
        Yc = yc_all[open_cells]
        real = np.empty((k, len(open_cells)))
        pick = np.empty((k, len(open_cells)), dtype=np.int64)
        for i in range(k):
            scores = np.einsum("cgd,nd->cgn", cwrench[i], Yc).max(axis=1)  # (candidates, cells)
            pick[i] = scores.argmin(axis=0)
            real[i] = scores.min(axis=0)
        # witnesses: every region has an exact candidate with max_g y_c . w_g <= 0
        for q in np.flatnonzero((real <= np.array(cscale)[:, None]).all(axis=0)):
            key = tuple(int(v) for v in pick[:, q])
            if key in tried:
                continue
            tried.add(key)
            work += CERTIFY_COST
            found = _certify_choice(regions, cands, key)
            if found[0] is not None:
                return BranchResult("not_robust", witness=found[0], verdict=found[1],
                                    choice=[cands[i][j][2] for i, j in enumerate(key)], work=work)
            failures.append(found[1])
        # refinement: the pieces of the region best at the centre direction (among its exact
        # candidates) whose bound there is far below that region's score, when halving them
        # improves that bound; otherwise the cell is split in four
        slot = np.full(len(batch), -1, dtype=np.int64)
        slot[open_cells] = np.arange(len(open_cells))
        best_i = real.argmax(axis=0)
        target = L * real[best_i, np.arange(len(open_cells))]
        item_slot = slot[it["cell"]]
        cand_items = np.flatnonzero((item_slot >= 0) & ~good)
        cand_items = cand_items[(it["contact"][cand_items] == best_i[item_slot[cand_items]])
                                & (target[item_slot[cand_items]] > 0)]
        accepted: dict[int, dict[int, np.ndarray]] = {}
        if len(cand_items):
            work += len(cand_items)
            Ycand = np.repeat(Yc[item_slot[cand_items]][:, None, :], 4, axis=1)
            lbc, _ = bounds(regions, arcs, model, it["contact"][cand_items], it["arc"][cand_items], None, None,
                            it["s0"][cand_items], it["s1"][cand_items], it["t0"][cand_items], it["t1"][cand_items], Y=Ycand)
            far = lbc <= 0.5 * target[item_slot[cand_items]]
            sel = cand_items[far]
            if len(sel):
                _, sp_s, sp_t = _centre_values(regions, arcs, model, it["contact"][sel], it["arc"][sel],
                                               Yc[item_slot[sel]], it["s0"][sel], it["s1"][sel], it["t0"][sel], it["t1"][sel])
                halves, ok = _split_pieces(it["piece"][sel], arcs, sp_s, sp_t)
                if ok.any():
                    H = halves[ok].reshape(-1, 6)
                    work += len(H)
                    cells_of = np.repeat(it["cell"][sel][ok], 2)
                    lbh, _ = bounds(regions, arcs, model, H[:, 0].astype(np.int64), H[:, 1].astype(np.int64), None, None,
                                    H[:, 2], H[:, 3], H[:, 4], H[:, 5],
                                    Y=np.repeat(yc_all[cells_of][:, None, :], 4, axis=1))
                    lo, hi = lbh[0::2], lbh[1::2]
                    worse = np.where(hi < lo, hi, lo)  # Python's min(lo, hi)
                    lbc_j, tg = lbc[far][ok], target[item_slot[sel]][ok]
                    gain = worse > lbc_j + 0.05 * (tg - lbc_j)
                    for c, r, q in zip(it["cell"][sel][ok][gain].tolist(), it["row"][sel][ok][gain].tolist(),
                                       np.flatnonzero(ok)[gain].tolist()):
                        accepted.setdefault(c, {})[r] = halves[q]
        kids, small = _quarters(np.array([batch[c][1] for c in open_cells]))
        for q, c in enumerate(open_cells.tolist()):
            f, box, pieces = batch[c]
            if c in accepted:
                parts = accepted[c]
                queue.append((f, box, np.vstack([parts.get(r, pieces[r:r + 1]) for r in range(len(pieces))])))
            elif small[q]:
                stuck += 1
            else:
                queue.extend((f, kid, pieces) for kid in kids[q])
    if stuck:
        why = "; ".join(sorted(set(failures))) if failures else "no exact candidate choice separates there"
        return BranchResult("undecided", reason=f"{stuck} direction cells reached the finest size uncovered "
                            f"(the worst choice is on the closure boundary, or between the given points; {why})",
                            work=work)
    return BranchResult("robust", cells=covered, work=work, geometry=arcs)


def _quarters(boxes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The four quarters (n, 4, 4) of each cell box (n, 4) (``lo0, hi0, lo1, hi1``; first coordinate
    slowest), and whether a quarter's width is below :data:`MIN_CELL` (n,)."""
    h = (boxes[:, 1] - boxes[:, 0]) / 2
    lo0, lo1 = boxes[:, 0], boxes[:, 2]
    kids = np.stack([np.stack([a0, a0 + h, a1, a1 + h], axis=1) for a0 in (lo0, lo0 + h) for a1 in (lo1, lo1 + h)],
                    axis=1)
    return kids, h < MIN_CELL


def _split_pieces(rows: np.ndarray, arcs: Geometry, spread_s: np.ndarray, spread_t: np.ndarray):
    """Two pieces covering each piece ``[contact, stretch, s0, s1, t0, t1]`` of ``rows`` (n, 6): a
    stretch of several arcs is cut at its middle point; a single arc along ``s`` or ``t`` (the
    larger spread). Returns the halves (n, 2, 6) and whether each piece may be split."""
    g = rows[:, 1].astype(np.int64)
    multi = arcs.j1[g] - arcs.j0[g] > 1
    splittable_s, exact = arcs.splittable_s[g], arcs.exact[g]
    halves = np.repeat(rows[:, None, :], 2, axis=1)
    ok = np.zeros(len(rows), dtype=bool)
    for q in np.flatnonzero(multi).tolist():  # in order: new stretches get their ids as before
        ids = arcs.halves(int(g[q]))
        if ids is not None:
            halves[q, :, 1] = ids
            halves[q, :, 2:] = (0.0, 1.0, 0.0, 1.0)
            ok[q] = True
    can_s = splittable_s & (rows[:, 3] - rows[:, 2] > MIN_PIECE)
    can_t = ~exact & (rows[:, 5] - rows[:, 4] > MIN_PIECE)
    single = ~multi & (can_s | can_t)
    along_s = can_s & (~can_t | (spread_s >= spread_t))
    q = np.flatnonzero(single)
    a = np.where(along_s[q], 2, 4)
    mid = (rows[q, a] + rows[q, a + 1]) / 2
    halves[q, 0, a + 1] = mid
    halves[q, 1, a] = mid
    ok[q] = True
    return halves, ok


def _items(batch, k):
    """Flat item arrays of a batch of cells (one item per piece), grouped by (cell, contact)."""
    counts = np.array([len(p) for _, _, p in batch])
    P = np.vstack([p for _, _, p in batch])
    cell = np.repeat(np.arange(len(batch)), counts)
    contact = P[:, 0].astype(np.int64)
    key = cell * k + contact
    start = np.flatnonzero(np.r_[True, key[1:] != key[:-1]])
    cell_start = np.r_[0, np.cumsum(counts)]
    return {"cell": cell, "cell_start": cell_start, "piece": P, "contact": contact,
            "arc": P[:, 1].astype(np.int64), "s0": P[:, 2], "s1": P[:, 3],
            "t0": P[:, 4], "t1": P[:, 5], "row": np.arange(len(P)) - cell_start[cell],
            "group_start": start, "group_cell": cell[start], "group_contact": contact[start]}


def _certify_choice(regions: RegionTuple, cands, choice):
    contacts = []
    for r, cs, j in zip(regions.regions, cands, choice):
        p, n, _ = cs[j]
        contacts.append(Contact(p, n, r.model, **dict(r.params)))
    grasp = Grasp(tuple(contacts), center=regions.center, length=regions.length)
    verdict = force_closure(grasp)
    if verdict.status == "no_closure" and verify(grasp, verdict.certificate, status="no_closure"):
        return grasp, verdict
    return None, f"certify: {verdict.status} at the candidate choice"


# --------------------------------------------------------------------------------------------------
# The certificate and its check

def cells_certificate(cells, geo: Geometry) -> dict[str, Any]:
    """The JSON certificate of robustness: ``[face, lo0, hi0, lo1, hi1, contact, pieces]`` per
    covered cell (face index into :data:`FACES`, the cell's box on it), each piece
    ``[j0, j1, s0, s1, t0, t1, candidate]``: arcs ``j0`` to ``j1 - 1`` of the contact's region,
    the sub-box of a single arc's chord parameter and normal fraction, and the combination of
    generators (:func:`candidate_weights`) whose bound is positive."""
    out = []
    for f, box, i, pieces in cells:
        rows = []
        for p in pieces:
            g = int(p[0])
            rows.append([int(geo.j0[g]), int(geo.j1[g]), float(p[1]), float(p[2]), float(p[3]), float(p[4]), int(p[5])])
        out.append([int(f), *[float(v) for v in box], int(i), rows])
    return {"kind": "cells", "faces": [list(f) for f in FACES], "cells": out}


def _dyadic_square(lo0, hi0, lo1, hi1):
    """``(width, ix, iy)`` of a dyadic square of the face ``[-1, 1]^2``, or None."""
    a0, b0, a1, b1 = (Fraction(v) for v in (lo0, hi0, lo1, hi1))
    w = b0 - a0
    if w <= 0 or w != b1 - a1 or w > 1 or w.numerator != 1 or w.denominator & (w.denominator - 1):
        return None
    x, y = (a0 + 1) / w, (a1 + 1) / w
    if x.denominator != 1 or y.denominator != 1 or x < 0 or y < 0 or (b0 > 1) or (b1 > 1):
        return None
    return w, int(x), int(y)


def check_cells(regions: RegionTuple, certificate: Any) -> Check:
    """Re-check a ``cells`` certificate (module docstring): the cells are dyadic squares tiling
    every face, each cell's pieces tile every arc of its contact's region, and every piece's
    bound (recomputed with the stated candidate, in floating point with its rigorous error
    bound) is positive. Not a search: nothing is solved or refined."""
    if not isinstance(certificate, dict) or certificate.get("kind") != "cells":
        return Check(False, "expected a certificate of kind 'cells'")
    cells = certificate.get("cells")
    if not isinstance(cells, list) or not cells:
        return Check(False, "a cells certificate lists its cells")
    arcs = Geometry(regions)
    model = _model(regions)
    k = len(regions.regions)
    try:
        seen: dict = {}
        area = [Fraction(0)] * 6
        items = {key: [] for key in ("contact", "arc", "face", "box", "s0", "s1", "t0", "t1", "cand")}
        for c in cells:
            f, lo0, hi0, lo1, hi1, i, pieces = c
            f, i = int(f), int(i)
            if not (0 <= f < 6 and 0 <= i < k):
                return Check(False, f"cell {c[:6]}: face or contact out of range")
            sq = _dyadic_square(float(lo0), float(hi0), float(lo1), float(hi1))
            if sq is None:
                return Check(False, f"cell {c[:6]}: not a dyadic square of the face")
            key = (f,) + sq
            if key in seen:
                return Check(False, f"cell {c[:6]} is listed twice")
            seen[key] = True
            area[f] += sq[0] ** 2
            P = np.array(pieces, dtype=float).reshape(-1, 7)
            if not np.isfinite(P).all() or (P[:, :2] != np.round(P[:, :2])).any() or (P[:, 6] != np.round(P[:, 6])).any():
                return Check(False, f"cell {c[:6]}: malformed piece")
            check = _pieces_tile(P, arcs.arcs(i))
            if not check:
                return Check(False, f"cell {c[:6]}: {check.reason}")
            ids = [arcs.id(i, int(j0), int(j1)) for j0, j1 in P[:, :2]]
            if None in ids:
                return Check(False, f"cell {c[:6]}: a piece spans arcs whose normals turn too much to be bounded")
            cand = P[:, 6].astype(np.int64)
            if (cand < 0).any() or (cand >= model.weights.shape[1]).any() or not model.cmask[i, cand].all():
                return Check(False, f"cell {c[:6]}: unknown candidate combination")
            m = len(P)
            items["contact"].append(np.full(m, i))
            items["arc"].append(np.array(ids, dtype=np.int64))
            items["face"].append(np.full(m, f))
            items["box"].append(np.tile([float(lo0), float(hi0), float(lo1), float(hi1)], (m, 1)))
            for q, name in enumerate(("s0", "s1", "t0", "t1"), start=2):
                items[name].append(P[:, q])
            items["cand"].append(cand)
        for (f, w, x, y) in seen:
            wa, xa, ya = w, x, y
            while wa < 1:
                wa, xa, ya = wa * 2, xa // 2, ya // 2
                if (f, wa, xa, ya) in seen:
                    return Check(False, f"cells overlap on face {f}")
        if any(a != 4 for a in area):
            return Check(False, "the cells do not cover every face of the direction cube")
        cat = {key: np.concatenate(v) for key, v in items.items()}
        lb, _ = bounds(regions, arcs, model, cat["contact"], cat["arc"], cat["face"].astype(np.int64),
                       cat["box"], cat["s0"], cat["s1"], cat["t0"], cat["t1"], cand=cat["cand"])
        if not (lb > 0).all():
            j = int(np.argmin(lb))
            return Check(False, f"a piece's bound is not positive ({lb[j]:.3g} on arc {int(cat['arc'][j])})")
    except (TypeError, ValueError, IndexError, KeyError, OverflowError) as err:
        return Check(False, f"malformed cells certificate: {err}")
    return Check(True)


def _pieces_tile(P: np.ndarray, count: int) -> Check:
    """Do the pieces ``P`` (rows ``j0, j1, s0, s1, t0, t1, cand``) tile the ``count`` arcs of a
    region? Stretches of several arcs take whole arcs (``s`` and ``t`` over ``[0, 1]``); the
    pieces of a single arc tile its ``[0, 1]^2``."""
    j0, j1 = P[:, 0].astype(np.int64), P[:, 1].astype(np.int64)
    s0, s1, t0, t1 = P[:, 2], P[:, 3], P[:, 4], P[:, 5]
    if (j0 < 0).any() or (j1 > count).any() or (j1 <= j0).any():
        return Check(False, "a piece is not a stretch of the region's arcs")
    if (s0 < 0).any() or (s1 > 1).any() or (t0 < 0).any() or (t1 > 1).any() or (s0 >= s1).any() or (t0 >= t1).any():
        return Check(False, "a piece leaves [0, 1]^2 or is empty")
    whole = (j1 - j0 > 1) | ((s0 == 0) & (s1 == 1) & (t0 == 0) & (t1 == 1))
    if ((j1 - j0 > 1) & ~whole).any():
        return Check(False, "a piece of several arcs must take them whole")
    cover = np.zeros(count, dtype=np.int64)
    for a, b in zip(j0[whole], j1[whole]):
        cover[a:b] += 1
    if (cover > 1).any():
        return Check(False, "pieces overlap")
    for a in range(count):
        part = ~whole & (j0 == a)
        if cover[a]:
            if part.any():
                return Check(False, f"arc {a}: pieces overlap")
            continue
        if not part.any():
            return Check(False, f"arc {a} has no piece")
        a0, a1, b0, b1 = s0[part], s1[part], t0[part], t1[part]
        total = sum((Fraction(x1) - Fraction(x0)) * (Fraction(y1) - Fraction(y0)) for x0, x1, y0, y1 in zip(a0, a1, b0, b1))
        if total != 1:
            return Check(False, f"arc {a}: the pieces do not cover it")
        over = ((a0[:, None] < a1[None, :]) & (a0[None, :] < a1[:, None]) &
                (b0[:, None] < b1[None, :]) & (b0[None, :] < b1[:, None]))
        np.fill_diagonal(over, False)
        if over.any():
            return Check(False, f"arc {a}: pieces overlap")
    return Check(True)

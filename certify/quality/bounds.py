"""Grasp quality: Ferrari-Canny epsilon of the L1 and L-infinity grasp wrench spaces, with evidence.

The grasp wrench space (GWS) is built from each contact's wrenches with unit normal force,
``W_i = {G_i f : f in cone_i, f_n = 1}``. The L1 GWS is ``conv(0 and all W_i)`` (total normal
force at most 1), the L-infinity GWS the Minkowski sum of the ``conv(0, W_i)`` (each normal force
at most 1). Epsilon is the radius of the largest ball centred at the origin inside the GWS,
``epsilon = min over unit u of h(u)``, with the support function

    h_L1(u) = max_i max(0, a_n,i + mu_i norm(a_t,i))      h_Linf(u) = sum_i max(0, a_n,i + mu_i norm(a_t,i))

(``(a_n, a_t)`` the components of ``G_i' u`` in the contact frame; frictionless: ``a_n`` only).

Torque scaling is explicit: wrenches are ``(f, (p - center) x f / length)``, so epsilon depends on
``center`` and ``length`` (every :class:`Epsilon` states both). Scaling the object, the contacts,
``center`` and ``length`` together leaves epsilon unchanged; dividing ``length`` by ``s`` multiplies
the torque coordinates by ``s``. The min-weight margin of :mod:`qualgrasp.certify.core.closure` depends on neither.

Every :class:`Epsilon` states rigorous bounds ``lo <= epsilon <= hi`` and carries
:class:`~qualgrasp.certify.quality.evidence.Evidence` that :mod:`qualgrasp.certify.quality.evidence` re-checks
without a solver: a direction ``u`` with ``h(u) = hi`` and an inscribed polytope (a closed
triangulated surface on points of the GWS) whose faces are all at distance ``lo`` or more.

Planar grasps: every contact model is polyhedral in the plane, so epsilon is exact, the minimum of
``h`` over a finite set of directions holding every facet normal of the GWS (``k`` generators,
``m`` contacts):

* L1: the grasp is in closure, so the origin is interior and the facets of the GWS are those of
  the hull of the generators: the compiled enumeration of triples for ``k <= L1_ENUMERATION_MAX``,
  else the hull of the generators (:func:`~qualgrasp.certify._kernels.hull.hull_faces`). The hull's
  triangles are the lower-bound evidence, so
  ``lo = hi``.
* L-infinity: every facet normal of a Minkowski sum in 3-D is normal to two edges of the summands:
  the compiled enumeration of pairs of edges for ``k <= LINF_ENUMERATION_MAX`` (``O(k^3)``), else
  a sweep around the great circle orthogonal to each edge (``O(k^2 log k)``,
  :func:`qualgrasp.certify._kernels.epsilon.linf_sweep`). The evidence for ``lo`` is the hull of
  all sums of one vertex per summand when there are at most ``SUMS_MAX`` of them (then
  ``lo = hi``); beyond that the hull of support points of the GWS (each the sum of every contact's
  generator furthest along a direction), refined along the normals of its faces nearest the
  origin until it proves ``hi`` (each cut adds a vertex of the GWS beyond the face, so this
  ends), stored as its directions. If that does not succeed within 640 vertices
  or the time limit, the L1 GWS, which lies inside the L-infinity one, proves the L1 epsilon
  (``lo < hi``, honestly reported).

Spatial grasps with exact cones: an inner and an outer approximation refined together. ``hi`` is
the least ``h(u)`` found over directions ``u`` (the best of a fixed set of starting directions,
refined by local minimisation, a tangent-plane SOCP solved by clarabel, and the normals of the
polytope below). ``lo`` is the epsilon of an inscribed polytope: the hull of support points of the
GWS (the contact wrenches maximising ``u . w``, pulled inside their cones and proved inside
exactly, scaled by at most ``2^-14`` towards the origin to put them in general position), starting
from the 12 coordinate directions (while the points lie in a hyperplane, adding those along its
normal both ways, then along more fixed starting directions), then adding the support points along
the normal of its weakest face, which pushes that face out, until ``hi - lo <= rel_gap * hi``,
the polytope has ``MAX_VERTICES`` vertices or the work ``budget`` is spent. Each round costs
``O(m)`` per direction examined plus a hull of at most ``MAX_VERTICES`` points, whatever ``m``.

A per-grasp time limit (``time_limit``, seconds) stops the L-infinity sweep, the refinement of
the planar ``support`` evidence and the spatial refinement early: the row keeps its closure
verdict and reports the bounds reached (planar L-infinity: ``hi`` the best support value found,
``lo`` the L1 epsilon or what the support points found so far prove; spatial: the polytope's
``lo`` and the best ``hi``), with ``limited`` set whenever the limit cut a bound. Results then
depend on the machine's speed; without the limit being hit they are deterministic. The clock
counts computation only: it starts once the closure verdict is known, and the kernels are
compiled (or loaded from numba's cache, or awaited from another process compiling them into a
cold cache: :func:`qualgrasp.certify.warmup.compile_ahead`) before it runs, so a cold compile
cache never changes a result.

Epsilon is 0 for grasps not in closure (and for degenerate ones): the closure verdict is decided
first, so flat hulls and rank-deficient sets never reach a hull.

Many planar grasps sharing one generator layout (the columnar batch path):
:func:`planar_epsilon_rows` gives, row for row, what :func:`planar_epsilons` gives, with the
epsilons, the sums and the rigorous float checks of every surface compiled for the whole batch
(:mod:`qualgrasp.certify._kernels.evidence`, :mod:`qualgrasp.certify._kernels.hull`); the ``support``
refinement runs per row, and a row whose surfaces need exact arithmetic takes
:func:`planar_epsilons` itself.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Literal, get_args

import clarabel
import numpy as np
import scipy.sparse as sp
from scipy.spatial import ConvexHull, QhullError

from .._kernels.epsilon import hull_minima, linf_sweep, planar_edges, planar_epsilon_one, support_rows
from .._kernels.epsilon import planar_epsilon as epsilon_kernel
from .._kernels.evidence import NOT_HERE, REFINED, minkowski_sums, support_refine, support_refine_rows, surface_rows
from .._kernels.hull import face_planes, grow_start, hull_grow, live_facets, used_vertices, weakest_plane
from .._kernels.jit import await_compiled, compiled_here, kernel_array, mark_compiled, precompile
from .._kernels.sets import EPSILON_SETS, KERNEL_SETS
from .._kernels.surface import leibniz_tables
from ..core.arguments import count_in, number_in, require
from ..errors import ArgumentError
from ..core.closure import Verdict, force_closure
from .evidence import EPS_TOL, Evidence, EvidenceColumns, stated_lo, surface_minimum
from .gws import (ConicSupport, oriented_surface, planar_support_choices,
                  hull_rows, sum_rows, surface_faces)
from ..core.grasp import Grasp
from ..core.problem import System, grasp_system
from ..core.wrench import planar_generator_arrays
from ..solvers.clarabel_direct import settings

__all__ = ["Norm", "NORMS", "Epsilon", "epsilon", "epsilons", "planar_epsilon", "planar_epsilons",
           "planar_epsilon_rows", "planar_epsilon_columns", "epsilon_of_points", "check_norm", "L1_ENUMERATION_MAX",
           "LINF_ENUMERATION_MAX", "SUMS_MAX", "MAX_VERTICES", "SOCP_COST"]

#: A norm of the grasp wrench space.
Norm = Literal["L1", "Linf"]
NORMS: tuple[str, ...] = get_args(Norm)

#: Planar L1 with at most this many generators: compiled enumeration of triples (else the hull).
L1_ENUMERATION_MAX = 16
#: Planar L-infinity with at most this many generators: compiled enumeration of edge pairs
#: (else the sweep).
LINF_ENUMERATION_MAX = 24
#: Planar L-infinity: the surface of all sums is the lower-bound evidence when there are at
#: most this many sums (the product over contacts of generators + 1), else the L1 surface.
SUMS_MAX = 4096
#: Spatial: most vertices of the inscribed polytope (bounds its hull and its evidence).
MAX_VERTICES = 1280
#: Planar L-infinity: most directions of ``support`` evidence.
_PLANAR_DIRECTIONS = 640
#: Work of one local minimisation step (an SOCP) in units of directions examined, for the budget.
SOCP_COST = 25
#: Candidate directions kept by the L-infinity sweep for the direct evaluation of ``h``.
_TOP = 16
#: A local minimisation of the spatial support function stops at a step gaining less than this
#: fraction of ``h``.
_STEP_GAIN = 1e-7
#: Circles swept between two looks at the clock.
_SWEEP_BATCH = 64
#: The planar support refinement adds the normals of twice this many weakest faces per round (the
#: spatial one, that of its weakest face: more per round cost more hull than they save rounds).
_ADD = 2
#: Rounds of the compiled planar support refinement between two looks at the clock.
_ROUNDS = 16
#: Shortest time limit (seconds) under which planar rows' first refinement calls run in one batch
#: (:func:`_support_rows`): the row-by-row route looks at the clock before a row's first call and
#: then only after it, and a limit this long cannot have passed by then.
_ONE_CALL = 0.01


@dataclass(frozen=True)
class Epsilon:
    """Ferrari-Canny epsilon with the torque scaling it was computed with.

    Attributes
    ----------
    norm : {'L1', 'Linf'}
    lo, hi : float
        Rigorous bounds ``lo <= epsilon <= hi`` (0 when not in closure), in the unit of the
        wrenches (force, with torques divided by ``length``).
    direction : tuple of float or None
        Unit wrench direction where ``h`` attains ``hi``: the weakest direction found.
    center : tuple of float
        Reference point of torques used.
    length : float
        Length dividing torques used.
    exact : bool
        True when ``lo == hi`` (planar grasps whose surface evidence is complete, grasps not in
        closure).
    rounds : int
        Refinement rounds spent (spatial grasps).
    limited : bool
        The time limit stopped the computation (the bounds are those reached).
    evidence : Evidence or None
        What proves ``lo`` and ``hi`` (:mod:`qualgrasp.certify.quality.evidence`); None when not in
        closure.
    """

    norm: str
    lo: float
    hi: float
    direction: tuple[float, ...] | None
    center: tuple[float, ...]
    length: float
    exact: bool
    rounds: int = 0
    limited: bool = False
    evidence: Evidence | None = None

    @property
    def gap(self) -> float:
        """Relative gap ``(hi - lo) / hi`` (0 when ``hi`` is 0)."""
        return (self.hi - self.lo) / self.hi if self.hi > 0 else 0.0


def check_norm(norm: Norm) -> None:
    """Refuse a norm other than those of :data:`NORMS` (``"L1"``, ``"Linf"``).

    Raises
    ------
    ArgumentError
        Naming the norm given (a ``ValueError``).

    Examples
    --------
    >>> check_norm("L2")
    Traceback (most recent call last):
    ...
    qualgrasp.certify.errors.ArgumentError: unknown norm 'L2'; use 'L1' or 'Linf'
    """
    if not isinstance(norm, str) or norm not in NORMS:
        raise ArgumentError(f"unknown norm {norm!r}; use 'L1' or 'Linf'")


def _zero(grasp: Grasp, norm: str) -> Epsilon:
    return Epsilon(norm, 0.0, 0.0, None, tuple(grasp.center), grasp.length, True)


def _expired(deadline: float | None) -> bool:
    return deadline is not None and time.perf_counter() > deadline


def _after_compiling(deadline: float | None, dim: int, large: bool = False, columns: bool = False) -> float | None:
    """Compile (or load) the kernel sets of ``dim`` (:data:`KERNEL_SETS`; for planar grasps with
    ``large`` the large set too, with ``columns`` the columnar route's, with both the columnar
    route's for large grasps), first waiting for another
    process compiling a set (:func:`~qualgrasp.certify.warmup.compile_ahead`), and return
    ``deadline`` pushed back by the time that took: a time limit counts computation, never
    compilation, so that a cold compile cache cannot change a result."""
    names = EPSILON_SETS[dim] + (("quality-planar-large",) if large and dim == 2 else ()) + (
        ("quality-planar-columns",) if columns and dim == 2 else ()) + (
        ("quality-planar-large-columns",) if large and columns and dim == 2 else ())
    if all(compiled_here(KERNEL_SETS[name]) for name in names):  # every call after a process's first
        return deadline
    start = time.perf_counter()
    for name in names:
        if not compiled_here(KERNEL_SETS[name]):
            await_compiled(name)
            precompile(KERNEL_SETS[name])
            mark_compiled(name)
    return None if deadline is None else deadline + (time.perf_counter() - start)


# --- planar ---------------------------------------------------------------------------------------

class _NoExact(Exception):
    """The exact data needed to settle a face is not available."""


def _prove(V: np.ndarray, EV: np.ndarray, faces, exact_vertex, closed: bool = False):
    """Bounds ``(lo, hi)`` of the smallest squared face distance of a surface proving a ball
    (:func:`qualgrasp.certify.quality.evidence.surface_minimum`, the checker's own rule; ``closed``:
    the faces are known to close up), or None when it proves nothing."""
    if faces is None or len(faces) == 0:
        return None
    try:
        reason, lo, hi = surface_minimum(V, EV, faces, exact_vertex, closed=closed)
    except _NoExact:
        return None
    return None if reason or lo <= 0 else (lo, hi)


def _no_exact(i):
    raise _NoExact


def _lower(eps: float, bounds) -> float | None:
    """The ``lo`` to state from proved bounds of the squared surface distance: ``eps`` itself
    when the surface proves it to well within the evidence tolerance, else the surface's own
    value (None: nothing proved)."""
    if bounds is None:
        return None
    d2_lo, d2_hi = bounds
    x = eps * eps
    if d2_lo >= x * (1 - EPS_TOL / 4) and d2_hi <= x * (1 + EPS_TOL / 4):
        return eps
    return min(stated_lo(d2_lo, d2_hi), eps)


def _hull_minimum(W, owner, m, faces):
    """Planar L1 epsilon ``(value, direction)`` of one grasp from its generators' hull
    (:func:`_hull_minima`)."""
    eps, arg = _hull_minima(W[None], owner, m, faces, np.array([0, len(faces)], dtype=np.int64))
    return float(eps[0]), arg[0]


def _hull_minima(W, owner, m, faces, fstart):
    """Planar L1 epsilon of many grasps (``W`` (B, 3, k)) from the triangles of their generators'
    hulls (grasp ``b`` owning ``faces[fstart[b]:fstart[b + 1]]``): the support function, evaluated
    directly, at the normals of the :data:`_TOP` faces nearest the origin
    (:func:`~qualgrasp.certify._kernels.epsilon.hull_minima`); the enumeration's where no face
    has a normal (a hull of slivers). Every grasp must own at least one face."""
    W = np.ascontiguousarray(W, dtype=float)
    eps, arg = hull_minima(W, owner, m, kernel_array(faces, np.int64), fstart, _TOP)
    none = np.flatnonzero(np.isinf(eps))
    if len(none):
        eps[none], arg[none] = epsilon_kernel(W[none], owner, m, False)
    return eps, arg


def _large(k: int, owner, m: int) -> bool:
    """Whether a planar grasp of ``k`` generators (contacts ``owner``) needs the large kernel set:
    more than :data:`L1_ENUMERATION_MAX` generators, or more than :data:`SUMS_MAX` sums."""
    return k > L1_ENUMERATION_MAX or _sum_count(np.asarray(owner), m) > SUMS_MAX


def _sum_count(owner, m: int) -> int:
    """Number of sums of one point per contact polytope (the origin or a generator)."""
    return math.prod(int(s) + 1 for s in np.bincount(owner, minlength=m))


def _sums(W, E, owner, m):
    """Every sum of one point per contact polytope (the origin or a generator): the points
    (n, 3), their error bounds and the generator chosen per contact (n, m; -1 for the origin);
    None when there are more than :data:`SUMS_MAX`
    (:func:`~qualgrasp.certify._kernels.evidence.minkowski_sums`)."""
    if _sum_count(owner, m) > SUMS_MAX:
        return None
    pts, err, choice = minkowski_sums(W[None], E[None], owner, m)
    return pts[0], err[0], choice


def planar_epsilons(W, E, owner, m: int, *, deadline: float | None = None, exact=None) -> dict:
    """Planar epsilon of both norms with evidence (module docstring), for a grasp in closure.

    Parameters
    ----------
    W, E : ndarray, shape (3, k)
        Generator wrenches and bounds on their distance to the exact ones
        (:func:`~qualgrasp.certify.core.wrench.planar_generator_arrays`).
    owner : ndarray of int, shape (k,)
        Contact of each generator (sorted).
    m : int
        Number of contacts.
    deadline : float, optional
        :func:`time.perf_counter` value after which the L-infinity sweep and the refinement of
        its ``support`` evidence stop (``limited``); pushed back by the time spent compiling
        kernels here.
    exact : callable, optional
        ``exact()`` returns the exact generators (3, k) (Fractions), asked for only when the
        rigorous float checks of a surface cannot decide a face; without it such a surface
        proves nothing.

    Returns
    -------
    dict
        ``{"L1": (lo, hi, direction, evidence, limited), "Linf": (...)}``.
    """
    deadline = _after_compiling(deadline, 2, _large(np.shape(W)[1], owner, m))
    W = np.ascontiguousarray(W, dtype=float)
    E = np.ascontiguousarray(E, dtype=float)
    owner = np.ascontiguousarray(owner, dtype=np.int64)
    k = W.shape[1]
    out = {}
    # L1: the hull of the generators
    faces = surface_faces(W.T)
    if k <= L1_ENUMERATION_MAX or faces is None:
        eps, u = planar_epsilon_one(W, owner, m, False)
        eps = float(eps)
    else:
        eps, u = _hull_minimum(W, owner, m, faces)
    gens = _exact_once(exact)
    lo = _lower(eps, _prove(W.T, E.T, faces, lambda i: list(gens()[:, i])))
    direction = tuple(float(v) for v in u)
    if lo is None:
        out["L1"] = (0.0, eps, direction, Evidence("none", direction), False)
    else:
        out["L1"] = (lo, eps, direction, Evidence("generators", direction, faces=tuple(int(i) for i in faces.ravel())), False)
    l1_lo = out["L1"][0]
    # L-infinity
    limited = False
    if k <= LINF_ENUMERATION_MAX:
        eps, u = planar_epsilon_one(W, owner, m, True)
        eps = float(eps)
    else:
        eps, u, limited = _sweep(W, owner, m, deadline)
    direction = tuple(float(v) for v in u)
    ev = None
    if not limited:
        sums = _sums(W, E, owner, m)
        if sums is not None:
            pts, err, choice = sums
            faces = surface_faces(pts)
            if faces is not None:
                used = np.unique(faces)
                remap = np.full(len(pts), -1, dtype=np.int64)
                remap[used] = np.arange(len(used))
                faces = remap[faces]
                picks = choice[used]

                def vertex(i, picks=picks):
                    C = gens()
                    return [sum((C[r, j] for j in picks[i] if j >= 0), 0) for r in range(3)]

                lo = _lower(eps, _prove(pts[used], err[used], faces, vertex))
                if lo is not None and lo >= l1_lo:
                    ev = Evidence("sums", direction, ref=tuple(int(i) for i in choice[used].ravel()),
                                  faces=tuple(int(i) for i in faces.ravel()))
        else:
            out["Linf"] = _support_row(W, E, owner, m, eps, u, l1_lo, deadline, gens)
            return out
    if ev is None:
        lo = min(l1_lo, eps)
        ev = Evidence("l1", direction)
    out["Linf"] = (lo, eps, direction, ev, limited)
    return out


def planar_epsilon_rows(W, E, owner, m: int, *, time_limit: float | None = None, exact=None) -> list[dict]:
    """:func:`planar_epsilons` of ``B`` grasps in closure sharing one generator layout, the
    same results row for row, with the per-row work compiled for the whole batch.

    The epsilons (:func:`~qualgrasp.certify._kernels.epsilon.planar_epsilon`), the sums of
    ``sums`` evidence (:func:`~qualgrasp.certify._kernels.evidence.minkowski_sums`) and the
    rigorous float checks of every surface
    (:func:`~qualgrasp.certify._kernels.evidence.surface_rows`) and the hulls whose faces the
    evidence states (:func:`~qualgrasp.certify.quality.gws.surfaces_faces`) run on the whole batch;
    only the ``support`` refinement (more than :data:`SUMS_MAX` sums) is computed row by row. A row
    whose surfaces the float checks cannot settle, whose points span no hull, or with more than
    :data:`LINF_ENUMERATION_MAX` generators takes :func:`planar_epsilons` itself, so that every row
    is what the per-grasp route gives.

    Parameters
    ----------
    W, E : ndarray, shape (B, 3, k)
        Generator wrenches of each grasp and bounds on their distance to the exact ones
        (:func:`~qualgrasp.certify._kernels.evidence.generator_rows`).
    owner : ndarray of int, shape (k,)
        Contact of each generator (sorted), shared by the rows.
    m : int
        Number of contacts.
    time_limit : float, optional
        Seconds of the ``support`` refinement per row (the ``deadline`` of
        :func:`planar_epsilons`, started when that row's refinement starts: the batch's
        compiled work is not counted) and of the rows taking :func:`planar_epsilons`.
    exact : callable, optional
        ``exact(b)`` returns the exact generators (3, k) of row ``b`` (Fractions), asked for only
        on the per-grasp route.

    Returns
    -------
    list of dict
        Per row, what :func:`planar_epsilons` returns.

    Examples
    --------
    Two antipodal point contacts on the unit circle with ``mu = 0.5``, as for :func:`epsilon`:

    >>> from qualgrasp.certify import Contact, Grasp
    >>> g = Grasp((Contact((1, 0), (-1, 0), "point", 0.5), Contact((-1, 0), (1, 0), "point", 0.5)))
    >>> W, E, owner = planar_generator_arrays(g)
    >>> row = planar_epsilon_rows(W[None], E[None], owner, 2)[0]
    >>> row == planar_epsilons(W, E, owner, 2)
    True
    >>> round(row["L1"][0], 6), row["Linf"][3].kind
    (0.333333, 'sums')
    """
    vals, limited, l1, linf = planar_epsilon_columns(W, E, owner, m, time_limit=time_limit, exact=exact)
    out = []
    for b in range(len(vals)):
        a, c = l1.row(b), linf.row(b)
        out.append({"L1": (float(vals[b, 0]), float(vals[b, 1]), a.direction, a, False),
                    "Linf": (float(vals[b, 2]), float(vals[b, 3]), c.direction, c, bool(limited[b]))})
    return out


def planar_epsilon_columns(W, E, owner, m: int, *, time_limit: float | None = None, exact=None):
    """:func:`planar_epsilon_rows` held in columns, as the batch path writes them: the same
    values and evidence, without an object per row.

    Returns
    -------
    values : ndarray, shape (B, 4)
        L1 ``lo``, ``hi``, L-infinity ``lo``, ``hi`` of each row.
    limited : ndarray of bool, shape (B,)
        Whether the time limit cut a row's L-infinity bounds.
    l1, linf : EvidenceColumns
        The evidence of each norm.
    """
    _after_compiling(None, 2, _large(np.shape(W)[2], owner, m), columns=True)
    W = np.ascontiguousarray(W, dtype=float)
    E = np.ascontiguousarray(E, dtype=float)
    owner = np.ascontiguousarray(owner, dtype=np.int64)
    B, _, k = W.shape
    slow = np.full(B, k > LINF_ENUMERATION_MAX)
    vals = np.zeros((B, 4))
    limited = np.zeros(B, dtype=bool)
    rows, directions, (lengths, items) = _l1_rows(W, E, owner, m, np.flatnonzero(~slow), slow, vals)
    blocks2 = _linf_rows(W, E, owner, m, np.flatnonzero(~slow), slow, vals, limited, time_limit, exact)
    keep = ~slow[rows]  # rows that L-infinity sent to the per-grasp route lose their L1 block
    faces = (lengths[keep], items[np.repeat(keep, lengths)])
    blocks1 = [(rows[keep], "generators", directions[keep], {"faces": faces})]
    slow_rows = np.flatnonzero(slow)
    evs1, evs2 = [], []
    for b in slow_rows:
        deadline = None if time_limit is None else time.perf_counter() + time_limit
        row = planar_epsilons(W[b], E[b], owner, m, deadline=deadline,
                              exact=None if exact is None else (lambda b=b: exact(b)))
        (vals[b, 0], vals[b, 1], _, ev1, _), (vals[b, 2], vals[b, 3], _, ev2, limited[b]) = row["L1"], row["Linf"]
        evs1.append(ev1)
        evs2.append(ev2)
    if len(slow_rows):
        blocks1.append(EvidenceColumns.block(slow_rows, evs1))
        blocks2.append(EvidenceColumns.block(slow_rows, evs2))
    return vals, limited, EvidenceColumns.assemble(B, blocks1), EvidenceColumns.assemble(B, blocks2)


def _checked(V, EV, faces):
    """:func:`_flat_checks` of the surfaces ``faces`` (a list of (F, 3) arrays, None for none) on
    the vertices ``V``, ``EV`` (lists of (n, 3) arrays): per surface the proved bounds ``(d2_lo,
    d2_hi)`` of its squared distance, or None where the float checks cannot settle it. The
    bounds are floats, which :func:`_lower` compares as exactly as the Fractions :func:`_prove`
    gives."""
    vstart = np.r_[0, np.cumsum([len(v) for v in V])].astype(np.int64)
    fs = [np.zeros((0, 3), dtype=np.int64) if f is None else f for f in faces]
    fstart = np.r_[0, np.cumsum([len(f) for f in fs])].astype(np.int64)
    cat = lambda a: np.concatenate(a) if a else np.zeros((0, 3))  # noqa: E731
    decided, lo, hi = _flat_checks(cat(V), cat(EV), vstart, kernel_array(cat(fs), np.int64), fstart)
    return [(float(a), float(b)) if ok else None for ok, a, b in zip(decided, lo, hi)]


def _flat_checks(V, EV, vstart, faces, fstart):
    """:func:`~qualgrasp.certify._kernels.evidence.surface_rows` of surfaces held flat (as
    :func:`~qualgrasp.certify.quality.gws.hull_rows` gives them): per surface whether the float
    checks settle it and the proved bounds ``(d2_lo, d2_hi)`` of its squared distance."""
    perms, signs = leibniz_tables(2)
    return surface_rows(kernel_array(V), kernel_array(EV), vstart, faces, fstart, perms, signs, EPS_TOL / 8)


def _lowers(eps: np.ndarray, d2_lo: np.ndarray, d2_hi: np.ndarray) -> np.ndarray:
    """:func:`_lower` of many rows, elementwise, in the same floating-point operations."""
    x = eps * eps
    tight = (d2_lo >= x * (1 - EPS_TOL / 4)) & (d2_hi <= x * (1 + EPS_TOL / 4))
    stated = np.where(d2_lo > 0, np.sqrt(np.sqrt(np.maximum(d2_lo, 0)) * np.sqrt(np.maximum(d2_hi, 0))), 0.0)
    return np.where(tight, eps, np.minimum(stated, eps))


def _l1_rows(W, E, owner, m, rows, slow, vals):
    """L1 part of :func:`planar_epsilon_columns`: fills ``lo`` and ``hi`` of the rows settled in
    floats and returns them with their directions and faces ``(lengths, items)``; rows whose
    points span no hull or whose surface the float checks cannot settle are marked ``slow``."""
    k = W.shape[2]
    V = W[rows].transpose(0, 2, 1).reshape(-1, 3)
    EV = E[rows].transpose(0, 2, 1).reshape(-1, 3)
    vstart = np.arange(len(rows) + 1, dtype=np.int64) * k
    faces, fstart = hull_rows(V, vstart)
    have = np.diff(fstart) > 0
    if k <= L1_ENUMERATION_MAX:
        eps, arg = epsilon_kernel(W[rows[have]], owner, m, False)
    else:  # the rows without a hull own no faces: the others' ranges follow one another
        eps, arg = _hull_minima(W[rows[have]], owner, m, faces, np.append(fstart[:-1][have], fstart[-1]))
    decided, d2_lo, d2_hi = _flat_checks(V, EV, vstart, faces, fstart)
    ok = decided[have]
    slow[rows[~have]] = True
    slow[rows[have][~ok]] = True
    done = rows[have][ok]
    vals[done, 0] = _lowers(eps[ok], d2_lo[have][ok], d2_hi[have][ok])
    vals[done, 1] = eps[ok]
    lengths = 3 * np.diff(fstart)
    settled = np.zeros(len(rows), dtype=bool)
    settled[np.flatnonzero(have)[ok]] = True
    return done, np.asarray(arg, dtype=float)[ok], (lengths[settled], faces.ravel()[np.repeat(settled, lengths)])


def _linf_rows(W, E, owner, m, rows, slow, vals, limited, time_limit, exact):
    """L-infinity part of :func:`planar_epsilon_columns`: fills ``lo`` and ``hi`` of the rows
    settled in floats (``vals[:, 0]`` holding their L1 ``lo``) and returns their evidence as
    blocks of :meth:`EvidenceColumns.assemble`; rows not settled in floats are marked ``slow``."""
    if not len(rows):
        return []
    eps, arg = epsilon_kernel(W[rows], owner, m, True)
    n = _sum_count(owner, m)
    if n > SUMS_MAX:
        return _support_rows(W, E, owner, m, rows, eps, arg, vals, limited, time_limit, exact)
    blocks = []
    step = max(1, (1 << 20) // n)  # rows of sums held at once
    for a in range(0, len(rows), step):
        part = rows[a:a + step]
        e, u = eps[a:a + step], np.asarray(arg[a:a + step], dtype=float)
        pts, err, choice = minkowski_sums(W[part], E[part], owner, m)
        vstart = np.arange(len(part) + 1, dtype=np.int64) * n
        faces, fstart = hull_rows(pts.reshape(-1, 3), vstart)
        used, ustart, local = used_vertices(faces, fstart, vstart)
        at = used + np.repeat(vstart[:-1], np.diff(ustart))
        decided, d2_lo, d2_hi = _flat_checks(pts.reshape(-1, 3)[at], err.reshape(-1, 3)[at], ustart, local, fstart)
        has = np.diff(fstart) > 0
        good = ~has | decided  # no hull: the L1 evidence; a hull the floats cannot settle: per grasp
        slow[part[~good]] = True
        l1_lo = vals[part, 0]
        sums = has & decided
        sums[sums] = _lowers(e[sums], d2_lo[sums], d2_hi[sums]) >= l1_lo[sums]
        lo = np.minimum(l1_lo, e)
        lo[sums] = _lowers(e[sums], d2_lo[sums], d2_hi[sums])
        vals[part[good], 2] = lo[good]
        vals[part[good], 3] = e[good]
        nf = np.where(sums, 3 * np.diff(fstart), 0)
        nr = np.where(sums, m * np.diff(ustart), 0)
        lists = {"faces": (nf[good], local.ravel()[np.repeat(sums, 3 * np.diff(fstart))]),
                 "ref": (nr[good], choice[used].ravel()[np.repeat(sums, m * np.diff(ustart))])}
        blocks.append((part[good], np.where(sums, "sums", "l1")[good], u[good], lists))
    return blocks


def _support_rows(W, E, owner, m, todo, eps, arg, vals, limited, time_limit, exact):
    """The L-infinity part of :func:`planar_epsilon_columns` beyond :data:`SUMS_MAX` sums: the
    rows' ``support`` surfaces refined in one compiled call
    (:func:`~qualgrasp.certify._kernels.evidence.support_refine_rows`: each row as
    :func:`_support_surface` refines it, up to the :data:`_ROUNDS` rounds it runs before it first
    looks at the clock, all of them without a time limit), their float checks and evidence made
    in columns. The rows that call does not finish (their hull declined, or their rounds are
    spent) go through :func:`_support_rows_each`, which starts them again under their own
    deadline; so does every row under a time limit below :data:`_ONE_CALL`, which may pass before
    the first call ends. Fills ``vals`` and ``limited`` and returns the evidence as blocks of
    :meth:`EvidenceColumns.assemble`."""
    if (time_limit is not None and time_limit < _ONE_CALL) or not len(todo):
        return _support_rows_each(W, E, owner, m, todo, eps, arg, vals, limited, time_limit, exact)
    U = np.ascontiguousarray(np.asarray(arg, dtype=float).reshape(len(todo), 3))
    cap = max(7, _PLANAR_DIRECTIONS + 2 * _ADD)
    state, D, R, V, EV, vstart, F, fstart = support_refine_rows(
        np.ascontiguousarray(W[todo]), np.ascontiguousarray(E[todo]), owner, m, U, eps * (1 - EPS_TOL / 16),
        _PLANAR_DIRECTIONS, _ADD, cap, _PLANAR_DIRECTIONS if time_limit is None else _ROUNDS)
    here = state == REFINED
    decided, d2_lo, d2_hi = _flat_checks(V, EV, vstart, F, fstart)
    lo = np.full(len(todo), np.nan)
    ok = here & decided
    lo[ok] = _lowers(eps[ok], d2_lo[ok], d2_hi[ok])
    for q in np.flatnonzero(here & ~decided):  # exact arithmetic needed: as the per-grasp route
        b, (a, z), (f, g) = todo[q], vstart[q:q + 2], fstart[q:q + 2]
        found = _lower(float(eps[q]), _support_bounds(V[a:z], EV[a:z], F[f:g], R[a:z], _row_gens(exact, b)))
        lo[q] = np.nan if found is None else found
    rows = todo[here]
    l1_lo, e = vals[rows, 0], eps[here]
    support = lo[here] >= l1_lo  # False where nothing was proved (NaN)
    vals[rows, 2] = np.where(support, lo[here], np.minimum(l1_lo, e))
    vals[rows, 3] = e
    stated = np.zeros(len(todo), dtype=bool)
    stated[here] = support
    n = np.diff(vstart)
    points = D[np.repeat(stated, n)].ravel()  # the directions of each row with support evidence
    blocks = [(rows, np.where(support, "support", "l1"), U[here], {"points": (3 * n[here] * support, points)})]
    if not here.all():
        blocks += _support_rows_each(W, E, owner, m, todo[~here], eps[~here], U[~here], vals, limited, time_limit,
                                     exact)
    return blocks


def _support_rows_each(W, E, owner, m, todo, eps, arg, vals, limited, time_limit, exact):
    """:func:`_support_rows` row by row: each row's ``support`` surface refined on its own
    (:func:`_support_surface`, which gives its hull's faces, under its own deadline), then the
    float checks of all rows at once; a surface those cannot settle is proved as
    :func:`_planar_support` proves it. Fills ``vals`` and ``limited`` and returns the evidence
    as one block of :meth:`EvidenceColumns.assemble`."""
    refined = []
    for b, e, u in zip(todo, eps, arg):
        deadline = None if time_limit is None else time.perf_counter() + time_limit
        refined.append(_support_surface(W[b], E[b], owner, m, float(e), np.asarray(u, dtype=float), deadline))
    done = [q for q, (surface, _) in enumerate(refined) if surface is not None]
    proved = dict(zip(done, _checked([refined[q][0][1] for q in done], [refined[q][0][2] for q in done],
                                     [refined[q][0][4] for q in done])))
    evs = []
    for q, (b, e, u) in enumerate(zip(todo, eps, arg)):
        surface, cut = refined[q]
        found = None
        if surface is not None:
            dirs, V, EV, R, faces = surface
            bounds = proved.get(q)
            if bounds is None:  # exact arithmetic needed: as the per-grasp route
                bounds = _support_bounds(V, EV, faces, R, _row_gens(exact, b))
            lo = _lower(float(e), bounds)
            found = None if lo is None else (lo, dirs)
        vals[b, 2], vals[b, 3], _, ev, limited[b] = _support_result(float(e), u, vals[b, 0], found, cut)
        evs.append(ev)
    return [EvidenceColumns.block(todo, evs)]


def _exact_once(exact):
    """``exact()`` called once and kept (the exact generators), or :class:`_NoExact` raised when
    there is no ``exact``."""
    cache = []

    def gens():
        if exact is None:
            raise _NoExact
        if not cache:
            cache.append(exact())
        return cache[0]

    return gens


def _support_row(W, E, owner, m, eps, u, l1_lo, deadline, gens):
    """Planar L-infinity bounds ``(lo, hi, direction, evidence, limited)`` by ``support``
    evidence (:func:`_planar_support`), or by the L1 evidence when that proves more."""
    found, limited = _planar_support(W, E, owner, m, eps, np.asarray(u, dtype=float), deadline, gens)
    return _support_result(eps, u, l1_lo, found, limited)


def _support_result(eps, u, l1_lo, found, limited):
    """The L-infinity bounds of :func:`_support_row` from what the ``support`` surface proved
    (``found``: ``(lo, directions)`` or None)."""
    direction = tuple(float(v) for v in u)
    if found is not None and found[0] >= l1_lo:
        lo, dirs = found
        points = tuple(np.asarray(dirs, dtype=float).ravel().tolist())  # the same floats, at once
        return lo, eps, direction, Evidence("support", direction, points=points), limited
    return min(l1_lo, eps), eps, direction, Evidence("l1", direction), limited


def _planar_support(W, E, owner, m, eps, u, deadline, gens):
    """Planar L-infinity lower bound by ``support`` evidence (:func:`_support_surface`, proved
    by :func:`_prove`). Returns ``((lo, directions) or None, limited)``, ``limited`` when the
    deadline stopped the refinement."""
    surface, limited = _support_surface(W, E, owner, m, eps, u, deadline)
    if surface is None:
        return None, limited
    dirs, V, EV, R, faces = surface
    lo = _lower(eps, _support_bounds(V, EV, faces, R, gens))
    return (None if lo is None else (lo, dirs)), limited


def _support_bounds(V, EV, faces, R, gens):
    """:func:`_prove` of a ``support`` surface: vertices ``V`` (error bounds ``EV``), their
    generator choices ``R`` (the exact vertices, from ``gens()``, where needed) and hull faces."""

    def vertex(i):
        C = gens()
        return [sum((C[r, j] for j in R[i] if j >= 0), 0) for r in range(3)]

    return _prove(V, EV, faces, vertex)


def _row_gens(exact, b: int):
    """:func:`_exact_once` of row ``b``'s exact generators (``exact(b)``; none without ``exact``)."""
    return _exact_once(None if exact is None else (lambda: exact(b)))


def _support_surface(W, E, owner, m, eps, u, deadline):
    """The vertices of ``support`` evidence: the hull of support points along the coordinate
    directions and ``u``, refined along the normals of its faces nearest the origin (each cut
    adds a vertex of the GWS beyond the face) until the hull reaches ``eps`` or
    :data:`_PLANAR_DIRECTIONS` directions are used, or the ``deadline`` passes (looked at every
    :data:`_ROUNDS` rounds). Returns ``((directions, vertices, their error bounds, generator
    choices, the faces of their hull as surface_faces gives them) or None when the points span
    no hull, limited)``.

    The refinement is compiled (:func:`~qualgrasp.certify._kernels.evidence.support_refine`);
    where its hull declines the vertices (points near a plane), it goes on here with qhull's
    faces (:func:`_refine_here`)."""
    W = np.ascontiguousarray(W, dtype=float)
    E = np.ascontiguousarray(E, dtype=float)
    owner = np.ascontiguousarray(owner, dtype=np.int64)
    u = np.ascontiguousarray(u, dtype=float)
    cap = max(7, _PLANAR_DIRECTIONS + 2 * _ADD)
    dirs, picks = np.empty((cap, 3)), np.empty((cap, m), dtype=np.int64)
    cut = eps * (1 - EPS_TOL / 16)
    # a deadline already passed stops it after the first hull, as a look every round would
    rounds = _PLANAR_DIRECTIONS if deadline is None else 0 if _expired(deadline) else _ROUNDS
    n, limited = 0, False
    while True:
        n, state, faces, V, EV = support_refine(W, E, owner, m, u, cut, _PLANAR_DIRECTIONS, _ADD, dirs, picks, n,
                                                rounds)
        if state == NOT_HERE:
            return _refine_here(W, E, owner, m, cut, list(dirs[:n]), list(picks[:n]), deadline)
        if state == REFINED:
            break
        if _expired(deadline):
            limited = True
            break
        rounds = _ROUNDS
    return (dirs[:n].copy(), V, EV, picks[:n].copy(), faces), limited


def _refine_here(W, E, owner, m, cut, dirs, picks, deadline):
    """:func:`_support_surface` going on from the directions ``dirs`` and their choices
    ``picks`` (lists), with the hulls of :func:`~qualgrasp.certify.quality.gws.surface_faces`
    (qhull's where the compiled hull declines)."""
    seen = {r.tobytes() for r in picks}  # the choices (int64): equal rows, equal bytes

    def fresh(rows):
        out = []
        for v, r in zip(rows, planar_support_choices(W, owner, m, np.array(rows))):
            key = r.tobytes()
            if key not in seen:
                seen.add(key)
                out.append(v)
                picks.append(r)
        return out

    limited = False
    while True:
        pts = sum_rows(W, E, np.array(picks))[0]
        faces = surface_faces(pts)
        if faces is None:
            return None, limited
        normal, dist = face_planes(pts, faces)
        if dist.min() >= cut or len(dirs) >= _PLANAR_DIRECTIONS:
            break
        if _expired(deadline):
            limited = True
            break
        new = fresh(list(normal[np.argsort(dist, kind="stable")[:2 * _ADD]]))
        if not new:
            break
        dirs += new
    R = np.array(picks)
    return (np.array(dirs),) + sum_rows(W, E, R) + (R, faces), limited


def _sweep(W, owner, m, deadline):
    """Planar L-infinity epsilon by :func:`~qualgrasp.certify._kernels.epsilon.linf_sweep`, a
    batch of circles at a time; ``(value, direction, limited)``."""
    E = planar_edges(W, owner)
    top_val = np.full(_TOP, np.inf)
    top_u = np.zeros((_TOP, 3))
    n, a, limited = len(E), 0, False
    while a < n:
        b = min(n, a + _SWEEP_BATCH)
        linf_sweep(W, owner, m, E, a, b, top_val, top_u)
        a = b
        if a < n and _expired(deadline):
            limited = True
            break
    U = top_u[np.isfinite(top_val)]
    if not len(U):  # stopped before any candidate: the coordinate directions bound it
        U = np.vstack([np.eye(3), -np.eye(3)])
    h = support_rows(W, owner, m, np.ascontiguousarray(U), True)
    j = int(np.argmin(h))
    return float(h[j]), U[j], limited


def planar_epsilon(grasp: Grasp, norm: str) -> tuple[float, np.ndarray]:
    """Exact planar epsilon and its direction, for a grasp in force closure (the value
    :func:`epsilon` reports as ``hi``)."""
    check_norm(norm)
    W, E, owner = planar_generator_arrays(grasp)
    lo, hi, u, ev, limited = planar_epsilons(W, E, owner, len(grasp.contacts),
                                             exact=lambda: grasp_system(grasp, exact=True).columns)[norm]
    return hi, np.array(u)


# --- entry points --------------------------------------------------------------------------------

def epsilon(grasp: Grasp, norm: Norm = "L1", *, rel_gap: float = 0.01, budget: int = 200_000,
            time_limit: float | None = None, verdict: Verdict | None = None) -> Epsilon:
    """Ferrari-Canny epsilon of ``grasp`` for the ``norm`` GWS (module docstring).

    Parameters
    ----------
    grasp : Grasp
    norm : {'L1', 'Linf'}
    rel_gap : float
        Spatial grasps: stop when ``hi - lo <= rel_gap * hi``.
    budget : int
        Spatial grasps: the most work spent, in directions examined (a local minimisation step,
        an SOCP, counts as :data:`SOCP_COST`); the gap reached is reported. A count, not a
        time, so that results are reproducible on any machine.
    time_limit : float, optional
        Seconds after which the computation stops with the bounds reached (``limited``),
        counted from the closure verdict, compiling kernels excluded.
    verdict : Verdict, optional
        The grasp's force-closure verdict, if already known.

    Returns
    -------
    Epsilon
        Bounds with the ``center`` and ``length`` used and their evidence; 0 unless the grasp is
        in force closure.

    Raises
    ------
    ArgumentError
        Unknown ``norm``; ``rel_gap`` not in ``[0, 1)``, ``budget`` below 1, ``time_limit``
        negative or not finite.
    TypeError
        ``grasp`` is not a :class:`~qualgrasp.certify.Grasp`.

    Examples
    --------
    Two antipodal point contacts on the unit circle with ``mu = 0.5`` (exact in the plane):

    >>> from qualgrasp.certify import Contact, Grasp
    >>> from qualgrasp.certify.quality.bounds import epsilon
    >>> g = Grasp((Contact((1, 0), (-1, 0), "point", 0.5), Contact((-1, 0), (1, 0), "point", 0.5)))
    >>> e = epsilon(g, "L1")
    >>> round(e.lo, 6), e.exact, e.center, e.length, e.evidence.kind
    (0.333333, True, (0.0, 0.0), 1.0, 'generators')
    """
    check_norm(norm)
    norms = ("L1",) if norm == "L1" else ("L1", "Linf")
    return epsilons(grasp, norms, rel_gap=rel_gap, budget=budget, time_limit=time_limit,
                    verdict=verdict)[norm]


def epsilons(grasp: Grasp, norms=NORMS, *, rel_gap: float = 0.01, budget: int = 200_000,
             time_limit: float | None = None, verdict: Verdict | None = None) -> dict[str, Epsilon]:
    """Epsilon of ``grasp`` for each of ``norms`` (:func:`epsilon`), sharing the work: the
    planar generators, and the L1 bounds that serve as the L-infinity lower bound. The
    ``time_limit`` (seconds) is for all norms together; its clock starts once the closure
    verdict is known and stops while kernels compile.

    Returns
    -------
    dict
        ``{norm: Epsilon}``.
    """
    require(grasp, Grasp, "grasp")
    for norm in norms:
        check_norm(norm)
    number_in(rel_gap, "rel_gap", 0, 1, high_open=True)
    count_in(budget, "budget", 1, what="direction")
    if time_limit is not None:
        number_in(time_limit, "time_limit", 0, math.inf, unit="seconds")
    verdict = verdict or force_closure(grasp)
    if verdict.status != "closure":
        return {norm: _zero(grasp, norm) for norm in norms}
    deadline = None if time_limit is None else time.perf_counter() + time_limit
    deadline = _after_compiling(deadline, grasp.dim)
    center, length = tuple(grasp.center), grasp.length
    out = {}
    if grasp.dim == 2:
        W, E, owner = planar_generator_arrays(grasp)
        exact = lambda: grasp_system(grasp, exact=True).columns  # noqa: E731
        for norm, (lo, hi, u, ev, limited) in planar_epsilons(W, E, owner, len(grasp.contacts),
                                                             deadline=deadline, exact=exact).items():
            if norm in norms:
                out[norm] = Epsilon(norm, lo, hi, u, center, length, lo == hi, 0, limited, ev)
        return out
    sup = ConicSupport(grasp)
    pieces = _Pieces(grasp_system(grasp, socp=True))
    l1 = None
    for norm in ("L1", "Linf"):
        if norm == "L1" or "Linf" in norms:
            out[norm] = _spatial(grasp, sup, pieces, norm, rel_gap, budget, deadline, l1)
            l1 = out["L1"]
    return {norm: out[norm] for norm in norms}


# --- spatial --------------------------------------------------------------------------------------

class _Pieces:
    """Each contact's support ``c_b(v) = p_b . v + kappa_b norm(T_b v)`` as stacked arrays, so
    that ``h_L1 = max_b max(0, c_b)`` and ``h_Linf = sum_b max(0, c_b)`` cost ``O(m)`` per
    direction."""

    def __init__(self, system: System) -> None:
        C = system.columns
        d = C.shape[0]
        rows = []
        self.p = np.zeros((len(system.blocks), d))
        self.kappa = np.zeros(len(system.blocks))
        for i, b in enumerate(system.blocks):
            cols = C[:, list(b.cols)].T  # functional rows: a = cols @ v
            if b.cone == "ray":
                self.p[i] = cols[0]
                rows.append(np.zeros((0, d)))
                continue
            n = np.asarray(b.n, dtype=float)
            rn = np.linalg.norm(n)
            n_hat = n / rn
            dim = len(n)
            self.p[i] = n_hat @ cols[:dim]
            T = cols[:dim] - np.outer(n_hat, self.p[i])
            if len(b.cols) > dim:  # moment columns, weighted as in qualgrasp.certify.core.cones.polar
                T = np.vstack([T, float(b.g) / rn * cols[dim:]])
            rows.append(T)
            self.kappa[i] = float(b.mu)
        r = max(1, max(len(t) for t in rows))
        self.T = np.zeros((len(rows), r, d))
        for i, t in enumerate(rows):
            self.T[i, : len(t)] = t
        self.rank = [int(np.count_nonzero(np.abs(t).sum(axis=1))) for t in self.T]
        self._programmes: dict = {}
        self._solvers: dict = {}

    def h(self, V: np.ndarray, norm: str) -> np.ndarray:
        """Support function at the rows of ``V`` (n, d)."""
        Tv = np.einsum("brd,nd->nbr", self.T, V)
        c = np.maximum(V @ self.p.T + self.kappa * np.linalg.norm(Tv, axis=2), 0.0)
        return c.max(axis=1) if norm == "L1" else c.sum(axis=1)

    def tangent_minimum(self, u0: np.ndarray, norm: str) -> np.ndarray | None:
        """Minimise ``h`` over the tangent plane ``u . u0 = 1`` (an SOCP, solved by clarabel;
        built sparse, so its size is linear in the number of contacts, and once per norm, later
        planes updating its one row); the unit minimiser, or
        None when clarabel fails. At a minimiser of ``h`` on the sphere the tangent-plane
        problem has the same solution, so iterating from ``u / norm(u)`` converges to it."""
        A, where, P, q, b, cones = self._tangent_programme(norm)
        solver = self._solvers.get(norm)
        if solver is None:
            A.data[where] = u0  # the plane's row, in place: clarabel copies A when it builds the solver
            solver = self._solvers[norm] = clarabel.DefaultSolver(P, q, A, b, cones, settings())
        else:  # the same structure: only the plane's row changes (no new symbolic factorisation)
            solver.update(A=(where, np.asarray(u0, dtype=float)))
        sol = solver.solve()
        if str(sol.status) not in ("Solved", "AlmostSolved"):
            return None
        d = len(u0)
        u = np.asarray(sol.x)[:d]
        norm_u = np.linalg.norm(u)
        return u / norm_u if norm_u > 0 else None

    def _tangent_programme(self, norm: str):
        """The tangent-plane SOCP of ``norm`` with the plane's row left to fill (built once per
        norm: its building cost several times clarabel's solve): ``(A, positions of that row's
        entries in A.data, P, q, b, cones)``."""
        if norm in self._programmes:
            return self._programmes[norm]
        nb, r, d = self.T.shape
        nt = 1 if norm == "L1" else nb
        n = d + nt
        ri, ci, vals = [np.zeros(d, int)], [np.arange(d)], [np.ones(d)]  # the plane's row, filled per call
        ri.append(1 + np.arange(nt)), ci.append(d + np.arange(nt)), vals.append(-np.ones(nt))
        cones = [clarabel.ZeroConeT(1), clarabel.NonnegativeConeT(nt)]
        row = 1 + nt
        for i in range(nb):
            rk = self.rank[i]
            ri.append(np.full(d, row)), ci.append(np.arange(d)), vals.append(self.p[i])
            ri.append(np.array([row])), ci.append(np.array([d + (0 if norm == "L1" else i)]))
            vals.append(np.array([-1.0]))
            if rk:
                ri.append(np.repeat(row + 1 + np.arange(rk), d)), ci.append(np.tile(np.arange(d), rk))
                vals.append((-self.kappa[i] * self.T[i, :rk]).ravel())
            cones.append(clarabel.SecondOrderConeT(1 + rk) if rk else clarabel.NonnegativeConeT(1))
            row += 1 + rk
        A = sp.csc_matrix((np.concatenate(vals), (np.concatenate(ri), np.concatenate(ci))), shape=(row, n))
        A.sort_indices()  # row 0 first in each column: where the plane's entries are
        where = A.indptr[:d]
        assert np.all(A.indices[where] == 0)
        b = np.zeros(row)
        b[0] = 1.0
        q = np.r_[np.zeros(d), np.ones(nt)]
        self._programmes[norm] = (A, where, sp.csc_matrix((n, n)), q, b, cones)
        return self._programmes[norm]

    def local_minimum(self, u: np.ndarray, norm: str, iters: int = 8):
        """Refine ``u`` towards a local minimiser of ``h`` on the sphere; return ``(u, h(u),
        SOCPs solved)``. Stops once a step gains less than :data:`_STEP_GAIN` of ``h`` (the
        iteration converges linearly, and ``hi`` matters to within the gap, 1 %, not to 1e-12)."""
        h_u = float(self.h(u[None], norm)[0])
        steps = 0
        for _ in range(iters):
            v = self.tangent_minimum(u, norm)
            steps += 1
            if v is None:
                break
            h_v = float(self.h(v[None], norm)[0])
            moved = np.linalg.norm(v - u)
            if h_v < h_u:
                u, h_u, gain = v, h_v, h_u - h_v
            else:
                gain = 0.0
            if gain <= _STEP_GAIN * h_u or moved < 1e-10:
                break
        return u, h_u, steps


class _Guide:
    """The hull of the spatial refinement's points, kept from round to round: the compiled
    incremental hull grown by :func:`~qualgrasp.certify._kernels.hull.hull_grow`, each round
    inserting only its new points, by a rule that depends on the points alone, so that the
    checker's hull of the final points (:func:`~qualgrasp.certify.quality.gws.surface_faces`)
    has the same facets; qhull where no hull grows (not qhull's own incremental mode, whose
    precision errors end the process: scipy issue 4974, exit code 7, no exception)."""

    def __init__(self) -> None:
        self.state = None

    def _grow(self, V: np.ndarray) -> np.ndarray:
        V = np.ascontiguousarray(V, dtype=float)
        if self.state is None:
            self.state = grow_start(V.shape[1])
        if len(V) > self.state[6]:
            self.state = hull_grow(V, *self.state)
        return V

    def weakest(self, V: np.ndarray):
        """The unit outward normal (d,) and offset of the facet of the hull of ``V`` (the points
        of the last call and new ones after them) nearest the origin, or None when ``V`` spans no
        hull."""
        V = self._grow(V)
        verts, normal, off, alive, F, centre, done = self.state
        if F:
            return weakest_plane(normal, off, alive, F)
        try:
            eq = ConvexHull(V).equations
        except (QhullError, ValueError):
            return None
        f = int(np.argmin(-eq[:, -1]))
        return np.ascontiguousarray(eq[f, :-1]), float(-eq[f, -1])

    def faces(self, V: np.ndarray) -> tuple[np.ndarray | None, bool]:
        """The faces of the hull of ``V`` (the points of the last call and new ones after them), as
        :func:`~qualgrasp.certify.quality.gws.surface_faces` gives them, from the hull kept, and
        whether they were found to close up (:func:`~qualgrasp.certify.quality.gws.oriented_surface`)."""
        V = self._grow(V)
        verts, normal, off, alive, F, centre, done = self.state
        return oriented_surface(V, live_facets(verts, alive, F))


def _initial_directions(d: int) -> np.ndarray:
    rng = np.random.default_rng(0)  # fixed: results are reproducible
    R = rng.normal(size=(16 * d, d))
    return np.vstack([np.eye(d), -np.eye(d), R / np.linalg.norm(R, axis=1, keepdims=True)])


def _spatial(grasp, sup: ConicSupport, pieces: _Pieces, norm, rel_gap, budget, deadline,
             l1: Epsilon | None) -> Epsilon:
    """Spatial epsilon by the inner polytope and outer directions (module docstring)."""
    d = sup.C.shape[0]
    U = _initial_directions(d)
    h = pieces.h(U, norm)
    work = len(U)
    u_best, hi = U[int(np.argmin(h))], float(h.min())
    limited = _expired(deadline)  # then hi is not even refined locally
    if not limited:
        u_best, hi, steps = pieces.local_minimum(u_best, norm)
        work += SOCP_COST * steps
    V, EV, dirs, refs, parts = [], [], [], [], []
    owner = np.zeros(sup.C.shape[1], dtype=np.int64)
    for b, blk in enumerate(sup.blocks):
        owner[list(blk.cols)] = b

    def add(v):
        out = sup.vertex(v, norm, len(V))
        if out is not None:
            w, err, x = out
            V.append(w)
            EV.append(err)
            dirs.append(np.asarray(v, dtype=float))
            refs.append(int(owner[np.flatnonzero(x)[0]]) if x.any() else 0)
            parts.append(x)

    for v in np.vstack([np.eye(d), -np.eye(d), u_best[None]]):
        add(v)
    spare = iter(U[2 * d:])  # more starting directions while the hull is flat
    looked = 0  # the number of points when the points' hyperplane was last looked off
    rounds, hull, done, guide = 0, None, 0, _Guide()
    while not limited:
        rounds += 1
        if len(V) > d and (hull is None or len(V) > done):
            hull = guide.weakest(np.array(V))  # None: a flat or degenerate set, more directions first
            done = len(V)
        if hull is not None:
            weakest, dist = hull  # the unit outward normal and offset nearest the origin: a guide, not a proof
            if hi - dist <= rel_gap * hi:
                break
        if _expired(deadline):
            limited = True
            break
        if len(V) >= MAX_VERTICES or work >= budget:
            break
        if hull is None:
            flat = _off_span(np.array(V)) if len(V) > max(d, looked) else None
            if flat is not None:
                # the points lie in a hyperplane: the GWS extends beyond it on one side or both
                looked = len(V)
                add(flat)
                add(-flat)
                work += 2
                continue
            v = next(spare, None)
            if v is None:
                break
            add(v)
            work += 1
            continue
        hv = float(pieces.h(weakest[None], norm)[0])
        work += 1
        if hv < hi:
            u, h_u, steps = pieces.local_minimum(weakest, norm)
            work += SOCP_COST * steps
            if h_u < hi:
                u_best, hi = u, h_u
                add(u_best)
        before = len(V)
        add(weakest)
        if len(V) == before and hv >= hi:
            break  # nothing new to add: the polytope is as good as this direction makes it
    faces, closed = guide.faces(np.array(V)) if len(V) > d else (None, False)
    direction = tuple(float(v) for v in u_best)
    lo, ev = 0.0, Evidence("none", direction)
    bounds = _prove(np.array(V), np.array(EV), faces, lambda i: sup.exact_vertex(parts[i]), closed)
    if bounds is not None:
        lo = min(stated_lo(*bounds), hi)
        ev = Evidence("support", direction, ref=tuple(refs) if norm == "L1" else (),
                      points=tuple(float(v) for v in np.ravel(dirs)))
    if norm == "Linf" and l1 is not None and l1.lo > lo:
        lo, ev = l1.lo, Evidence("l1", direction)
    return Epsilon(norm, lo, hi, direction, tuple(grasp.center), grasp.length, lo == hi, rounds,
                   limited, ev)


def _off_span(V: np.ndarray) -> np.ndarray | None:
    """The unit normal of the hyperplane holding the points ``V`` (n, d), when they lie in one
    (to within ``1e-9`` of their spread); None when they span the space."""
    _, s, vt = np.linalg.svd(V - V.mean(axis=0))
    if len(s) < V.shape[1] or s[-1] <= 1e-9 * s[0]:
        return vt[-1]
    return None


def epsilon_of_points(points) -> float:
    """Radius of the largest origin-centred ball inside ``conv(points)`` (qhull); 0 if the origin
    is not interior or the hull is flat."""
    pts = np.asarray(points, dtype=float)
    try:
        eq = ConvexHull(pts).equations
    except (QhullError, ValueError):
        return 0.0
    return max(0.0, float((-eq[:, -1]).min()))

"""Evidence for the Ferrari-Canny epsilon bounds of a results row, and its re-check without a
solver.

Every epsilon bound a results row states (:mod:`qualgrasp.certify.quality.bounds`) carries evidence that
:func:`verify_epsilon` re-checks in exact rational arithmetic on the float data (or with rigorous
floating-point error bounds, :mod:`qualgrasp.certify._kernels.surface`):

Upper bound ``hi``
    A direction ``u`` (``direction``): ``epsilon <= h(u) / |u|`` for the support function ``h``
    of the grasp wrench space (GWS, :mod:`qualgrasp.certify.quality.bounds`). In the plane ``h(u)`` is
    rational (a maximum or a sum of maxima of dot products with the generators), so ``h(u)^2``
    and ``hi^2 |u|^2`` are compared exactly; in space every contact's term
    ``(a . n + mu sqrt(q)) / |n|`` is bounded by integer square roots to 60 bits.
Lower bound ``lo``
    An inscribed polytope given by its vertices, points of the GWS, and a closed triangulated
    surface on them (``faces``: index tuples, ``d`` per face). It proves that the ball ``B(0,
    lo)`` lies inside the GWS when (i) every ridge (a face without one of its vertices) appears in
    exactly two faces with opposite orientations (a closed oriented cycle), (ii) every face is
    positively oriented about the origin (``det(v_1, ..., v_d) > 0``) and (iii) every face's
    hyperplane is at distance at least ``lo`` from the origin (``lo^2 |n|^2 <= det^2``, ``n`` the
    generalised cross product of ``v_2 - v_1, ..., v_d - v_1``, for which ``n . v_1 = det``).
    Then the radial projection of the surface onto the sphere has degree at least 1, so every
    ray from the origin meets some face at a point of ``conv(vertices)``, inside the GWS, at
    distance at least ``lo``. The checks are exact (integer arithmetic after scaling each
    coordinate to integers).

Vertices, by the evidence ``kind``:

``generators`` (planar L1)
    The generator wrenches themselves; ``faces`` index them.
``sums`` (planar L-infinity)
    ``ref`` holds ``m`` entries per vertex: for contact ``i`` the index of one of its generators,
    or -1 for the origin; the vertex is their sum, a point of the Minkowski sum.
``support`` (planar L-infinity)
    ``points`` holds one direction ``v`` (3 floats) per vertex; the vertex is the support point
    of the GWS along ``v``: for each contact its generator with the largest ``v . g`` (the first
    such, by :func:`~qualgrasp.certify.quality.gws.planar_support_choice`), or the origin when none is positive, summed.
    The faces are not stored: the checker triangulates the vertices
    (:func:`~qualgrasp.certify.quality.gws.surface_faces`) and then checks that triangulation (see below).
``support`` (spatial)
    ``points`` holds one direction ``v`` (6 floats) per vertex; the vertex is the support point
    of the GWS along ``v`` computed by :meth:`~qualgrasp.certify.quality.gws.ConicSupport.vertices` (compiled, a
    fixed sequence of float operations that uses no BLAS, so that it gives the same bits on every
    machine), the contact forces (and
    moments) that maximise ``v . w`` with unit normal force, pulled inside the cone by the
    factor :data:`~qualgrasp.certify.quality.gws.SHRINK` and proved inside it exactly, then scaled towards the origin by the
    factor :func:`~qualgrasp.certify.quality.gws.vertex_scale` of the vertex's position (in ``[1 - 2^-14, 1]``: the GWS is
    star-shaped about the origin, so the point stays inside; the scaling puts the vertices in
    general position, for the support points of one contact all lie in one affine flat). For L1
    ``ref`` names the one contact of each vertex; for L-infinity every contact whose term is
    positive along ``v`` is summed.
    The faces are not stored (a 6-D hull has many more faces than vertices): the checker
    triangulates the vertices (:func:`~qualgrasp.certify.quality.gws.surface_faces`: a compiled hull, qhull
    where that declines) and then checks that triangulation exactly, so a
    wrong triangulation can only make the check fail, never pass.
``l1`` (L-infinity)
    The L1 GWS lies inside the L-infinity one, so the L1 evidence proves the L1 ``lo`` for
    L-infinity too (used when the L-infinity surface would be too large).
``none``
    No surface: ``lo`` must be 0.

The stated bounds must equal what the evidence proves to within the relative tolerance
:data:`EPS_TOL`: ``|hi - h(u)/|u|| <= EPS_TOL h(u)/|u|`` and ``|lo - D| <= EPS_TOL D``, ``D`` the
smallest face distance. Tampering with either (or with the evidence) beyond that is caught.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction
from typing import Any, Sequence

import numpy as np

from .._kernels.surface import cycle_code, face_bounds, face_bounds_laplace, leibniz_tables, planar_h_bounds
from ..core.certificates import Check
from ..core.grasp import Grasp
from ..core.problem import grasp_system
from ..core.wrench import planar_generator_arrays
from .gws import ConicSupport, planar_support_vertices, sum_rows, surface_faces

__all__ = ["EPS_TOL", "KINDS", "Evidence", "EvidenceColumns", "cycle_check", "exact_face", "surface_minimum",
           "stated_lo",
           "planar_vertex_arrays", "spatial_vertex_arrays", "verify_bounds", "check_hi", "verify_epsilon",
           "EPS_COLUMNS"]

#: Relative tolerance between a stated epsilon bound and the value its evidence proves.
EPS_TOL = 1e-9
#: Evidence kinds (module docstring).
KINDS = ("generators", "sums", "support", "l1", "none")
#: The epsilon columns of a results row, in order.
EPS_COLUMNS = ("eps_l1_lo", "eps_l1_hi", "eps_linf_lo", "eps_linf_hi")


@dataclass(frozen=True)
class Evidence:
    """Evidence for one norm's epsilon bounds (module docstring).

    Attributes
    ----------
    kind : str
        One of :data:`KINDS`: what the vertices are.
    direction : tuple of float or None
        The direction ``u`` proving ``hi`` (None when there is none, ``hi = 0``).
    ref : tuple of int
        ``sums``: ``m`` generator indices (or -1) per vertex; ``support`` L1: the contact of each
        vertex.
    points : tuple of float
        ``support``: the direction of each vertex, flattened (6 per vertex).
    faces : tuple of int
        ``generators`` and ``sums``: the faces, 3 vertex indices each, flattened.
    """

    kind: str
    direction: tuple[float, ...] | None
    ref: tuple[int, ...] = ()
    points: tuple[float, ...] = ()
    faces: tuple[int, ...] = ()

    def to_json(self) -> dict[str, Any]:
        """The evidence as a JSON-ready dict (every field present)."""
        return {"kind": self.kind, "direction": None if self.direction is None else list(self.direction),
                "ref": list(self.ref), "points": list(self.points), "faces": list(self.faces)}

    @classmethod
    def from_json(cls, d: Any) -> "Evidence":
        """Read evidence back; raises ValueError (naming the field) when malformed."""
        if not isinstance(d, dict):
            raise ValueError("evidence must be an object")
        kind = d.get("kind")
        if not isinstance(kind, str) or kind not in KINDS:
            raise ValueError(f"evidence kind must be one of {', '.join(KINDS)}")

        def numbers(key, integer):
            v = d.get(key)
            if v is None:
                return None
            if not isinstance(v, (list, tuple)):
                raise ValueError(f"evidence {key} must be a list")
            if _plain_numbers(v, integer):  # the usual list: the loop's values, without its checks one by one
                return tuple(v)
            out = []
            for x in v:
                if isinstance(x, bool) or not isinstance(x, (int, float)):
                    raise ValueError(f"evidence {key} must hold numbers")
                if integer:
                    if not isinstance(x, int) and not (isinstance(x, float) and x.is_integer()):
                        raise ValueError(f"evidence {key} must hold integers")
                    if abs(x) > 2**31:
                        raise ValueError(f"evidence {key} holds an integer out of range")
                    out.append(int(x))
                else:
                    if not math.isfinite(float(x)):
                        raise ValueError(f"evidence {key} holds a non-finite number")
                    out.append(float(x))
            return tuple(out)

        direction = numbers("direction", False)
        return cls(kind, direction, numbers("ref", True) or (), numbers("points", False) or (),
                   numbers("faces", True) or ())


def _plain_numbers(v: Sequence, integer: bool) -> bool:
    """Whether every item of ``v`` is a plain ``int`` within 2^31 (``integer``) or a finite plain
    ``float``: items :meth:`Evidence.from_json` keeps as they are."""
    if integer:
        return all(type(x) is int for x in v) and (not v or (-(2**31) <= min(v) and max(v) <= 2**31))
    return all(type(x) is float for x in v) and all(map(math.isfinite, v))


#: The list fields of :class:`Evidence` and the dtype each is held in by :class:`EvidenceColumns`.
LIST_FIELDS = (("ref", np.int64), ("points", np.float64), ("faces", np.int64))


def _positions(starts: np.ndarray, lengths: np.ndarray) -> np.ndarray:
    """Where the items of segments of ``lengths``, held one after another, go when segment ``i``
    starts at ``starts[i]``."""
    before = np.cumsum(lengths) - lengths
    return np.repeat(starts - before, lengths) + np.arange(int(lengths.sum()))


def _scatter(blocks, name: str, start: np.ndarray, dtype) -> np.ndarray:
    """The items of list ``name`` of every block, each row's at ``start[row]``."""
    full = [b for b in blocks if name in b[3] and len(b[3][name][1])]
    rows = full[0][0] if len(full) == 1 else None
    if (rows is not None and len(full[0][3][name][1]) == start[-1] and rows[0] >= 0
            and np.all(np.diff(rows) > 0)):
        # one block in row order holds every item: they are already where they go (the column
        # is then the block's array itself, not a copy)
        return np.ascontiguousarray(full[0][3][name][1], dtype=dtype)
    values = np.empty(int(start[-1]), dtype=dtype)
    for rows, _, _, lists in full:
        values[_positions(start[rows], lists[name][0])] = lists[name][1]
    return values


@dataclass(frozen=True, eq=False)
class EvidenceColumns:
    """The :class:`Evidence` of one norm for ``B`` rows, held flat (as a results column holds
    it) instead of as ``B`` objects: row ``b`` has the kind ``kind[b]`` (None: no evidence), the
    direction ``direction[b]`` (NaN: none) and the ``ref`` items
    ``ref[ref_start[b]:ref_start[b + 1]]``, and likewise ``points`` and ``faces``.

    Examples
    --------
    >>> a = Evidence("sums", (1.0, 0.0, 0.0), ref=(0, -1), faces=(0, 1, 2))
    >>> cols = EvidenceColumns.assemble(3, [EvidenceColumns.block([2, 0], [a, Evidence("l1", (0.0, 1.0, 0.0))])])
    >>> cols.row(2) == a, cols.row(1), cols.row(0).kind
    (True, None, 'l1')
    """

    kind: np.ndarray
    direction: np.ndarray
    ref: np.ndarray
    ref_start: np.ndarray
    points: np.ndarray
    points_start: np.ndarray
    faces: np.ndarray
    faces_start: np.ndarray

    def row(self, b: int) -> Evidence | None:
        """The evidence of row ``b`` as an :class:`Evidence` (None where there is none)."""
        if self.kind[b] is None:
            return None
        d = self.direction[b]
        lists = [tuple(getattr(self, name)[getattr(self, name + "_start")[b]:getattr(self, name + "_start")[b + 1]]
                       .tolist()) for name, _ in LIST_FIELDS]
        return Evidence(self.kind[b], None if np.isnan(d).any() else tuple(d.tolist()), *lists)

    @staticmethod
    def block(rows, evidences: Sequence[Evidence], width: int = 3) -> tuple:
        """A block of :meth:`assemble` from :class:`Evidence` objects, one per row of ``rows``."""
        lists = {}
        for name, dtype in LIST_FIELDS:
            parts = [getattr(e, name) for e in evidences]
            lists[name] = (np.array([len(p) for p in parts], dtype=np.int64),
                           np.array([x for p in parts for x in p], dtype=dtype))
        direction = np.array([(np.nan,) * width if e.direction is None else e.direction for e in evidences],
                             dtype=float).reshape(-1, width)
        return np.asarray(rows, dtype=np.int64), [e.kind for e in evidences], direction, lists

    @classmethod
    def assemble(cls, B: int, blocks, width: int = 3) -> "EvidenceColumns":
        """The columns of ``B`` rows from blocks ``(rows, kind, direction, lists)``: rows (r,),
        their kinds (a string or r of them), directions (r, width) and, for some of ``ref``,
        ``points`` and ``faces``, ``(lengths (r,), items of the rows one after another)``. Each
        row is in at most one block; rows in none have no evidence."""
        kind = np.full(B, None, dtype=object)
        direction = np.full((B, width), np.nan)
        lengths = {name: np.zeros(B, dtype=np.int64) for name, _ in LIST_FIELDS}
        for rows, k, d, lists in blocks:
            kind[rows] = k
            direction[rows] = d
            for name, (n, _) in lists.items():
                lengths[name][rows] = n
        out = {}
        for name, dtype in LIST_FIELDS:
            start = np.zeros(B + 1, dtype=np.int64)
            np.cumsum(lengths[name], out=start[1:])
            out[name], out[name + "_start"] = _scatter(blocks, name, start, dtype), start
        return cls(kind, direction, **out)


# --- surfaces ------------------------------------------------------------------------------------

_CYCLE_REASONS = {
    1: "a face index is out of range",
    2: "a face repeats a vertex",
    3: "the faces do not close up (a ridge is not shared by exactly two faces)",
    4: "two faces sharing a ridge are not oppositely oriented",
}


def cycle_check(faces: np.ndarray, nv: int) -> str | None:
    """None when ``faces`` (F, d) form a closed oriented cycle on ``nv`` vertices: indices in
    range and distinct within a face, every ridge in exactly two faces with opposite
    orientations; else the reason."""
    faces = np.asarray(faces, dtype=np.int64)
    if faces.ndim != 2 or len(faces) == 0 or faces.shape[1] < 2:
        return "no faces"
    d = faces.shape[1]
    if nv <= 0 or (d - 1) * math.log2(max(nv, 2)) >= 62:
        return "too many vertices"
    code = cycle_code(np.ascontiguousarray(faces), int(nv))
    return _CYCLE_REASONS.get(int(code))


def _bareiss(M: list[list[int]]) -> int:
    """Exact determinant of a square integer matrix (fraction-free elimination)."""
    n = len(M)
    if n == 0:
        return 1
    A = [row[:] for row in M]
    sign, prev = 1, 1
    for k in range(n - 1):
        if A[k][k] == 0:
            p = next((i for i in range(k + 1, n) if A[i][k] != 0), None)
            if p is None:
                return 0
            A[k], A[p] = A[p], A[k]
            sign = -sign
        akk = A[k][k]
        for i in range(k + 1, n):
            aik = A[i][k]
            row_i, row_k = A[i], A[k]
            for j in range(k + 1, n):
                row_i[j] = (row_i[j] * akk - aik * row_k[j]) // prev
        prev = akk
    return sign * A[n - 1][n - 1]


def exact_face(vertices: Sequence[Sequence[Fraction]]) -> Fraction | None:
    """Squared distance from the origin of the hyperplane of one face (``d`` exact vertices),
    ``det^2 / |n|^2``, or None when the face is not positively oriented (``det <= 0``). Exact:
    each coordinate is scaled to integers (``x_r = y_r / s_r``), so that ``n_r = n'_r s_r /
    prod(s)``, ``det = det' / prod(s)`` and the distance is ``det'^2 / sum (n'_r s_r)^2``."""
    d = len(vertices[0])
    s = []
    for r in range(d):
        den = 1
        for v in vertices:
            den = math.lcm(den, Fraction(v[r]).denominator)
        s.append(den)
    Y = [[int(Fraction(v[r]) * s[r]) for r in range(d)] for v in vertices]
    y0 = Y[0]
    D = [[y[r] - y0[r] for r in range(d)] for y in Y[1:]]
    n = [(-1) ** r * _bareiss([[row[c] for c in range(d) if c != r] for row in D]) for r in range(d)]
    det = sum(a * b for a, b in zip(n, y0))
    if det <= 0:
        return None
    return Fraction(det * det, sum((a * b) ** 2 for a, b in zip(n, s)))


def surface_minimum(V: np.ndarray, EV: np.ndarray, faces: np.ndarray, exact_vertex, *,
                    tight: float = EPS_TOL / 8, closed: bool = False) -> tuple[str | None, Fraction, Fraction]:
    """Check conditions (i) to (iii) of the module docstring for ``faces`` on the vertices whose
    float values ``V`` (nv, d) are within ``EV`` of the exact ones, and bound the smallest face
    distance ``D``: ``(reason or None, lo, hi)`` with ``lo <= D^2 <= hi``, ``hi <= (1 + tight)
    lo``. Rigorous float bounds (:func:`qualgrasp.certify._kernels.surface.face_bounds`, or
    :func:`~qualgrasp.certify._kernels.surface.face_bounds_laplace` beyond 3-D) decide
    every face they can; ``exact_vertex(i)`` (exact coordinates of vertex ``i``) is asked only
    for the faces they leave undecided, or too loosely bounded to tell the minimum. ``closed``:
    the faces are known to form a closed oriented cycle (the producer's faces oriented by
    :func:`~qualgrasp.certify.quality.gws.oriented_surface`, which checks the same conditions), so
    condition (i) is not checked again; the checker always checks it."""
    reason = None if closed else cycle_check(faces, len(V))
    if reason:
        return reason, Fraction(0), Fraction(0)
    d = V.shape[1]
    perms, signs = leibniz_tables(d - 1)
    checks = face_bounds if d <= 3 else face_bounds_laplace  # the same bounds; shared minors in 6-D
    ok, lo, hi = checks(np.ascontiguousarray(V, dtype=float), np.ascontiguousarray(EV, dtype=float),
                        np.ascontiguousarray(faces, dtype=np.int64), perms, signs)
    exact: dict[int, Fraction] = {}  # faces settled exactly: their squared distance
    cache: dict[int, Any] = {}

    def settle(f: int) -> bool:
        verts = [cache.setdefault(int(i), exact_vertex(int(i))) for i in faces[f]]
        d2 = exact_face(verts)
        if d2 is None:
            return False
        exact[f] = d2
        x = float(d2)  # float bounds of the exact value, for the float comparisons below
        lo[f], hi[f] = np.nextafter(x, 0.0), np.nextafter(x, np.inf)
        return True

    for f in np.flatnonzero(~ok):
        if not settle(int(f)):
            return "a face of the surface is not positively oriented about the origin", Fraction(0), Fraction(0)
    open_ = np.ones(len(faces), dtype=bool)
    open_[list(exact)] = False
    while True:
        loose = np.flatnonzero(open_ & (lo < hi.min()) & (hi > lo * (1 + tight)))
        if not len(loose):
            break
        for f in loose:
            settle(int(f))
            open_[f] = False
    lows, highs = list(exact.values()), list(exact.values())
    if open_.any():
        lows.append(Fraction(float(lo[open_].min())))
        highs.append(Fraction(float(hi[open_].min())))
    return None, min(lows), min(highs)



def stated_lo(d2_lo: Fraction, d2_hi: Fraction) -> float:
    """The lower bound to state for a surface whose smallest squared face distance lies in
    ``[d2_lo, d2_hi]``: their geometric mean's square root, as a float."""
    return math.sqrt(math.sqrt(float(d2_lo)) * math.sqrt(float(d2_hi))) if d2_lo > 0 else 0.0


def _within(stated: float, proved2: Fraction, what: str, proved2_hi: Fraction | None = None) -> str | None:
    """``stated`` within :data:`EPS_TOL` (relative) of the value whose square lies in
    ``[proved2, proved2_hi]``."""
    hi2 = proved2 if proved2_hi is None else proved2_hi
    x = Fraction(stated) ** 2
    tol = Fraction(EPS_TOL)
    if x < (1 - tol) ** 2 * hi2 or x > (1 + tol) ** 2 * proved2:
        return f"{what} {stated!r} differs from the {math.sqrt(float(proved2)):.17g} its evidence proves"
    return None


# --- planar vertices -----------------------------------------------------------------------------

def planar_vertex_arrays(W, E, owner: np.ndarray, m: int, ev: Evidence, blas: bool = False):
    """Float vertices, their error bounds and, per vertex, the generators it sums, of planar
    evidence (``generators``, ``sums`` or ``support``; ``blas``: ``support`` vertices chosen as
    builds before 2026-11-28 chose them, :func:`~qualgrasp.certify.quality.gws.planar_support_choices`);
    or a reason string."""
    k = W.shape[1]
    if ev.kind == "generators":
        if ev.ref:
            return "generators evidence has no ref"
        return W.T, E.T, [(j,) for j in range(k)]
    if ev.kind == "support":
        if ev.ref or ev.faces or not ev.points or len(ev.points) % 3 or len(ev.points) < 12:
            return "planar support evidence needs 3 numbers per direction (4 or more) and nothing else"
        V, EV, R = planar_support_vertices(W, E, owner, m, np.array(ev.points, dtype=float).reshape(-1, 3),
                                           blas=blas)
        return V, EV, [tuple(int(j) for j in r if j >= 0) for r in R]
    if not ev.ref or len(ev.ref) % m:
        return f"sums evidence needs {m} entries per vertex"
    R = np.array(ev.ref, dtype=np.int64).reshape(-1, m)
    if ((R < -1) | (R >= k)).any():
        return "sums evidence: an entry is not a generator"
    used = R >= 0
    if (owner[np.where(used, R, 0)][used] != np.nonzero(used)[1]).any():
        return "sums evidence: an entry is not a generator of its contact"
    V, EV = sum_rows(W, E, R)
    return V, EV, [tuple(int(j) for j in r if j >= 0) for r in R]


def _spatial_lower(sup: ConicSupport, ev: Evidence, norm: str, lo: float, key: str, col: str,
                   numpy_route: bool = False) -> str | None:
    """Why the spatial ``support`` evidence ``ev`` does not prove the stated ``lo`` (None: it
    does), its vertices built by the kernel or (``numpy_route``) by the formula of earlier builds."""
    built = spatial_vertex_arrays(sup, ev, norm, numpy_route)
    if isinstance(built, str):
        return f"eps_evidence.{key}: {built}"
    V, EV, parts = built
    faces = surface_faces(V)
    if faces is None:
        return f"eps_evidence.{key}: the vertices span no full-dimensional hull"
    return _surface_lower(V, EV, faces, lambda i: sup.exact_vertex(parts[i]), lo, key, col)


def _surface_lower(V, EV, faces, exact_vertex, lo: float, key: str, col: str) -> str | None:
    """Why the surface ``faces`` on the vertices ``V`` (within ``EV``) does not prove the stated
    ``lo`` (:func:`surface_minimum`, then :func:`_within`); None when it does."""
    reason, d2_lo, d2_hi = surface_minimum(V, EV, faces, exact_vertex)
    if reason:
        return f"eps_evidence.{key}: {reason}"
    return _within(lo, d2_lo, col, d2_hi)


# --- spatial vertices ---------------------------------------------------------------------------

def spatial_vertex_arrays(sup: ConicSupport, ev: Evidence, norm: str, numpy_route: bool = False):
    """Float vertices, error bounds and the column values of each vertex of ``support``
    evidence, or a reason string; ``numpy_route``: by
    :meth:`~qualgrasp.certify.quality.gws.ConicSupport.vertices_numpy` (evidence of earlier builds)."""
    d = sup.C.shape[0]
    if not ev.points or len(ev.points) % d:
        return f"points must hold {d} numbers per vertex"
    N = len(ev.points) // d
    if norm == "L1" and len(ev.ref) != N:
        return "L1 support evidence needs one contact per vertex"
    if norm == "Linf" and ev.ref:
        return "L-infinity support evidence has no ref"
    if N <= d:
        return "too few vertices"
    if (d - 1) * math.log2(N) >= 62:  # the hull's ridge keys would overflow: refused before building it
        return "too many vertices"
    P = np.array(ev.points, dtype=float).reshape(N, d)
    ref = None
    if norm == "L1":
        ref = np.array(ev.ref, dtype=np.int64)
        bad = np.flatnonzero((ref < 0) | (ref >= len(sup.blocks)))
        if len(bad):
            return f"vertex {bad[0]} names no contact"
    V, EV, X, ok = (sup.vertices_numpy if numpy_route else sup.vertices)(P, norm, np.arange(N), ref)
    if not ok.all():
        return f"vertex {np.flatnonzero(~ok)[0]}: a support force is not inside its cone"
    return V, EV, list(X)


def _planar_h2(Cx, owner: np.ndarray, m: int, u: Sequence[float], norm: str) -> Fraction | None:
    """``(h(u) / |u|)^2`` exactly for a planar grasp (None for a zero ``u``)."""
    ux = [Fraction(float(t)) for t in u]
    uu = sum(x * x for x in ux)
    if uu == 0:
        return None
    best = [Fraction(0)] * m
    for j in range(Cx.shape[1]):
        v = Cx[0, j] * ux[0] + Cx[1, j] * ux[1] + Cx[2, j] * ux[2]
        if v > best[owner[j]]:
            best[owner[j]] = v
    h = max(best) if norm == "L1" else sum(best)
    return h * h / uu


def _hi_message(col: str, stated: float, proved: float) -> str:
    return f"{col} {stated!r} differs from the {proved:.17g} its evidence proves"


def check_hi(stated: float, h_lo: float, h_hi: float, col: str, exact=None) -> str | None:
    """Is the stated ``hi`` within :data:`EPS_TOL` of ``H = h(u)/|u|``, given float bounds
    ``h_lo <= H <= h_hi``? ``exact()`` gives ``(H^2 lo, H^2 hi)`` exactly when the float
    bounds cannot tell; None when it is."""
    tol = EPS_TOL
    if h_hi < 0:
        return f"the direction proving {col} is zero"
    if stated >= (1 - tol) * h_hi * (1 + 1e-15) and stated <= (1 + tol) * h_lo * (1 - 1e-15):
        return None
    if stated < (1 - tol) * h_lo * (1 - 1e-15) or stated > (1 + tol) * h_hi * (1 + 1e-15):
        return _hi_message(col, stated, 0.5 * (h_lo + h_hi))
    if exact is None:
        return _hi_message(col, stated, 0.5 * (h_lo + h_hi))
    lo2, hi2 = exact()
    if hi2 < 0:
        return f"the direction proving {col} is zero"
    return _within(stated, lo2, col, hi2)


# --- the re-check of a row's epsilon claims ------------------------------------------------------

def _number(row: dict, key: str):
    v = row.get(key)
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        return None
    try:
        x = float(v)
    except OverflowError:
        return None
    return x if math.isfinite(x) else None


def verify_epsilon(grasp: Grasp, row: dict, closure: bool) -> Check:
    """Re-check the epsilon columns of a results ``row`` against ``grasp`` (module docstring).

    Without quality every epsilon column, ``eps_limited`` and ``eps_evidence`` are null. With
    quality: four finite numbers ``0 <= lo <= hi``, all 0 (and no evidence) when the grasp is not
    in force closure (``closure``), else bounds proved by the evidence within :data:`EPS_TOL`.
    A malformed row is a failed check naming the column, never an exception.
    """
    keys = EPS_COLUMNS + ("eps_limited", "eps_evidence")
    for key in keys:
        if key not in row:
            return Check(False, f"column {key} is missing")
    if all(row[k] is None for k in keys):
        return Check(True)
    for key in keys[:-1]:
        if row[key] is None:
            return Check(False, f"{key} is null although other epsilon columns are not")
    vals = {}
    for key in EPS_COLUMNS:
        x = _number(row, key)
        if x is None or x < 0:
            return Check(False, f"{key} must be a finite number >= 0, got {_short(row[key])}")
        vals[key] = x
    if not isinstance(row["eps_limited"], bool):
        return Check(False, f"eps_limited must be true or false, got {_short(row['eps_limited'])}")
    for key in ("l1", "linf"):
        if vals[f"eps_{key}_lo"] > vals[f"eps_{key}_hi"]:
            return Check(False, f"eps_{key}_lo exceeds eps_{key}_hi")
    if not closure:
        for key in EPS_COLUMNS:
            if vals[key] != 0:
                return Check(False, f"{key} must be 0 when the grasp is not in force closure")
        if row["eps_evidence"] is not None:
            return Check(False, "eps_evidence must be null when the grasp is not in force closure")
        if row["eps_limited"]:
            return Check(False, "eps_limited must be false when the grasp is not in force closure")
        return Check(True)
    evd = row["eps_evidence"]
    if not isinstance(evd, dict):
        return Check(False, "eps_evidence must be an object with l1 and linf")
    evs = {}
    for key in ("l1", "linf"):
        try:
            evs[key] = Evidence.from_json(evd.get(key))
        except ValueError as err:
            return Check(False, f"eps_evidence.{key}: {err}")
    try:
        return verify_bounds(grasp, vals, evs)
    except (ValueError, IndexError, TypeError, ZeroDivisionError, OverflowError, MemoryError) as err:
        return Check(False, f"eps_evidence: malformed ({type(err).__name__})")


def _short(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def verify_bounds(grasp: Grasp, vals: dict, evs: dict, arrays=None) -> Check:
    """Re-check stated epsilon bounds ``vals`` (by column name) of a grasp in closure against
    their evidence ``evs`` (``{"l1": Evidence, "linf": Evidence}``). ``arrays``: the planar
    ``(W, E, owner)`` if already computed."""
    planar = grasp.dim == 2
    d = 3 if planar else 6
    if planar:
        W, E, owner = arrays if arrays is not None else planar_generator_arrays(grasp)
        m = len(grasp.contacts)
        exact_cols = []

        def Cx():
            if not exact_cols:
                exact_cols.append(grasp_system(grasp, exact=True).columns)
            return exact_cols[0]
    else:
        sup = ConicSupport(grasp)
    for key, norm in (("l1", "L1"), ("linf", "Linf")):
        ev = evs[key]
        lo, hi = vals[f"eps_{key}_lo"], vals[f"eps_{key}_hi"]
        col = f"eps_{key}_hi"
        if ev.direction is None or len(ev.direction) != d:
            return Check(False, f"eps_evidence.{key}.direction must hold {d} numbers")
        u = np.array(ev.direction, dtype=float)
        if planar:
            h_lo, h_hi = planar_h_bounds(W, E, owner, m, u, norm == "Linf")

            def exact(norm=norm, u=u):
                h2 = _planar_h2(Cx(), owner, m, u, norm)
                return (Fraction(0), Fraction(-1)) if h2 is None else (h2, h2)

            bad = check_hi(hi, h_lo, h_hi, col, exact)
        else:
            b_lo, b_hi = sup.h_bounds(u, norm)
            bad = (f"the direction proving {col} is zero" if b_hi < 0
                   else check_hi(hi, float(b_lo) * (1 - 1e-15), float(b_hi) * (1 + 1e-15), col,
                                 lambda: (b_lo * b_lo, b_hi * b_hi)))
        if bad:
            return Check(False, bad)
        col = f"eps_{key}_lo"
        if ev.kind == "none":
            if lo != 0:
                return Check(False, f"{col} must be 0 without a surface (evidence kind none)")
            continue
        if ev.kind == "l1":
            if key != "linf":
                return Check(False, "eps_evidence.l1: kind l1 is for L-infinity only")
            if lo != vals["eps_l1_lo"]:
                return Check(False, f"{col} must equal eps_l1_lo (evidence kind l1)")
            continue
        if planar:
            if ev.kind not in ("generators", "sums", "support") or (ev.kind == "generators") != (norm == "L1"):
                return Check(False, f"eps_evidence.{key}: kind {ev.kind} does not fit a planar {norm} GWS")
            if ev.points and ev.kind != "support":
                return Check(False, f"eps_evidence.{key}.points must be empty for {ev.kind} evidence")
            bad = _planar_lower(W, E, owner, m, ev, Cx, lo, key, col)
            if bad and ev.kind == "support":  # perhaps evidence of an earlier build, its ties broken by BLAS
                bad = _planar_lower(W, E, owner, m, ev, Cx, lo, key, col, True) and bad
            if bad:
                return Check(False, bad)
            continue
        else:
            if ev.kind != "support":
                return Check(False, f"eps_evidence.{key}: kind {ev.kind} does not fit a spatial GWS")
            if ev.faces:
                return Check(False, f"eps_evidence.{key}.faces must be empty in space")
            bad = _spatial_lower(sup, ev, norm, lo, key, col)
            if bad:  # perhaps evidence of an earlier build, its vertices in numpy's rounding
                bad = _spatial_lower(sup, ev, norm, lo, key, col, True) and bad
            if bad:
                return Check(False, bad)
    return Check(True)


def _planar_lower(W, E, owner, m: int, ev: Evidence, Cx, lo: float, key: str, col: str,
                  blas: bool = False) -> str | None:
    """Why the planar evidence ``ev`` (``generators``, ``sums`` or ``support``; ``blas`` as
    :func:`planar_vertex_arrays`) does not prove the stated ``lo`` (None: it does); ``Cx()``
    gives the exact generators."""
    built = planar_vertex_arrays(W, E, owner, m, ev, blas)
    if isinstance(built, str):
        return f"eps_evidence.{key}: {built}"
    V, EV, parts = built

    def exact_vertex(i):
        C = Cx()
        return [sum((C[r, j] for j in parts[i]), Fraction(0)) for r in range(3)]

    if ev.kind == "support":
        faces = surface_faces(V)
        if faces is None:
            return f"eps_evidence.{key}: the vertices span no full-dimensional hull"
    else:
        if len(ev.faces) % 3 or not ev.faces:
            return f"eps_evidence.{key}.faces must hold 3 indices per face"
        faces = np.array(ev.faces, dtype=np.int64).reshape(-1, 3)
    return _surface_lower(V, EV, faces, exact_vertex, lo, key, col)

"""Exact decision for straight contact regions with constant normals (``normal_tol = 0``).

Notation: region ``i`` is the segment ``q_i(s) = a_i + s (b_i - a_i)``, ``0 <= s <= 1``, with
inward normal ``n_i`` and tangent ``t_i`` (``n_i`` turned +90 degrees). Every generator ``g`` of
the contact model (:func:`qualgrasp.certify.core.wrench.generator_layout`) is the force
``f_g = n_i + friction_g mu_i t_i`` applied at ``q_i(s) + offset_g width_i t_i``, so with
certify's torque scaling (``center`` c, ``length`` L) its wrench is
``w_g(s) = (f_g, tau0_g + s beta_g)``, ``tau0_g = ((a_i + offset_g width_i t_i - c) x f_g) / L``,
``beta_g = ((b_i - a_i) x f_g) / L``: affine in ``s``, and ``s`` multiplies only the torque.

**Not robust** iff some choice ``s`` and some ``y != 0`` have ``y . w_g(s) <= 0`` for every
generator (the choice's wrenches lie in a closed half-space; rank deficiency included). With
``z_i = s_i y_tau`` the conditions ``y_f . f_g + y_tau tau0_g + beta_g z_i <= 0`` are linear in
``x = (y_fx, y_fy, y_tau, z_1, ..., z_k)``, with ``0 <= z_i <= y_tau`` when ``y_tau >= 0`` and
``y_tau <= z_i <= 0`` when ``y_tau <= 0``. ``y`` is normalised onto the faces of the cube
``[-1, 1]^3``, split where the sign of ``y_tau`` is not fixed: 10 faces (:data:`FACES`), on each of
which every variable lies in a box (the face's coordinate fixed, ``y_tau`` in ``[0, 1]`` or
``[-1, 0]``, ``z_i`` in the same half) and the ``z`` rows ``z_i - y_tau <= 0`` (or ``y_tau - z_i
<= 0``) hold. On each face the max-slack LP::

    maximise sigma  subject to  G x + sigma <= 0 (one row per generator),  H x <= 0,  x in the box

has ``sigma* >= 0`` iff a non-closure choice has its separating direction on that face.

**Certificate of robustness.** Per face, multipliers ``lambda >= 0`` of the generator rows and
``mu >= 0`` of the ``z`` rows. With ``r = G' lambda + H' mu``, every feasible ``x`` with slack
``sigma`` has ``sigma sum(lambda) <= -lambda' G x <= -r . x`` (because ``mu' H x <= 0``), so when
``sum(lambda) > 0`` and ``min over the box of r . x > 0`` the face holds no separating
direction. :func:`check_faces` recomputes ``G`` and ``H`` from the region data in exact rationals
(every float is a dyadic rational ``m 2^e``: :class:`Dyadic`, no rounding), takes the
multipliers as given (a negative one is refused) and evaluates the box minimum
``sum_j min(r_j l_j, r_j u_j)`` exactly; no solver, no tolerance.

**Witness.** On a face with ``sigma* >= 0`` the LP's ``x`` gives ``y`` and ``s_i = z_i / y_tau``
(any ``s`` when ``y_tau = 0``). For a fixed ``y`` each contact's admissible ``s`` form an interval,
and when ``n_i`` is perpendicular to the segment every ``beta_g`` has the same sign, so that
interval contains an end of the segment: the witness takes the segment's end points whenever
they do as well as the LP's ``s``, so that its contacts lie exactly on the segments. The witness
grasp is certified by :func:`qualgrasp.certify.force_closure` and its Farkas certificate re-checked
by :func:`qualgrasp.certify.verify`.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from fractions import Fraction
from typing import Any, Sequence

import clarabel
import numpy as np
import scipy.sparse as sp

from .. import models as registry
from ..core.certificates import Check, verify
from ..core.closure import force_closure
from ..errors import SolverError
from ..core.grasp import Grasp
from .data import RegionTuple

__all__ = ["FACES", "FaceSolution", "Dyadic", "generator_rows", "scaled_rows", "face_box", "solve_faces", "check_faces",
           "check_faces_float", "faces_certificate", "point_on_segment", "on_segment", "straight_witness",
           "region_variant"]

#: The 10 faces: ``(axis, sign, tau_sign)``, axis 0 ``y_fx``, 1 ``y_fy``, 2 ``y_tau`` fixed at
#: ``sign``; ``tau_sign`` the sign of ``y_tau`` on the face.
FACES: tuple[tuple[int, int, int], ...] = (
    (2, 1, 1), (2, -1, -1),
    (0, 1, 1), (0, 1, -1), (0, -1, 1), (0, -1, -1),
    (1, 1, 1), (1, 1, -1), (1, -1, 1), (1, -1, -1),
)


def region_variant(region) -> int:
    """The model variant of a region's contacts (:meth:`ContactModel.variant`)."""
    model = registry.get(region.model)
    if not region.params:
        return 0
    return int(model.variant({name: np.array([v]) for name, v in region.params})[0])


def generator_rows(regions: RegionTuple):
    """Float rows ``G`` (one per generator, columns ``y_fx, y_fy, y_tau, z_1..z_k``) and the
    owner region of each row."""
    k = len(regions.regions)
    cx, cy = regions.center
    L = regions.length
    rows, owner = [], []
    for i, r in enumerate(regions.regions):
        for fx, fy, tau, beta in _generator_terms(r, cx, cy, float, float):
            row = [fx, fy, tau / L] + [0.0] * k
            row[3 + i] = beta / L
            rows.append(row)
            owner.append(i)
    return rows, owner


def _generator_terms(r, cx, cy, num, one):
    """``(f_x, f_y, L tau0, L beta)`` of every generator of region ``r``, in the arithmetic of
    ``num`` (float, or exact dyadic pairs with ``one`` its unit)."""
    gens = registry.get(r.model).generators(2, region_variant(r))
    ax, ay = num(r.a[0]), num(r.a[1])
    bx, by = num(r.b[0]), num(r.b[1])
    nx, ny = num(r.n[0]), num(r.n[1])
    mu, w = num(r.mu), num(r.offset_length)
    out = []
    for g in gens:
        fr, off = num(g.friction), num(g.offset)
        fx, fy = nx - fr * mu * ny, ny + fr * mu * nx          # n + friction mu t, t = (-n_y, n_x)
        px, py = ax - off * w * ny - cx, ay + off * w * nx - cy  # a + offset width t - c
        dx, dy = bx - ax, by - ay
        out.append((fx, fy, px * fy - py * fx, dx * fy - dy * fx))
    return out


class Dyadic:
    """An exact dyadic rational ``m 2^e`` (every float is one): sums and products of floats
    without rounding and without the gcd of :class:`fractions.Fraction`."""

    __slots__ = ("m", "e")

    def __init__(self, m: int, e: int = 0) -> None:
        self.m, self.e = m, e

    @classmethod
    def of(cls, x) -> "Dyadic":
        n, d = float(x).as_integer_ratio()
        return cls(n, -(d.bit_length() - 1))

    def __add__(self, o: "Dyadic") -> "Dyadic":
        if not self.m:
            return o
        if not o.m:
            return self
        e = min(self.e, o.e)
        return Dyadic((self.m << (self.e - e)) + (o.m << (o.e - e)), e)

    def __neg__(self) -> "Dyadic":
        return Dyadic(-self.m, self.e)

    def __sub__(self, o: "Dyadic") -> "Dyadic":
        return self + (-o)

    def __mul__(self, o: "Dyadic") -> "Dyadic":
        return Dyadic(self.m * o.m, self.e + o.e)

    def sign(self) -> int:
        return (self.m > 0) - (self.m < 0)

    def __float__(self) -> float:
        return float(Fraction(self.m) * Fraction(2) ** self.e)


def scaled_rows(regions: RegionTuple):
    """``L G`` and ``L H`` in exact dyadic arithmetic: ``L`` times every generator row (the
    torque columns are then ``(p - c) x f`` and ``(b - a) x f``, sums of products of floats),
    and the owner of each row. Multiplying every row by ``L > 0`` multiplies ``r`` by ``L`` and
    leaves the sign of the box minimum unchanged."""
    k = len(regions.regions)
    cx, cy = (Dyadic.of(v) for v in regions.center)
    L = Dyadic.of(regions.length)
    zero = Dyadic(0)
    rows, owner = [], []
    for i, r in enumerate(regions.regions):
        for fx, fy, tau, beta in _generator_terms(r, cx, cy, Dyadic.of, Dyadic(1)):
            row = [L * fx, L * fy, tau] + [zero] * k
            row[3 + i] = beta
            rows.append(row)
            owner.append(i)
    return rows, owner, L


def face_box(face: tuple[int, int, int], k: int):
    """Lower and upper bounds of ``x`` on a face, and its ``z`` rows (each a coefficient list)."""
    axis, sign, ts = face
    lo = [-1, -1, 0 if ts > 0 else -1] + [0 if ts > 0 else -1] * k
    hi = [1, 1, 1 if ts > 0 else 0] + [1 if ts > 0 else 0] * k
    lo[axis] = hi[axis] = sign
    H = []
    if axis != 2:
        for i in range(k):
            row = [0] * (3 + k)
            row[3 + i], row[2] = (1, -1) if ts > 0 else (-1, 1)
            H.append(row)
    return lo, hi, H


@dataclass(frozen=True)
class FaceSolution:
    """The max-slack LP on one face: ``sigma``, the optimal ``x`` and the multipliers."""

    face: tuple[int, int, int]
    sigma: float
    x: np.ndarray
    lam: np.ndarray
    mu: np.ndarray


def solve_faces(G: np.ndarray, k: int) -> list[FaceSolution]:
    """Solve the max-slack LP on every face (module docstring): all 10 at once as one
    block-diagonal LP (clarabel; its objective is the sum of the slacks, so each block is solved
    for its own), per face with scipy's HiGHS when clarabel does not report success. Any
    solver would do: the certificate is checked exactly. ``G`` must be finite."""
    m = G.shape[0]
    blocks = []
    for face in FACES:
        lo, hi, H = face_box(face, k)
        A = np.vstack([np.hstack([G, np.ones((m, 1))])] + ([np.hstack([np.array(H, float), np.zeros((len(H), 1))])]
                                                          if H else []))
        blocks.append((face, A, lo, hi))
    try:
        return _clarabel_faces(blocks, m)
    except SolverError:
        pass
    from scipy.optimize import linprog  # clarabel failed (rare): scipy.optimize stays out of start-ups

    out = []
    for face, A, lo, hi in blocks:
        c = np.zeros(A.shape[1])
        c[-1] = -1.0
        res = linprog(c, A_ub=A, b_ub=np.zeros(len(A)), bounds=list(zip(lo, hi)) + [(None, None)], method="highs")
        if res.status != 0:
            raise SolverError(f"region LP on face {face}: {res.message}")
        marg = -np.asarray(res.ineqlin.marginals, dtype=float)
        out.append(FaceSolution(face, float(-res.fun), np.asarray(res.x[:-1], dtype=float),
                                np.maximum(marg[:m], 0.0), np.maximum(marg[m:], 0.0)))
    return out


def _clarabel_faces(blocks, m: int) -> list[FaceSolution]:
    """Every face's LP as one clarabel problem: the face's fixed coordinate is substituted,
    the others get box rows; variables per block: the free coordinates, then sigma."""
    rows, cols, vals, b = [], [], [], []
    layout = []
    r0 = c0 = 0
    for face, A, lo, hi in blocks:
        axis, sign = face[0], face[1]
        free = [j for j in range(A.shape[1]) if j != axis]
        Af = A[:, free]
        nr, nf = Af.shape
        ii, jj = np.nonzero(Af)
        rows.append(r0 + ii), cols.append(c0 + jj), vals.append(Af[ii, jj])
        b.append(-A[:, axis] * sign)
        box = [j for j in free if j < len(lo)]
        for q, j in enumerate(box):  # x_j <= hi_j and -x_j <= -lo_j
            rows.append(np.array([r0 + nr + 2 * q, r0 + nr + 2 * q + 1])), cols.append(np.array([c0 + q, c0 + q]))
            vals.append(np.array([1.0, -1.0]))
            b.append(np.array([float(hi[j]), -float(lo[j])]))
        layout.append((face, free, r0, nr, c0, nf))
        r0 += nr + 2 * len(box)
        c0 += nf
    A = sp.csc_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(r0, c0))
    q = np.zeros(c0)
    for _, _, _, _, c, nf in layout:
        q[c + nf - 1] = -1.0
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.tol_gap_abs = settings.tol_gap_rel = 1e-11
    settings.tol_feas = 1e-11
    settings.max_iter = 200
    solver = clarabel.DefaultSolver(sp.csc_matrix((c0, c0)), q, A, np.concatenate(b),
                                    [clarabel.NonnegativeConeT(r0)], settings)
    sol = solver.solve()
    if str(sol.status) not in ("Solved", "AlmostSolved"):
        raise SolverError(f"region LPs: clarabel status {sol.status}")
    x, z = np.array(sol.x), np.array(sol.z)
    out = []
    for face, free, r, nr, c, nf in layout:
        full = np.zeros(len(free) + 1)
        full[free] = x[c:c + nf]
        full[face[0]] = face[1]
        dual = z[r:r + nr]
        out.append(FaceSolution(face, float(full[-1]), full[:-1], np.maximum(dual[:m], 0.0), np.maximum(dual[m:], 0.0)))
    return out


def _box_min(r, lo, hi):
    return sum(min(rj * l, rj * u) for rj, l, u in zip(r, lo, hi))


def check_faces_float(G: np.ndarray, k: int, sols: Sequence[FaceSolution], rel: float = 1e-9) -> bool:
    """Fast float screen of the certificate: every face's box minimum above ``rel`` times its
    scale (far above rounding; :func:`check_faces` is the exact check)."""
    for s in sols:
        lo, hi, H = face_box(s.face, k)
        r = G.T @ s.lam + (np.array(H, float).T @ s.mu if H else 0.0)
        scale = np.abs(G).T @ s.lam + (np.abs(np.array(H, float)).T @ s.mu if H else 0.0)
        if not (s.lam.sum() > 0 and _box_min(r, lo, hi) > rel * max(1.0, float(scale.sum()))):
            return False
    return True


def faces_certificate(sols: Sequence[FaceSolution]) -> dict[str, Any]:
    """The JSON certificate of robustness: per face its multipliers (and the LP's slack, for
    information)."""
    return {"kind": "faces",
            "faces": [{"face": list(s.face), "lambda": [float(v) for v in s.lam], "mu": [float(v) for v in s.mu],
                       "slack": s.sigma} for s in sols]}


def check_faces(regions: RegionTuple, certificate: Any) -> Check:
    """Exact re-check of a ``faces`` certificate against straight regions (module docstring).

    Returns a :class:`~qualgrasp.certify.Check`; a malformed certificate is a failed check.
    """
    if not regions.straight or regions.normal_tol != 0:
        return Check(False, "a faces certificate applies to straight regions with normal_tol 0")
    if not isinstance(certificate, dict) or certificate.get("kind") != "faces":
        return Check(False, "expected a certificate of kind 'faces'")
    faces = certificate.get("faces")
    if not isinstance(faces, list) or len(faces) != len(FACES):
        return Check(False, f"a faces certificate has {len(FACES)} faces")
    k = len(regions.regions)
    G, _, L = scaled_rows(regions)
    zero = Dyadic(0)
    try:
        for want, item in zip(FACES, faces):
            if tuple(item.get("face", ())) != want:
                return Check(False, f"face {item.get('face')!r}: expected {list(want)}")
            lam, mu = item["lambda"], item["mu"]
            lo, hi, H = face_box(want, k)
            if len(lam) != len(G) or len(mu) != len(H):
                return Check(False, f"face {list(want)}: expected {len(G)} generator and {len(H)} z multipliers")
            vals = [float(v) for v in list(lam) + list(mu)]
            if not all(math.isfinite(v) for v in vals):
                return Check(False, f"face {list(want)}: multipliers must be finite")
            if any(v < 0 for v in vals):
                return Check(False, f"face {list(want)}: a multiplier is negative")
            if not any(float(v) > 0 for v in lam):
                return Check(False, f"face {list(want)}: the generator multipliers are all zero")
            lx = [Dyadic.of(v) for v in lam]
            mx = [Dyadic.of(v) for v in mu]
            total = zero
            for j in range(3 + k):
                rj = zero
                for g in range(len(G)):
                    if lx[g].m and G[g][j].m:
                        rj = rj + lx[g] * G[g][j]
                for h in range(len(H)):
                    if mx[h].m and H[h][j]:
                        rj = rj + mx[h] * (L if H[h][j] > 0 else -L)
                bound = lo[j] if rj.sign() >= 0 else hi[j]
                if bound:
                    total = total + (rj if bound > 0 else -rj)
            if not total.sign() > 0:
                return Check(False, f"face {list(want)}: the combined row does not exclude the face "
                                    "(box minimum not positive)")
    except (TypeError, ValueError, KeyError, AttributeError, OverflowError) as err:
        return Check(False, f"malformed faces certificate: {err}")
    return Check(True)


def on_segment(p, a, b) -> bool:
    """Is the float point ``p`` exactly (in rationals) on the segment ``[a, b]``?"""
    px, py, ax, ay, bx, by = (Fraction(float(v)) for v in (*p, *a, *b))
    dx, dy = bx - ax, by - ay
    ex, ey = px - ax, py - ay
    if ex * dy - ey * dx != 0:
        return False
    dot = ex * dx + ey * dy
    return 0 <= dot <= dx * dx + dy * dy


def point_on_segment(a, b, s: float, lo: float = 0.0, hi: float = 1.0):
    """A float point exactly on ``[a, b]`` at a parameter in ``[lo, hi]`` near ``s``: an end point
    when ``s`` is one, else the first dyadic parameter ``m / 2^j`` (j up to 60) whose point is
    exactly representable; ``(point, parameter)`` or None when there is none."""
    if s <= 0 and lo <= 0:
        return tuple(float(v) for v in a), 0.0
    if s >= 1 and hi >= 1:
        return tuple(float(v) for v in b), 1.0
    A = [Fraction(float(v)) for v in a]
    D = [Fraction(float(v)) - x for v, x in zip(b, A)]
    for j in range(1, 61):
        base = round(s * 2 ** j)
        for m in (base, base - 1, base + 1):
            t = Fraction(m, 2 ** j)
            if not (Fraction(lo) <= t <= Fraction(hi)) or not 0 <= t <= 1:
                continue
            P = [x + t * d for x, d in zip(A, D)]
            if all(Fraction(float(v)) == v for v in P):
                return tuple(float(v) for v in P), float(t)
    return None


def _margins(G: np.ndarray, owner: np.ndarray, y: np.ndarray, i: int, s: float) -> float:
    """Smallest ``-(y . w_g(s))`` over the generators of region ``i``."""
    rows = G[owner == i]
    vals = rows[:, :3] @ y + rows[:, 3 + i] * s * y[2]
    return float(-vals.max())


def straight_witness(regions: RegionTuple, G: np.ndarray, owner: np.ndarray, sols: Sequence[FaceSolution],
                     tol: float, limit: int = 256):
    """A choice of one contact per region that certify proves not in closure, from the faces
    with ``sigma >= -tol`` (then from the end-point choices, best first): ``(grasp, verdict,
    parameters)`` or ``(None, reason, None)``."""
    k = len(regions.regions)
    tried: set = set()
    reasons = []
    candidates = []
    for s in sorted(sols, key=lambda s: -s.sigma):
        if s.sigma < -tol:
            break
        y = s.x[:3]
        choice = []
        for i in range(k):
            lp = min(1.0, max(0.0, s.x[3 + i] / y[2])) if abs(y[2]) > 1e-12 else 0.5
            best = max((0.0, 1.0, lp), key=lambda v: (_margins(G, owner, y, i, v) + (1e-12 if v in (0.0, 1.0) else 0)))
            choice.append(best)
        candidates.append(tuple(choice))
        # all end-point choices, ordered by their margins along this direction
        ends = sorted(itertools.product((0.0, 1.0), repeat=k),
                      key=lambda c: -min(_margins(G, owner, y, i, v) for i, v in enumerate(c)))
        candidates.extend(ends[:limit])
    for choice in candidates:
        if choice in tried:
            continue
        tried.add(choice)
        contacts, params = [], []
        for r, v in zip(regions.regions, choice):
            found = point_on_segment(r.a, r.b, v)
            if found is None:
                reasons.append("no floating-point point lies exactly on the segment at the worst choice")
                break
            p, t = found
            contacts.append(r.contact(p))
            params.append(t)
        else:
            grasp = Grasp(tuple(contacts), center=regions.center, length=regions.length)
            verdict = force_closure(grasp)
            if verdict.status == "no_closure" and verify(grasp, verdict.certificate, status="no_closure"):
                return grasp, verdict, params
            reasons.append(f"certify: {verdict.status}")
        if len(tried) >= limit:
            break
    return None, "; ".join(sorted(set(reasons))) or "no candidate choice", None

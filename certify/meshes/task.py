"""The weight-holding task: does a grasp hold the object's own weight, in a direction of gravity
or in every direction, with a grip force of at most ``F``? A conic programme with certificates.

The programme
-------------
A grasp's contacts (certify's cones: exact Lorentz cones for ``point`` and ``soft`` contacts,
rays for frictionless ones) hold the object of mass ``m`` with centre of mass ``com`` against
gravity ``g d`` (``d`` a unit direction, ``g`` = :data:`G`) when forces ``x`` on certify's
certificate columns ``C`` (:func:`qualgrasp.certify.core.problem.grasp_system`; torques about the
grasp's ``center``, divided by its ``length``) satisfy

    C x + w(d) = 0,   x_b in K_b for every contact b,   nu_b(x) <= s for every contact b,

with ``w(d)`` the wrench of the weight ``m g d`` applied at ``com`` and ``nu_b(x) = f_b . n_b``
the normal force of contact ``b`` (the stored unit normal). ``s`` is the **grip force**: the
largest normal force a finger applies, for parallel jaws the squeeze of the jaws. The **least grip
force** ``s*(d)`` is the smallest ``s`` for which forces exist (``inf`` when none exist at any
``s``). It is computed from the homogeneous programme ``max theta : C x + theta w(d) = 0,
x_b in K_b, nu_b(x) <= 1`` (always feasible and bounded): ``s* = 1 / theta*``.

Certificates (re-checked here without any solver, in exact rational arithmetic on the floats)
-----------------------------------------------------------------------------------------------
``holds at s``: forces ``x``. The checker forms the exact residual ``r = C x + w`` and solves
``C_B delta = -r`` exactly on a basis ``B`` of the columns (:mod:`qualgrasp.certify.core.exact`); the
corrected forces must lie strictly inside every cone (:func:`qualgrasp.certify.core.cones.inside`)
and have ``nu_b < s``. That exhibits exact forces holding the weight at grip force ``s``.

``slips at s`` (no forces exist at grip force ``s``): a Farkas certificate, a wrench functional
``y`` and multipliers ``lambda_b >= 0``, with a set of ``tight`` contacts that ``y`` is projected
orthogonal to (exactly), such that for every other contact ``a_b = C_b' y - lambda_b nu_b`` lies
strictly in the polar cone (:func:`qualgrasp.certify.core.cones.polar`) and ``-y . w > s sum lambda_b``.
For any forces in the cones with ``nu_b <= s``: ``-y . w = y . C x = sum_b a_b . x_b + sum_b
lambda_b nu_b(x_b) <= s sum_b lambda_b``, a contradiction. With ``lambda = 0`` it proves that no
grip force at all holds the weight (for example two point contacts and a weight off the line
through them: a torque about that line no contact can resist).

Making the certificates (solver side)
-------------------------------------
The least grip force is reported as a certified bracket ``lo <= s* <= hi``: forces at ``hi`` and
a Farkas certificate at ``lo``, ``hi / lo - 1`` about ``2e-6``. The functional ``y`` is the dual of
the equilibrium; the multipliers are not the solver's duals of ``nu_b <= 1`` (their error on a
lightly loaded contact exceeds any fixed margin) but computed from ``y``: the least ``lambda_b``
putting ``a_b`` in the polar cone is ``(c_n + mu norm((c_t, c_m g))) / |n|^2`` for ``c = C_b' y``
(subtracting ``lambda_b n_b`` moves only the normal part), raised by a small multiple of
``norm(c)`` to make it strict. The ``lo`` stated is then what ``y`` proves, ``-y . w / sum
lambda_b`` (a hair less), at most ``s*(1 - 1e-6)``. Both certificates are re-checked exactly
before a bound is stated: a failing slip certificate is retried with larger margins, failing
forces at wider budgets (``1e-4``, ``1e-2``), and an end that still does not re-check is withdrawn
(``lo = 0`` or ``hi = inf``). :attr:`GripBound.note` says when an end was widened or withdrawn.

Every direction
---------------
``s*(d)`` is sublinear in ``d`` (convex and positively homogeneous, because the feasible set is a
convex cone in ``(x, w, s)``). Let ``u_j`` be the vertices of a triangulated polytope inscribed
in the unit sphere whose faces all lie at least ``r`` from the origin (an icosphere,
:func:`direction_polytope`). Then the polytope with vertices ``v_j = u_j / r`` contains the unit
ball, every unit ``d`` is a convex combination of the ``v_j``, and by sublinearity
``s*(d) <= max_j s*(v_j) = max_j s*(u_j) / r``; the ``u_j`` themselves are directions, so
``max_j s*(u_j) <= max_{|d| = 1} s*(d)``. Hence

    max_j s*(u_j)  <=  max over every direction of s*(d)  <=  max_j s*(u_j) / r,

certified by a Farkas certificate at the worst ``u_j`` (with ``|u_j| <= 1`` exactly) and by
forces at every ``v_j`` (the checker also checks exactly that the faces of the ``v_j`` polytope
are closed, positively oriented and at least 1 from the origin,
:func:`qualgrasp.certify.quality.evidence.exact_face`). ``r`` is 0.795 for the icosahedron (level 0),
0.934 at level 1 (42 directions), 0.982 at level 2 (162) and 0.995 at level 3 (642).

Closed form (the tests): a box of mass ``m`` held across two opposite faces by two point contacts
with friction ``mu`` on the line through its centre, gravity along the faces, needs
``s* = m g / (2 mu)``: it holds its weight iff ``mu F >= m g / 2``.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from fractions import Fraction
from typing import Sequence

import clarabel
import numpy as np
import scipy.sparse as sp
import trimesh

from ..core import cones
from ..core import exact as ex
from ..core.certificates import Check
from ..quality.evidence import cycle_check, exact_face
from ..core.grasp import Grasp
from ..core.problem import Block, grasp_system
from ..solvers.clarabel_direct import settings
from ..core.wrench import to_exact, wrench
from ..errors import OptionError

__all__ = ["G", "GripBound", "SlipCertificate", "EveryDirection", "gravity_wrench", "least_grip",
           "check_holds", "check_slips", "check_bound", "direction_polytope", "every_direction",
           "check_every_direction",
           "hold_verdict", "parse_gravity", "hold_fields"]

#: Standard gravity, m/s^2.
G = 9.80665
#: Relative width of the certified bracket around the solver's least grip force, each side.
_BRACKET = 1e-6


@dataclass(frozen=True)
class SlipCertificate:
    """Farkas certificate that no forces hold the weight at grip force ``budget`` (module
    docstring): functional ``y`` (6), multipliers ``lam`` (one per contact), ``tight`` contacts."""

    budget: float
    y: tuple[float, ...]
    lam: tuple[float, ...]
    tight: tuple[int, ...]

    def to_json(self) -> dict:
        return {"budget": self.budget, "y": list(self.y), "lam": list(self.lam), "tight": list(self.tight)}


@dataclass(frozen=True)
class GripBound:
    """The least grip force for one gravity direction, certified both ways.

    Attributes
    ----------
    direction : tuple of float
        Gravity direction ``d`` (unit, or shorter for a slip certificate of the every-direction
        bound).
    lo, hi : float
        ``lo <= s*(d) <= hi``, newtons; ``hi`` is ``inf`` when no holding forces were found, and
        ``lo`` is ``inf`` too when the slip certificate proves that no grip force holds the
        weight (JSON: null).
    forces : tuple of float or None
        Forces on the certificate columns holding the weight at grip force ``hi`` (None when
        ``hi`` is ``inf``).
    slip : SlipCertificate or None
        Certificate that grip force ``lo`` does not hold (None when ``lo`` is 0); when ``lo`` is
        ``inf`` its multipliers are all 0, which proves it at every grip force.
    note : str
        Empty, or why an end is wider than the solver's bracket or not stated (an end whose
        certificate did not re-check exactly is widened or withdrawn, never stated unproved).
    """

    direction: tuple[float, ...]
    lo: float
    hi: float
    forces: tuple[float, ...] | None
    slip: SlipCertificate | None
    note: str = ""

    def to_json(self) -> dict:
        return {"direction": list(self.direction), "lo": None if math.isinf(self.lo) else self.lo,
                "hi": None if math.isinf(self.hi) else self.hi,
                "forces": None if self.forces is None else list(self.forces),
                "slip": None if self.slip is None else self.slip.to_json(), "note": self.note}


def gravity_wrench(grasp: Grasp, mass: float, com: Sequence[float], direction: Sequence[float], *,
                   exact: bool = False) -> np.ndarray:
    """The wrench of the weight ``mass G direction`` applied at ``com``, in the grasp's wrench
    coordinates (torques about ``grasp.center`` divided by ``grasp.length``); exact: Fractions of
    the same floats.

    Examples
    --------
    >>> from qualgrasp.certify import Contact, Grasp
    >>> g = Grasp((Contact((0.1, 0, 0), (-1, 0, 0), "point", 0.5),
    ...            Contact((-0.1, 0, 0), (1, 0, 0), "point", 0.5)), center=(0, 0, 0))
    >>> (gravity_wrench(g, 1.0, (0, 0, 0), (0, 0, -1)) + 0.0).tolist()
    [0.0, 0.0, -9.80665, 0.0, 0.0, 0.0]
    """
    force = np.asarray(direction, dtype=float) * float(mass * G)
    conv = to_exact if exact else (lambda a: np.asarray(a, dtype=float))
    L = Fraction(grasp.length) if exact else grasp.length
    return wrench(conv(com), conv(force), conv(grasp.center), L)


# --- the solver side ---------------------------------------------------------------------------

def _normal_rows(blocks: Sequence[Block], k: int) -> np.ndarray:
    """``nu_b(x) = N[b] @ x``: the normal force of each contact (float)."""
    N = np.zeros((len(blocks), k))
    for i, b in enumerate(blocks):
        if b.cone == "ray":
            N[i, b.cols[0]] = 1.0
        else:
            N[i, list(b.cols[:len(b.n)])] = [float(v) for v in b.n]
    return N


class _Programs:
    """The two programmes of one grasp, in clarabel's form ``min q'z : A z + s = b, s in K``
    (:func:`qualgrasp.certify.solvers.clarabel_direct.settings`), over ``z = (x, theta)`` or ``(x,
    t)``. The cone rows are built once; the weight and the budget change per solve."""

    def __init__(self, grasp: Grasp) -> None:
        C, blocks, _ = grasp_system(grasp, socp=True)
        self.C, self.blocks = np.asarray(C, dtype=float), blocks
        d, k = self.C.shape
        self.N = _normal_rows(blocks, k)
        # per block: the rows of -(its cone's slack) in x, and how the margin variable enters its first row
        rows, tcol, cones = [], [], []
        for b in blocks:
            if b.cone == "ray":
                r = np.zeros((1, k))
                r[0, b.cols[0]] = -1.0
                rows.append(r), tcol.append([1.0]), cones.append(clarabel.NonnegativeConeT(1))
                continue
            dim = len(b.n)
            n = np.array([float(v) for v in b.n])
            r = np.zeros((1 + len(b.cols), k))  # (mu n.f, tangent part of f, moments / g)
            f = list(b.cols[:dim])
            r[0, f] = -float(b.mu) * n
            r[1:dim + 1, f] = -(np.eye(dim) - np.outer(n, n))
            for i, j in enumerate(b.cols[dim:]):
                r[dim + 1 + i, j] = -1.0 / float(b.g)
            rows.append(r), tcol.append([1.0] + [0.0] * (len(r) - 1)), cones.append(clarabel.SecondOrderConeT(len(r)))
        self.cone_A = np.vstack(rows) if rows else np.zeros((0, k))
        self.cone_t = np.concatenate(tcol) if tcol else np.zeros(0)
        self.cones = cones

    def _solve(self, A: np.ndarray, b: np.ndarray, cones: list):
        n = A.shape[1]
        q = np.zeros(n)
        q[-1] = -1.0
        try:
            sol = clarabel.DefaultSolver(sp.csc_matrix((n, n)), q, sp.csc_matrix(A), b, cones, settings()).solve()
        except (ValueError, RuntimeError):  # clarabel refuses malformed data; not seen on grasps
            return None
        return sol if str(sol.status) in ("Solved", "AlmostSolved") else None

    def least(self, w: np.ndarray) -> tuple[float, np.ndarray] | None:
        """``max theta : C x + theta w = 0, N x <= 1, theta >= 0, x in K``: ``theta*`` and the
        dual of the equilibrium rows, or None when the solver fails."""
        d, k = self.C.shape
        m = len(self.N)
        theta_row = np.concatenate([np.zeros(k), [-1.0]])[None]  # -theta <= 0
        A = np.vstack([np.column_stack([self.C, w]), np.column_stack([self.N, np.zeros(m)]), theta_row,
                       np.column_stack([self.cone_A, np.zeros(len(self.cone_A))])])
        b = np.concatenate([np.zeros(d), np.ones(m), [0.0], np.zeros(len(self.cone_A))])
        sol = self._solve(A, b, [clarabel.ZeroConeT(d), clarabel.NonnegativeConeT(m + 1), *self.cones])
        if sol is None:
            return None
        return float(np.asarray(sol.x)[-1]), np.asarray(sol.z)[:d]

    def interior(self, w: np.ndarray, budget: float) -> tuple[np.ndarray, float] | None:
        """``max t : C x + w = 0, N x <= budget - t, t <= budget``, every cone's slack ``>= t``:
        forces ``x`` and ``t``, or None when the solver fails."""
        d, k = self.C.shape
        m = len(self.N)
        A = np.vstack([np.column_stack([self.C, np.zeros(d)]), np.column_stack([self.N, np.ones(m)]),
                       np.concatenate([np.zeros(k), [1.0]])[None], np.column_stack([self.cone_A, self.cone_t])])
        b = np.concatenate([-w, np.full(m + 1, budget), np.zeros(len(self.cone_A))])
        sol = self._solve(A, b, [clarabel.ZeroConeT(d), clarabel.NonnegativeConeT(m + 1), *self.cones])
        if sol is None:
            return None
        z = np.asarray(sol.x)
        return z[:-1], float(z[-1])


def _multipliers(C: np.ndarray, blocks: Sequence[Block], y: np.ndarray, tight: tuple[int, ...],
                 rel: float) -> np.ndarray:
    """The least ``lambda_b >= 0`` putting each non-tight contact's functional ``C_b' y - lambda_b
    n_b`` in the polar cone, plus ``rel`` times the functional's size (strict; float).

    Subtracting ``lambda_b n_b`` moves only the normal part ``a_n`` of the functional, so the least
    multiplier is ``(c_n + mu norm((c_t, c_m g))) / |n|^2`` for ``c = C_b' y``: the support of the
    contact's unit-normal-force wrenches along ``y``, computed here from ``y`` itself rather than
    taken from the solver's duals (whose error on a lightly loaded contact can exceed any fixed
    margin)."""
    lam = np.zeros(len(blocks))
    for i, b in enumerate(blocks):
        if i in tight:
            continue
        c = C[:, list(b.cols)].T @ y
        if b.cone == "ray":
            need = c[0]
        else:
            n = np.array([float(v) for v in b.n])
            nn, dim = n @ n, len(n)
            cn = c[:dim] @ n
            ct = c[:dim] - cn / nn * n  # explicit tangent: nn |c|^2 - cn^2 cancels when c is near n
            tang = nn * (ct @ ct) + float(np.sum((c[dim:] * float(b.g)) ** 2))
            need = (cn + float(b.mu) * math.sqrt(tang)) / nn
        need += rel * np.abs(c).max()
        lam[i] = need if need > 0 else 0.0
    return lam


#: Relative margins tried, in turn, to make a slip certificate's multipliers strict.
_MARGINS = (1e-10, 1e-7, 1e-4)


def _slip(programs: _Programs, y_eq: np.ndarray, grasp: Grasp, mass: float, com, direction, w: np.ndarray,
          cap: float) -> tuple[SlipCertificate | None, float]:
    """A slip certificate from the dual ``y_eq`` of the homogeneous programme's equilibrium (either
    sign) and the grip force
    ``lo`` it proves, at most ``cap`` (``inf`` when it proves that no grip force holds); ``(None,
    0)`` when none re-checks. Every certificate returned has passed :func:`check_slips`."""
    C, blocks = programs.C, programs.blocks
    scale = np.abs(C).max()
    for sign in (1.0, -1.0):
        y = sign * np.asarray(y_eq, dtype=float).ravel()
        if not -y @ w > 0:
            continue
        y = y / -(y @ w)  # normalise: -y . w = 1, so lam's sum is about theta*
        A = C.T @ y
        tight = tuple(i for i, b in enumerate(blocks) if np.abs(A[list(b.cols)]).max() <= 1e-9 * scale * np.abs(y).max())
        cols = [j for i in tight for j in blocks[i].cols]
        if cols:  # as the checker will, exactly: y orthogonal to the tight contacts
            B = C[:, cols]
            y = y - B @ np.linalg.lstsq(B, y, rcond=None)[0]
        for rel in _MARGINS:
            lam = _multipliers(C, blocks, y, tight, rel)
            total = lam.sum()
            if total > 0:
                # the budget the certificate proves, a hair below -y.w / sum(lam); the check is exact
                lo = min(cap, float(-(y @ w)) / total * (1 - 1e-12))
                if not lo > 0:
                    continue
            else:
                lo = math.inf
            cert = SlipCertificate(0.0 if math.isinf(lo) else lo, tuple(float(v) for v in y),
                                   tuple(float(v) for v in lam), tight)
            if check_slips(grasp, mass, com, direction, cert):
                return cert, lo
    return None, 0.0


def _holding(programs: _Programs, grasp: Grasp, mass: float, com, direction,
             budget: float) -> tuple[float, tuple[float, ...] | None]:
    """Forces holding the weight at grip force ``budget``, or at the least of two wider budgets
    that re-checks, with that budget; ``(inf, None)`` when none re-checks. Every pair returned has
    passed :func:`check_holds`."""
    w = gravity_wrench(grasp, mass, com, direction)
    for widen in (1.0, 1 + 1e-4, 1 + 1e-2):
        got = programs.interior(w, budget * widen)
        if got is None or not got[1] > 0:
            continue
        forces = tuple(float(v) for v in got[0])
        if check_holds(grasp, mass, com, direction, budget * widen, forces):
            return budget * widen, forces
    return math.inf, None


def least_grip(grasp: Grasp, mass: float, com: Sequence[float], direction: Sequence[float], *,
               programs: _Programs | None = None) -> GripBound:
    """The least grip force holding the weight against gravity ``direction``, certified both ways
    (module docstring).

    Parameters
    ----------
    grasp : Grasp
        Spatial, its ``center`` and ``length`` give the torque coordinates.
    mass : float
        kg.
    com : sequence of 3 float
        Centre of mass, m.
    direction : sequence of 3 float
        Gravity direction (unit).

    Returns
    -------
    GripBound
        Each end is stated only when its certificate has passed the exact re-check
        (:func:`check_holds`, :func:`check_slips`; :func:`check_bound` repeats both): an end whose
        certificate does not re-check is widened to what a certificate proves (``lo`` lower,
        ``hi`` higher), or withdrawn (``lo = 0``, ``hi = inf``), and ``note`` says so.

    Examples
    --------
    >>> from qualgrasp.certify import Contact, Grasp
    >>> g = Grasp((Contact((0.05, 0, 0), (-1, 0, 0), "point", 0.5),
    ...            Contact((-0.05, 0, 0), (1, 0, 0), "point", 0.5)), center=(0, 0, 0))
    >>> b = least_grip(g, 1.0, (0, 0, 0), (0, 0, -1))
    >>> b.lo <= 9.80665 <= b.hi, round(b.hi / b.lo - 1, 6), b.note      # m g / (2 mu) = 9.80665 N
    (True, 2e-06, '')
    """
    programs = programs or _Programs(grasp)
    d = tuple(float(v) for v in direction)
    w = gravity_wrench(grasp, mass, com, d)
    got = programs.least(w)
    if got is None:
        return GripBound(d, 0.0, math.inf, None, None, "the solver failed: no bound stated")
    theta, y_eq = got
    s_star = 1.0 / theta if theta > 0 else math.inf
    cap = s_star * (1 - _BRACKET)
    slip, lo = _slip(programs, y_eq, grasp, mass, com, d, w, cap)
    notes = []
    if slip is None:
        notes.append("no lower bound: no slip certificate re-checked")
    elif lo < cap and math.isfinite(s_star):
        notes.append(f"lower end widened to {lo!r} N, what the slip certificate proves (solver: {s_star!r} N)")
    if math.isinf(lo) or math.isinf(s_star):
        return GripBound(d, lo, math.inf, None, slip, "; ".join(notes))
    hi, forces = _holding(programs, grasp, mass, com, d, s_star * (1 + _BRACKET))
    if forces is None:
        notes.append("no upper bound: no holding forces re-checked")
    elif hi > s_star * (1 + _BRACKET):
        notes.append(f"upper end widened to {hi!r} N, the least grip force whose forces re-checked "
                     f"(solver: {s_star!r} N)")
    return GripBound(d, lo, hi, forces, slip, "; ".join(notes))


# --- the checker side (exact, no solver) -------------------------------------------------------

def _exact_correction(Cx, r: list) -> list | None:
    """``delta`` with ``Cx delta = -r`` exactly, non-zero only on pivot columns; None when ``-r``
    is not in the column space."""
    d, k = Cx.shape
    cols = ex.independent_columns([list(row) for row in Cx])
    aug = [[Cx[i, j] for j in cols] + [-r[i]] for i in range(d)]
    R, pivots = ex.row_echelon(aug)
    if len(cols) in pivots:
        return None
    delta = [Fraction(0)] * k
    for row, p in zip(R, pivots):
        delta[cols[p]] = row[-1]
    return delta


def _normal_force(b: Block, v: Sequence) -> Fraction:
    return v[0] if b.cone == "ray" else sum(a * c for a, c in zip(v[:len(b.n)], b.n))


def check_holds(grasp: Grasp, mass: float, com: Sequence[float], direction: Sequence[float], budget: float,
                forces: Sequence[float] | None, *, residual: float = 1e-6) -> Check:
    """Re-check that ``forces`` hold the weight against ``direction`` with grip force below
    ``budget`` (module docstring), exactly and without a solver.

    Examples
    --------
    >>> from qualgrasp.certify import Contact, Grasp
    >>> g = Grasp((Contact((0.05, 0, 0), (-1, 0, 0), "point", 0.5),
    ...            Contact((-0.05, 0, 0), (1, 0, 0), "point", 0.5)), center=(0, 0, 0))
    >>> b = least_grip(g, 1.0, (0, 0, 0), (0, 0, -1))
    >>> bool(check_holds(g, 1.0, (0, 0, 0), (0, 0, -1), b.hi, b.forces))
    True
    >>> check_holds(g, 1.0, (0, 0, 0), (0, 0, -1), 9.0, b.forces).reason
    'contact 0: normal force 9.80666 is not below the grip force 9'
    """
    Cx, blocks, _ = grasp_system(grasp, socp=True, exact=True)
    d, k = Cx.shape
    if forces is None or len(forces) != k or not all(math.isfinite(float(v)) for v in forces):
        return Check(False, f"the certificate needs {k} finite forces")
    x = list(to_exact(np.asarray(forces, dtype=float)))
    w = gravity_wrench(grasp, mass, com, direction, exact=True)
    r = [sum(Cx[i, j] * x[j] for j in range(k)) + w[i] for i in range(d)]
    size = max(1.0, float(mass * G), max(abs(float(v)) for v in x))
    if max(abs(float(v)) for v in r) > residual * size:
        return Check(False, "the forces are not in equilibrium with the weight (residual too large)")
    delta = _exact_correction(Cx, r)
    if delta is None:
        return Check(False, "the weight's residual is not a wrench the contacts can apply")
    x = [a + b for a, b in zip(x, delta)]
    F = Fraction(float(budget))
    for i, b in enumerate(blocks):
        v = [x[j] for j in b.cols]
        if not cones.inside(b.cone, v, b.n, b.mu, b.g):
            return Check(False, f"contact {i}: the force is not strictly inside its cone")
        fn = _normal_force(b, v)
        if not fn < F:
            return Check(False, f"contact {i}: normal force {float(fn):.6g} is not below the grip force {float(F):.6g}")
    return Check(True)


def check_slips(grasp: Grasp, mass: float, com: Sequence[float], direction: Sequence[float],
                slip: SlipCertificate | None) -> Check:
    """Re-check a Farkas certificate that no forces hold the weight against ``direction`` with
    grip force ``slip.budget`` (module docstring), exactly and without a solver.

    Examples
    --------
    >>> from qualgrasp.certify import Contact, Grasp
    >>> g = Grasp((Contact((0.05, 0, 0), (-1, 0, 0), "point", 0.5),
    ...            Contact((-0.05, 0, 0), (1, 0, 0), "point", 0.5)), center=(0, 0, 0))
    >>> b = least_grip(g, 1.0, (0, 0, 0), (0, 0, -1))
    >>> bool(check_slips(g, 1.0, (0, 0, 0), (0, 0, -1), b.slip))
    True
    """
    if slip is None:
        return Check(False, "no slip certificate")
    Cx, blocks, _ = grasp_system(grasp, socp=True, exact=True)
    d, k = Cx.shape
    if len(slip.y) != d or len(slip.lam) != len(blocks) or not all(math.isfinite(v) for v in slip.y + slip.lam):
        return Check(False, f"the certificate needs a finite y of length {d} and {len(blocks)} multipliers")
    if any(v < 0 for v in slip.lam) or not set(slip.tight) <= set(range(len(blocks))):
        return Check(False, "multipliers must be >= 0 and tight contacts in range")
    y = list(to_exact(np.asarray(slip.y, dtype=float)))
    lam = list(to_exact(np.asarray(slip.lam, dtype=float)))
    cols = [j for b in sorted(set(slip.tight)) for j in blocks[b].cols]
    if cols:
        y = ex.project_out(y, [[Cx[i, j] for j in cols] for i in range(d)])
    for i, b in enumerate(blocks):
        if i in slip.tight:
            continue
        a = [sum(Cx[r, j] * y[r] for r in range(d)) for j in b.cols]
        dim = len(b.n) if b.cone == "lorentz" else 1
        normal = list(b.n) if b.cone == "lorentz" else [Fraction(1)]
        a = [a[q] - lam[i] * normal[q] if q < dim else a[q] for q in range(len(a))]
        if not cones.polar(b.cone, a, b.n, b.mu, b.g):
            return Check(False, f"contact {i}: the functional is not strictly in the polar cone")
    w = gravity_wrench(grasp, mass, com, direction, exact=True)
    lhs = -sum(a * b for a, b in zip(y, w))
    if not lhs > Fraction(float(slip.budget)) * sum(lam):
        return Check(False, "the weight is not separated: -y.w <= budget * sum(lambda)")
    return Check(True)


def _check_lower(grasp: Grasp, mass: float, com, direction, lo: float, slip: SlipCertificate | None) -> Check:
    """Does ``slip`` prove the stated lower end ``lo`` (``inf``: every grip force fails)?"""
    if lo == 0:
        return Check(True)
    if slip is None:
        return Check(False, "no slip certificate at the stated lower end")
    if math.isinf(lo) and any(v != 0 for v in slip.lam):
        return Check(False, "a lower end of inf needs multipliers that are all 0")
    if not math.isinf(lo) and slip.budget != lo:
        return Check(False, "the slip certificate is not at the stated lower end")
    return check_slips(grasp, mass, com, direction, slip)


def check_bound(grasp: Grasp, mass: float, com: Sequence[float], bound: GripBound) -> Check:
    """Re-check both stated ends of a :class:`GripBound` exactly: the forces at ``hi`` (when
    finite, :func:`check_holds`) and the slip certificate at ``lo`` (when positive,
    :func:`check_slips`; at ``inf`` its multipliers must all be 0).

    Examples
    --------
    >>> from qualgrasp.certify import Contact, Grasp
    >>> g = Grasp((Contact((0.05, 0, 0), (-1, 0, 0), "point", 0.5),
    ...            Contact((-0.05, 0, 0), (1, 0, 0), "point", 0.5)), center=(0, 0, 0))
    >>> b = least_grip(g, 1.0, (0, 0, 0), (0, 0, -1))
    >>> bool(check_bound(g, 1.0, (0, 0, 0), b))
    True
    >>> import dataclasses
    >>> check_bound(g, 1.0, (0, 0, 0), dataclasses.replace(b, lo=b.lo * 1.01)).reason
    'lower end: the slip certificate is not at the stated lower end'
    """
    d = bound.direction
    if not math.isinf(bound.hi):
        got = check_holds(grasp, mass, com, d, bound.hi, bound.forces)
        if not got:
            return Check(False, f"upper end: {got.reason}")
    got = _check_lower(grasp, mass, com, d, bound.lo, bound.slip)
    return got if got else Check(False, f"lower end: {got.reason}")


# --- every direction -----------------------------------------------------------------------

def direction_polytope(level: int) -> tuple[np.ndarray, np.ndarray, float]:
    """Vertices (unit, shrunk by ``1e-12`` so that ``|u| <= 1`` holds exactly), outward faces and
    the inradius ``r`` (rounded down) of an icosphere of subdivision ``level`` (0 to 4).

    Examples
    --------
    >>> [round(direction_polytope(k)[2], 3) for k in range(4)]
    [0.795, 0.934, 0.982, 0.995]
    """
    if not 0 <= level <= 4:
        raise ValueError(f"level must be between 0 and 4, got {level}")
    sphere = trimesh.creation.icosphere(subdivisions=level, radius=1.0)
    U = sphere.vertices / np.linalg.norm(sphere.vertices, axis=1, keepdims=True) * (1 - 1e-12)
    faces = np.asarray(sphere.faces, dtype=np.int64)
    T = U[faces]
    n = np.cross(T[:, 1] - T[:, 0], T[:, 2] - T[:, 0])
    dist = np.einsum("ij,ij->i", n, T[:, 0]) / np.linalg.norm(n, axis=1)
    return U, faces, float(dist.min()) * (1 - 1e-9)


@dataclass(frozen=True)
class EveryDirection:
    """The least grip force holding the weight in every direction of gravity, bracketed.

    Attributes
    ----------
    lo, hi : float
        ``lo <= max over unit d of s*(d) <= hi`` (newtons; ``hi`` may be ``inf``).
    worst : GripBound
        The bound at the vertex direction with the largest ``s*`` (its slip certificate proves
        ``lo``).
    level : int
        Icosphere level of the direction polytope.
    radius : float
        Its inradius ``r``: the vertices ``u_j / r`` carry the hold certificates.
    vertices : tuple of GripBound
        The bound at every ``u_j / r`` (its forces prove ``hi``).
    note : str
        Empty, or how many of the bounds behind ``lo`` and ``hi`` were widened or withdrawn
        because a certificate did not re-check (:attr:`GripBound.note`), with the first reason.
    """

    lo: float
    hi: float
    worst: GripBound
    level: int
    radius: float
    vertices: tuple[GripBound, ...]
    note: str = ""


def every_direction(grasp: Grasp, mass: float, com: Sequence[float], *, level: int = 1) -> EveryDirection:
    """Bracket the least grip force that holds the weight in every direction of gravity (module
    docstring, "Every direction").

    Examples
    --------
    >>> from qualgrasp.certify import Contact, Grasp
    >>> g = Grasp((Contact((0.05, 0, 0), (-1, 0, 0), "soft", 0.5, torsion=0.005),
    ...            Contact((-0.05, 0, 0), (1, 0, 0), "soft", 0.5, torsion=0.005)), center=(0, 0, 0))
    >>> e = every_direction(g, 0.2, (0, 0, 0), level=1)
    >>> mg = 0.2 * G  # the worst gravity lies 45 degrees between the faces and the closing axis: sqrt(2) m g
    >>> bool(e.lo <= 2 ** 0.5 * mg <= e.hi), round(e.hi / e.lo, 3)
    (True, 1.07)
    >>> bool(check_every_direction(g, 0.2, (0, 0, 0), e))
    True
    """
    programs = _Programs(grasp)
    U, _, r = direction_polytope(level)
    at_u = [least_grip(grasp, mass, com, u, programs=programs) for u in U]
    worst = max(at_u, key=lambda b: (b.hi, b.lo))
    lo = max(b.lo for b in at_u)
    vertices = []
    for u, b in zip(U, at_u):
        v = u / r
        if math.isinf(b.hi):
            vertices.append(GripBound(tuple(v), 0.0, math.inf, None, None))
            continue
        # sublinear: s*(u / r) = s*(u) / r; hold certificates at the scaled direction
        vertices.append(least_grip(grasp, mass, com, v, programs=programs))
    hi = max(b.hi for b in vertices)
    worst_lo = max(at_u, key=lambda b: b.lo)
    noted = [b.note for b in (worst_lo, *vertices) if b.note]
    note = f"{len(noted)} of {len(vertices) + 1} bounds widened or withdrawn: {noted[0]}" if noted else ""
    return EveryDirection(lo, hi, worst_lo if worst_lo.lo >= worst.lo else worst, level, r, tuple(vertices), note)


def check_every_direction(grasp: Grasp, mass: float, com: Sequence[float], result: EveryDirection) -> Check:
    """Re-check both ends of an :class:`EveryDirection` bracket exactly: the slip certificate at
    the worst direction (``|u| <= 1``) proves ``lo``; the direction polytope's faces (closed,
    positively oriented, every face at least 1 from the origin) and the hold certificate at every
    vertex prove ``hi``.
    """
    u = result.worst.direction
    if sum(Fraction(v) ** 2 for v in u) > 1:
        return Check(False, "the worst direction is longer than 1")
    got = _check_lower(grasp, mass, com, u, result.lo, result.worst.slip)
    if not got:
        return Check(False, f"lower bound: {got.reason}")
    if math.isinf(result.hi):
        return Check(True)
    V = np.array([b.direction for b in result.vertices])
    _, faces, _ = direction_polytope(result.level)
    if len(V) != len(direction_polytope(result.level)[0]):
        return Check(False, "the vertices are not those of the stated direction polytope")
    reason = cycle_check(faces, len(V))
    if reason:
        return Check(False, f"direction polytope: {reason}")
    Vx = to_exact(V)
    for f in faces:
        d2 = exact_face([list(Vx[i]) for i in f])
        if d2 is None or d2 < 1:
            return Check(False, "a face of the direction polytope is nearer than 1 to the origin")
    for b in result.vertices:
        if b.hi > result.hi:
            return Check(False, "a vertex needs more than the stated upper bound")
        got = check_holds(grasp, mass, com, b.direction, result.hi * (1 + 1e-12), b.forces)
        if not got:
            return Check(False, f"upper bound at {np.round(b.direction, 4).tolist()}: {got.reason}")
    return Check(True)


def hold_verdict(lo: float, hi: float, budget: float) -> str:
    """``'holds'`` when the certified upper end ``hi <= budget``, ``'slips'`` when the certified
    lower end ``lo > budget``, else ``'undecided'`` (the budget lies within the bracket).

    Examples
    --------
    >>> hold_verdict(9.8, 9.81, 10.0), hold_verdict(9.8, 9.81, 9.0), hold_verdict(9.8, 9.81, 9.805)
    ('holds', 'slips', 'undecided')
    """
    if hi <= budget:
        return "holds"
    if lo > budget:
        return "slips"
    return "undecided"


def parse_gravity(text: str) -> np.ndarray | None:
    """The ``--gravity`` option: ``all`` (None: every direction) or one direction ``x,y,z``
    (normalised); an :class:`~qualgrasp.certify.errors.OptionError` naming it otherwise.

    Examples
    --------
    >>> parse_gravity("all") is None, parse_gravity("0,0,-2").tolist()
    (True, [0.0, 0.0, -1.0])
    """
    if text == "all":
        return None
    try:
        d = np.array([float(v) for v in text.split(",")])
    except ValueError:
        d = np.zeros(0)
    if d.shape != (3,) or not np.isfinite(d).all() or np.linalg.norm(d) == 0:
        raise OptionError(f"--gravity must be 'all' or a direction x,y,z (three numbers, not all 0), got {text!r}")
    return d / np.linalg.norm(d)


def hold_fields(grasp: Grasp, props, budget: float, gravity: np.ndarray | None, level: int) -> dict:
    """The hold columns of one grasp (``hold_status``, ``hold_budget``, ``grip_lo``, ``grip_hi``,
    ``hold_verified``, ``hold_note``, ``hold_certificate``) for the grip force ``budget`` (N):
    :func:`least_grip` along ``gravity``, or :func:`every_direction` at icosphere ``level`` when
    ``gravity`` is None, with ``props`` the object's mass properties. Both ends are re-checked
    here once more; should that fail, neither end is stated (``undecided``) and ``hold_note``
    gives the reason."""
    if gravity is None:
        e = every_direction(grasp, props.mass, props.com, level=level)
        ok = check_every_direction(grasp, props.mass, props.com, e)
        lo, hi, note = e.lo, e.hi, e.note
        cert = {"level": e.level, "radius": e.radius, "worst": e.worst.to_json(),
                "vertices": [v.to_json() for v in e.vertices]}
    else:
        b = least_grip(grasp, props.mass, props.com, gravity)
        ok = check_bound(grasp, props.mass, props.com, b)
        lo, hi, note, cert = b.lo, b.hi, b.note, b.to_json()
    if not ok:
        lo, hi, note = 0.0, math.inf, f"no bound stated: the re-check failed ({ok.reason})"
    status = hold_verdict(lo, hi, budget)
    return {"hold_status": status, "hold_budget": budget, "grip_lo": None if math.isinf(lo) else lo,
            "grip_hi": None if math.isinf(hi) else hi,
            "hold_verified": bool(ok), "hold_note": note or None, "hold_certificate": json.dumps(cert)}


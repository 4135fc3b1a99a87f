"""The weight-holding task: does a grasp hold the object's own weight, in a direction of gravity
or in every direction, with a grip force of at most ``F``? A conic programme with certificates.

The programme
-------------
A grasp's contacts (certify's cones: exact Lorentz cones for ``point`` and ``soft`` contacts,
rays for frictionless ones) hold the object of mass ``m`` with centre of mass ``com`` against
gravity ``g d`` (``d`` a unit direction, ``g`` = :data:`G`) when forces ``x`` on certify's
certificate columns ``C`` (:func:`qualgrasp.certify.problem.grasp_system`; torques about the
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
``C_B delta = -r`` exactly on a basis ``B`` of the columns (:mod:`qualgrasp.certify.exact`); the
corrected forces must lie strictly inside every cone (:func:`qualgrasp.certify.cones.inside`)
and have ``nu_b < s``. That exhibits exact forces holding the weight at grip force ``s``.

``slips at s`` (no forces exist at grip force ``s``): a Farkas certificate, a wrench functional
``y`` and multipliers ``lambda_b >= 0``, with a set of ``tight`` contacts that ``y`` is projected
orthogonal to (exactly), such that for every other contact ``a_b = C_b' y - lambda_b nu_b`` lies
strictly in the polar cone (:func:`qualgrasp.certify.cones.polar`) and ``-y . w > s sum lambda_b``.
For any forces in the cones with ``nu_b <= s``: ``-y . w = y . C x = sum_b a_b . x_b + sum_b
lambda_b nu_b(x_b) <= s sum_b lambda_b``, a contradiction. With ``lambda = 0`` it proves that no
grip force at all holds the weight (for example two point contacts and a weight off the line
through them: a torque about that line no contact can resist).

The least grip force is reported as a certified bracket ``lo <= s* <= hi``: forces at ``hi`` and
a Farkas certificate at ``lo``, ``hi / lo - 1`` about ``2e-6``.

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
:func:`qualgrasp.certify.evidence.exact_face`). ``r`` is 0.795 for the icosahedron (level 0),
0.934 at level 1 (42 directions), 0.982 at level 2 (162) and 0.995 at level 3 (642).

Closed form (the tests): a box of mass ``m`` held across two opposite faces by two point contacts
with friction ``mu`` on the line through its centre, gravity along the faces, needs
``s* = m g / (2 mu)``: it holds its weight iff ``mu F >= m g / 2``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction
from typing import Sequence

import cvxpy as cp
import numpy as np
import trimesh

from ..core import cones
from ..core import exact as ex
from ..core.certificates import Check
from ..quality.evidence import cycle_check, exact_face
from ..core.grasp import Grasp
from ..core.problem import Block, grasp_system
from ..core.wrench import to_exact, wrench

__all__ = ["G", "GripBound", "SlipCertificate", "EveryDirection", "gravity_wrench", "least_grip",
           "check_holds", "check_slips", "direction_polytope", "every_direction", "check_every_direction",
           "hold_verdict"]

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
        Certificate that grip force ``lo`` does not hold (None when ``lo`` is 0).
    """

    direction: tuple[float, ...]
    lo: float
    hi: float
    forces: tuple[float, ...] | None
    slip: SlipCertificate | None

    def to_json(self) -> dict:
        return {"direction": list(self.direction), "lo": None if math.isinf(self.lo) else self.lo,
                "hi": None if math.isinf(self.hi) else self.hi,
                "forces": None if self.forces is None else list(self.forces),
                "slip": None if self.slip is None else self.slip.to_json()}


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
    """The two programmes of one grasp, built once (cvxpy Parameters for the weight)."""

    def __init__(self, grasp: Grasp) -> None:
        C, blocks, _ = grasp_system(grasp, socp=True)
        self.C, self.blocks = np.asarray(C, dtype=float), blocks
        d, k = self.C.shape
        self.N = _normal_rows(blocks, k)
        self.w = cp.Parameter(d)
        self.budget = cp.Parameter(nonneg=True)
        x, theta, t = cp.Variable(k), cp.Variable(), cp.Variable()
        self.x, self.theta, self.t = x, theta, t
        cone_h = self._cones(x, 0)
        self.equilibrium = self.C @ x + theta * self.w == 0
        self.normal = self.N @ x <= 1
        self.least = cp.Problem(cp.Maximize(theta), [self.equilibrium, self.normal, theta >= 0, *cone_h])
        # strict forces at a budget: maximise the smallest slack of the cones and of the budget
        self.interior = cp.Problem(cp.Maximize(t), [self.C @ x + self.w == 0, self.N @ x <= self.budget - t,
                                                    t <= self.budget, *self._cones(x, t)])

    def _cones(self, x, t) -> list:
        out = []
        for b in self.blocks:
            if b.cone == "ray":
                out.append(x[b.cols[0]] >= t)
                continue
            dim = len(b.n)
            n = np.array([float(v) for v in b.n])
            f = x[list(b.cols[:dim])]
            fn = n @ f
            parts = [f - fn * n] + [x[j] / float(b.g) for j in b.cols[dim:]]
            out.append(cp.SOC(float(b.mu) * fn - t, cp.hstack(parts)))
        return out

    def solve(self, problem: cp.Problem) -> bool:
        try:
            problem.solve(solver=cp.CLARABEL)
        except cp.error.SolverError:
            return False
        return problem.status in (cp.OPTIMAL, cp.OPTIMAL_INACCURATE)


def _slip(programs: _Programs, w: np.ndarray, theta: float, budget: float) -> SlipCertificate | None:
    """A Farkas certificate at ``budget`` from the duals of the homogeneous programme, made
    strict (module docstring); None when it does not check."""
    y_eq = programs.equilibrium.dual_value
    lam = programs.normal.dual_value
    if y_eq is None or lam is None:
        return None
    lam = np.maximum(np.asarray(lam, dtype=float).ravel(), 0.0)
    scale = np.abs(programs.C).max()
    for sign in (1.0, -1.0):
        y = sign * np.asarray(y_eq, dtype=float).ravel()
        if not -y @ w > 0:
            continue
        y = y / -(y @ w)  # normalise: -y . w = 1, so lam's sum is about theta*
        A = programs.C.T @ y
        tight = tuple(i for i, b in enumerate(programs.blocks)
                      if np.abs(A[list(b.cols)]).max() <= 1e-9 * scale * np.abs(y).max())
        lam_b = np.where(np.isin(np.arange(len(lam)), tight), 0.0, lam / max(lam.sum(), 1e-300) * theta)
        # use half the slack 1 - budget sum(lam) to push every functional strictly into its polar cone
        room = 1.0 - budget * lam_b.sum()
        if room <= 0:
            continue
        lam_b = lam_b + np.where(np.isin(np.arange(len(lam)), tight), 0.0, room / (2 * max(budget, 1e-300) * len(lam)))
        cert = SlipCertificate(float(budget), tuple(float(v) for v in y), tuple(float(v) for v in lam_b), tight)
        return cert
    return None


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
        Its certificates still need :func:`check_holds` / :func:`check_slips` (they are made
        here from floating-point solver output; the checks are exact).

    Examples
    --------
    >>> from qualgrasp.certify import Contact, Grasp
    >>> g = Grasp((Contact((0.05, 0, 0), (-1, 0, 0), "point", 0.5),
    ...            Contact((-0.05, 0, 0), (1, 0, 0), "point", 0.5)), center=(0, 0, 0))
    >>> b = least_grip(g, 1.0, (0, 0, 0), (0, 0, -1))
    >>> b.lo <= 9.80665 <= b.hi, round(b.hi / b.lo - 1, 6)      # m g / (2 mu) = 9.80665 N
    (True, 2e-06)
    """
    programs = programs or _Programs(grasp)
    d = tuple(float(v) for v in direction)
    w = gravity_wrench(grasp, mass, com, d)
    programs.w.value = w
    if not programs.solve(programs.least):
        return GripBound(d, 0.0, math.inf, None, None)
    theta = float(programs.theta.value)
    if theta <= 0:
        slip = _slip(programs, w, 0.0, 1.0)
        return GripBound(d, 0.0 if slip is None else math.inf, math.inf, None, slip)
    s_star = 1.0 / theta
    lo, hi = s_star * (1 - _BRACKET), s_star * (1 + _BRACKET)
    slip = _slip(programs, w, theta, lo)
    if slip is not None and sum(slip.lam) == 0:
        # theta* is a rounding residue: the certificate separates the weight at every grip force
        return GripBound(d, math.inf, math.inf, None, slip)
    programs.budget.value = hi
    forces = None
    if programs.solve(programs.interior) and programs.t.value is not None and programs.t.value > 0:
        forces = tuple(float(v) for v in programs.x.value)
    return GripBound(d, lo if slip is not None else 0.0, hi if forces is not None else math.inf, forces, slip)


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
    """

    lo: float
    hi: float
    worst: GripBound
    level: int
    radius: float
    vertices: tuple[GripBound, ...]


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
    return EveryDirection(lo, hi, worst_lo if worst_lo.lo >= worst.lo else worst, level, r, tuple(vertices))


def check_every_direction(grasp: Grasp, mass: float, com: Sequence[float], result: EveryDirection) -> Check:
    """Re-check both ends of an :class:`EveryDirection` bracket exactly: the slip certificate at
    the worst direction (``|u| <= 1``) proves ``lo``; the direction polytope's faces (closed,
    positively oriented, every face at least 1 from the origin) and the hold certificate at every
    vertex prove ``hi``.
    """
    u = result.worst.direction
    if sum(Fraction(v) ** 2 for v in u) > 1:
        return Check(False, "the worst direction is longer than 1")
    if result.lo > 0:
        if result.worst.slip is None or result.worst.slip.budget != result.lo:
            return Check(False, "no slip certificate at the stated lower bound")
        got = check_slips(grasp, mass, com, u, result.worst.slip)
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

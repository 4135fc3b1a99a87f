"""Columnar certification of a chunk of grasps: compiled kernels for whole groups at once.

:func:`certify_table` takes a grasp table (any layout :func:`qualgrasp.certify.files.columns.grasp_columns`
reads) and returns the results table (:data:`qualgrasp.certify.files.results.RESULT_SCHEMA`), row for
row equal to what :func:`qualgrasp.certify.certify_grasp` gives grasp by grasp. Valid grasps are
grouped by contact pattern (dimension, contact count, each contact's model and variant):

* planar groups go through :func:`qualgrasp.certify._kernels.planar.planar_batch`: the LP (the
  same kernel the per-grasp path calls), the certificate and its rigorous re-check in floating
  point with error bounds; a force-closure LP with too many bases to enumerate (over 30
  generators: 16 point contacts or more) by the compiled dual barrier method for the whole group,
  as the per-grasp fast route solves it, its clear verdicts proved in floats (:func:`_planar_barrier`);
  with quality, the exact planar epsilon and its evidence of every
  closure row by :func:`qualgrasp.certify.quality.bounds.planar_epsilon_columns`, compiled for the
  whole group and row for row what the per-grasp path's
  :func:`~qualgrasp.certify.quality.bounds.planar_epsilons` gives (rows its float checks cannot
  settle take that function);
* spatial groups through the compiled dual barrier method over exact cones, with clear verdicts
  proved columnar, and near-boundary rows decided by the per-grasp rules on the arrays already
  built (the squeeze rule, then clarabel); form closure with six or more contacts by the fast
  solver's own route.

Planar rows whose generator matrix is numerically rank deficient (normals through one point:
antipodal grasps of discs, squares grasped through the centre; repeated or collinear contacts) are
decided by the per-grasp rules on the arrays (:func:`_planar_thin`: the dual direction's Farkas
certificate, clarabel where the enumeration has no dual direction, the exact rank in integers or
proved in floats), each certificate's exact re-check decided without Fractions. Where the dual
direction is orthogonal to nearly parallel generators only in floats, both routes state the
exact normal of their span instead (:func:`qualgrasp.certify.core.closure.exact_farkas`), here
from integers (:func:`_projected_normal`).

Every row these rules do not settle (invalid input, near-degenerate problems, certificates the
float re-check cannot decide, spatial rows that need the epsilon) goes through the per-grasp
path, so the two agree by construction. This module solves; the results tables
are built in Arrow by ``qualgrasp.certify.batch._arrow``.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import partial
from itertools import combinations

import numpy as np
import pyarrow as pa

from .._kernels.barrier import barrier_batch
from .._kernels.evidence import generator_rows
from .._kernels.jit import kernel_array
from .._kernels.linalg import U as U_ROUND, projection_bound, world_values
from .._kernels.planar import pair_null_rows, planar_batch, thin_screen
from .._kernels.recheck import certify_rows, null_rows, verify_farkas_general, verify_interior_general
from ..core.certificates import Tolerances, margin_proved, verify
from ..core.closure import decide, farkas_from_arrays
from ..errors import SolverError
from ..files.columns import GraspColumns, grasp_columns
from ..core.cones import LORENTZ
from ..core.grasp import Contact, Grasp
from ..core.problem import (Block, ClosureProblem, System, conic_block_arrays, conic_columns, grasp_problem,
                            grasp_system, ray_block_arrays, ray_blocks, ray_problem)
from ..quality.bounds import planar_epsilon_columns
from ..solvers import BARRIER_NEAR_ZERO, FastSolver, make_solver
from ..solvers.barrier import EXIT_BELOW, GAP_TOL, MAX_NEWTON
from ..solvers.enumeration import FEAS, bases
from ..solvers.squeeze import squeeze_farkas
from ..files.reader import rows_to_table
from ._arrow import assemble, evidence_array, group_table
from .. import models as registry
from ..core.exact import dyadic_integers, unit_direction
from ..core.wrench import (force_column_errors, force_columns, generator_columns, generator_layout,
                           planar_generator_rank, planar_pair_normal)

__all__ = ["certify_table", "PlanarScreen", "planar_screen"]


def _planar_kernel(P, N, mu, width, c, L, models, variants, tol: Tolerances, quality: bool, *,
                   form_only: bool = False):
    """:func:`qualgrasp.certify._kernels.planar.planar_batch` on grasps sharing the contact models
    and variants: force and form closure (verdict codes, margins, weights, bases, directions)
    and epsilons. ``form_only``: form closure on both sides (for a group whose force-closure LP
    has too many bases to enumerate)."""
    owner_f, offset_f, friction_f = generator_layout(models, variants, 2, frictionless=True)
    owner, offset, friction = (owner_f, offset_f, friction_f) if form_only else generator_layout(models, variants, 2)
    same = (np.array_equal(owner, owner_f) and np.array_equal(offset, offset_f)
            and np.array_equal(friction, friction_f))  # frictionless contacts only: form is force
    return planar_batch(
        kernel_array(P), kernel_array(N), kernel_array(mu), kernel_array(width), kernel_array(c), kernel_array(L),
        owner, offset, friction, bases(len(owner), 3), owner_f, offset_f, friction_f,
        bases(len(owner_f), 3), same, tol.margin, FEAS, tol.residual, quality)


@dataclass(frozen=True, eq=False)
class PlanarScreen:
    """Columnar force-closure verdicts and exact epsilons of a batch of planar grasps.

    Attributes
    ----------
    closure : numpy.ndarray
        ``(B,)`` bool: force closure **proved** (LP optimum above the margin tolerance and the
        interior certificate re-checked in floating point with rigorous error bounds).
    settled : numpy.ndarray
        ``(B,)`` bool: the columnar rules settled the verdict (closure proved, or a strict or
        null-space Farkas certificate proved); unsettled rows (near-degenerate, tight contacts)
        are what :func:`qualgrasp.certify.certify_grasp` decides grasp by grasp.
    margin : numpy.ndarray
        ``(B,)`` min-weight margin ``t*`` of force closure (``-inf`` when infeasible).
    eps_l1, eps_linf : numpy.ndarray
        ``(B,)`` exact Ferrari-Canny epsilon of the L1 and L-infinity grasp wrench spaces where
        ``closure``, else 0 (with the batch's ``center`` and ``length``).
    """

    closure: np.ndarray
    settled: np.ndarray
    margin: np.ndarray
    eps_l1: np.ndarray
    eps_linf: np.ndarray


def planar_screen(P, N, mu, center, length, *, quality: bool = True,
                  tol: Tolerances = Tolerances()) -> PlanarScreen:
    """Force closure and epsilon of many planar grasps sharing one contact pattern, columnar.

    The same compiled kernels as :func:`certify_table` (:func:`qualgrasp.certify._kernels.planar.planar_batch`:
    min-weight LP by basis enumeration, certificate re-checked in floating point, exact planar
    epsilon), called directly on arrays, without building grasp tables or certificates. Use it
    to screen large candidate sets (a grasp search); a grasp retained is then certified with
    :func:`qualgrasp.certify.certify_grasp`, which decides exactly the rows left unsettled here.

    Parameters
    ----------
    P, N : array_like
        ``(B, m, 2)`` contact points and **inward** normals (normalised here).
    mu : array_like
        ``(B, m)`` friction coefficients; 0 is a frictionless contact. Every row must have the
        same pattern of frictionless and ``point`` contacts.
    center : array_like
        ``(B, 2)`` or ``(2,)`` reference point of torques.
    length : array_like or float
        ``(B,)`` or scalar length dividing torques, ``> 0``.
    quality : bool
        Compute the epsilons (otherwise they are 0).
    tol : Tolerances
        Verdict tolerances (as for :func:`qualgrasp.certify.certify_grasp`).

    Returns
    -------
    PlanarScreen

    Raises
    ------
    ValueError
        Shapes disagree, rows mix contact patterns, or a normal or length is not usable.
    """
    P = np.asarray(P, dtype=float)
    N = np.asarray(N, dtype=float)
    if P.ndim != 3 or P.shape[2] != 2 or N.shape != P.shape:
        raise ValueError(f"P and N must both be (B, m, 2), got {P.shape} and {N.shape}")
    B, m, _ = P.shape
    mu = np.broadcast_to(np.asarray(mu, dtype=float), (B, m))
    center = np.broadcast_to(np.asarray(center, dtype=float), (B, 2))
    length = np.broadcast_to(np.asarray(length, dtype=float), (B,))
    norm = np.linalg.norm(N, axis=2, keepdims=True)
    if not (np.isfinite(P).all() and np.isfinite(N).all() and (norm >= 1e-9).all()):
        raise ValueError("points and normals must be finite, normals non-zero")
    if not (np.isfinite(mu).all() and (mu >= 0).all() and (length > 0).all() and np.isfinite(length).all()):
        raise ValueError("mu must be finite and >= 0, length finite and > 0")
    pattern = mu > 0
    if B and not (pattern == pattern[0]).all():
        raise ValueError("every row must have the same pattern of frictionless and point contacts")
    N = np.where(np.abs(norm - 1.0) > 1e-12, N / norm, N)  # as certify.core.grasp.Contact stores it
    if B == 0:
        empty = np.zeros(0)
        return PlanarScreen(empty.astype(bool), empty.astype(bool), empty, empty, empty)
    models = tuple(registry.POINT.name if f else registry.FRICTIONLESS.name for f in pattern[0])
    code, t, *_, eps = _planar_kernel(P, N, mu, np.zeros((B, m)), center, length, models, (0,) * m,
                                      tol, quality)
    closure = code == 1
    return PlanarScreen(closure, code > 0, t, np.where(closure, eps[:, 0], 0.0),
                        np.where(closure, eps[:, 1], 0.0))


def _planar_group(cols: GraspColumns, rows: np.ndarray, options, tol: Tolerances):
    """Certify the planar grasps ``rows`` (one contact pattern) with :func:`planar_batch`;
    return the settled rows and their result columns."""
    models, variants = cols.models_of(rows[0]), cols.variants_of(rows[0])
    layouts = {fl: generator_layout(models, variants, 2, frictionless=fl) for fl in (False, True)}
    force_layout = layouts[False]
    enumerated = FastSolver.enumerates(len(force_layout[0]), 3)
    if not FastSolver.enumerates(len(layouts[True][0]), 3):
        # the per-grasp fast route solves both by the barrier method: both routes give its rows
        return np.zeros(len(rows), dtype=bool), {}
    P, N, params = cols.contacts(rows)
    # the kernels' arrays once, for _planar_kernel and _planar_thin's per-row kernel calls alike
    P, N, mu, width = kernel_array(P[:, :, :2]), kernel_array(N[:, :, :2]), params["mu"], registry.offset_lengths(models, params)
    c, L = cols.center[rows, :2], cols.length[rows]
    (code, t, lam, basis, y, code_f, t_f, lam_f, basis_f, y_f, _) = _planar_kernel(
        P, N, mu, width, c, L, models, variants, tol, False, form_only=not enumerated)
    out = {"force": (code, t, lam, basis, y), "form": (code_f, t_f, lam_f, basis_f, y_f)}
    verified = {}
    sides = (("force", False), ("form", True))
    if not enumerated:  # force closure as the per-grasp fast route solves it: the barrier method
        W, E = generator_rows(P, N, kernel_array(mu), kernel_array(width), kernel_array(c), kernel_array(L),
                              *force_layout)
        out["force"], out["tight"] = _planar_barrier(W, E, tol), {}
        verified["force"] = np.ones(len(rows), dtype=bool)
        sides = (("form", True),)
    for side, frictionless in sides:
        layout = layouts[frictionless]
        if side == "form" and all(np.array_equal(a, b) for a, b in zip(layout, force_layout)):
            out["form"], out["form_tight"] = out["force"], out["tight"]  # frictionless: form is force
            break
        out[side], out["tight" if side == "force" else "form_tight"], verified[side] = _planar_thin(
            P, N, mu, width, c, L, layout, out[side], tol)
    out["verified"] = verified["force"] & verified.get("form", verified["force"])
    code, code_f = out["force"][0], out["form"][0]
    settled = (code > 0) & (code_f > 0)
    if options.quality:
        out["eps"] = _planar_quality(cols, rows, (code == 1) & settled, P, N, mu, width, c, L, models,
                                     variants, options)
    return settled, out


def _planar_barrier(W, E, tol: Tolerances):
    """Force closure of planar grasps whose LP has too many bases to enumerate, as the per-grasp
    fast route decides it: :func:`_barrier_rays` on the generator columns ``W`` (B, 3, k) and
    their error bounds ``E``, an interior certificate kept only where its margin is proved
    (:func:`~qualgrasp.certify.core.certificates.margin_proved`). Returns ``(code, t, lam, basis,
    y)``."""
    k = W.shape[2]
    return _barrier_rays(W, E, np.zeros((len(W), k, 2)), max(1e-6, 2 * tol.rank), tol, margins=True)


def _barrier_rays(W, E, normals, thin_rel: float, tol: Tolerances, *, closure: bool = True, margins: bool = False):
    """Closure programmes of generator rays ``W`` (B, d, k) (error bounds ``E``) whose LPs the
    per-grasp fast route hands to the compiled dual barrier method
    (:class:`qualgrasp.certify.solvers.FastSolver`), solved by that method for the whole batch;
    its clear verdicts proved columnar (:func:`~qualgrasp.certify._kernels.recheck.certify_rows`,
    ``normals`` (B, k, .) its rays' normals): an interior certificate (unless ``closure`` is
    False; with ``margins``, only where its stated margin is proved as well, by
    :func:`~qualgrasp.certify.core.certificates.margin_proved`) or a strict Farkas direction.
    Rows numerically thin (least singular value not above ``thin_rel`` times the largest:
    conservative, the per-grasp rank test is sharper), near the boundary (what FastSolver hands
    to clarabel) or not proved this way keep code 0, for the per-grasp route. Returns ``(code,
    t, lam, basis, y)``."""
    B, d, k = W.shape
    status, t, y, xn, _ = barrier_batch(np.ascontiguousarray(np.swapaxes(W, 1, 2)), np.zeros((B, k, 1, d)),
                                        np.zeros(k, dtype=np.int64), np.ones((B, k)), EXIT_BELOW, GAP_TOL,
                                        MAX_NEWTON)
    sv = np.linalg.svd(W, compute_uv=False)
    thin = ~(sv[:, -1] > thin_rel * sv[:, 0])
    near = (status == 2) | (np.abs(t) < BARRIER_NEAR_ZERO)  # what FastSolver hands to clarabel
    interior = ~thin & ~near & (status == 0) & (t >= tol.margin) & closure
    farkas = ~thin & ~near & (t < tol.margin)
    values = xn + 0.0  # the identity value map's values (ClosureProblem.values): -0 stated as +0
    with np.errstate(invalid="ignore", divide="ignore"):
        yn = np.nan_to_num(y / np.sqrt(np.sum(y * y, axis=1, keepdims=True)))
    arrays = ray_blocks(k, normals.shape[2])
    zeros = np.zeros((B, k))
    code, basis = certify_rows(W, E, *arrays[:3], np.ascontiguousarray(normals), zeros, zeros, values, yn,
                               interior, farkas, np.abs(W).max(axis=(1, 2)), tol.residual)
    for i in np.flatnonzero(code == 1) if margins else ():  # the margin stated must be the one verify certifies
        if not margin_proved(float(t[i]), W[i], E[i], arrays, values[i], basis[i]):
            code[i] = 0
    return code, np.where(code == 1, t, 0.0), values, basis, yn


THIN_CODES = {2: "strict Farkas", 3: "null space", 4: "Farkas with tight generators", 5: "degenerate (rank)"}
"""Verdict codes :func:`_planar_thin` gives rows whose generators are numerically rank deficient."""


def _planar_thin(P, N, mu, width, c, L, layout, verdict, tol: Tolerances):
    """Settle the rows of a planar group that the compiled rules leave because their generator
    matrix is numerically rank deficient (normals through one point, repeated or collinear
    contacts), by the per-grasp rules of :func:`qualgrasp.certify.core.closure.decide` on the
    arrays, each certificate's exact re-check decided without rationals.

    With fewer than three generators ``decide`` states the null direction the compiled kernel
    already tried. With three or more and a singular value ratio at most ``tol.rank`` it takes,
    in order: the Farkas certificate of the fast solver's dual direction (the kernel's, or
    clarabel's when the kernel has none, as :class:`qualgrasp.certify.solvers.FastSolver` does;
    :func:`qualgrasp.certify.core.closure.farkas_from_arrays`, the same call); else, by the exact
    rank (:func:`qualgrasp.certify.core.wrench.planar_generator_rank`: integers, no Fractions),
    the null direction of the last left singular vector, or ``degenerate`` (reason ``rank``).
    The exact re-check is then decided: a strict direction by the rigorous float check; one
    orthogonal to some generators by :func:`_orthogonal`; ``degenerate`` by the exact rank
    itself (what the checker recomputes). A certificate proved to fail the re-check is stated
    unverified, as the per-grasp path states it; rows decided neither way stay unsettled (the
    per-grasp path). ``verdict`` is the side's ``(code, t, lam, basis, y)``; returns it updated
    (codes :data:`THIN_CODES`), the tight generators of code-4 rows and the verified flags."""
    code, t, lam, basis, y = (np.array(a) for a in verdict)
    verified = np.ones(len(code), dtype=bool)
    owner, offset, friction = layout
    k = len(owner)
    rows = np.flatnonzero(code == 0)

    def pair_normal(i, cols=slice(None)):  # the exact normal of two generators of row i
        return planar_pair_normal(P[i], N[i], mu[i], width[i], c[i], L[i], owner[cols], offset[cols], friction[cols])

    tight_rows: dict[int, np.ndarray] = {}
    if len(rows):
        W, E = generator_rows(*(kernel_array(a[rows]) for a in (P, N, mu, width, c, L)), owner, offset, friction)
    else:  # nothing to settle: no kernel to load or compile
        W, E = np.empty((0, 3, k)), np.empty((0, 3, k))
    if k < 3:  # the kernel's float proof of its null direction failed: decided exactly
        for i in rows if k == 2 else ():
            z = pair_normal(i)
            yi = y[i] if _pair_orthogonal(z, y[i]) else _projected_normal(z, y[i])
            if yi is not None and _pair_orthogonal(z, yi):
                code[i], y[i] = 3, yi
        return (code, t, lam, basis, y), tight_rows, verified
    U, sv, _ = np.linalg.svd(W, full_matrices=False) if len(rows) else (None, np.ones((0, 1)), None)
    thin_rows = np.flatnonzero(sv[:, -1] <= tol.rank * sv[:, 0])
    if not len(thin_rows):
        return (code, t, lam, basis, y), tight_rows, verified
    at = rows[thin_rows]
    ok, yf, tight, proved, full, parallel = thin_screen(
        np.ascontiguousarray(W[thin_rows]), np.ascontiguousarray(E[thin_rows]), np.ascontiguousarray(y[at]),
        np.ascontiguousarray(t[at]), tol.margin, 1e-7, np.ascontiguousarray(P[at]), np.ascontiguousarray(N[at]),
        np.ascontiguousarray(width[at]), owner, not friction.any(), not offset.any())
    has_y = np.any(y[at] != 0, axis=1)
    strict = has_y & ok & ~tight.any(axis=1)
    code[at[strict & proved]] = 2
    y[at[strict & proved]] = yf[strict & proved]
    code[at[has_y & ~ok & full]] = 5  # no certificate from the dual direction, exact rank 3
    # every generator tight, exact rank 3: nothing is left once projected, the rank decides
    refused = has_y & ok & tight.all(axis=1) & full
    code[at[refused]] = 5
    arrays = ray_blocks(k, 2)
    solver = make_solver("fast")
    # rank at most 2 (parallel normals, two distinct contacts): the all-tight direction, or the last singular vector
    # when the dual direction gives no certificate, decided in one compiled pass
    pair = has_y & parallel & (~ok | tight.all(axis=1))
    if pair.any():
        yp = np.where(ok[pair][:, None], yf[pair], U[thin_rows[pair], :, -1])
        state = pair_null_rows(np.ascontiguousarray(W[thin_rows[pair]]), np.ascontiguousarray(E[thin_rows[pair]]),
                               np.ascontiguousarray(yp))
        for q, i in zip(np.flatnonzero(state == 0), at[pair][state == 0]):  # refuted: the span's exact normal
            z = _span_normal(partial(pair_normal, i), range(k))
            yq = None if z is None else _projected_normal(z, yp[q])
            if yq is not None and _pair_orthogonal(z, yq):
                yp[q], state[q] = yq, 1
        done = state == 1
        sel = at[pair][done]
        code[sel], y[sel] = 3, yp[done]
        pair[np.flatnonzero(pair)[~done]] = False
    for q in np.flatnonzero((~has_y | (ok & ~strict & ~refused) | (~ok & ~full)) & ~pair):
        r, i = thin_rows[q], at[q]
        rank_all = []  # the exact rank of every generator, computed once

        def exact_rank(cols=None, i=i, rank_all=rank_all):
            if cols is not None and len(cols) < k:
                return planar_generator_rank(P[i], N[i], mu[i], width[i], owner, offset, friction, cols)
            if not rank_all:
                rank_all.append(3 if full[q] else
                                planar_generator_rank(P[i], N[i], mu[i], width[i], owner, offset, friction))
            return rank_all[0]

        if has_y[q]:
            yc, mask = (yf[q], tight[q]) if ok[q] else (None, None)
        else:  # no dual basis: the fast solver asks clarabel, as grasp by grasp
            ti, yi = _solve_generators(solver, W[r])
            cert = None if yi is None or not ti < tol.margin else farkas_from_arrays(W[r], arrays, "generators", yi)
            yc, mask = (None, None) if cert is None else (np.array(cert.y), np.isin(np.arange(k), cert.tight))
        if yc is None:
            if exact_rank() == 3:
                code[i] = 5
                continue
            yc, mask = U[r, :, -1], np.ones(k, dtype=bool)
        if not mask.any():
            if verify_farkas_general(W[r], E[r], *arrays, yc, mask, 0.0):
                code[i], y[i] = 2, yc
            continue
        cols = np.flatnonzero(mask)
        proof, shift = _orthogonal(W[r], E[r], cols, exact_rank, partial(pair_normal, i), yc)
        if proof is False:  # as exact_farkas: the exact normal of the tight generators' span, if rank 2
            if exact_rank(cols) == 3:
                code[i] = 5  # nothing is left once projected; the exact rank of all is 3 as well
                continue
            z = _span_normal(partial(pair_normal, i), cols) if exact_rank(cols) == 2 else None
            yc = None if z is None else _projected_normal(z, yc)
            proof = None if yc is None or not _pair_orthogonal(z, yc) else True
            shift = 0.5e-6 * np.sqrt(yc @ yc) * (1 + 8 * U_ROUND) if proof else np.inf
        if proof and not mask.all():
            proof = None if not verify_farkas_general(W[r], E[r], *arrays, yc, mask, shift) else proof
        if proof:
            code[i], y[i] = (3 if mask.all() else 4), yc
            if not mask.all():
                tight_rows[int(i)] = cols
    return (code, t, lam, basis, y), tight_rows, verified


def _orthogonal(C, E, cols, exact_rank, pair_normal, y):
    """Is ``y`` orthogonal to the exact generators ``cols`` as the exact checker requires (its
    exact projection off their span non-zero and within ``1e-6 |y|`` of ``y``)? ``(True,
    bound on that distance)``, ``(False, inf)`` when proved not, ``(None, inf)`` when undecided.

    The exact rank ``r`` of the generators is computed: 3 leaves nothing once projected (not);
    two independent generators have an exact normal direction (``pair_normal(cols)``,
    :func:`_pair_orthogonal`); otherwise ``r`` of them proved independent in floats span the
    same space, which bounds the projection
    (:func:`qualgrasp.certify._kernels.linalg.projection_bound`); a generator whose functional
    on ``y`` is far from zero proves the projection large (:func:`_refuted`)."""
    ny = np.sqrt(y @ y)
    r = exact_rank(cols)
    if r == 3:
        return False, np.inf
    if r == 2 and len(cols) == 2:
        ok = _pair_orthogonal(pair_normal(cols), y)
        return ok, (0.5e-6 * ny * (1 + 8 * U_ROUND) if ok else np.inf)
    for keep in combinations(cols, r):
        keep = list(keep)
        bound = projection_bound(np.ascontiguousarray(C[:, keep]), np.ascontiguousarray(E[:, keep]), y)
        if np.isfinite(bound):
            if bound <= 1e-6 * ny * (1.0 - 8 * U_ROUND):
                return True, bound
            break
    return (False if _refuted(C, E, cols, y) else None), np.inf


def _span_normal(pair_normal, cols) -> tuple[int, ...] | None:
    """The exact normal direction (integers) of the span of the generators ``cols``, known to have
    exact rank 2: that of the first two of them that are not parallel (``pair_normal(pair)``,
    :func:`qualgrasp.certify.core.wrench.planar_pair_normal`); None when every pair is."""
    for pair in combinations(cols, 2):
        z = pair_normal(list(pair))
        if any(z):
            return tuple(z)
    return None


def _projected_normal(z, y) -> np.ndarray | None:
    """The exact projection of ``y`` off a plane with exact normal ``z`` (integers), rounded as
    :func:`qualgrasp.certify.core.closure.exact_farkas` rounds it: ``sign(y . z) z`` as a unit
    vector; None when ``y . z`` is exactly 0 or ``z`` is zero."""
    Y = dyadic_integers(y)[0]
    s = sum(a * b for a, b in zip(Y, z))
    if s == 0 or not any(z):
        return None
    return np.array(unit_direction([v if s > 0 else -v for v in z]))


def _pair_orthogonal(z, y) -> bool | None:
    """Does the exact checker accept ``y`` as orthogonal to two generators whose exact normal
    direction is ``z`` (:func:`qualgrasp.certify.core.wrench.planar_pair_normal`)? Its distance
    to its projection off their span is ``|y| sin(y, z)``, compared with ``1e-6 |y|`` exactly in
    integers: True below half of it, False above twice of it (the checker's own rounding
    cannot cross those), None otherwise or for parallel generators."""
    Y = dyadic_integers(y)[0]
    nz = sum(v * v for v in z)
    ny = sum(v * v for v in Y)
    if nz == 0 or ny == 0:
        return None
    yz = sum(a * b for a, b in zip(Y, z))
    gap = (ny * nz - yz * yz) * 10**12  # |y|^2 |z|^2 sin^2 / 1e-12
    if 4 * gap < ny * nz:
        return True
    if gap > 4 * ny * nz:
        return False
    return None


def _refuted(C, E, cols, y) -> bool:
    """Rigorous float proof that the exact projection of ``y`` onto the span of the exact
    generators ``cols`` (within ``E`` of ``C``) is longer than ``2e-6 |y|``: for any one
    generator ``c`` it is at least ``|c . y| / |c|``. Twice the checker's threshold, so that its
    own rounding cannot accept it."""
    g = 5 * U_ROUND / (1 - 5 * U_ROUND)
    ny = np.sqrt(y @ y) * (1 + 4 * U_ROUND)
    for j in cols:
        a = abs(C[:, j] @ y)
        err = np.sum((E[:, j] + g * np.abs(C[:, j])) * np.abs(y))
        nc = np.sqrt(np.sum((np.abs(C[:, j]) + E[:, j]) ** 2)) * (1 + 4 * U_ROUND)
        if (a - err) * (1 - 4 * U_ROUND) > 2e-6 * ny * nc:
            return True
    return False


def _solve_generators(solver, W):
    """``(t, y)`` of the fast solver on the closure programme of the generator columns ``W``
    (``y`` None when it has none, ``t`` -inf when it fails: decide then goes by the rank)."""
    problem = ray_problem(System(W, (), "generators"))
    try:
        sol = solver.solve(problem)
    except SolverError:
        return -np.inf, None
    return sol.t, sol.y


def _planar_quality(cols, rows, closure, P, N, mu, width, c, L, models, variants, options):
    """Epsilon columns of a planar group: :func:`qualgrasp.certify.quality.bounds.planar_epsilon_columns`
    (row for row what the per-grasp path's :func:`~qualgrasp.certify.quality.bounds.planar_epsilons`
    gives, on the same generator floats) for every closure row; 0 and no evidence elsewhere.
    Returns ``(l1_lo, l1_hi, linf_lo, linf_hi, limited, evidence)``, the evidence an Arrow column
    (None: no row in closure)."""
    B, m = mu.shape
    owner, offset, friction = generator_layout(models, variants, 2)
    vals = np.zeros((B, 4))
    limited = np.zeros(B, dtype=bool)
    at = np.flatnonzero(closure)
    if not len(at):
        return vals[:, 0], vals[:, 1], vals[:, 2], vals[:, 3], limited, None
    W, E = generator_rows(*(kernel_array(a[at]) for a in (P, N, mu, width, c, L)), owner, offset, friction)
    exact = lambda q: grasp_system(cols.grasps([rows[at[q]]])[0], exact=True).columns  # noqa: E731
    found, cut, l1, linf = planar_epsilon_columns(W, E, owner, m, time_limit=options.eps_time, exact=exact)
    vals[at], limited[at] = found, cut
    return vals[:, 0], vals[:, 1], vals[:, 2], vals[:, 3], limited, evidence_array(l1, linf, at, B)


def _polyhedral_rows(P, N, c, L, W, E, options, tol: Tolerances):
    """Form closure of spatial grasps (also the force closure of frictionless ones) whose LP has
    too many bases for a columnar rule: decided row by row exactly as the per-grasp path decides
    it (same problem, same fast solver, same certificate), with the certificate then proved by
    the rigorous float kernels instead of rationals (the exact checker only where floats cannot
    decide). ``W`` and ``E`` are the frictionless generator columns and their error bounds
    (:func:`qualgrasp.certify.core.wrench.force_column_errors`). Returns ``(code, t, lam, basis, y)`` and the tight blocks of
    code-4 rows."""
    B, m, d = P.shape
    zeros = np.zeros((B, m))
    cone, first, width = ray_block_arrays(m)
    code = np.zeros(B, dtype=np.int64)
    t, lam = np.zeros(B), np.zeros((B, m))
    basis, y = np.zeros((B, 2 * d), dtype=np.int64), np.zeros((B, 2 * d))
    tight_rows = {}
    solver = make_solver("fast")
    for i in range(B):
        grasp = Grasp(tuple(Contact(P[i, j], N[i, j]) for j in range(m)), center=c[i], length=L[i])
        v = decide(grasp_problem(grasp, frictionless=True),
                   lambda g=grasp: grasp_system(g, frictionless=True, exact=True).columns, solver, tol)
        cert = v.certificate
        if v.status == "closure":
            t[i], lam[i], basis[i] = v.margin, cert.values, cert.basis
            if not options.quality and verify_interior_general(
                    W[i], E[i], cone, first, width, N[i], zeros[i], zeros[i], lam[i], basis[i],
                    tol.residual):
                code[i] = 1
        elif v.status == "no_closure":
            y[i] = cert.y
            mask = np.zeros(m, dtype=bool)
            mask[list(cert.tight)] = True
            proved = not cert.null_space and not mask.any() and verify_farkas_general(
                W[i], E[i], cone, first, width, N[i], zeros[i], zeros[i], y[i], mask, 0.0)
            if proved or verify(grasp, cert, status="no_closure", frictionless=True):
                code[i] = 3 if cert.null_space else 4 if mask.any() else 2
                tight_rows[i] = np.flatnonzero(mask)
    return (code, t, lam, basis, y), tight_rows


def _polyhedral(P, N, c, L, options, tol: Tolerances):
    """Form closure of spatial grasps with 6 or more contacts (also the force closure of
    frictionless ones), by the fast solver's own route: LPs it solves by enumerating bases go
    row by row (:func:`_polyhedral_rows`); larger ones, which it hands to the compiled barrier
    method, are solved here by that method for the whole batch, and clear verdicts are proved
    columnar. Rows near the boundary, thin, or with certificates not proved this way are decided
    row by row. Returns ``(code, t, lam, basis, y)`` and the tight blocks of code-4 rows."""
    B, m, d = P.shape
    models = (registry.FRICTIONLESS.name,) * m
    zeros = np.zeros((B, m))
    W, _ = generator_columns(P, N, zeros, models, c, L, frictionless=True, variants=(0,) * m)
    W = np.ascontiguousarray(W)  # (B, 6, m): one ray per contact, as barrier_arrays lays it out
    E = force_column_errors(P, N, models, c, L)
    if FastSolver.enumerates(m, 2 * d):
        return _polyhedral_rows(P, N, c, L, W, E, options, tol)
    out = list(_barrier_rays(W, E, N, 1e-6, tol, closure=not options.quality))
    code = out[0]
    tight = {}
    rest = np.flatnonzero(code == 0)
    if len(rest):
        sub, sub_tight = _polyhedral_rows(P[rest], N[rest], c[rest], L[rest], W[rest], E[rest],
                                          options, tol)
        for arr, part in zip(out, sub):
            arr[rest] = part
        tight = {int(rest[r]): v for r, v in sub_tight.items()}
    return tuple(out), tight


SPATIAL_CONTACTS = 16
"""Most contacts of a spatial grasp certified on the columnar path."""


def _spatial_group(cols: GraspColumns, rows: np.ndarray, options, tol: Tolerances):
    """Certify the spatial grasps ``rows`` (one contact pattern with friction): force closure
    by the compiled dual barrier method, form closure by the null-space direction (fewer than 6
    contacts) or the enumerated LP, every certificate re-checked in floating point with error
    bounds. Rows these rules do not settle (thin, near the boundary, tight contacts, unproved,
    or needing the spatial epsilon) are left to the per-grasp path, and so are grasps of more
    than :data:`SPATIAL_CONTACTS` contacts (the batch arrays grow with their square)."""
    m = int(cols.count[rows[0]])
    models = cols.models_of(rows[0])
    if m > SPATIAL_CONTACTS or not all(registry.get(name).exact_in_floats for name in models):
        return np.zeros(len(rows), dtype=bool), {}
    P, N, params = cols.contacts(rows)
    mu, c, L = params["mu"], cols.center[rows], cols.length[rows]
    B = len(rows)
    if all(registry.get(name).is_frictionless for name in models):  # force closure is form closure
        form, tight = _polyhedral(P, N, c, L, options, tol)
        return form[0] > 0, {"force": form, "form": form, "tight": tight, "form_tight": tight}
    # force closure: the barrier method on the solver columns
    columns, rays, cones, to_values = conic_columns(P, N, params, models, c, L)
    blocks = [(r, 1, np.ones(B)) for r in rays] + list(cones)
    rmax = max(size - 1 for _, size, _ in cones)
    Pm = np.zeros((B, len(blocks), 6))
    T = np.zeros((B, len(blocks), rmax, 6))
    rk = np.zeros(len(blocks), dtype=np.int64)
    kappa = np.ones((B, len(blocks)))
    for b, (start, size, k) in enumerate(blocks):
        Pm[:, b] = columns[:, :, start]
        if size > 1:
            T[:, b, : size - 1] = np.swapaxes(columns[:, :, start + 1:start + size], 1, 2)
            rk[b], kappa[:, b] = size - 1, k
    status, t, y, xn, xt = barrier_batch(Pm, T, rk, kappa, EXIT_BELOW, GAP_TOL, MAX_NEWTON)
    x = np.zeros((B, columns.shape[2]))
    for b, (start, size, _) in enumerate(blocks):
        x[:, start] = xn[:, b]
        x[:, start + 1:start + size] = xt[:, b, : size - 1]
    # the certificate system (world-frame force columns) and its error bounds
    C, owner = force_columns(P, N, models, c, L)
    C = np.ascontiguousarray(C)
    E = force_column_errors(P, N, models, c, L)
    cone, first, width, Nc, mu, g = conic_block_arrays(models, N, mu, params, 3)
    sv = np.linalg.svd(C, compute_uv=False)
    thin = sv[:, -1] <= 1e-6 * sv[:, 0]
    near = (status == 2) | ((status == 0) & (np.abs(t) < BARRIER_NEAR_ZERO))
    closure = ~thin & ~near & (status == 0) & (t >= tol.margin)
    if options.quality:
        closure_ok = np.zeros(B, dtype=bool)  # the spatial epsilon is the per-grasp path's
    else:
        closure_ok = closure
    values = world_values(np.ascontiguousarray(to_values), x)
    farkas = ~thin & ~near & (t < tol.margin)
    with np.errstate(invalid="ignore", divide="ignore"):
        yn = np.nan_to_num(y / np.sqrt(np.sum(y * y, axis=1, keepdims=True)))
    scale = np.abs(C).max(axis=(1, 2))
    funct = np.einsum("bdk,bd->bk", C, yn)
    for b_ in range(m):
        sel = owner == b_
        farkas &= ~(np.abs(funct[:, sel]).max(axis=1) <= 1e-7 * scale)  # no tight contacts
    code, basis = certify_rows(C, E, cone, first, width, Nc, mu, g, values, yn, closure_ok, farkas,
                               scale, tol.residual)
    # near the boundary the per-grasp rule re-solves with clarabel (tight contacts); settle those
    # verdicts here too, with the float re-check
    tight_rows = {}
    # these rows are exactly those the fast solver hands from the barrier method to its
    # near-boundary rule: the squeeze direction (tried below on the arrays), else clarabel
    solver = make_solver("clarabel")

    def grasp_of(i):
        return cols.grasps([rows[i]])[0]

    squeeze = ((cone == LORENTZ) & (width == 3)).sum() >= 2
    for i in np.flatnonzero(near & ~thin):
        # the squeeze rule first, on the arrays (the certificate decide makes of its direction),
        # then the per-grasp decision on the columns already built
        arrays = (cone, first, width, Nc[i], mu[i], g[i])
        y_sq = squeeze_farkas(C[i], *arrays) if squeeze else None
        if y_sq is not None:
            status, cert = "no_closure", farkas_from_arrays(C[i], arrays, "forces", y_sq)
        else:
            system = System(C[i], tuple(Block(registry.get(models[b]).cone,
                                              tuple(int(j) for j in np.flatnonzero(owner == b)),
                                              tuple(N[i, b]), float(mu[i, b]), float(g[i, b]), b)
                                        for b in range(m)), "forces")
            problem = ClosureProblem(columns[i], rays, tuple((st, sz, float(k[i])) for st, sz, k in cones),
                                     to_values[i], system)
            v = decide(problem, lambda i=i: grasp_system(grasp_of(i), exact=True).columns, solver, tol)
            status, cert = v.status, v.certificate
        if status == "closure" and not options.quality:
            values[i], basis[i], t[i] = cert.values, cert.basis, v.margin
            if verify_interior_general(C[i], E[i], cone, first, width, Nc[i], mu[i], g[i], values[i],
                                       basis[i], tol.residual):
                code[i] = 1
        elif status == "no_closure" and not cert.null_space:
            yn[i] = cert.y
            mask = np.zeros(m, dtype=bool)
            mask[list(cert.tight)] = True
            shift = 0.0
            if mask.any():
                shift = _tight_shift(C[i], E[i], owner, mask, models, P[i], yn[i])
            proved = shift <= 1e-6 * np.sqrt(np.sum(yn[i] ** 2)) and verify_farkas_general(
                C[i], E[i], cone, first, width, Nc[i], mu[i], g[i], yn[i], mask, shift)
            # tight blocks of lower rank than their columns (two fingers squeezing) have an
            # exact span that floats cannot certify: the exact checker decides those
            if proved or verify(grasp_of(i), cert, status="no_closure"):
                code[i] = 4 if mask.any() else 2
                tight_rows[int(i)] = np.flatnonzero(mask)
    # form closure: frictionless generators
    Wf, _ = generator_columns(P, N, mu, models, c, L, frictionless=True, variants=(0,) * m)
    Wf = np.ascontiguousarray(Wf)
    Ef = force_column_errors(P, N, registry.frictionless_names(models), c, L)
    code_f = np.zeros(B, dtype=np.int64)
    t_f = np.zeros(B)
    lam_f = np.zeros((B, m))
    basis_f = np.zeros((B, 6), dtype=np.int64)
    y_f = np.zeros((B, 6))
    if m < 6:
        y_f = np.ascontiguousarray(np.linalg.svd(Wf)[0][:, :, -1])
        code_f = null_rows(Wf, Ef, y_f)
    form_tight = {}
    if m >= 6:
        (code_f, t_f, lam_f, basis_f, y_f), form_tight = _polyhedral(P, N, c, L, options, tol)
    settled = (code > 0) & (code_f > 0)
    out = {"force": (code, t, values, basis, np.nan_to_num(yn)),
           "form": (code_f, t_f, lam_f, basis_f, y_f),
           "force_layout": ("forces", m), "tight": tight_rows, "form_tight": form_tight}
    return settled, out


def _tight_shift(C, E, owner, mask, models, P, y) -> float:
    """Rigorous bound on how far the exact projection of ``y`` off the span of the tight blocks'
    columns moves it (``inf`` when not proved in floats).

    The columns of one point contact are independent. Those of two point contacts at distinct
    points, ``(e_j, (p_i - c) x e_j / L)``, have rank exactly 5 for any data: the map
    ``(a, b) -> (a + b, (r_1 x a + r_2 x b) / L)`` has kernel ``{(a, -a) : a || r_1 - r_2}``. So
    their span is that of any 5 of them proved independent, which floats can bound. Other tight
    sets go to the exact checker. "Point contact" here is any model whose columns are the three
    world-axis forces and no moments (:attr:`~qualgrasp.certify.models.ContactModel.forces`,
    ``extra``)."""
    tight = np.flatnonzero(mask)
    cols = np.flatnonzero(mask[owner])
    spec = [registry.get(models[b]) for b in tight]
    if len(tight) == 2 and all(m.forces == "axes" and not m.extra for m in spec) and \
            not np.array_equal(P[tight[0]], P[tight[1]]):
        for drop in range(len(cols)):
            keep = np.delete(cols, drop)
            bound = projection_bound(np.ascontiguousarray(C[:, keep]), np.ascontiguousarray(E[:, keep]), y)
            if np.isfinite(bound):
                return bound
        return np.inf
    if len(tight) == 1 and not spec[0].extra:
        return projection_bound(np.ascontiguousarray(C[:, cols]), np.ascontiguousarray(E[:, cols]), y)
    return np.inf


def certify_table(table: pa.Table, lines, options, tol: Tolerances = Tolerances(), slow=None, *,
                  columns: GraspColumns | None = None, columnar: bool = True) -> pa.Table:
    """Results table of an Arrow grasp table (rows in input order), with the table's extra
    columns carried through.

    ``slow(row_indices) -> list of results rows`` certifies rows grasp by grasp (the per-grasp
    path, :func:`qualgrasp.certify.batch.chunk.certify_rows`); it receives every row that the columnar
    rules do not settle, invalid rows included. ``columns``: the table's checked columns, when
    the caller has them already. ``columnar=False`` sends every row to ``slow`` (the same rows,
    without compiling the columnar kernels: for a handful of grasps).
    """
    cols = grasp_columns(table) if columns is None else columns
    lines = (np.arange(lines.start, lines.stop, lines.step) if isinstance(lines, range)
             else np.asarray(lines, dtype=np.int64))
    n = len(lines)
    done = np.zeros(n, dtype=bool)
    pieces, order = [], []
    if columnar and options.method == "fast" and cols.ok.any():
        label = cols.pattern()
        for k in np.unique(label[cols.ok]):
            rows = np.flatnonzero(label == k)
            group = _planar_group if cols.dim[rows[0]] == 2 else _spatial_group
            settled, out = group(cols, rows, options, tol)
            if settled.all():
                sub = dict(out)
            elif settled.any():
                sub = {name: (value if name == "force_layout" else _take(value, settled))
                       for name, value in out.items() if name not in ("tight", "form_tight")}
                new = np.cumsum(settled) - 1  # re-index the per-row tight lists to the settled rows
                for name in ("tight", "form_tight"):
                    if name in out:
                        sub[name] = {int(new[r]): v for r, v in out[name].items() if settled[r]}
            if settled.any():
                pieces.append(group_table(cols, rows[settled], lines[rows[settled]], sub, options))
                order.append(rows[settled])
                done[rows[settled]] = True
    rest = np.flatnonzero(~done)
    if len(rest):
        pieces.append(rows_to_table(slow(rest)))
        order.append(rest)
    return assemble(pieces, order, table)


def _take(value, mask):
    """The rows ``mask`` of a group's result: of each array in a tuple (Arrow arrays too)."""
    if isinstance(value, tuple):
        return tuple(v[mask] if isinstance(v, np.ndarray) else v.filter(pa.array(mask)) if isinstance(v, pa.Array)
                     else v for v in value)
    return value[mask]

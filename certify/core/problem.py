"""The closure programme shared by every solver route.

Every closure question (form closure, force closure, positive spanning) is the same convex
programme over variables ``x`` that are generator weights (rays) or contact forces in the contact
frame (second-order cone blocks)::

    maximise t
    subject to  columns @ x = 0            (equilibrium: no net wrench)
                normal @ x = 1             (total normal force, or total weight, is 1)
                x_r >= t                   for every ray r
                kappa x_n - norm(x_tan) >= t   for every cone block (x_n its normal force)

``t*`` is the min-weight margin (Murray, Li & Sastry, Prop. 5.2; the min-weight LP of FRoGGeR):
the set is in closure iff ``columns`` has full row rank and ``t* > 0``. For rays ``t*`` lies in
``(0, 1/k]``; for a spatial frictional contact the slack is ``mu f_n - norm(f_t)`` (plus the
torsional term for soft contacts), and for a frictionless one ``f_n``.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from functools import lru_cache
from typing import Any, NamedTuple, Sequence

import numpy as np
import scipy.sparse as sp

from .grasp import Grasp
from .. import models as registry
from ..errors import ArgumentError, GraspError
from .._kernels.conic import lorentz_system
from .._kernels.linalg import world_values
from .cones import CONES, RAY, cone_code
from .wrench import (contact_frame, force_columns, generator_columns, grasp_arrays, tangent,
                     to_exact, variants_of, wrench)

__all__ = ["Block", "block_arrays", "array_blocks", "ray_block_arrays", "ray_blocks", "conic_block_arrays", "System",
           "ClosureProblem", "grasp_problem", "span_problem", "grasp_system", "span_system", "span_vectors",
           "is_polyhedral", "DENSE_COLUMNS", "LorentzLayout", "lorentz_layout", "ray_problem"]


@dataclass(frozen=True)
class Block:
    """One cone block over certificate columns ``cols``: its shape ``cone`` (``'ray'`` or
    ``'lorentz'``, :mod:`qualgrasp.certify.core.cones`), the stored normal ``n``, friction ``mu`` and
    moment length ``g`` of a Lorentz block (0 for none), and the ``contact`` it belongs to."""

    cone: str
    cols: tuple[int, ...]
    n: tuple = ()
    mu: Any = 0
    g: Any = 0
    contact: int = -1


def block_arrays(blocks: Sequence[Block], dim: int):
    """``(cone, first, width, n, mu, g)`` arrays of cone blocks, the form the compiled kernels
    take (:mod:`qualgrasp.certify._kernels.cones`); rays get zero normals."""
    cone = np.array([cone_code(b.cone) for b in blocks], dtype=np.int64)
    first = np.array([b.cols[0] for b in blocks], dtype=np.int64)
    width = np.array([len(b.cols) for b in blocks], dtype=np.int64)
    n = np.array([[float(v) for v in b.n] if b.n else [0.0] * dim for b in blocks]).reshape(len(blocks), dim)
    mu = np.array([float(b.mu) for b in blocks])
    g = np.array([float(b.g) for b in blocks])
    return cone, first, width, n, mu, g


def array_blocks(cone, first, width, n, mu, g) -> list[Block]:
    """The cone blocks of :func:`block_arrays`' arrays, each the ``contact`` of its index; a ray
    without the normal, friction and moment length that count for nothing on it.

    Examples
    --------
    >>> blocks = array_blocks(*block_arrays([Block("ray", (0,)), Block("lorentz", (1, 2), (1.0, 0.0), 0.5)], 2))
    >>> [(b.cone, b.cols, float(b.mu)) for b in blocks]
    [('ray', (0,), 0.0), ('lorentz', (1, 2), 0.5)]
    """
    return [Block("ray", (int(first[b]),), contact=b) if cone[b] == RAY else
            Block(CONES[cone[b]], tuple(range(first[b], first[b] + width[b])), tuple(n[b]), mu[b], g[b], b)
            for b in range(len(cone))]


def ray_block_arrays(k: int):
    """``(cone, first, width)`` block arrays of ``k`` rays, one per column (generator columns)."""
    return np.zeros(k, dtype=np.int64), np.arange(k, dtype=np.int64), np.ones(k, dtype=np.int64)


def ray_blocks(k: int, dim: int):
    """All six block arrays ``(cone, first, width, n, mu, g)`` (:func:`block_arrays`' form) of
    ``k`` rays in ``dim`` dimensions: :func:`ray_block_arrays`, and the zero normals, friction and
    moment lengths that count for nothing on a ray.

    Examples
    --------
    >>> cone, first, width, n, mu, g = ray_blocks(3, 2)
    >>> first.tolist(), width.tolist(), n.shape, float(mu.sum() + g.sum())
    ([0, 1, 2], [1, 1, 1], (3, 2), 0.0)
    """
    return (*ray_block_arrays(k), np.zeros((k, dim)), np.zeros(k), np.zeros(k))


def conic_block_arrays(models: Sequence[str], N: np.ndarray, mu: np.ndarray, params, dim: int):
    """Block arrays ``(cone, first, width, n, mu, g)`` of the conic form (:func:`force_columns`'
    layout) of a batch of grasps sharing ``models``: ``cone``, ``first``, ``width`` shared, the
    normals ``N`` (B, m, dim), friction ``mu`` (B, m) and each model's moment length ``g`` (its
    first ``extra`` parameter, 0 without) per row, as :func:`block_arrays` gives one grasp's."""
    cone = np.array([cone_code(registry.get(name).cone) for name in models], dtype=np.int64)
    width = np.array([registry.get(name).columns(dim) for name in models], dtype=np.int64)
    first = np.concatenate([[0], np.cumsum(width)[:-1]]).astype(np.int64)
    g = np.zeros(np.shape(mu))
    for i, name in enumerate(models):
        model = registry.get(name)
        if model.extra:
            g[:, i] = model.moment_lengths({p: params[p][:, i] for p in model.param_names})[0]
    return cone, first, width, np.ascontiguousarray(N), np.ascontiguousarray(mu), g


class System(NamedTuple):
    """What a certificate is written over: columns ``C`` (d x k), their cone blocks, the layout
    name (``generators`` or ``forces``). Float for the solvers, exact for the checker."""

    columns: np.ndarray
    blocks: tuple[Block, ...]
    layout: str


@dataclass(frozen=True, eq=False)
class ClosureProblem:
    """Data of the closure programme (see module docstring).

    Attributes
    ----------
    columns : ndarray, shape (d, nvar)
        Wrench (or vector) of each variable.
    rays : tuple of int
        Variables constrained by ``x_r >= t``.
    cones : tuple of (start, size, kappa)
        Second-order cone blocks; ``x[start]`` is the normal force, the next ``size - 1`` entries
        the tangential forces (and the scaled torsional moment).
    to_values : ndarray or scipy.sparse.csr_array, shape (ncert, nvar)
        Linear map from ``x`` to the certificate's values (world-frame forces): block diagonal,
        dense up to :data:`DENSE_COLUMNS` variables, else stored sparse (its size grows with the
        square of the contacts); see :meth:`values`.
    system : System
        The float certificate system (for polyhedral problems its columns are ``columns``).
    """

    columns: np.ndarray
    rays: tuple[int, ...]
    cones: tuple[tuple[int, int, float], ...]
    to_values: Any
    system: System

    def values(self, x: np.ndarray) -> np.ndarray:
        """The certificate's values ``to_values @ x``, each summed in variable order as
        :func:`qualgrasp.certify._kernels.linalg.world_values` sums the columnar batch (the
        zeros a sparse map skips add nothing: both sums start at +0, so a signed zero cannot
        survive either), so dense and sparse maps, and both routes, state the same values."""
        x = np.asarray(x, dtype=float)
        if sp.issparse(self.to_values):
            return np.asarray(self.to_values @ x, dtype=float)
        return world_values(np.ascontiguousarray(self.to_values)[None], x[None])[0]

    @property
    def d(self) -> int:
        return self.columns.shape[0]

    @property
    def nvar(self) -> int:
        return self.columns.shape[1]

    @property
    def normal(self) -> np.ndarray:
        """Coefficients of the normalisation row ``normal @ x = 1``."""
        e = np.zeros(self.nvar)
        e[list(self.rays)] = 1.0
        e[[start for start, _, _ in self.cones]] = 1.0
        return e

    @property
    def structure(self) -> tuple:
        """Hashable sparsity structure: problems sharing it can reuse a prebuilt solver."""
        return (self.d, self.nvar, self.rays, tuple((s, n) for s, n, _ in self.cones))


def span_problem(vectors) -> ClosureProblem:
    """Positive spanning of the rows of ``vectors`` (shape ``(k, d)``): every row is a ray."""
    return ray_problem(span_system(vectors))


def ray_problem(system: System) -> ClosureProblem:
    """The closure programme of a system of generator rays (layout ``generators``):
    every column a ray ``x_j >= t``, and the identity as the value map, dense up to
    :data:`DENSE_COLUMNS` columns (its values are the same, :meth:`ClosureProblem.values`)."""
    k = system.columns.shape[1]
    return ClosureProblem(system.columns, tuple(range(k)), (), _identity(k), system)


def _identity(k: int):
    """The identity value map of ``k`` rays, a new one each time (a caller may change its
    programme's map)."""
    return np.eye(k) if k <= DENSE_COLUMNS else sp.identity(k, format="csr")


def is_polyhedral(grasp: Grasp, frictionless: bool = False, socp: bool = False) -> bool:
    """True when the programme uses generator rays: frictionless grasps (and form closure), and
    planar grasps unless ``socp`` asks for their friction cones as 2-D second-order cones."""
    return frictionless or grasp.frictionless or (grasp.dim == 2 and not socp)


def _frames(N: np.ndarray) -> np.ndarray:
    """Contact frames, shape ``(..., m, dim, dim)``: rows ``n, t`` (plane) or ``n, t1, t2``
    (space)."""
    if N.shape[-1] == 2:
        return np.stack([N, tangent(N)], axis=-2)
    T1, T2 = contact_frame(N.reshape(-1, 3))
    return np.stack([N, T1.reshape(N.shape), T2.reshape(N.shape)], axis=-2)


def grasp_problem(grasp: Grasp, *, frictionless: bool = False, socp: bool = False) -> ClosureProblem:
    """The closure programme of ``grasp`` (form closure when ``frictionless=True``).

    Frictionless grasps and planar grasps are polyhedral (rays = generator wrenches; a planar
    friction cone is exactly its two edges, a pad's cone the edges at its two ends). Spatial
    frictional contacts are exact second-order cones in the contact frame ``(n, t1, t2)``; a
    soft contact's fourth variable is ``m / torsion``, so its cone is
    ``norm((f_t, m / torsion)) <= mu f_n``. ``socp=True`` writes planar friction cones as 2-D
    second-order cones ``abs(f_t) <= mu f_n`` instead of edges: the same verdict by another route
    (the margin's scale differs), used to cross-check the LP (not for pads, which have no
    conic form).

    A spatial grasp of point and soft contacts with at most :data:`DENSE_COLUMNS` columns, the
    call a planning loop makes per grasp, takes a compiled route (its layout cached per contact
    pattern, :func:`lorentz_layout`) that states the same floats as the array route of
    :func:`conic_columns` and :func:`grasp_system`, which batches and the other grasps take.
    """
    if not is_polyhedral(grasp, frictionless, socp):
        layout = lorentz_layout(tuple(contact.contact_model for contact in grasp.contacts), grasp.dim)
        if layout is not None and layout.ncols <= DENSE_COLUMNS:
            return _lorentz_problem(grasp, layout)
    system = grasp_system(grasp, frictionless=frictionless, socp=socp)
    if system.layout == "generators":
        return ray_problem(system)
    P, N, mu, params, c, L = grasp_arrays(grasp)
    models = tuple(contact.model for contact in grasp.contacts)
    columns, rays, cones, to_values = conic_columns(P, N, params, models, c, L)
    return ClosureProblem(columns, rays, cones, to_values, system)


#: Most columns of a programme whose value map :func:`grasp_problem` stores dense (32 KB); larger
#: ones keep it sparse (its size grows with the square of the contacts). Spatial grasps within
#: the bound take the compiled route (:func:`qualgrasp.certify._kernels.conic.lorentz_system`).
DENSE_COLUMNS = 64


class LorentzLayout(NamedTuple):
    """Column layout of a spatial grasp whose contacts all have Lorentz cones over world-axis
    forces (:func:`lorentz_layout`): per contact its ``first`` column, the number of moment
    columns ``nextra`` and their length parameters ``extra``, and its block's columns ``cols``;
    ``ncols`` columns in all."""

    first: np.ndarray
    nextra: np.ndarray
    extra: tuple[tuple[str, ...], ...]
    cols: tuple[tuple[int, ...], ...]
    ncols: int


@lru_cache(maxsize=256)
def lorentz_layout(models: tuple, dim: int) -> LorentzLayout | None:
    """The :class:`LorentzLayout` of a contact pattern (registered model objects, in contact
    order) in ``dim`` dimensions; None unless it is spatial and every model has a Lorentz cone
    over the world axes (those grasps take :func:`grasp_problem`'s array route). A pure function
    of the pattern, cached: a planning loop over one hand pays for it once.

    Examples
    --------
    >>> from qualgrasp.certify import models
    >>> layout = lorentz_layout((models.get("point"), models.get("soft")), 3)
    >>> layout.cols, layout.extra
    (((0, 1, 2), (3, 4, 5, 6)), ((), ('torsion',)))
    >>> lorentz_layout((models.get("frictionless"), models.get("point")), 3) is None
    True
    """
    if dim != 3 or not all(m.cone == "lorentz" and m.forces == "axes" for m in models):
        return None
    nextra = np.array([len(m.extra) for m in models], dtype=np.int64)
    width = 3 + nextra
    first = np.concatenate([[0], np.cumsum(width)[:-1]]).astype(np.int64)
    for a in (first, nextra):
        a.setflags(write=False)  # shared by every call with this pattern
    cols = tuple(tuple(range(int(f), int(f + w))) for f, w in zip(first, width))
    return LorentzLayout(first, nextra, tuple(tuple(m.extra) for m in models), cols, int(width.sum()))


def _lorentz_problem(grasp: Grasp, layout: LorentzLayout) -> ClosureProblem:
    """:func:`grasp_problem` of a spatial grasp of pattern ``layout``, by the compiled route:
    the same floats as the array route (:func:`conic_columns`, :func:`grasp_system`)."""
    contacts = grasp.contacts
    G = np.zeros((len(contacts), max(map(len, layout.extra))))
    for i, contact in enumerate(contacts):  # each model's moment lengths (a patch derives its own)
        model = contact.contact_model
        if model.extra:
            lengths = model.moment_lengths({name: contact.param(name) for name in model.param_names})
            G[i, :len(lengths)] = lengths
    mu = [contact.mu for contact in contacts]
    columns, to_values, C = lorentz_system(np.array([c.p for c in contacts]), np.array([c.n for c in contacts]),
                                           np.array(grasp.center), float(grasp.length), layout.first,
                                           layout.nextra, G)
    blocks = tuple(Block("lorentz", cols, contact.n, mu[i], float(G[i, 0]) if names else 0, i)
                   for i, (contact, cols, names) in enumerate(zip(contacts, layout.cols, layout.extra)))
    cones = tuple((cols[0], len(cols), mu[i]) for i, cols in enumerate(layout.cols))
    return ClosureProblem(columns, (), cones, to_values, System(C, blocks, "forces"))


def conic_columns(P, N, params, models, center, length):
    """Solver columns of a closure programme with cones, for one grasp or a batch.

    Parameters
    ----------
    P, N : array, shape (..., m, dim)
    params : mapping of str to array, shape (..., m)
        Model parameters (``mu``, moment lengths such as ``torsion``).
    models : sequence of str, length m (shared by the batch)
    center : array, shape (..., dim)
    length : array, shape (...)

    Returns
    -------
    columns : array, shape (..., d, nvar)
        Wrench of each variable: a ray contact one column (``n``); a Lorentz contact the normal
        and tangential forces of the contact frame ``(n, t1, t2)`` (``(n, t)`` in the plane) and,
        per moment of the model (a soft finger's torsion), the scaled moment ``m / g``.
    to_values : array, shape (..., ncert, nvar)
        Map from the variables to the certificate's world-frame values (forces, moments):
        dense for a batch, a sparse block-diagonal ``scipy.sparse.csr_array`` for one grasp.
    rays, cones : tuple
        As :class:`ClosureProblem` (the structure, shared by the batch).
    """
    frames = _frames(N)  # (..., m, dim, dim)
    c = np.asarray(center)[..., None, None, :]
    L = np.asarray(length)[..., None, None]
    wrenches = wrench(P[..., :, None, :], frames, c, L)  # (..., m, dim, d)
    dim = P.shape[-1]
    batch = P.shape[:-2]
    cols, rays, cones, blocks = [], [], [], []
    for i, name in enumerate(models):
        model = registry.get(name)
        start = len(cols)
        if model.cone == "ray":
            cols.append(wrenches[..., i, 0, :])
            rays.append(start)
            # its certificate value is the force along n itself (force_columns: one column, n)
            blocks.append(np.ones(batch + (1, 1)))
            continue
        if model.cone != "lorentz":
            raise ArgumentError(f"{name} contacts have no conic form (they are polyhedral: use the generators)")
        cols.extend(wrenches[..., i, j, :] for j in range(dim))
        frame = np.swapaxes(frames[..., i, :, :], -1, -2)
        if model.extra:
            size = dim + len(model.extra)
            frame_x = np.zeros(batch + (size, size))
            frame_x[..., :dim, :dim] = frame
            L_ = np.asarray(length)[..., None]
            lengths = model.moment_lengths({name: params[name][..., i] for name in model.param_names})
            for q, g in enumerate(lengths):
                g = np.asarray(g, dtype=float)
                cols.append(np.concatenate([np.zeros(batch + (dim,)), g[..., None] * N[..., i, :] / L_], axis=-1))
                frame_x[..., dim + q, dim + q] = g
            frame = frame_x
        cones.append((start, len(cols) - start, params["mu"][..., i]))
        blocks.append(frame)
    columns = np.stack(cols, axis=-1)
    to_values = _block_diag(blocks, batch) if batch else sp.block_diag(blocks, format="csr")
    if not batch:
        cones = [(start, size, float(k)) for start, size, k in cones]
    return columns, tuple(rays), tuple(cones), to_values


def _block_diag(blocks: list[np.ndarray], batch: tuple = ()) -> np.ndarray:
    rows = sum(b.shape[-2] for b in blocks)
    cols = sum(b.shape[-1] for b in blocks)
    out = np.zeros(batch + (rows, cols))
    r = c = 0
    for b in blocks:
        out[..., r:r + b.shape[-2], c:c + b.shape[-1]] = b
        r, c = r + b.shape[-2], c + b.shape[-1]
    return out


def grasp_system(grasp: Grasp, *, frictionless: bool = False, socp: bool = False,
                 exact: bool = False):
    """The certificate :class:`System` of ``grasp`` (exact: Fraction entries).

    Polyhedral programmes (:func:`is_polyhedral`) are written over the generator wrenches, one
    ray block per generator; the others over world-frame force (and moment) columns
    (:func:`qualgrasp.certify.core.wrench.force_columns`), one block per contact with the model's cone.
    """
    P, N, mu, params, c, L = grasp_arrays(grasp, exact)
    models = tuple(contact.model for contact in grasp.contacts)
    if is_polyhedral(grasp, frictionless, socp):
        C, owner = generator_columns(P, N, mu, models, c, L, frictionless=frictionless,
                                     width=registry.offset_lengths(models, params), variants=variants_of(grasp))
        return System(C, tuple(Block("ray", (j,), contact=int(owner[j])) for j in range(C.shape[1])),
                      "generators")
    C, owner = force_columns(P, N, models, c, L)
    conv = to_exact if exact else np.asarray
    num = Fraction if exact else float
    blocks = []
    for i, contact in enumerate(grasp.contacts):
        model = contact.contact_model
        cols = tuple(int(j) for j in np.flatnonzero(owner == i))
        g = model.moment_lengths({p: num(contact.param(p)) for p in model.param_names})[0] if model.extra else 0
        blocks.append(Block(model.cone, cols, tuple(conv(np.array(contact.n))), num(contact.mu), g, i))
    return System(C, tuple(blocks), "forces")


def span_vectors(vectors) -> np.ndarray:
    """``vectors`` as a finite float array ``(k, d)`` with ``k >= 1``, else :class:`GraspError`.

    Examples
    --------
    >>> span_vectors([[1, 2], [3]])
    Traceback (most recent call last):
    ...
    qualgrasp.certify.errors.GraspError: vectors must be a finite (k, d) array
    """
    try:
        V = np.asarray(vectors, dtype=float)
    except (TypeError, ValueError):
        V = None
    if V is None or V.ndim != 2 or V.size == 0 or not np.isfinite(V).all():
        raise GraspError("vectors must be a finite (k, d) array")
    return V


def span_system(vectors, *, exact: bool = False):
    """Certificate columns and blocks for positive spanning of the rows of ``vectors``."""
    V = np.asarray(vectors, dtype=float)
    C = (to_exact(V) if exact else V).T
    return System(C, tuple(Block("ray", (j,)) for j in range(C.shape[1])), "generators")

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

import numpy as np

from .grasp import Grasp
from .wrench import contact_frame, generator_columns, grasp_arrays, tangent, wrench

__all__ = ["ClosureProblem", "grasp_problem", "span_problem"]


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
    to_values : ndarray, shape (ncert, nvar)
        Linear map from ``x`` to the certificate's values (world-frame forces).
    layout : {'generators', 'forces'}
        What the certificate's values are: generator weights or world-frame contact forces.
    """

    columns: np.ndarray
    rays: tuple[int, ...]
    cones: tuple[tuple[int, int, float], ...]
    to_values: np.ndarray
    layout: str

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
    V = np.asarray(vectors, dtype=float)
    k = V.shape[0]
    return ClosureProblem(V.T.copy(), tuple(range(k)), (), np.eye(k), "generators")


def is_polyhedral(grasp: Grasp, frictionless: bool = False, socp: bool = False) -> bool:
    """True when the programme uses generator rays: frictionless grasps, and planar grasps
    unless ``socp`` asks for their friction cones as 2-D second-order cones."""
    return frictionless or grasp.frictionless or (grasp.dim == 2 and not socp)


def _frames(N: np.ndarray) -> np.ndarray:
    """Contact frames, shape ``(m, dim, dim)``: rows ``n, t`` (plane) or ``n, t1, t2`` (space)."""
    if N.shape[1] == 2:
        return np.stack([N, tangent(N)], axis=1)
    T1, T2 = contact_frame(N)
    return np.stack([N, T1, T2], axis=1)


def grasp_problem(grasp: Grasp, *, frictionless: bool = False, socp: bool = False) -> ClosureProblem:
    """The closure programme of ``grasp`` (form closure when ``frictionless=True``).

    Frictionless grasps and planar grasps are polyhedral (rays = generator wrenches; a planar
    friction cone is exactly its two edges). Spatial frictional contacts are exact second-order
    cones in the contact frame ``(n, t1, t2)``; a soft contact's fourth variable is
    ``m / torsion``, so its cone is ``norm((f_t, m / torsion)) <= mu f_n``. ``socp=True`` writes
    planar friction cones as 2-D second-order cones ``abs(f_t) <= mu f_n`` instead of edges: the same
    verdict by another route (the margin's scale differs), used to cross-check the LP.
    """
    P, N, mu, torsion, c, L = grasp_arrays(grasp)
    models = tuple(contact.model for contact in grasp.contacts)
    if is_polyhedral(grasp, frictionless, socp):
        W, _ = generator_columns(P, N, mu, models, c, L, frictionless=frictionless)
        k = W.shape[1]
        return ClosureProblem(W, tuple(range(k)), (), np.eye(k), "generators")
    frames = _frames(N)
    wrenches = wrench(P[:, None, :], frames, c, L)  # (m, dim, d): one per frame direction
    cols, rays, cones, blocks = [], [], [], []
    for i, model in enumerate(models):
        start = len(cols)
        if model == "frictionless":
            cols.append(wrenches[i, 0])
            rays.append(start)
            blocks.append(N[i][:, None])
            continue
        cols.extend(wrenches[i])
        frame = frames[i].T
        if model == "soft":
            g = torsion[i]
            cols.append(np.concatenate([np.zeros(3), g * N[i] / L]))
            frame = np.block([[frame, np.zeros((3, 1))], [np.zeros((1, 3)), np.array([[g]])]])
        cones.append((start, len(cols) - start, float(mu[i])))
        blocks.append(frame)
    return ClosureProblem(np.array(cols).T, tuple(rays), tuple(cones), _block_diag(blocks), "forces")


def _block_diag(blocks: list[np.ndarray]) -> np.ndarray:
    out = np.zeros((sum(b.shape[0] for b in blocks), sum(b.shape[1] for b in blocks)))
    r = c = 0
    for b in blocks:
        out[r:r + b.shape[0], c:c + b.shape[1]] = b
        r, c = r + b.shape[0], c + b.shape[1]
    return out

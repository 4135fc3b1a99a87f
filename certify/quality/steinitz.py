"""Steinitz efficiency of a grasp: its epsilon relative to what the whole boundary offers.

Mishra's notion (Kirkpatrick, Mishra & Yap 1992): let ``S`` be the set of unit-normal-force
wrenches that contacts anywhere on the object's boundary can apply. The boundary's epsilon
``epsilon(S)`` is the radius of the largest origin-centred ball in ``conv(S)``; a grasp's
efficiency is ``epsilon(grasp) / epsilon(S)`` with the same contact model, ``center`` and
``length``. It is at most 1, since the grasp's wrenches are a subset of ``S``.

Quantitative Steinitz theorems bound what few points can keep: if ``conv(S)`` contains the ball
``B(0, r)`` in ``R^d``, then

* some ``2d`` points of ``S`` have a hull containing ``B(0, r / (5 d^2))`` (Ivanov & Naszodi,
  "Quantitative Steinitz theorem: a polynomial bound", 2022, arXiv:2212.04308, improving
  Barany, Katchalski & Pach 1982, who had ``r d^(-2d)``);
* some ``m`` points (``m`` large) have one containing ``B(0, r (1 - 3d (2d^2 / m)^(2/(d-1))))``
  (Kirkpatrick, Mishra & Yap 1992).

Each finger contributes at least one of the chosen points, so with ``k >= 2d`` fingers the best
``k``-finger grasp has efficiency at least :func:`steinitz_bound` ``(k, d)``; for fewer fingers
these theorems guarantee nothing (``None``). Planar grasps live in ``d = 3`` wrench dimensions
(6 fingers), spatial ones in ``d = 6`` (12 fingers).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import models as registry
from ..errors import GraspError
from ..core.grasp import Contact, Grasp
from .bounds import epsilon, epsilon_of_points
from ..core.problem import grasp_system

__all__ = ["Efficiency", "polygon_frame", "edge_samples", "boundary_contacts", "boundary_epsilon",
           "steinitz_bound", "efficiency"]


def _polygon(vertices) -> np.ndarray:
    V = np.asarray(vertices, dtype=float)
    if V.ndim != 2 or V.shape[1] != 2 or len(V) < 3 or not np.isfinite(V).all():
        raise GraspError("a polygon is a finite (n, 2) array of at least 3 vertices")
    if np.allclose(V[0], V[-1]):
        V = V[:-1]
    return V


def _signed_area(V: np.ndarray) -> float:
    x, y = V[:, 0], V[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def polygon_frame(vertices) -> tuple[np.ndarray, float]:
    """The object's ``center`` (area centroid) and ``length`` (largest centroid-vertex distance)."""
    V = _polygon(vertices)
    a = _signed_area(V)
    if abs(a) < 1e-12:
        raise GraspError("the polygon has zero area")
    x, y = V[:, 0], V[:, 1]
    cross = x * np.roll(y, -1) - np.roll(x, -1) * y
    c = np.array([np.sum((x + np.roll(x, -1)) * cross), np.sum((y + np.roll(y, -1)) * cross)]) / (6 * a)
    return c, float(np.max(np.linalg.norm(V - c, axis=1)))


def edge_samples(vertices, spacing: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Points every ``spacing`` (at most) along each edge of a simple polygon, both ends of every
    edge included, with the edge's inward unit normal whatever the vertex order.

    Returns
    -------
    points, normals : numpy.ndarray
        ``(k, 2)``.
    edge : numpy.ndarray
        ``(k,)`` index of each point's edge (from vertex ``edge`` to the next; zero-length edges
        are skipped).
    s : numpy.ndarray
        ``(k,)`` position along the edge, 0 at its first vertex, 1 at its last.

    Examples
    --------
    >>> points, normals, edge, s = edge_samples([(0, 0), (2, 0), (2, 1), (0, 1)], 1.0)
    >>> points[:4].tolist(), s[:4].tolist()
    ([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [2.0, 0.0]], [0.0, 0.5, 1.0, 0.0])
    >>> normals[3].tolist()  # the right side's, pointing in
    [-1.0, 0.0]
    """
    V = _polygon(vertices)
    sign = 1.0 if _signed_area(V) > 0 else -1.0
    E = np.roll(V, -1, axis=0) - V
    L = np.linalg.norm(E, axis=1)
    keep = np.flatnonzero(L > 0)
    count = np.maximum(1, np.ceil(L[keep] / spacing).astype(int))
    edge = np.repeat(keep, count + 1)
    s = np.concatenate([np.linspace(0.0, 1.0, c + 1) for c in count])
    t = E[edge] / L[edge, None]
    normals = sign * np.column_stack([-t[:, 1], t[:, 0]])  # interior on the left of a positive-area polygon
    return V[edge] + s[:, None] * E[edge], normals, edge, s


def boundary_contacts(vertices, spacing: float, *, model: str = "point",
                      mu: float = 0.5) -> list[Contact]:
    """Contacts every ``spacing`` along each edge of a simple polygon, with inward normals
    whatever the vertex order (:func:`edge_samples`). Each edge's end points are included with
    that edge's normal (the limit of its interior points), so a vertex appears once per adjacent
    edge."""
    points, normals, _, _ = edge_samples(vertices, spacing)
    if registry.get(model).is_frictionless:
        return [Contact(p, n, model) for p, n in zip(points, normals)]
    return [Contact(p, n, model, mu) for p, n in zip(points, normals)]


def boundary_epsilon(vertices, *, spacing: float | None = None, model: str = "point",
                     mu: float = 0.5) -> tuple[float, np.ndarray, float, int]:
    """L1 epsilon of the whole boundary's wrench set ``S`` (dense sampling, qhull).

    Returns ``(epsilon, center, length, number of generator wrenches)``; ``center`` and
    ``length`` are those of :func:`polygon_frame`. ``spacing`` defaults to 1/200 of the perimeter.
    """
    V = _polygon(vertices)
    center, length = polygon_frame(V)
    if spacing is None:
        spacing = float(np.sum(np.linalg.norm(np.roll(V, -1, axis=0) - V, axis=1))) / 200
    g = Grasp(tuple(boundary_contacts(V, spacing, model=model, mu=mu)), center=center, length=length)
    W = grasp_system(g).columns
    return epsilon_of_points(np.vstack([np.zeros(3), W.T])), center, length, W.shape[1]


def steinitz_bound(fingers: int, d: int) -> float | None:
    """Efficiency guaranteed for the best grasp with ``fingers`` fingers in ``d`` wrench
    dimensions (module docstring), or None when the theorems give no guarantee (fewer than 2d)."""
    if fingers < 2 * d:
        return None
    kmy = 1 - 3 * d * (2 * d * d / fingers) ** (2 / (d - 1))
    return max(1 / (5 * d * d), kmy)


@dataclass(frozen=True)
class Efficiency:
    """A grasp's Steinitz efficiency on a polygonal object."""

    epsilon: float  # of the grasp, L1, with the object's center and length
    boundary_epsilon: float
    ratio: float
    bound: float | None  # guaranteed efficiency of the best grasp with this many fingers
    fingers: int
    center: tuple[float, float]
    length: float
    generators: int  # size of the boundary wrench set


def efficiency(grasp: Grasp, vertices, *, spacing: float | None = None) -> Efficiency:
    """Steinitz efficiency of a planar ``grasp`` on the polygon ``vertices``.

    The grasp is re-expressed with the object's ``center`` and ``length``
    (:func:`polygon_frame`), and the boundary is sampled with the grasp's contact model (all its
    contacts must share it; point contacts use the largest ``mu`` among them).
    """
    if grasp.dim != 2:
        raise GraspError("Steinitz efficiency is implemented for planar grasps on polygons")
    models = {c.model for c in grasp.contacts}
    if len(models) != 1:
        raise GraspError("efficiency needs contacts of one model, to sample the boundary alike")
    model = models.pop()
    mu = max(c.mu for c in grasp.contacts)
    eps_s, center, length, k = boundary_epsilon(vertices, spacing=spacing, model=model, mu=mu)
    g = Grasp(grasp.contacts, center=tuple(center), length=length)
    eps_g = epsilon(g, "L1").hi
    return Efficiency(eps_g, eps_s, eps_g / eps_s if eps_s > 0 else 0.0,
                      steinitz_bound(len(grasp.contacts), 3), len(grasp.contacts),
                      tuple(center), length, k)

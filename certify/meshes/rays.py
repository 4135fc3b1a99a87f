"""First hits of rays on a mesh, with Intel Embree (the ``embreex`` package) where it is
installed and trimesh's own pure-numpy intersector otherwise.

Both engines only say which face a ray meets first; the distance along the ray is computed here,
the same way for both (the ray's intersection with the face's plane), so that the two give the
same contacts (the tests compare them). Embree works in single precision: its choice of face can
differ from the numpy engine's for a ray through an edge or a vertex, where both faces give the
same distance.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import trimesh
from trimesh.ray import ray_triangle

__all__ = ["ENGINES", "embree_available", "Hits", "RayCaster"]

#: Engine names: ``auto`` is ``embree`` when embreex is installed, else ``triangle``.
ENGINES = ("auto", "embree", "triangle")


def embree_available() -> bool:
    """True when the ``embreex`` package (Embree ray tracing) can be imported."""
    try:
        import embreex  # noqa: F401
    except ImportError:
        return False
    return True


@dataclass(frozen=True)
class Hits:
    """First hits of a batch of rays.

    Attributes
    ----------
    t : ndarray, shape (n,)
        Distance along each (unit) ray to its first hit, ``inf`` where it meets nothing.
    face : ndarray of int, shape (n,)
        The face hit, -1 where none.
    """

    t: np.ndarray
    face: np.ndarray

    @property
    def hit(self) -> np.ndarray:
        """Which rays met the mesh."""
        return self.face >= 0


@dataclass(frozen=True, eq=False)
class RayCaster:
    """Casts rays on one mesh.

    Parameters
    ----------
    mesh : trimesh.Trimesh
    engine : str
        ``'auto'``, ``'embree'`` (raises ImportError without embreex) or ``'triangle'``.

    Examples
    --------
    >>> import numpy as np, trimesh
    >>> caster = RayCaster(trimesh.creation.box((2, 2, 2)), engine="triangle")
    >>> caster.first_hits(np.array([[5.0, 0, 0], [5.0, 5, 0]]), np.array([[-1.0, 0, 0]] * 2)).t.tolist()
    [4.0, inf]
    """

    mesh: trimesh.Trimesh
    engine: str = "auto"
    _intersector: object = field(init=False, repr=False)

    def __post_init__(self) -> None:
        if self.engine not in ENGINES:
            raise ValueError(f"unknown ray engine {self.engine!r}: give one of {', '.join(ENGINES)}")
        name = self.engine
        if name == "auto":
            name = "embree" if embree_available() else "triangle"
        if name == "embree":
            from trimesh.ray.ray_pyembree import RayMeshIntersector as Embree
            intersector = Embree(self.mesh)
        else:
            intersector = ray_triangle.RayMeshIntersector(self.mesh)
        object.__setattr__(self, "engine", name)
        object.__setattr__(self, "_intersector", intersector)

    def first_hits(self, origins: np.ndarray, directions: np.ndarray) -> Hits:
        """First hit of every ray ``origins[i] + t directions[i]``, ``t >= 0``.

        Parameters
        ----------
        origins, directions : ndarray, shape (n, 3)
            Directions of unit length.

        Returns
        -------
        Hits
        """
        origins = np.ascontiguousarray(origins, dtype=float).reshape(-1, 3)
        directions = np.ascontiguousarray(directions, dtype=float).reshape(-1, 3)
        n = len(origins)
        t = np.full(n, np.inf)
        face = np.full(n, -1, dtype=np.int64)
        if n == 0:
            return Hits(t, face)
        tri, ray = self._intersector.intersects_id(origins, directions, multiple_hits=False)[:2]
        tri, ray = np.asarray(tri, dtype=np.int64), np.asarray(ray, dtype=np.int64)
        normals = self.mesh.face_normals[tri]
        v0 = self.mesh.triangles[tri, 0, :]
        denom = np.einsum("ij,ij->i", normals, directions[ray])
        with np.errstate(divide="ignore", invalid="ignore"):
            dist = np.einsum("ij,ij->i", normals, v0 - origins[ray]) / denom
        ok = np.isfinite(dist)
        # a hit a hair behind the origin (the numpy engine accepts -1e-6) is a hit at the origin
        t[ray[ok]] = np.maximum(dist[ok], 0.0)
        face[ray[ok]] = tri[ok]
        return Hits(t, face)

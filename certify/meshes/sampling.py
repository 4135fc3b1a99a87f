"""Antipodal sampling of parallel-jaw poses on a mesh (as Dex-Net's and ACRONYM's samplers do),
so that a user with only a mesh gets a grasp set.

1. Sample a surface point ``p1`` (uniform over the area) with outward normal ``n1``.
2. Pick a direction ``v`` in the friction cone about the inward normal ``-n1`` (half-angle
   ``atan(mu)``, uniform in angle) and cast a ray through the object from ``p1`` along ``v``;
   where it leaves the object is ``p2``, with outward normal ``n2``.
3. Keep the pair when it is antipodal, ``v`` also within ``atan(mu)`` of ``n2`` (so the line
   ``p1 p2`` lies in both friction cones, Nguyen's condition), and fits the gripper:
   ``|p2 - p1| + 2 clearance`` at most the largest opening.
4. The pose: closing axis ``x`` from ``p2`` to ``p1`` (pad A touches ``p1``), origin at the
   midpoint, opening ``min(max opening, |p2 - p1| + 2 clearance)``; the approach axis ``z`` is
   drawn uniformly around ``x``, up to ``approaches`` times, and the first approach free of
   collisions (:func:`qualgrasp.certify.meshes.contacts.approach_collision`) whose open pads do
   not cut into the object (:func:`~qualgrasp.certify.meshes.contacts.pierces_pad`: on a curved
   surface the clearance may not clear a pad's corner) is kept.

Poses are returned in the ``qualgrasp`` convention; whether each pose then yields contacts, and
holds the object, is for ``qualgrasp contacts`` to say.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import trimesh

from .contacts import approach_collision, pierces_pad
from .gripper import ParallelJaw
from .rays import RayCaster

__all__ = ["SampledPose", "sample_poses", "CLEARANCE"]

#: Gap between each pad and the object before closing, m.
CLEARANCE = 0.005


@dataclass(frozen=True)
class SampledPose:
    """A sampled pose: ``T`` (``qualgrasp`` convention), opening ``width`` and the antipodal
    points ``p1``, ``p2`` it was built on."""

    T: np.ndarray
    width: float
    p1: np.ndarray
    p2: np.ndarray


def _perpendicular(x: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    a = np.eye(3)[np.argmin(np.abs(x))]
    b1 = np.cross(x, a)
    b1 /= np.linalg.norm(b1)
    b2 = np.cross(x, b1)
    theta = rng.uniform(0, 2 * np.pi)
    return np.cos(theta) * b1 + np.sin(theta) * b2


def sample_poses(mesh: trimesh.Trimesh, gripper: ParallelJaw, n: int, *, mu: float, seed: int = 0,
                 approaches: int = 8, tries: int = 50, caster: RayCaster | None = None) -> list[SampledPose]:
    """Up to ``n`` antipodal poses free of approach collisions (module docstring).

    Parameters
    ----------
    mesh : trimesh.Trimesh
        A checked mesh in metres.
    gripper : ParallelJaw
    n : int
        Poses wanted.
    mu : float
        Friction coefficient of the antipodal test.
    seed : int
    approaches : int
        Approach directions tried per antipodal pair.
    tries : int
        Surface points drawn per pose wanted, at most (the sampler stops there).
    caster : RayCaster, optional

    Returns
    -------
    list of SampledPose
        Fewer than ``n`` when the surface offers no more within ``tries * n`` points.

    Examples
    --------
    >>> import trimesh
    >>> from qualgrasp.certify.meshes.gripper import load_gripper
    >>> poses = sample_poses(trimesh.creation.box((0.04, 0.05, 0.06)), load_gripper("franka_panda"), 5, mu=0.5)
    >>> len(poses), all(p.width <= 0.08 for p in poses)
    (5, True)
    """
    caster = caster or RayCaster(mesh)
    vertices, edges = mesh.vertices.view(np.ndarray), np.asarray(mesh.edges_unique).view(np.ndarray)
    rng = np.random.default_rng(seed)
    half = np.arctan(mu)
    out: list[SampledPose] = []
    drawn, batch = 0, max(64, 2 * n)
    while len(out) < n and drawn < tries * n:
        pts, faces = trimesh.sample.sample_surface(mesh, batch, seed=int(rng.integers(2**31)))
        drawn += batch
        n1 = mesh.face_normals[faces]
        # a direction in the friction cone about -n1, uniform in angle
        phi = rng.uniform(0, half, len(pts))
        perp = np.array([_perpendicular(-v, rng) for v in n1])
        v = -n1 * np.cos(phi)[:, None] + perp * np.sin(phi)[:, None]
        # start inside, past the numpy engine's acceptance of hits up to 1e-6 behind the origin
        eps = max(1e-5, 1e-6 * mesh.scale)
        hits = caster.first_hits(pts + eps * v, v)
        for i in np.flatnonzero(hits.hit):
            n2, vi = mesh.face_normals[hits.face[i]], v[i]
            if n2 @ vi < np.cos(half):  # v not within the cone of the exit point (or an entry)
                continue
            d = float(hits.t[i] + eps)
            if d + 2 * CLEARANCE > gripper.max_opening:
                continue
            p1, p2 = pts[i], pts[i] + d * vi
            x = (p1 - p2) / d
            width = min(gripper.max_opening, max(gripper.min_opening, d + 2 * CLEARANCE))
            for _ in range(approaches):
                z = _perpendicular(x, rng)
                T = np.eye(4)
                T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = x, np.cross(z, x), z, (p1 + p2) / 2
                if approach_collision(mesh, caster, T, gripper, width) is None and not any(
                        pierces_pad((vertices - T[:3, 3]) @ T[:3, :3], edges, gripper, side, width)
                        for side in (1.0, -1.0)):
                    out.append(SampledPose(T, width, p1, p2))
                    break
            if len(out) == n:
                break
    return out

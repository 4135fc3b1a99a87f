"""Contacts from gripper poses: close the jaws on the mesh and take the patches where they touch.

Parallel jaws (:func:`jaw_contacts`), in the ``qualgrasp`` pose convention
(:mod:`qualgrasp.certify.meshes.gripper`):

1. **Opening.** A pose whose width lies outside the gripper's opening range is an error row
   (``too_wide``, or ``too_narrow``).
2. **Approach.** The hand comes from far away along ``+z`` with the jaws open at the pose's
   width, so each finger sweeps its cross-section (the pad and the finger behind it, ``x`` from
   the pad face outward by the finger's thickness, ``y`` across the pad) from ``z = -inf`` up to
   its tip (``z = height/2``), and the palm its face (``width x depth``) up to ``z = -offset``.
   The object must not enter these prisms: a ray cast back along ``-z`` from a grid on each
   finger's tip face and on the palm face must meet nothing, and no mesh vertex may lie inside a
   prism (which catches parts thinner than the grid). Otherwise the row is an error
   (``collision``, naming the part). The finger's shape between the pad and the palm is not
   modelled beyond its cross-section.
3. **Closing.** Each pad then closes along the closing axis on its own (the object is taken to
   stay put: a compliant or floating hand, as Dex-Net's and ACRONYM's contact models assume),
   until its first point touches the mesh, at most the opening width. The contact area is the
   pad's whole face, rim included, and the first touch is found exactly on it: the smallest
   travel of a linear function over the surface inside the pad's prism is reached at a corner of
   some triangle's piece in the prism, that is at a mesh vertex inside the prism, at a mesh edge
   crossing one of the prism's side planes, or where a prism edge (a ray from a pad corner)
   meets a face (:func:`rim_touch`; a disc pad's rim is sampled by ``8 resolution`` rays and its
   edge crossings solved on the cylinder). The pad is also sampled on a ``resolution x
   resolution`` grid of cells (a disc pad keeps the cells whose centre lies inside it); each
   cell casts a ray along the closing direction. A pad that meets nothing is an error row
   (``no_contact``); a ray that starts inside the object (its first face is met from behind), or
   a mesh edge passing through the pad's face (:func:`pierces_pad`: a thin wall between the
   approach test's rays cuts into the pad) is a ``collision``.
4. **Patch.** The cells whose ray meets the mesh within ``tolerance`` beyond the first touch
   form the patch: the pad pressed ``tolerance`` into the object would penetrate there (the
   pad's compliance). Its points are the ray hits. When no cell does (the object touches only
   the outer half-cell rim of the pad: a vertex, an edge or a face seen only by the rim), the
   patch is the touching point alone, with no area, the one-cell torsion floor below, and the
   pad's normal (a flat pad pressing a vertex or an edge of the object) or, for a pad's corner
   on a face, the face's.

Patch contact model (certify's ``soft`` contact, until a registry model ``patch`` replaces it):
the contact point is the patch's centroid, the normal the mean of the inward face normals at its
points (each cell stands for the same pad area, so this is the area-weighted normal), and the
torsional length is the patch's mean distance from the centroid, measured across the normal.
Under uniform pressure ``p`` over the patch of area ``A`` the normal force is ``f_n = p A`` and
the largest frictional moment about the normal ``mu p integral |r| dA = mu f_n mean(|r|)``, so
``torsion = mean(|r|)``; for a disc of radius ``a`` that is ``2a/3``, the classical value. A cell
at distance ``r_i`` counts ``sqrt(r_i^2 + h^2/6)`` (its root-mean-square distance, ``h`` the cell
size), so a one-cell patch keeps a torsion of about ``0.4 h``. certify's soft cone
``norm((f_t, m / torsion)) <= mu f_n`` couples force and moment by an ellipse, the usual
approximation of the limit surface (Howe and Cutkosky, 1996).

Point hands (:func:`fingertip_contacts`): each fingertip moves in a straight line towards the
mean of the fingertips, at most the hand's ``travel``, and touches at the first hit, a ``point``
contact with the inward face normal. A fingertip that meets nothing is ``no_contact``; one that
starts inside the object is a ``collision``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import trimesh

from .gripper import ParallelJaw, PointHand
from .rays import RayCaster

__all__ = ["TOLERANCE", "RESOLUTION", "Patch", "Outcome", "pad_grid", "pad_rim", "rim_touch", "pierces_pad",
           "approach_collision", "jaw_contacts", "fingertip_contacts", "REASONS"]

#: Default penetration tolerance, m (a rubber pad's compliance).
TOLERANCE = 5e-4
#: Default pad grid: cells per side.
RESOLUTION = 21
#: Cells per side of the approach grids on the fingers' tips and the palm.
_SWEEP = 9
#: Why a pose gives no contacts.
REASONS = ("too_wide", "too_narrow", "collision", "no_contact")


@dataclass(frozen=True)
class Patch:
    """Where one pad (or fingertip) touches the object.

    Attributes
    ----------
    centroid : ndarray, shape (3,)
        Contact point, m (object frame).
    normal : ndarray, shape (3,)
        Unit inward normal (into the object).
    area : float
        Pad area in contact, m^2 (0 for a fingertip).
    radius : float
        Largest distance of a patch point from the centroid across the normal, m.
    torsion : float
        Torsional length (module docstring), m; 0 for a fingertip.
    points : ndarray, shape (k, 3)
        The patch's points on the surface.
    travel : float
        How far the pad (fingertip) moved before it touched, m.
    """

    centroid: np.ndarray
    normal: np.ndarray
    area: float
    radius: float
    torsion: float
    points: np.ndarray
    travel: float


@dataclass(frozen=True)
class Outcome:
    """The contacts of one pose: its patches, or why there are none (``reason`` one of
    :data:`REASONS`, ``message`` a sentence)."""

    patches: tuple[Patch, ...] = ()
    reason: str | None = None
    message: str | None = None

    @property
    def ok(self) -> bool:
        return self.reason is None


def pad_grid(gripper: ParallelJaw, resolution: int = RESOLUTION) -> tuple[np.ndarray, float]:
    """Cell centres ``(y, z)`` of a pad (shape ``(k, 2)``, metres, about the pad centre) and the
    cell size ``h`` (the larger side of a cell).

    Examples
    --------
    >>> from qualgrasp.certify.meshes.gripper import load_gripper
    >>> uv, h = pad_grid(load_gripper("franka_panda"), 5)
    >>> uv.shape, round(h, 4)
    ((25, 2), 0.0037)
    """
    hy, hz = gripper.pad_width / resolution, gripper.pad_height / resolution
    centres = (np.arange(resolution) + 0.5) / resolution - 0.5
    y, z = np.meshgrid(centres * gripper.pad_width, centres * gripper.pad_height, indexing="ij")
    uv = np.column_stack([y.ravel(), z.ravel()])
    if gripper.pad_shape == "disc":
        uv = uv[np.hypot(uv[:, 0], uv[:, 1]) <= gripper.pad_width / 2]
    return uv, max(hy, hz)


def pad_rim(gripper: ParallelJaw, resolution: int = RESOLUTION) -> np.ndarray:
    """Points ``(y, z)`` on the pad's rim whose rays (with the exact rim test) cover it: a
    rectangle's four corners, or ``8 resolution`` points around a disc.

    Examples
    --------
    >>> from qualgrasp.certify.meshes.gripper import load_gripper
    >>> pad_rim(load_gripper("franka_panda")).tolist()
    [[-0.00875, -0.00925], [-0.00875, 0.00925], [0.00875, -0.00925], [0.00875, 0.00925]]
    """
    a, b = gripper.pad_width / 2, gripper.pad_height / 2
    if gripper.pad_shape == "disc":
        phi = np.arange(8 * resolution) * (2 * np.pi / (8 * resolution))
        return np.column_stack([a * np.cos(phi), a * np.sin(phi)])
    return np.array([(-a, -b), (-a, b), (a, -b), (a, b)])


def rim_touch(local: np.ndarray, edges: np.ndarray, gripper: ParallelJaw, side: float,
              w: float) -> tuple[float, np.ndarray | None]:
    """The exact first touch of a pad from the mesh's vertices inside its prism and its edges'
    crossings of the prism's side surface (module docstring, step 3): ``(travel, point)`` in
    gripper coordinates, ``(inf, None)`` when neither lies within the opening.

    Parameters
    ----------
    local : ndarray, shape (v, 3)
        Mesh vertices in gripper coordinates.
    edges : ndarray, shape (e, 2)
        Vertex indices of the mesh's edges.
    side : float
        ``+1`` for pad A (at ``x = +w/2``, closing along ``-x``), ``-1`` for pad B.

    Examples
    --------
    >>> from qualgrasp.certify.meshes.gripper import load_gripper
    >>> V = np.array([[0.025, 0.0095, 0.0], [0.0, 0.0, 0.0]])  # an edge entering the pad's prism
    >>> t, p = rim_touch(V, np.array([[0, 1]]), load_gripper("franka_panda"), 1.0, 0.06)
    >>> round(t, 6), p.round(6).tolist()     # it crosses the rim y = 0.00875 nearest to pad A (x = 0.03)
    (0.006974, [0.023026, 0.00875, 0.0])
    """
    a, b = gripper.pad_width / 2, gripper.pad_height / 2
    disc = gripper.pad_shape == "disc"
    if disc:
        b = a
    y, z = local[:, 1], local[:, 2]
    # which side of each of the prism's bounding planes a vertex lies on: an edge whose two ends lie
    # beyond the same plane cannot meet the prism, and one with both ends inside crosses no side
    low_y, high_y, low_z, high_z = y < -a, y > a, z < -b, z > b
    out = low_y | high_y | low_z | high_z
    if disc:
        out |= y * y + z * z > a * a
    travel = w / 2 - side * local[:, 0]
    inside = ~out & (travel >= 0) & (travel <= w)
    cands = [local[inside]]
    i, j = edges[:, 0], edges[:, 1]
    keep = ((out[i] | out[j]) & ~(low_y[i] & low_y[j]) & ~(high_y[i] & high_y[j])
            & ~(low_z[i] & low_z[j]) & ~(high_z[i] & high_z[j]))
    P0, D = local[i[keep]], local[j[keep]] - local[i[keep]]
    if disc:  # |(P0 + s D)_yz|^2 = a^2, a quadratic in s
        qa = D[:, 1] ** 2 + D[:, 2] ** 2
        qb = 2 * (P0[:, 1] * D[:, 1] + P0[:, 2] * D[:, 2])
        qc = P0[:, 1] ** 2 + P0[:, 2] ** 2 - a * a
        disc_ = qb * qb - 4 * qa * qc
        ok = (qa > 0) & (disc_ >= 0)
        root = np.sqrt(np.where(ok, disc_, 0.0))
        for sgn in (-1.0, 1.0):
            s = np.where(ok, (-qb + sgn * root) / np.where(ok, 2 * qa, 1.0), -1.0)
            hit = (s >= 0) & (s <= 1)
            cands.append(P0[hit] + s[hit, None] * D[hit])
    else:
        for axis, bound, other, obound in ((1, a, 2, b), (2, b, 1, a)):
            for c in (-bound, bound):
                ok = D[:, axis] != 0
                s = np.where(ok, (c - P0[:, axis]) / np.where(ok, D[:, axis], 1.0), -1.0)
                hit = (s >= 0) & (s <= 1)
                pts = P0[hit] + s[hit, None] * D[hit]
                pts[:, axis] = c  # exactly on the side plane
                cands.append(pts[np.abs(pts[:, other]) <= obound])
    pts = np.vstack(cands)
    t = w / 2 - side * pts[:, 0]
    pts, t = pts[(t >= 0) & (t <= w)], t[(t >= 0) & (t <= w)]
    if not len(t):
        return np.inf, None
    i = int(np.argmin(t))
    return float(t[i]), pts[i]


def pierces_pad(local: np.ndarray, edges: np.ndarray, gripper: ParallelJaw, side: float, w: float) -> bool:
    """Does a mesh edge pass through the pad's face (one end in front of it, the other behind,
    crossing inside the pad's outline)? The object then cuts into the pad: a thin wall can do so
    between the approach test's rays and with no vertex in the finger's prism.

    Examples
    --------
    >>> from qualgrasp.certify.meshes.gripper import load_gripper
    >>> wall = np.array([[0.02, 0.001, 0.0], [0.05, 0.001, 0.0]])  # an edge through pad A's face at x = 0.03
    >>> pierces_pad(wall, np.array([[0, 1]]), load_gripper("franka_panda"), 1.0, 0.06)
    True
    >>> pierces_pad(wall - [0.0, 0.02, 0.0], np.array([[0, 1]]), load_gripper("franka_panda"), 1.0, 0.06)
    False
    """
    travel = w / 2 - side * local[:, 0]
    i, j = edges[:, 0], edges[:, 1]
    cross = (travel[i] < 0) != (travel[j] < 0)
    cross &= (travel[i] != 0) & (travel[j] != 0)  # an end on the face touches, it does not cut
    i, j = i[cross], j[cross]
    s = travel[i] / (travel[i] - travel[j])
    yz = local[i, 1:] + s[:, None] * (local[j, 1:] - local[i, 1:])
    a, b = gripper.pad_width / 2, gripper.pad_height / 2
    if gripper.pad_shape == "disc":
        return bool((yz[:, 0] ** 2 + yz[:, 1] ** 2 < a * a).any())
    return bool(((np.abs(yz[:, 0]) < a) & (np.abs(yz[:, 1]) < b)).any())


def _grid(a: float, b: float, n: int) -> np.ndarray:
    return (np.arange(n) + 0.5) / n * (b - a) + a


def _sweep_boxes(gripper: ParallelJaw, w: float) -> list[tuple[str, np.ndarray, float]]:
    """The approach prisms in gripper coordinates: ``(part, [[x0, x1], [y0, y1]], z_top)``."""
    t, py, h = gripper.finger_thickness, gripper.pad_width / 2, gripper.pad_height / 2
    half = max(gripper.palm_width / 2, w / 2 + t)
    return [("finger A", np.array([[w / 2, w / 2 + t], [-py, py]]), h),
            ("finger B", np.array([[-w / 2 - t, -w / 2], [-py, py]]), h),
            ("palm", np.array([[-half, half], [-gripper.palm_depth / 2, gripper.palm_depth / 2]]), -gripper.palm_offset)]


def approach_collision(mesh: trimesh.Trimesh, caster: RayCaster, T: np.ndarray, gripper: ParallelJaw,
                        w: float) -> str | None:
    """The part that meets the object while approaching, or None (module docstring, step 2)."""
    R, o = T[:3, :3], T[:3, 3]
    V = mesh.vertices.view(np.ndarray)  # a plain array: trimesh's tracked one hashes itself on every use
    boxes = _sweep_boxes(gripper, w)
    # only vertices across the prisms' lateral extent can lie inside one
    reach = max(float(np.abs(box[1]).max()) for _, box, _ in boxes)
    near = np.abs((V - o) @ R[:, 1]) <= reach
    local = (V[near] - o) @ R  # those vertices in gripper coordinates
    origins, parts = [], []
    for part, box, top in boxes:
        inside = ((local[:, 0] >= box[0, 0]) & (local[:, 0] <= box[0, 1]) & (local[:, 1] >= box[1, 0])
                  & (local[:, 1] <= box[1, 1]) & (local[:, 2] <= top))
        if inside.any():
            return part
        x, y = np.meshgrid(_grid(*box[0], _SWEEP), _grid(*box[1], _SWEEP), indexing="ij")
        pts = np.column_stack([x.ravel(), y.ravel(), np.full(x.size, top)])
        origins.append(pts @ R.T + o)
        parts += [part] * len(pts)
    origins = np.vstack(origins)
    hits = caster.first_hits(origins, np.broadcast_to(-R[:, 2], origins.shape))
    if hits.hit.any():
        return parts[int(np.flatnonzero(hits.hit)[0])]
    return None


def _point_patch(point: np.ndarray, normal: np.ndarray, cell: float, travel: float) -> Patch:
    """A touch seen only by the pad's rim: the point alone, no area, the one-cell torsion floor."""
    return Patch(point, normal + 0.0, 0.0, 0.0, float(cell / np.sqrt(6)), point[None], travel)


def _patch(mesh: trimesh.Trimesh, origins: np.ndarray, direction: np.ndarray, t: np.ndarray, face: np.ndarray,
           tolerance: float, cell: float, cell_area: float, first: float) -> Patch:
    keep = t <= first + tolerance
    points = origins[keep] + t[keep, None] * direction
    centroid = points.mean(axis=0)
    normal = -mesh.face_normals[face[keep]].mean(axis=0)
    normal = normal / np.linalg.norm(normal) + 0.0  # + 0.0: no negative zeros in the output
    r = points - centroid
    r -= np.outer(r @ normal, normal)
    dist = np.linalg.norm(r, axis=1)
    torsion = float(np.sqrt(dist ** 2 + cell ** 2 / 6).mean())
    return Patch(centroid, normal, float(keep.sum() * cell_area), float(dist.max()), torsion, points, first)


def jaw_contacts(mesh: trimesh.Trimesh, gripper: ParallelJaw, poses: np.ndarray, widths: np.ndarray, *,
                 tolerance: float = TOLERANCE, resolution: int = RESOLUTION,
                 caster: RayCaster | None = None) -> list[Outcome]:
    """Close a parallel-jaw gripper at every pose (module docstring).

    Parameters
    ----------
    mesh : trimesh.Trimesh
        A checked mesh in metres (:func:`qualgrasp.certify.meshes.mesh.check_mesh`).
    gripper : ParallelJaw
    poses : ndarray, shape (n, 4, 4)
        Rigid transforms, ``qualgrasp`` convention (gripper to object coordinates).
    widths : ndarray, shape (n,)
        Opening widths, m.
    tolerance : float
        Penetration tolerance, m.
    resolution : int
        Pad grid cells per side.
    caster : RayCaster, optional
        A ray caster on ``mesh`` (default: a new one, Embree when installed).

    Returns
    -------
    list of Outcome
        One per pose: two patches (pad A at ``x = +w/2``, pad B), or the reason there are none.

    Examples
    --------
    >>> import numpy as np, trimesh
    >>> from qualgrasp.certify.meshes.gripper import load_gripper
    >>> box = trimesh.creation.box((0.05, 0.06, 0.06))
    >>> out = jaw_contacts(box, load_gripper("franka_panda"), np.eye(4)[None], np.array([0.07]))
    >>> [p.centroid.round(4).tolist() for p in out[0].patches], [p.normal.tolist() for p in out[0].patches]
    ([[0.025, 0.0, 0.0], [-0.025, 0.0, 0.0]], [[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    """
    caster = caster or RayCaster(mesh)
    uv, cell = pad_grid(gripper, resolution)
    rim = pad_rim(gripper, resolution)
    edges = np.asarray(mesh.edges_unique).view(np.ndarray)
    cell_area = gripper.pad_width * gripper.pad_height / resolution ** 2
    out = []
    for T, w in zip(np.asarray(poses, dtype=float), np.asarray(widths, dtype=float)):
        if w > gripper.max_opening:
            out.append(Outcome(reason="too_wide", message=f"opening {w:.4g} m is wider than the gripper opens "
                                                          f"({gripper.max_opening:g} m)"))
            continue
        if w < gripper.min_opening:
            out.append(Outcome(reason="too_narrow", message=f"opening {w:.4g} m is narrower than the gripper's "
                                                            f"smallest ({gripper.min_opening:g} m)"))
            continue
        part = approach_collision(mesh, caster, T, gripper, w)
        if part is not None:
            out.append(Outcome(reason="collision", message=f"the {part} meets the object while approaching"))
            continue
        R, o = T[:3, :3], T[:3, 3]
        vertices = (mesh.vertices.view(np.ndarray) - o) @ R  # in gripper coordinates
        patches = []
        for name, side in (("A", 1.0), ("B", -1.0)):
            patch = _pad_patch(mesh, caster, R, o, vertices, edges, gripper, side, w, uv, rim,
                               tolerance, cell, cell_area)
            if isinstance(patch, tuple):
                patches = Outcome(reason=patch[0], message=f"pad {name} {patch[1]}")
                break
            patches.append(patch)
        out.append(patches if isinstance(patches, Outcome) else Outcome(tuple(patches)))
    return out


def _pad_patch(mesh, caster, R, o, vertices, edges, gripper, side, w, uv, rim, tolerance, cell,
               cell_area) -> Patch | tuple[str, str]:
    """One pad's patch (module docstring, steps 3 and 4), or the reason it has none and why."""
    yz = np.vstack([uv, rim])
    origins = np.column_stack([np.full(len(yz), side * w / 2), yz]) @ R.T + o
    direction = -side * R[:, 0]
    hits = caster.first_hits(origins, np.broadcast_to(direction, origins.shape))
    reach = hits.hit & (hits.t <= w)
    if pierces_pad(vertices, edges, gripper, side, w):
        return "collision", "cuts into the object (an edge of the mesh passes through the pad's face)"
    t_exact, point = rim_touch(vertices, edges, gripper, side, w)
    if not reach.any() and point is None:
        return "no_contact", "meets nothing within the opening"
    if reach.any():
        first = np.flatnonzero(reach)[np.argmin(hits.t[reach])]
        if mesh.face_normals[hits.face[first]] @ direction > 0:
            return "collision", "starts inside the object"
    t_ray = hits.t[reach].min() if reach.any() else np.inf
    t0 = float(min(t_ray, t_exact))
    cells = reach[:len(uv)] & (hits.t[:len(uv)] <= t0 + tolerance)
    if cells.any():
        return _patch(mesh, origins[:len(uv)][cells], direction, hits.t[:len(uv)][cells],
                      hits.face[:len(uv)][cells], tolerance, cell, cell_area, t0)
    if t_exact <= t_ray:  # a vertex or an edge of the object against the flat pad
        return _point_patch(point @ R.T + o, direction, cell, t0)
    j = len(uv) + int(np.argmin(np.where(reach[len(uv):], hits.t[len(uv):], np.inf)))  # a pad corner on a face
    return _point_patch(origins[j] + hits.t[j] * direction, -mesh.face_normals[hits.face[j]], cell, t0)


def fingertip_contacts(mesh: trimesh.Trimesh, hand: PointHand, fingertips: np.ndarray, *,
                       caster: RayCaster | None = None) -> list[Outcome]:
    """Close a point hand from every set of fingertip positions (module docstring).

    Parameters
    ----------
    mesh : trimesh.Trimesh
    hand : PointHand
    fingertips : ndarray, shape (n, fingers, 3)
        Open fingertip positions, object frame, m.
    caster : RayCaster, optional

    Returns
    -------
    list of Outcome
        One per row: a zero-area patch per finger (a point contact), or the reason there are none.

    Examples
    --------
    >>> import numpy as np, trimesh
    >>> from qualgrasp.certify.meshes.gripper import load_gripper
    >>> tips = np.array([[[0.1, 0, 0], [-0.05, 0.0866, 0], [-0.05, -0.0866, 0]]])
    >>> out = fingertip_contacts(trimesh.creation.icosphere(3, 0.03), load_gripper("three_finger_point"), tips)
    >>> [round(float(np.linalg.norm(p.centroid)), 3) for p in out[0].patches]
    [0.03, 0.03, 0.03]
    """
    caster = caster or RayCaster(mesh)
    tips = np.asarray(fingertips, dtype=float)
    out = []
    for row in tips:
        direction = row.mean(axis=0) - row
        length = np.linalg.norm(direction, axis=1)
        if (length == 0).any():
            out.append(Outcome(reason="no_contact", message="a fingertip lies at the fingertips' centre and has "
                                                            "no direction to close in"))
            continue
        direction /= length[:, None]
        hits = caster.first_hits(row, direction)
        reach = hits.hit & (hits.t <= hand.travel)
        behind = hits.hit & (np.einsum("ij,ij->i", mesh.face_normals[hits.face], direction) > 0)
        if behind.any():
            out.append(Outcome(reason="collision",
                               message=f"fingertip {int(np.flatnonzero(behind)[0])} starts inside the object"))
            continue
        if not reach.all():
            i = int(np.flatnonzero(~reach)[0])
            out.append(Outcome(reason="no_contact", message=f"fingertip {i} meets nothing within its travel "
                                                            f"({hand.travel:g} m)"))
            continue
        points = row + hits.t[:, None] * direction
        out.append(Outcome(tuple(Patch(p, 0.0 - mesh.face_normals[f], 0.0, 0.0, 0.0, p[None], float(t))
                                 for p, f, t in zip(points, hits.face, hits.t))))
    return out

"""Object meshes: reading, checks (closed, non-degenerate, plausible size) and mass properties.

Meshes are read with trimesh (OBJ, STL, PLY, GLB/GLTF, OFF and the other formats it knows; a
file holding a scene of several parts is merged into one mesh) and converted to metres
(``units``). A mesh is usable when

* it has faces and finite vertices;
* no face is degenerate (area below ``(1e-9 size)^2``, ``size`` the bounding-box diagonal);
* it is closed: every edge is shared by exactly two faces (no holes, no non-manifold edges);
* its faces are wound consistently and outward (positive signed volume);
* its volume is not zero (at least ``1e-9 size^3``);
* its size (bounding-box diagonal) lies between :data:`SIZE_MIN` and :data:`SIZE_MAX` metres: a
  mesh drawn in millimetres but read as metres is 1000 times too large, and is refused with the
  ``units`` that would fix it.

Each failed rule raises :class:`~qualgrasp.certify.meshes.errors.MeshError` with the count and
what to do. :func:`repair_mesh` applies trimesh's standard repairs on request and says what it
changed; nothing is repaired silently.

Mass properties (:func:`mass_properties`) are those of a solid of uniform density: the centre
of mass and the inertia tensor about it, from the mesh and either a density or a total mass.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import trimesh

from .errors import MeshError

__all__ = ["UNITS", "SIZE_MIN", "SIZE_MAX", "load_mesh", "check_mesh", "repair_mesh", "MassProperties",
           "mass_properties"]

#: Length units a mesh file may be drawn in, and their size in metres.
UNITS = {"m": 1.0, "cm": 0.01, "mm": 0.001, "in": 0.0254}
#: Smallest and largest accepted object size (bounding-box diagonal), metres.
SIZE_MIN, SIZE_MAX = 1e-3, 5.0
#: Relative thresholds: degenerate face area (times size squared), zero volume (times size cubed).
_AREA_EPS, _VOLUME_EPS = 1e-18, 1e-9
#: Density of water, kg/m^3: the default when neither a density nor a mass is given.
WATER = 1000.0


def load_mesh(path: str | Path, *, units: str = "m", repair: bool = False) -> trimesh.Trimesh:
    """Read a mesh file, convert it to metres and check it (:func:`check_mesh`).

    Parameters
    ----------
    path : str or pathlib.Path
        OBJ, STL, PLY, GLB/GLTF, OFF or any other format trimesh reads.
    units : str
        The unit the file is drawn in: ``'m'``, ``'cm'``, ``'mm'`` or ``'in'``.
    repair : bool
        Apply :func:`repair_mesh` before checking (its notes are in ``mesh.metadata['repairs']``).

    Returns
    -------
    trimesh.Trimesh
        In metres.

    Raises
    ------
    MeshError
        The file cannot be read, or the mesh breaks a rule (module docstring).

    Examples
    --------
    >>> import tempfile, pathlib, trimesh
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "box.stl"
    >>> _ = trimesh.creation.box((400, 200, 100)).export(path)
    >>> load_mesh(path, units="mm").extents.round(3).tolist()
    [0.4, 0.2, 0.1]
    >>> load_mesh(path)
    Traceback (most recent call last):
    ...
    qualgrasp.certify.meshes.errors.MeshError: the mesh is 458 m across, more than 5 m: if it is drawn in millimetres, give units='mm' (--units mm)
    """
    if units not in UNITS:
        raise MeshError(f"unknown unit {units!r}: give one of {', '.join(UNITS)}")
    path = Path(path)
    if not path.is_file():
        raise MeshError(f"cannot read {path}: " + ("it is a folder" if path.is_dir() else "no such file"))
    try:
        loaded = trimesh.load(path, force="mesh", process=True)
    except Exception as err:  # trimesh raises many kinds for unreadable files
        first = str(err).splitlines()[0] if str(err) else type(err).__name__
        raise MeshError(f"cannot read {path} as a mesh: {first}") from None
    if not isinstance(loaded, trimesh.Trimesh) or len(loaded.faces) == 0:
        raise MeshError(f"{path} holds no triangles")
    mesh = loaded.copy()
    mesh.apply_scale(UNITS[units])
    if repair:
        mesh, notes = repair_mesh(mesh)
        mesh.metadata["repairs"] = notes
    check_mesh(mesh, units=units)
    return mesh


def _size(mesh: trimesh.Trimesh) -> float:
    return float(np.linalg.norm(mesh.bounds[1] - mesh.bounds[0]))


def check_mesh(mesh: trimesh.Trimesh, *, units: str = "m") -> None:
    """Raise :class:`MeshError` naming the first rule (module docstring) ``mesh`` breaks.

    Parameters
    ----------
    mesh : trimesh.Trimesh
        In metres.
    units : str
        The unit the mesh was read in, for the advice of the size rule.

    Examples
    --------
    >>> import trimesh
    >>> box = trimesh.creation.box((0.1, 0.05, 0.02))
    >>> check_mesh(box)
    >>> open_box = trimesh.Trimesh(box.vertices, box.faces[:-2])
    >>> check_mesh(open_box)
    Traceback (most recent call last):
    ...
    qualgrasp.certify.meshes.errors.MeshError: the mesh is not closed: 4 edges belong to one face only (holes); close it in a mesh editor or a watertight remesher, or try --repair (trimesh.repair.fill_holes)
    """
    if len(mesh.faces) == 0:
        raise MeshError("the mesh has no faces")
    if not np.isfinite(mesh.vertices).all():
        raise MeshError(f"{int((~np.isfinite(mesh.vertices)).any(axis=1).sum())} vertices are not finite numbers")
    size = _size(mesh)
    if size <= 0:
        raise MeshError("the mesh has zero size (all vertices coincide)")
    degenerate = int((mesh.area_faces <= _AREA_EPS * size * size).sum())
    if degenerate:
        raise MeshError(f"{degenerate} of {len(mesh.faces)} faces are degenerate (zero area); remove them "
                        "(trimesh: mesh.update_faces(mesh.nondegenerate_faces())) or try --repair")
    uses = _edge_uses(mesh)
    once, many = int((uses == 1).sum()), int((uses > 2).sum())
    if once:
        raise MeshError(f"the mesh is not closed: {once} edges belong to one face only (holes); close it in a "
                        "mesh editor or a watertight remesher, or try --repair (trimesh.repair.fill_holes)")
    if many:
        raise MeshError(f"the mesh is not manifold: {many} edges belong to three faces or more; split or "
                        "remesh it into closed solids")
    if not mesh.is_winding_consistent:
        raise MeshError("faces are wound inconsistently (neighbours disagree on the outside); fix with "
                        "trimesh.repair.fix_winding or --repair")
    volume = float(mesh.volume)
    if abs(volume) <= _VOLUME_EPS * size ** 3:
        raise MeshError(f"the mesh has zero volume ({volume:.3g} m^3 for a size of {size:.3g} m): a flat or "
                        "self-cancelling surface is not a solid")
    if volume < 0:
        raise MeshError(f"faces are wound inward (signed volume {volume:.3g} m^3); invert them "
                        "(mesh.invert()) or try --repair")
    if size > SIZE_MAX or size < SIZE_MIN:
        _size_error(size, units)


def _edge_uses(mesh: trimesh.Trimesh) -> np.ndarray:
    """How many faces use each distinct edge."""
    _, counts = np.unique(mesh.edges_sorted, axis=0, return_counts=True)
    return counts


def _size_error(size: float, units: str) -> None:
    scale = UNITS[units]
    # of the units that bring the size into range, the one giving the most typical object size
    # (0.2 m, in log scale) is the likely one
    fits = sorted((abs(np.log(size / scale * s / 0.2)), u) for u, s in UNITS.items()
                  if SIZE_MIN <= size / scale * s <= SIZE_MAX)
    hint = f": if it is drawn in {_NAMES[fits[0][1]]}, give units='{fits[0][1]}' (--units {fits[0][1]})" if fits else ""
    bound = f"more than {SIZE_MAX:g}" if size > SIZE_MAX else f"less than {SIZE_MIN:g}"
    raise MeshError(f"the mesh is {size:.3g} m across, {bound} m{hint}")


_NAMES = {"m": "metres", "cm": "centimetres", "mm": "millimetres", "in": "inches"}


def repair_mesh(mesh: trimesh.Trimesh) -> tuple[trimesh.Trimesh, tuple[str, ...]]:
    """trimesh's standard repairs, each reported: merge duplicate vertices, drop degenerate and
    duplicate faces, make the winding consistent and outward, fill simple holes.

    Returns
    -------
    mesh : trimesh.Trimesh
        A repaired copy (the input is not changed).
    notes : tuple of str
        What was changed, one sentence each (empty when nothing was).

    Examples
    --------
    >>> import trimesh
    >>> box = trimesh.creation.box((0.1, 0.05, 0.02))
    >>> fixed, notes = repair_mesh(trimesh.Trimesh(box.vertices, box.faces[:, ::-1]))
    >>> notes
    ('inverted the faces (they were wound inward)',)
    """
    m = mesh.copy()
    notes = []
    nv = len(m.vertices)
    m.merge_vertices()
    if len(m.vertices) < nv:
        notes.append(f"merged {nv - len(m.vertices)} duplicate vertices")
    size = _size(m)
    keep = m.area_faces > _AREA_EPS * size * size
    if not keep.all():
        m.update_faces(keep)
        notes.append(f"removed {int((~keep).sum())} degenerate faces")
    nf = len(m.faces)
    m.update_faces(m.unique_faces())
    if len(m.faces) < nf:
        notes.append(f"removed {nf - len(m.faces)} duplicate faces")
    m.remove_unreferenced_vertices()
    if not m.is_winding_consistent:
        trimesh.repair.fix_winding(m)
        notes.append("made the winding consistent")
    if not m.is_watertight:
        before = int((_edge_uses(m) == 1).sum())
        trimesh.repair.fill_holes(m)
        after = int((_edge_uses(m) == 1).sum())
        notes.append(f"filled holes: {before} open edges before, {after} after")
    if m.is_watertight and m.volume < 0:
        m.invert()
        notes.append("inverted the faces (they were wound inward)")
    return m, tuple(notes)


@dataclass(frozen=True)
class MassProperties:
    """Mass properties of a solid of uniform density.

    Attributes
    ----------
    mass : float
        kg.
    volume : float
        m^3.
    density : float
        kg/m^3.
    com : tuple of float
        Centre of mass, m, in the mesh frame.
    inertia : tuple of tuple of float
        Inertia tensor about the centre of mass, in the mesh frame's axes, kg m^2.
    radius : float
        Largest distance from the centre of mass to a vertex, m (the grasps' torque length).
    """

    mass: float
    volume: float
    density: float
    com: tuple[float, float, float]
    inertia: tuple[tuple[float, ...], ...]
    radius: float


def mass_properties(mesh: trimesh.Trimesh, *, density: float | None = None,
                    mass: float | None = None) -> MassProperties:
    """Mass properties of ``mesh`` as a uniform solid, from a density or a total mass.

    Parameters
    ----------
    mesh : trimesh.Trimesh
        A checked mesh in metres (:func:`check_mesh`).
    density : float, optional
        kg/m^3.
    mass : float, optional
        kg; the density is then ``mass / volume``. Give at most one of ``density`` and ``mass``;
        with neither, the density of water (1000 kg/m^3).

    Raises
    ------
    MeshError
        Both given, or a value that is not a finite positive number.

    Examples
    --------
    >>> import trimesh
    >>> p = mass_properties(trimesh.creation.box((0.1, 0.2, 0.3)), mass=2.0)
    >>> round(p.density, 6), [round(v, 12) for v in p.com]
    (333.333333, [0.0, 0.0, 0.0])
    >>> round(p.inertia[0][0], 6)  # m (b^2 + c^2) / 12
    0.021667
    """
    if density is not None and mass is not None:
        raise MeshError("give a density or a mass, not both")
    for name, value in (("density", density), ("mass", mass)):
        if value is not None and not (np.isfinite(value) and value > 0):
            raise MeshError(f"{name} must be a finite positive number, got {value}")
    volume = float(mesh.volume)
    rho = WATER if density is None and mass is None else (density if density is not None else mass / volume)
    com = np.asarray(mesh.center_mass, dtype=float)
    # trimesh's moment of inertia is about the centre of mass for density 1
    inertia = np.asarray(mesh.moment_inertia, dtype=float) * rho
    radius = float(np.linalg.norm(mesh.vertices - com, axis=1).max())
    return MassProperties(rho * volume, volume, float(rho), tuple(float(v) for v in com),
                          tuple(tuple(float(v) for v in row) for row in inertia), radius)

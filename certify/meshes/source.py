"""Poses on a mesh as the input of a certification run: contacts and certificates in one pass.

``qualgrasp certify POSES --mesh MESH --gripper G`` reads a pose file (JSON Lines or Parquet, as
:mod:`qualgrasp.certify.meshes.poses` describes) in chunks, like any grasp set. In each worker a
chunk's poses are closed on the mesh (:func:`pose_grasps`, the same step as ``qualgrasp
contacts``) and the grasps found are certified at once; so the run is resumable and
dask-distributable as every batch (:mod:`qualgrasp.certify.batch.engine`), and the manifest of
its checkpoint folder records the :class:`PoseSource` (mesh file and its SHA-256, gripper and
contact options): a resume with another mesh or other options is refused.

Each pose gives one results row, with its line: the certified grasp of its contacts with the
pose's fields carried (``pose_id``, ``gripper``, ``width``, ``mass``, ``com``, ``patches``, and the
pose's own line as ``input_line``), or an error row naming why the pose has no contacts
(``reason``: one of :data:`qualgrasp.certify.meshes.contacts.REASONS` or ``bad_pose``).
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
import trimesh

from .. import models
from ..batch.chunk import RowFailure
from ..core.arguments import number_in
from ..errors import OptionError
from ..files.reader import Chunk
from .contacts import RESOLUTION, TOLERANCE, fingertip_contacts, jaw_contacts
from .gripper import CONVENTIONS, Gripper, ParallelJaw, load_gripper
from .mesh import MassProperties, load_mesh, mass_properties
from .errors import PoseFileError
from .poses import HDF5_MAGIC, PoseRow, chunk_poses, contact_row, grasp_of
from .rays import RayCaster
from .task import hold_fields, parse_gravity

__all__ = ["PoseSource", "check_contact_options", "check_pose_file", "pose_grasps", "file_digest"]


def check_contact_options(convention: str, model: str, tolerance: float, resolution: int,
                          mu: float | None) -> None:
    """Refuse a pose convention, patch model, tolerance (m), grid resolution or friction
    coefficient out of range, with an :class:`~qualgrasp.certify.errors.OptionError` naming it.

    Examples
    --------
    >>> check_contact_options("qualgrasp", "soft", 0.0005, 21, None)
    >>> check_contact_options("qualgrasp", "elliptic", 0.0005, 21, None)
    Traceback (most recent call last):
    ...
    qualgrasp.certify.errors.OptionError: --model must be a model that describes a patch (point, soft, patch), got 'elliptic'
    """
    if convention not in CONVENTIONS:
        raise OptionError(f"--convention must be one of {', '.join(CONVENTIONS)}, got {convention!r}")
    known = models.names()
    if model not in known or not models.get(model).describes_patches:
        choices = [m.name for m in models.models() if m.describes_patches]
        raise OptionError(f"--model must be a model that describes a patch ({', '.join(choices)}), got {model!r}")
    number_in(tolerance, "--tolerance", 0, 0.1, unit="m", error=OptionError)
    if not 2 <= resolution <= 200:
        raise OptionError(f"--resolution must be between 2 and 200 cells per side, got {resolution}")
    if mu is not None:
        number_in(mu, "--mu", 0, 1e6, error=OptionError)


def check_pose_file(path: str | Path) -> None:
    """Refuse a pose file a certification run cannot read in chunks: an ACRONYM HDF5 file (read
    it with ``qualgrasp contacts``, whose output ``qualgrasp certify`` reads) is named as such;
    other problems are left to the run's own input checks."""
    try:
        with Path(path).open("rb") as fh:
            head = fh.read(len(HDF5_MAGIC))
    except OSError:
        return
    if head == HDF5_MAGIC:
        raise PoseFileError(f"{path}: an HDF5 pose file; --mesh reads poses from JSON Lines or Parquet: "
                            "turn it into a grasp set with 'qualgrasp contacts' and certify that")


def file_digest(path: str | Path) -> str:
    """SHA-256 (hex) of a file's bytes."""
    h = hashlib.sha256()
    with Path(path).open("rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def pose_grasps(rows: list[PoseRow], mesh: trimesh.Trimesh, gripper: Gripper, caster: RayCaster,
                props: MassProperties, *, mu: float, model: str = "soft", tolerance: float = TOLERANCE,
                resolution: int = RESOLUTION, points: bool = True, hold: float | None = None,
                gravity: np.ndarray | None = None, level: int = 1) -> list[dict | RowFailure]:
    """Close the gripper at every pose of ``rows`` on the mesh: for each pose, in order, its grasp
    row (:func:`~qualgrasp.certify.meshes.poses.contact_row`, certify's grasp format) or a
    :class:`~qualgrasp.certify.batch.chunk.RowFailure` whose fields are ``pose_id`` and
    ``reason`` (``bad_pose`` for a row that cannot be read, else the contact search's reason).
    With a grip force ``hold`` (N), each grasp row also has the hold columns
    (:func:`~qualgrasp.certify.meshes.task.hold_fields`, ``gravity`` and ``level`` as there).

    Examples
    --------
    >>> import numpy as np, trimesh
    >>> from qualgrasp.certify.meshes.poses import PoseRow
    >>> box = trimesh.creation.box((0.05, 0.06, 0.06))
    >>> jaw = load_gripper("franka_panda")
    >>> rows = [PoseRow(1, "a", T=np.eye(4), width=0.07), PoseRow(2, "b", T=np.eye(4), width=0.03)]
    >>> out = pose_grasps(rows, box, jaw, RayCaster(box), mass_properties(box), mu=0.5)
    >>> [c["model"] for c in out[0]["contacts"]], out[1].fields["reason"]
    (['soft', 'soft'], 'collision')
    """
    out: list[dict | RowFailure | None] = [None] * len(rows)
    good = []
    for k, r in enumerate(rows):
        if r.error is None:
            good.append(k)
        else:
            out[k] = RowFailure(r.error, id=r.id, fields={"pose_id": r.id, "reason": "bad_pose"})
    if isinstance(gripper, ParallelJaw):
        found = jaw_contacts(mesh, gripper, np.array([rows[k].T for k in good]).reshape(-1, 4, 4),
                             np.array([rows[k].width for k in good]), tolerance=tolerance,
                             resolution=resolution, caster=caster)
    else:
        found = fingertip_contacts(mesh, gripper, np.array([rows[k].fingertips for k in good]).reshape(
            -1, gripper.fingers, 3), caster=caster)
    for k, outcome in zip(good, found):
        r = rows[k]
        if not outcome.ok:
            out[k] = RowFailure(outcome.message, id=r.id, fields={"pose_id": r.id, "reason": outcome.reason})
            continue
        grasp = grasp_of(outcome, mu, model if isinstance(gripper, ParallelJaw) else models.POINT.name, props, r.id)
        out[k] = contact_row(r, outcome, grasp, gripper, props, points=points)
        if hold is not None:
            out[k].update(hold_fields(grasp, props, hold, gravity, level))
    return out


@dataclass(frozen=True)
class PoseSource:
    """Poses on a mesh as a certification run's input (module docstring).

    Attributes
    ----------
    mesh : str
        Absolute path of the mesh file; ``digest`` its SHA-256 (:meth:`of` fills both).
    gripper, convention, units, repair, mu, model, tolerance, resolution, density, mass, engine, points
        As for ``qualgrasp contacts`` (:func:`qualgrasp.certify.meshes.cli.contacts_file`): the
        gripper (built-in name or file), the pose convention, the mesh's unit and repairs, the
        friction coefficient (None: the gripper's), the patch model, the penetration tolerance (m),
        the pad grid, density (kg/m^3) or mass (kg), the ray engine, and whether rows keep the
        patches' points.
    hold, gravity, level
        The weight-holding certificate of every grasp (:func:`~qualgrasp.certify.meshes.task.hold_fields`):
        the grip force budget (N; None: not computed), ``all`` or a direction ``x,y,z``, and the
        icosphere level for ``all``.
    """

    mesh: str
    digest: str
    gripper: str = "franka_panda"
    convention: str = "qualgrasp"
    units: str = "m"
    repair: bool = False
    mu: float | None = None
    model: str = "soft"
    tolerance: float = TOLERANCE
    resolution: int = RESOLUTION
    density: float | None = None
    mass: float | None = None
    engine: str = "auto"
    points: bool = True
    hold: float | None = None
    gravity: str = "all"
    level: int = 1

    @classmethod
    def of(cls, mesh: str | Path, **options: Any) -> "PoseSource":
        """The source of ``mesh`` with ``options``, checked: the options in range, the gripper and
        the mesh loadable (a :class:`~qualgrasp.certify.errors.CertifyError` naming the problem
        before any work)."""
        check_contact_options(options.get("convention", "qualgrasp"), options.get("model", "soft"),
                              options.get("tolerance", TOLERANCE), options.get("resolution", RESOLUTION),
                              options.get("mu"))
        if options.get("hold") is not None:
            number_in(options["hold"], "--hold", 0, 1e9, unit="N", low_open=True, error=OptionError)
        parse_gravity(options.get("gravity", "all"))
        if not 0 <= options.get("level", 1) <= 4:
            raise OptionError(f"--level must be between 0 and 4, got {options['level']}")
        source = cls(str(Path(mesh).resolve()), "", **options)
        source.load()  # the mesh's own errors (missing, unreadable, not closed) first
        return replace(source, digest=file_digest(mesh))

    def load(self) -> tuple[trimesh.Trimesh, Gripper, RayCaster, MassProperties]:
        """The mesh, gripper, ray caster and mass properties the contacts are computed with."""
        mesh = load_mesh(self.mesh, units=self.units, repair=self.repair)
        props = mass_properties(mesh, density=self.density, mass=self.mass)
        return mesh, load_gripper(self.gripper), RayCaster(mesh, self.engine), props

    def inputs(self) -> tuple[Path]:
        """The file the source reads besides the pose file: the mesh."""
        return (Path(self.mesh),)

    def grasp_values(self, chunk: Chunk) -> list[dict | RowFailure]:
        """The grasp rows (or failures) of a chunk of the pose file, in order."""
        mesh, gripper, caster, props = self.load()
        rows = chunk_poses(chunk, gripper, self.convention)
        return pose_grasps(rows, mesh, gripper, caster, props, mu=gripper.mu if self.mu is None else self.mu,
                           model=self.model, tolerance=self.tolerance, resolution=self.resolution,
                           points=self.points, hold=self.hold, gravity=parse_gravity(self.gravity),
                           level=self.level)

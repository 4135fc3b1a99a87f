"""Pose files in, certify grasp sets out.

Pose files
----------
JSON Lines or Parquet (recognised by content, read in chunks by certify's reader,
:func:`qualgrasp.certify.files.reader.iter_chunks`), one pose per line or row:

* parallel jaws: ``pose`` (4x4, nested or 16 numbers row-major) in the file's convention
  (:mod:`qualgrasp.certify.meshes.gripper`), ``width`` (opening, m; default the gripper's
  largest), and for GraspNet rows optionally ``depth``; GraspNet's own fields ``translation`` and
  ``rotation_matrix`` are read in place of ``pose``;
* point hands: ``fingertips``, one 3-vector per finger (object frame, m);
* optional ``id`` (string or integer; default the line number). Other fields are carried to the
  output row.

or an ACRONYM-style HDF5 file (read with h5py, when installed): ``grasps/transforms`` (n x 4 x 4,
ACRONYM convention, the jaws fully open) and, when present,
``grasps/qualities/flex/object_in_gripper`` (carried as ``acronym_success``).

Output rows
-----------
Each pose with contacts is one grasp of certify's grasp-set format (README "Grasp-set files"),
ready for ``qualgrasp certify``: ``id``, ``contacts`` (``soft`` patch contacts, or ``point``),
``center`` (the object's centre of mass) and ``length`` (its radius about it), plus ``pose_id``,
``line``, ``gripper``, ``width``, ``mass``, ``com`` and ``patches`` (per contact: ``area``,
``radius``, ``torsion``, ``travel`` and, unless left out, the patch's ``points``). A pose without
contacts is an error row, written to the error file: ``id``, ``pose_id``, ``line``, ``reason``
(one of :data:`qualgrasp.certify.meshes.contacts.REASONS` or ``bad_pose``) and ``error``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterator

import numpy as np

from ..errors import GraspFileError
from .. import models
from ..core.grasp import Contact, Grasp, grasp_to_dict
from ..files.reader import Chunk, chunk_values, iter_chunks
from ..core.validation import number, numbers, show
from .contacts import Outcome
from .errors import PoseError, PoseFileError
from .gripper import CONVENTIONS, Gripper, ParallelJaw, check_pose, to_qualgrasp
from .mesh import MassProperties

__all__ = ["PoseRow", "HDF5_MAGIC", "chunk_poses", "read_poses", "grasp_of", "contact_row", "error_row"]

HDF5_MAGIC = b"\x89HDF\r\n\x1a\n"
#: Fields of a pose row that are read (the others are carried to the output).
_READ = ("id", "pose", "width", "depth", "translation", "rotation_matrix", "fingertips")


@dataclass(frozen=True)
class PoseRow:
    """One pose read from a file: ``T`` (``qualgrasp`` convention) and ``width`` for parallel
    jaws, ``fingertips`` for point hands, or ``error`` (a sentence) when it cannot be read."""

    line: int
    id: Any
    T: np.ndarray | None = None
    width: float | None = None
    fingertips: np.ndarray | None = None
    error: str | None = None
    extra: dict = field(default_factory=dict)


def _row(value: Any, line: int, gripper: Gripper, convention: str) -> PoseRow:
    if isinstance(value, Exception):
        return PoseRow(line, line, error=str(value))
    if not isinstance(value, dict):
        return PoseRow(line, line, error=f"a pose is a JSON object, got {show(value)}")
    pid = value.get("id", line)
    if isinstance(pid, bool) or not isinstance(pid, (str, int)):
        return PoseRow(line, line, error=f"id: expected a string or an integer, got {show(pid)}")
    extra = {k: v for k, v in value.items() if k not in _READ}
    try:
        if isinstance(gripper, ParallelJaw):
            T, width = _jaw_pose(value, gripper, convention)
            return PoseRow(line, pid, T=T, width=width, extra=extra)
        tips = value.get("fingertips")
        rows = [numbers(t) for t in tips] if isinstance(tips, list) else None
        if rows is None or len(rows) != gripper.fingers or any(r is None or len(r) != 3 for r in rows):
            raise PoseError(f"fingertips: expected {gripper.fingers} points of 3 numbers, got {show(tips)}")
        arr = np.array(rows, dtype=float)
        if not np.isfinite(arr).all() or np.abs(arr).max() > 1e6:
            raise PoseError("fingertips: coordinates must be finite numbers of at most 1e6 in absolute value")
        return PoseRow(line, pid, fingertips=arr, extra=extra)
    except PoseError as err:
        return PoseRow(line, pid, error=str(err), extra=extra)


def _jaw_pose(value: dict, gripper: ParallelJaw, convention: str) -> tuple[np.ndarray, float]:
    depth = None
    if "depth" in value:
        depth = number(value["depth"])
        if depth is None or not (np.isfinite(depth) and 0 <= depth <= 1):
            raise PoseError(f"depth: expected a number between 0 and 1 (m), got {show(value['depth'])}")
    if "pose" in value:
        T = check_pose(value["pose"])
    elif "translation" in value and "rotation_matrix" in value:
        t, R = numbers(value["translation"]), value["rotation_matrix"]
        flat = numbers(R) if not (isinstance(R, list) and R and isinstance(R[0], list)) else (
            numbers([v for r in R for v in r]) if all(isinstance(r, list) and len(r) == 3 for r in R) else None)
        if t is None or len(t) != 3 or flat is None or len(flat) != 9:
            raise PoseError("translation and rotation_matrix: expected 3 and 9 numbers")
        T = np.eye(4)
        T[:3, :3], T[:3, 3] = np.reshape(flat, (3, 3)), t
        T = check_pose(T, "rotation_matrix")
    else:
        raise PoseError("no pose: give pose (4x4), or translation and rotation_matrix")
    width = value.get("width", gripper.max_opening)
    w = number(width)
    if w is None or not (np.isfinite(w) and w >= 0):
        raise PoseError(f"width: expected a number >= 0 (m), got {show(width)}")
    return to_qualgrasp(T, convention, gripper, depth), w


def chunk_poses(chunk: Chunk, gripper: Gripper, convention: str = "qualgrasp") -> list[PoseRow]:
    """The poses of one chunk of a JSON Lines or Parquet pose file
    (:func:`~qualgrasp.certify.files.reader.iter_chunks`), in order; a row that cannot be read is
    a :class:`PoseRow` with its ``error``."""
    return [_row(v, line, gripper, convention) for v, line in zip(chunk_values(chunk), chunk.lines)]


def read_poses(path: str | Path, gripper: Gripper, convention: str = "qualgrasp", *,
               chunk_size: int = 1024) -> Iterator[list[PoseRow]]:
    """The poses of a pose file (module docstring), in chunks; a row that cannot be read is a
    :class:`PoseRow` with its ``error``, never dropped.

    Raises
    ------
    PoseFileError
        The file cannot be read at all, or an HDF5 file lacks ``grasps/transforms``.

    Examples
    --------
    >>> import json, tempfile, pathlib
    >>> from qualgrasp.certify.meshes.gripper import load_gripper
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "poses.jsonl"
    >>> _ = path.write_text(json.dumps({"id": "a", "pose": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]],
    ...                                 "width": 0.05}) + "\\n" + json.dumps({"pose": "x"}) + "\\n")
    >>> rows = [r for chunk in read_poses(path, load_gripper("franka_panda")) for r in chunk]
    >>> [(r.id, r.width, r.error) for r in rows]
    [('a', 0.05, None), (2, None, 'pose: expected a 4x4 matrix of numbers (4 rows of 4, or 16 numbers), got "x"')]
    """
    if convention not in CONVENTIONS:
        raise PoseFileError(f"unknown pose convention {convention!r}: give one of {', '.join(CONVENTIONS)}")
    path = Path(path)
    try:
        with path.open("rb") as fh:
            head = fh.read(8)
    except OSError as err:
        raise PoseFileError(f"cannot read {path}: {err.strerror or err}") from None
    if head == HDF5_MAGIC:
        yield from _hdf5_poses(path, gripper, chunk_size)
        return
    try:
        for chunk in iter_chunks(path, chunk_size):
            yield chunk_poses(chunk, gripper, convention)
    except GraspFileError as err:
        raise PoseFileError(str(err).replace("neither JSON Lines nor Parquet", "neither JSON Lines, Parquet nor HDF5"))


def _hdf5_poses(path: Path, gripper: Gripper, chunk_size: int) -> Iterator[list[PoseRow]]:
    try:
        import h5py
    except ImportError:
        raise PoseFileError(f"{path} is an HDF5 file: reading it needs h5py (pip install h5py)") from None
    if not isinstance(gripper, ParallelJaw):
        raise PoseFileError("ACRONYM HDF5 files hold parallel-jaw poses; give a parallel-jaw gripper")
    try:
        with h5py.File(path, "r") as f:
            if "grasps/transforms" not in f:
                raise PoseFileError(f"{path} has no dataset grasps/transforms (an ACRONYM grasp file has)")
            transforms = np.asarray(f["grasps/transforms"], dtype=float)
            key = "grasps/qualities/flex/object_in_gripper"
            success = np.asarray(f[key]).ravel() if key in f else None
    except OSError as err:
        raise PoseFileError(f"cannot read {path} as HDF5: {err}") from None
    if transforms.ndim != 3 or transforms.shape[1:] != (4, 4):
        raise PoseFileError(f"{path}: grasps/transforms has shape {transforms.shape}, expected (n, 4, 4)")
    rows = []
    for i, T in enumerate(transforms):
        extra = {} if success is None else {"acronym_success": int(success[i])}
        try:
            rows.append(PoseRow(i + 1, i, T=to_qualgrasp(check_pose(T), "acronym", gripper),
                                width=gripper.max_opening, extra=extra))
        except PoseError as err:
            rows.append(PoseRow(i + 1, i, error=str(err), extra=extra))
        if len(rows) == chunk_size:
            yield rows
            rows = []
    if rows:
        yield rows


def grasp_of(outcome: Outcome, mu: float, model: str, props: MassProperties, gid: Any = None,
             meta: dict | None = None) -> Grasp:
    """certify's :class:`~qualgrasp.certify.Grasp` of a pose's patches: contacts of ``model`` with
    the parameters the model states for each patch (:meth:`~qualgrasp.certify.models.ContactModel.patch_params`:
    ``soft`` takes the torsion from the patch's points, ``patch`` the radius of the disc of its
    area), or ``point`` contacts where it states none (a fingertip's one-point patch), torques about
    the centre of mass with the object's radius as length.

    Examples
    --------
    >>> import numpy as np, trimesh
    >>> from qualgrasp.certify.meshes.contacts import jaw_contacts
    >>> from qualgrasp.certify.meshes.gripper import load_gripper
    >>> from qualgrasp.certify.meshes.mesh import mass_properties
    >>> box = trimesh.creation.box((0.05, 0.06, 0.06))
    >>> out = jaw_contacts(box, load_gripper("franka_panda"), np.eye(4)[None], np.array([0.07]))[0]
    >>> g = grasp_of(out, 0.5, "soft", mass_properties(box))
    >>> [c.model for c in g.contacts], round(g.contacts[0].torsion, 4)
    (['soft', 'soft'], 0.0069)
    """
    described = models.get(model)
    contacts = []
    for p in outcome.patches:
        params = described.patch_params(mu, p.area, p.torsion)
        name = model if params is not None else models.POINT.name
        contacts.append(Contact(tuple(p.centroid), tuple(p.normal), name, **(params or {"mu": mu})))
    return Grasp(tuple(contacts), center=props.com, length=props.radius, id=gid, meta=meta or {})


def contact_row(row: PoseRow, outcome: Outcome, grasp: Grasp, gripper: Gripper, props: MassProperties, *,
                points: bool = True) -> dict:
    """The output row of a pose with contacts (module docstring, "Output rows")."""

    out = grasp_to_dict(grasp)
    patches = []
    for p in outcome.patches:
        item = {"area": p.area, "radius": p.radius, "torsion": p.torsion, "travel": p.travel}
        if points:
            item["points"] = p.points.tolist()
        patches.append(item)
    out.update(pose_id=row.id, line=row.line, gripper=gripper.name, mass=props.mass, com=list(props.com),
               patches=patches)
    if row.width is not None:
        out["width"] = row.width
    for k, v in row.extra.items():
        out.setdefault(k, v)
    return out


def error_row(row: PoseRow, reason: str, message: str) -> dict:
    """The error row of a pose without contacts."""
    return {"id": row.id, "pose_id": row.id, "line": row.line, "reason": reason,
            "error": f"line {row.line}: {message}"}

"""Grippers as data, and the pose conventions of parallel-jaw grasp sets.

Gripper files
-------------
A gripper is a small TOML (or JSON, same structure) file; ``data/grippers/`` holds the built-in
ones (:func:`builtin_grippers`), each citing the source of its numbers. Lengths in metres.

``kind = "parallel_jaw"``: two flat pads facing each other.

* ``mu``: friction of the pads on the object (an assumption; the command line's ``--mu``
  overrides it).
* ``[pad]``: ``shape`` (``rectangle`` or ``disc``), ``width`` (across the finger, the lateral
  axis ``y``) and ``height`` (along the approach axis ``z``); a disc has diameter ``width`` and
  ``height`` equal to it.
* ``[finger] thickness``: the finger behind the pad, outward along the closing axis.
* ``[opening] min, max``: the range of the distance between the pads.
* ``[palm] offset, width, depth``: the palm face lies ``offset`` behind the pad centres (along
  ``-z``) and spans ``width`` along ``x`` and ``depth`` along ``y``.
* ``[frame] flange_to_pad``: the pad centres' distance from the hand's flange along ``z`` (the
  origin of ACRONYM's grasp frame).

``kind = "point_hand"``: ``fingers`` fingertips, each closing at most ``travel`` towards the
mean of the given fingertip positions and touching at a point with friction ``mu``.

Pose conventions (parallel jaws)
--------------------------------
A pose is a 4x4 rigid transform ``T`` taking gripper coordinates to object (mesh) coordinates,
and an opening width ``w`` (the distance between the pads before they close).

``qualgrasp`` (this package's own)
    Origin midway between the two pad centres; ``+z`` the approach axis (the direction the hand
    moves towards the object, from the palm to the fingertips); ``x`` the closing axis, pad A at
    ``x = +w/2`` facing ``-x`` and pad B at ``x = -w/2`` facing ``+x``; ``y = z x x`` across
    the pads.
``acronym`` (ACRONYM, and Contact-GraspNet's outputs, on the Franka hand)
    Origin at the hand's flange; ``+z`` approach, ``x`` closing (ACRONYM's gripper marker puts
    the fingers at ``x = +-0.041``, from ``z = 0.066`` to ``0.112``). The ``qualgrasp`` frame is
    this one moved ``flange_to_pad`` along ``z``: ``T_q = T_a Trans(0, 0, flange_to_pad)``.
``graspnet`` (GraspNet-1Billion, graspnetAPI)
    Origin at the grasp point (``translation``); ``+x`` approach, ``y`` closing, ``z = x x y``
    (graspnetAPI's ``plot_gripper_pro_max`` draws the fingers at ``y = +-width/2`` reaching
    ``x = depth``, the palm at ``x = -0.02``). The fingertips are at ``x = depth``, so the pad
    centres are at ``x = depth - height/2``: ``T_q = T_g [[0, 0, 1, depth - h/2], [1, 0, 0, 0],
    [0, 1, 0, 0], [0, 0, 0, 1]]`` (the ``qualgrasp`` axes ``x, y, z`` are GraspNet's ``y, z, x``).
"""

from __future__ import annotations

import json
import math
import tomllib
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from ..core.validation import number, show
from .errors import GripperError, PoseError

__all__ = ["ParallelJaw", "PointHand", "Gripper", "CONVENTIONS", "builtin_grippers", "load_gripper",
           "gripper_from_dict", "to_qualgrasp", "from_qualgrasp", "check_pose"]

#: Pose conventions :func:`to_qualgrasp` understands.
CONVENTIONS = ("qualgrasp", "acronym", "graspnet")
#: GraspNet's default depth (graspnetAPI's ``Grasp()``: 0.02 m), used when a row gives none.
GRASPNET_DEPTH = 0.02


@dataclass(frozen=True)
class ParallelJaw:
    """A parallel-jaw gripper (module docstring, "Gripper files"); lengths in metres."""

    name: str
    pad_shape: str
    pad_width: float
    pad_height: float
    finger_thickness: float
    min_opening: float
    max_opening: float
    palm_offset: float
    palm_width: float
    palm_depth: float
    flange_to_pad: float
    mu: float
    kind: str = "parallel_jaw"


@dataclass(frozen=True)
class PointHand:
    """A hand of point fingertips closing towards their centre (module docstring)."""

    name: str
    fingers: int
    travel: float
    mu: float
    kind: str = "point_hand"


Gripper = ParallelJaw | PointHand


def _package_folder():
    return resources.files("qualgrasp.certify.meshes") / "data" / "grippers"


def builtin_grippers() -> tuple[str, ...]:
    """Names of the built-in gripper descriptions.

    Examples
    --------
    >>> builtin_grippers()
    ('franka_panda', 'robotiq_2f85', 'three_finger_point')
    """
    return tuple(sorted(p.name[:-5] for p in _package_folder().iterdir() if p.name.endswith(".toml")))


def load_gripper(name_or_path: str | Path) -> Gripper:
    """A built-in gripper by name, or a gripper file (``.toml`` or ``.json``).

    Raises
    ------
    GripperError
        Unknown name, unreadable file, or a description that breaks a rule (the message names
        the key).

    Examples
    --------
    >>> g = load_gripper("franka_panda")
    >>> g.max_opening, g.pad_width, g.pad_height
    (0.08, 0.0175, 0.0185)
    """
    text = str(name_or_path)
    if text in builtin_grippers():
        data = tomllib.loads((_package_folder() / f"{text}.toml").read_text(encoding="utf-8"))
        return gripper_from_dict(data, where=text)
    path = Path(text)
    if not path.is_file():
        raise GripperError(f"no gripper {text!r}: give a file (.toml or .json) or one of "
                           f"{', '.join(builtin_grippers())}")
    try:
        raw = path.read_text(encoding="utf-8")
        data = json.loads(raw) if path.suffix.lower() == ".json" else tomllib.loads(raw)
    except (OSError, UnicodeDecodeError, ValueError) as err:  # TOMLDecodeError is a ValueError
        raise GripperError(f"cannot read the gripper file {path}: {err}") from None
    return gripper_from_dict(data, where=str(path))


def _length(data: Mapping, section: str, key: str, where: str, *, positive: bool = True) -> float:
    table = data.get(section) if section else data
    value = None if not isinstance(table, Mapping) else table.get(key)
    name = f"{section}.{key}" if section else key
    x = number(value)
    if x is None or not math.isfinite(x) or x < 0 or (positive and x == 0) or x > 10:
        rule = "> 0" if positive else ">= 0"
        raise GripperError(f"{where}: {name} must be a number {rule} and at most 10 (metres), got {show(value)}")
    return x


def gripper_from_dict(data: Any, where: str = "gripper") -> Gripper:
    """Build a gripper from a parsed description (module docstring, "Gripper files").

    Examples
    --------
    >>> gripper_from_dict({"name": "g", "kind": "point_hand", "fingers": 3, "travel": 0.1, "mu": 0.4})
    PointHand(name='g', fingers=3, travel=0.1, mu=0.4, kind='point_hand')
    >>> gripper_from_dict({"name": "g", "kind": "suction"})
    Traceback (most recent call last):
    ...
    qualgrasp.certify.meshes.errors.GripperError: gripper: kind must be parallel_jaw or point_hand, got "suction"
    """
    if not isinstance(data, Mapping):
        raise GripperError(f"{where}: a gripper description is a table of keys")
    name = data.get("name")
    if not isinstance(name, str) or not name:
        raise GripperError(f"{where}: name must be a non-empty string, got {show(name)}")
    kind = data.get("kind")
    if kind not in ("parallel_jaw", "point_hand"):
        raise GripperError(f"{where}: kind must be parallel_jaw or point_hand, got {show(kind)}")
    mu = number(data.get("mu"))
    if mu is None or not (math.isfinite(mu) and 0 <= mu <= 1e6):
        raise GripperError(f"{where}: mu must be a number between 0 and 1e6, got {show(data.get('mu'))}")
    if kind == "point_hand":
        fingers = data.get("fingers")
        if isinstance(fingers, bool) or not isinstance(fingers, int) or not 2 <= fingers <= 10:
            raise GripperError(f"{where}: fingers must be an integer between 2 and 10, got {show(fingers)}")
        return PointHand(name, fingers, _length(data, "", "travel", where), mu)
    pad = data.get("pad") if isinstance(data.get("pad"), Mapping) else {}
    shape = pad.get("shape", "rectangle")
    if shape not in ("rectangle", "disc"):
        raise GripperError(f"{where}: pad.shape must be rectangle or disc, got {show(shape)}")
    width, height = _length(data, "pad", "width", where), _length(data, "pad", "height", where)
    if shape == "disc" and width != height:
        raise GripperError(f"{where}: a disc pad has one diameter: pad.width ({width}) and pad.height ({height}) differ")
    lo = _length(data, "opening", "min", where, positive=False)
    hi = _length(data, "opening", "max", where)
    if lo >= hi:
        raise GripperError(f"{where}: opening.min ({lo}) must be below opening.max ({hi})")
    return ParallelJaw(
        name, shape, width, height, _length(data, "finger", "thickness", where), lo, hi,
        _length(data, "palm", "offset", where, positive=False), _length(data, "palm", "width", where),
        _length(data, "palm", "depth", where), _length(data, "frame", "flange_to_pad", where, positive=False), mu)


# --- pose conventions ------------------------------------------------------------------------

#: GraspNet's gripper axes (x approach, y closing, z height) as columns of the qualgrasp axes.
_GRASPNET_AXES = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])


def _offset(convention: str, gripper: ParallelJaw, depth: float | None) -> np.ndarray:
    """The transform from the convention's gripper frame to the qualgrasp frame."""
    M = np.eye(4)
    if convention == "acronym":
        M[2, 3] = gripper.flange_to_pad
    elif convention == "graspnet":
        M[:3, :3] = _GRASPNET_AXES
        M[0, 3] = (GRASPNET_DEPTH if depth is None else depth) - gripper.pad_height / 2
    elif convention != "qualgrasp":
        raise PoseError(f"unknown pose convention {convention!r}: give one of {', '.join(CONVENTIONS)}")
    return M


def to_qualgrasp(T: np.ndarray, convention: str, gripper: ParallelJaw, depth: float | None = None) -> np.ndarray:
    """The ``qualgrasp`` pose of a pose given in ``convention`` (module docstring).

    Parameters
    ----------
    T : ndarray, shape (..., 4, 4)
    convention : str
        ``'qualgrasp'``, ``'acronym'`` or ``'graspnet'``.
    gripper : ParallelJaw
    depth : float, optional
        GraspNet's ``depth`` (fingertips beyond the grasp point, m); default 0.02.

    Examples
    --------
    >>> import numpy as np
    >>> g = load_gripper("franka_panda")
    >>> to_qualgrasp(np.eye(4), "acronym", g)[:3, 3].tolist()
    [0.0, 0.0, 0.10365]
    >>> to_qualgrasp(np.eye(4), "graspnet", g, depth=0.03)[:3, :].round(5).tolist()
    [[0.0, 0.0, 1.0, 0.02075], [1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0]]
    """
    return np.asarray(T, dtype=float) @ _offset(convention, gripper, depth)


def from_qualgrasp(T: np.ndarray, convention: str, gripper: ParallelJaw, depth: float | None = None) -> np.ndarray:
    """Inverse of :func:`to_qualgrasp`: the pose in ``convention`` of a ``qualgrasp`` pose.

    Examples
    --------
    >>> import numpy as np
    >>> g = load_gripper("robotiq_2f85")
    >>> T = np.eye(4); T[:3, 3] = (0.1, 0.2, 0.3)
    >>> np.allclose(to_qualgrasp(from_qualgrasp(T, "graspnet", g, 0.01), "graspnet", g, 0.01), T)
    True
    """
    return np.asarray(T, dtype=float) @ np.linalg.inv(_offset(convention, gripper, depth))


def check_pose(value: Any, what: str = "pose") -> np.ndarray:
    """``value`` as a 4x4 rigid transform (nested lists or 16 numbers, row-major), or a
    :class:`PoseError` saying what is wrong.

    The rotation must be orthonormal with determinant +1 to within ``1e-6``; the last row must be
    ``0 0 0 1``. Coordinates at most 1e6 in absolute value.

    Examples
    --------
    >>> float(check_pose([[1, 0, 0, 0.1], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])[0, 3])
    0.1
    >>> check_pose([[2, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])
    Traceback (most recent call last):
    ...
    qualgrasp.certify.meshes.errors.PoseError: pose: the rotation is not orthonormal (largest error of R'R - I: 3)
    """
    rows = value.tolist() if isinstance(value, np.ndarray) else value
    flat = None
    if isinstance(rows, (list, tuple)) and len(rows) == 4 and all(isinstance(r, (list, tuple)) for r in rows):
        parts = [tuple(number(v) for v in r) if len(r) == 4 else None for r in rows]
        if all(p is not None and None not in p for p in parts):
            flat = [v for p in parts for v in p]
    elif isinstance(rows, (list, tuple)) and len(rows) == 16:
        flat = [number(v) for v in rows]
        flat = None if None in flat else flat
    if flat is None:
        raise PoseError(f"{what}: expected a 4x4 matrix of numbers (4 rows of 4, or 16 numbers), got {show(value)}")
    T = np.array(flat, dtype=float).reshape(4, 4)
    if not np.isfinite(T).all() or np.abs(T).max() > 1e6:
        raise PoseError(f"{what}: entries must be finite numbers of at most 1e6 in absolute value")
    if not np.allclose(T[3], (0, 0, 0, 1), rtol=0, atol=1e-9):
        raise PoseError(f"{what}: the last row must be 0 0 0 1, got {show(T[3].tolist())}")
    R = T[:3, :3]
    err = float(np.abs(R.T @ R - np.eye(3)).max())
    if err > 1e-6:
        raise PoseError(f"{what}: the rotation is not orthonormal (largest error of R'R - I: {err:.3g})")
    if np.linalg.det(R) < 0:
        raise PoseError(f"{what}: the rotation is a reflection (determinant -1)")
    return T

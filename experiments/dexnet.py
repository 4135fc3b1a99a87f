"""Dex-Net's force-closure test, loaded from a graspnetAPI sdist at benchmark time, for
``qualgrasp bench --single`` (issue 27: one grasp through the API against Dex-Net).

Dex-Net's point-grasp quality code ships in the graspnetAPI sdist (1.2.11:
``pip download graspnetAPI==1.2.11 --no-deps --no-binary :all:``) as
``graspnetAPI/utils/dexnet/grasping/quality.py``. Importing that module drags meshes, SDFs,
matplotlib and IPython; its class ``PointGraspMetrics3D`` needs only numpy and cvxopt. So
:func:`load_dexnet` reads the file from the sdist (the ``.tar.gz``, its unpacked folder, or the
file itself), compiles that class alone and nothing else, and runs it with ``cvxopt``
(``pip install cvxopt``). qualgrasp neither ships nor depends on any of it.

:func:`dexnet_inputs` states a :class:`~qualgrasp.certify.Grasp` as Dex-Net's
``force_closure_qp`` takes it, as ``PointGraspMetrics3D.grasp_quality`` builds it: per contact
the 8 edges ``n + mu (cos(2 pi j / 8) t1 + sin(2 pi j / 8) t2)`` of the inscribed friction cone
(``Contact3D.friction_cone``, unit normal force), their torques ``(p - c) x f``
(``Contact3D.torques``, the moment arm from the grasp's ``center``) and ``torque_scaling = 1 /
length``, so that its wrenches are the grasp's (:mod:`qualgrasp.certify.core.wrench`) on 8
edges of each exact cone. The tangents ``t1, t2`` are the grasp's contact frame
(:func:`qualgrasp.certify.core.wrench.contact_frame`); Dex-Net turns them to align ``t1`` with
the object's x axis, which turns the octagon in the tangent plane and leaves the solve as it is.
"""

from __future__ import annotations

import ast
import logging
import tarfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..certify import models
from ..certify.core import Grasp
from ..certify.errors import ArgumentError, OptionError
from ..certify.core.wrench import contact_frame, torque

__all__ = ["QUALITY_FILE", "DexNet", "load_dexnet", "dexnet_inputs"]

#: Where Dex-Net's quality module sits in the graspnetAPI sdist.
QUALITY_FILE = "graspnetAPI/utils/dexnet/grasping/quality.py"


class _Config(dict):
    """``GraspQualityConfig``'s interface as ``force_closure_qp`` uses it: keys, read as attributes."""

    def __getattr__(self, name: str) -> Any:
        try:
            return self[name]
        except KeyError:
            raise AttributeError(name) from None


@dataclass(frozen=True)
class DexNet:
    """Dex-Net's ``PointGraspMetrics3D`` class (``metrics``), loaded from ``source``."""

    metrics: type
    source: str

    def force_closure_qp(self, forces, torques, normals, config) -> int:
        """``PointGraspMetrics3D.force_closure_qp`` (point contacts, ``soft_fingers=False``): 1
        when the origin is within ``1e-3`` of the convex hull of the wrenches, else 0."""
        return self.metrics.force_closure_qp(forces, torques, normals, soft_fingers=False, params=config)


def _quality_source(path: Path) -> tuple[str, str]:
    """The text of Dex-Net's quality module in ``path`` and where it was read."""
    if not path.exists():
        raise OptionError(f"--dexnet: {path} does not exist")
    if path.is_file() and path.suffix == ".py":
        return path.read_text(), str(path)
    if path.is_dir():
        found = sorted(p for p in path.rglob("quality.py") if p.as_posix().endswith(QUALITY_FILE))
        if not found:
            raise OptionError(f"--dexnet: no {QUALITY_FILE} under {path}")
        return found[0].read_text(), str(found[0])
    try:
        with tarfile.open(path) as tar:
            member = next((m for m in tar.getmembers() if m.name.endswith(QUALITY_FILE)), None)
            if member is None:
                raise OptionError(f"--dexnet: {path} holds no {QUALITY_FILE}")
            return tar.extractfile(member).read().decode(), f"{path}:{member.name}"
    except tarfile.TarError as err:
        raise OptionError(f"--dexnet: {path} is not a graspnetAPI sdist ({err})") from None


def load_dexnet(path) -> DexNet:
    """Dex-Net's ``PointGraspMetrics3D`` from a graspnetAPI sdist (module docstring).

    Parameters
    ----------
    path : str or Path
        The sdist ``graspnetAPI-1.2.11.tar.gz``, its unpacked folder, or ``quality.py`` itself.

    Raises
    ------
    OptionError
        No such file, no quality module in it, no ``PointGraspMetrics3D`` in that, or cvxopt is
        not installed.

    Examples
    --------
    >>> load_dexnet("/nonexistent/graspnetAPI-1.2.11.tar.gz")
    Traceback (most recent call last):
    ...
    qualgrasp.certify.errors.OptionError: --dexnet: /nonexistent/graspnetAPI-1.2.11.tar.gz does not exist
    """
    try:
        text, source = _quality_source(Path(path))
    except (OSError, UnicodeDecodeError) as err:
        raise OptionError(f"--dexnet: cannot read {path} ({err})") from None
    try:
        import cvxopt
    except ImportError:
        raise OptionError("--dexnet: Dex-Net's force_closure_qp needs cvxopt (pip install cvxopt)") from None
    try:
        tree = ast.parse(text)
    except SyntaxError as err:
        raise OptionError(f"--dexnet: {source} is not Python ({err.msg})") from None
    found = [node for node in tree.body if isinstance(node, ast.ClassDef) and node.name == "PointGraspMetrics3D"]
    if not found:
        raise OptionError(f"--dexnet: {source} defines no PointGraspMetrics3D")
    # the class alone: its methods use numpy, cvxopt (as cvx) and logging, nothing else on this path
    namespace = {"np": np, "cvx": cvxopt, "logging": logging}
    exec(compile(ast.Module(body=found, type_ignores=[]), source, "exec"), namespace)
    cvxopt.solvers.options["show_progress"] = False  # as the module does on import
    return DexNet(namespace["PointGraspMetrics3D"], source)


def dexnet_inputs(grasp: Grasp, edges: int = 8):
    """``(forces, torques, normals, config)`` of ``grasp`` as Dex-Net's ``force_closure_qp``
    takes them (module docstring): forces and torques ``(3, edges * m)``, inward normals
    ``(3, m)``, ``config`` with ``torque_scaling = 1 / length``. Spatial point contacts.

    Examples
    --------
    >>> from qualgrasp.certify import Contact, Grasp
    >>> g = Grasp((Contact((1, 0, 0), (-1, 0, 0), "point", 0.5), Contact((-1, 0, 0), (1, 0, 0), "point", 0.5)))
    >>> forces, torques, normals, config = dexnet_inputs(g)
    >>> forces.shape, torques.shape, normals.shape, config.torque_scaling
    ((3, 16), (3, 16), (3, 2), 1.0)
    >>> bool(np.allclose(np.linalg.norm(forces[1:, :8], axis=0), 0.5))  # each edge mu off the normal
    True
    """
    if grasp.dim != 3 or any(c.model != models.POINT.name for c in grasp.contacts):
        raise ArgumentError("dexnet_inputs takes spatial grasps of point contacts")
    P, N = grasp.points, grasp.normals
    mu = np.array([c.mu for c in grasp.contacts])
    t1, t2 = contact_frame(N)
    theta = 2 * np.pi * np.arange(edges) / edges
    tangents = np.cos(theta)[None, :, None] * t1[:, None, :] + np.sin(theta)[None, :, None] * t2[:, None, :]
    forces = (N[:, None, :] + mu[:, None, None] * tangents).reshape(-1, 3)
    arms = np.repeat(P - np.asarray(grasp.center), edges, axis=0)
    torques = torque(arms, forces)
    return forces.T.copy(), torques.T.copy(), N.T.copy(), _Config(torque_scaling=1.0 / grasp.length)

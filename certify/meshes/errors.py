"""Exceptions of :mod:`qualgrasp.certify.meshes`, in certify's hierarchy.

Every error derives from :class:`qualgrasp.certify.errors.CertifyError`, so a caller that
catches that one class catches these too; each message is one line naming the problem and, where
there is one, what to do about it.
"""

from __future__ import annotations

from ..errors import CertifyError, GraspFileError

__all__ = ["MeshError", "GripperError", "PoseError", "PoseFileError"]


class MeshError(CertifyError, ValueError):
    """A mesh cannot be used: unreadable, open (holes), degenerate, zero volume, wrong scale."""


class GripperError(CertifyError, ValueError):
    """A gripper description is malformed (missing key, bad number, unknown kind)."""


class PoseError(CertifyError, ValueError):
    """One gripper pose is malformed (not a rigid transform, bad width); an error row, not fatal."""


class PoseFileError(GraspFileError):
    """A pose file cannot be read at all (missing, wrong format, missing HDF5 dataset)."""

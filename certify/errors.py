"""Exceptions raised by :mod:`qualgrasp.certify`.

Every error a user can cause derives from :class:`CertifyError`, so a caller can catch one class;
the subclasses say which kind of input was wrong.
"""

from __future__ import annotations

__all__ = [
    "CertifyError",
    "GraspError",
    "GraspFileError",
    "CertificateError",
    "SolverError",
    "OptionError",
    "WriteError",
]


class CertifyError(Exception):
    """Base class of every error raised by :mod:`qualgrasp.certify`."""


class GraspError(CertifyError, ValueError):
    """A grasp or contact is malformed (NaN coordinates, zero normal, negative friction, ...)."""


class GraspFileError(CertifyError, ValueError):
    """A grasp-set or results file cannot be read (malformed JSON, missing file, wrong schema)."""


class CertificateError(CertifyError, ValueError):
    """A certificate is structurally malformed (wrong keys, lengths or types)."""


class SolverError(CertifyError, RuntimeError):
    """A convex solver failed to return a usable answer."""


class OptionError(CertifyError, ValueError):
    """A command-line option or path is unusable (the message names the flag)."""


class WriteError(OptionError, OSError):
    """An output could not be written (a full disk, a read-only folder, a file-size limit): an
    :class:`OptionError` whose message names the flag, and an ``OSError`` with the cause's
    ``errno`` and reason (``strerror``), so that callers catching either see it."""

    def __init__(self, message: str, code: int | None = None, reason: str | None = None) -> None:
        OSError.__init__(self, code, reason)
        self.message = message

    def __str__(self) -> str:
        return self.message

"""Exceptions raised by :mod:`qualgrasp`.

Every error a user can cause derives from :class:`QualgraspError`, so a caller can catch one
class: :class:`CertifyError` for :mod:`qualgrasp.certify` (this module; certify is the base layer)
and :class:`qualgrasp.qualitative.errors.QualitativeError` for the qualitative half. The
subclasses say which kind of input was wrong; each is also the built-in exception it refines
(``ValueError``, ``RuntimeError``, ``OSError``), so code catching those keeps working.

The rule of the public functions: a value of the right Python type that is out of the function's
domain (NaN, an empty or wrongly shaped array, an unknown method, norm or model name, a contact
model an option does not apply to) raises a :class:`QualgraspError`; an argument of a plainly
wrong Python type (a number where a :class:`~qualgrasp.certify.Grasp` is expected, say) raises
``TypeError``, as Python's own functions do.
"""

from __future__ import annotations

__all__ = [
    "QualgraspError",
    "CertifyError",
    "ArgumentError",
    "GraspError",
    "GraspFileError",
    "CertificateError",
    "SolverError",
    "OptionError",
    "WriteError",
]


class QualgraspError(Exception):
    """Base class of every error :mod:`qualgrasp` raises on purpose."""


class CertifyError(QualgraspError):
    """Base class of every error raised by :mod:`qualgrasp.certify`."""


class ArgumentError(CertifyError, ValueError):
    """An argument is outside what the function accepts: an unknown method or norm, an option
    that does not apply to the grasp's contact models, a number out of its range (the message
    names the argument)."""


class GraspError(CertifyError, ValueError):
    """A grasp or contact is malformed (NaN coordinates, zero normal, negative friction, ...)."""


class GraspFileError(CertifyError, ValueError):
    """A grasp-set or results file cannot be read (malformed JSON, missing file, wrong schema)."""


class CertificateError(CertifyError, ValueError):
    """A certificate is structurally malformed (wrong keys, lengths or types)."""


class SolverError(CertifyError, RuntimeError):
    """A convex solver failed to return a usable answer."""


class OptionError(ArgumentError):
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

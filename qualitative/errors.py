"""Exceptions raised by :mod:`qualgrasp.qualitative`.

Every error a user can cause derives from :class:`QualitativeError`; the subclasses say which kind
of input was wrong. Messages name the problem and, where there is one, the fix.
"""

from __future__ import annotations

from ..certify.errors import QualgraspError

__all__ = [
    "QualitativeError",
    "ImageError",
    "SegmentationError",
    "ContourError",
    "OutlineError",
    "FormulaError",
    "TraceError",
    "NetworkError",
    "RegionError",
    "ZoneError",
    "SynthesisError",
]


class QualitativeError(QualgraspError):
    """Base class of every error raised by :mod:`qualgrasp.qualitative`."""


class ImageError(QualitativeError, ValueError):
    """An image cannot be read or holds nothing usable (unreadable file, empty, constant)."""


class SegmentationError(QualitativeError, ValueError):
    """Segmentation did not give exactly one usable object (none, several, cut by the border)."""


class ContourError(QualitativeError, ValueError):
    """A contour is degenerate (too few points, zero area, self-intersecting, too small)."""


class OutlineError(QualitativeError, ValueError):
    """A qualitative outline string is not well formed (names the rule it breaks)."""


class FormulaError(QualitativeError, ValueError):
    """An ST0 formula does not parse (with the position of the problem)."""


class TraceError(QualitativeError, ValueError):
    """A spatio-temporal trace is malformed (unknown relation, bad pair, wrong type)."""


class NetworkError(QualitativeError, ValueError):
    """An RCC-8 network is malformed (unknown relation name, bad pair)."""


class RegionError(QualitativeError, ValueError):
    """A region or grasp scene cannot be built (not polygonal, empty, invalid, bad scene parameters)."""


class ZoneError(QualitativeError, ValueError):
    """Contacts given to the zone-of-freedom computation are malformed (shapes, NaN, zero normal)."""


class SynthesisError(QualitativeError, ValueError):
    """Grasp synthesis parameters are invalid (finger count, friction, thresholds)."""

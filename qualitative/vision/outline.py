"""Qualitative outlines (Galton & Meathrel 1999) extracted from a contour: the contour as a cyclic
string of curvature types (the grammar of the strings: :mod:`~qualgrasp.qualitative.vision.grammar`)
with its segments, at one scale (the hierarchy of scales:
:mod:`~qualgrasp.qualitative.vision.scales`).

Conventions
-----------
* **Orientation.** Contours are traversed so that the shoelace area on the image's (x, y) values
  (x = column, y = row, pixels) is positive; the object lies on the side of the tangent ``t``
  turned by +90 degrees, so the inward unit normal is ``(-t_y, t_x)``. Turning in the positive
  sense along this traversal is convex. On screen (y down) this traversal is clockwise, the
  direction in which the paper reads its figure 3.
* **Canonical start.** :attr:`Outline.segments` start at the segment where the canonical string
  (:func:`~qualgrasp.qualitative.vision.grammar.canonical`) starts (for periodic strings, the first
  such segment along the contour).

Scale
-----
An outline is computed at a **scale** ``s``: the standard deviation of the Gaussian smoothing of the
contour as a fraction of its perimeter ``P`` (``sigma = s * P`` pixels), so the same object at
another size in the image gives the same string at the same ``s``. The default ``s = 0.004``
(:data:`DEFAULT_SCALE`) describes features down to about a percent of the perimeter. The lengths
of the extraction are tied to the scale: the corner window is ``WINDOW * s * P`` (``WINDOW = 5``,
0.02 P at the default; it is also the shortest line-like run and the distance under which corners
merge), so at coarser scales small features (notches, bumps) are smoothed away rather than read as
corners. Angles and the straightness threshold do not change with the scale. Scales run up to
:data:`SCALE_MAX` (0.032).

Extraction (curvature scale space style; every threshold is an angle or a fraction of the
perimeter ``P``, so the string does not depend on position, rotation or scale):

1. resample the contour at ``samples`` (1024) points evenly spaced by arc length (``h = P / samples``);
2. smooth with a periodic Gaussian of ``s * P`` (0.004 P at the default scale); turning angle
   ``phi_i`` at every sample (they add up to exactly 2 pi for a simple contour);
3. corners: greedily, the window of ``WINDOW * s * P`` (0.02 P) holding the largest absolute turning
   in excess of its background, while that excess exceeds ``corner_angle`` (30 degrees), re-centred
   on its sharpest sample. The background is the turning the surrounding curve would put in the
   window anyway: the smallest same-signed turning per sample on each flank (one window on either
   side), the larger of the two, times the window's length; it is zero next to a straight line or a
   change of sign, so polygon corners are untouched, but a curve that is tight for the window (a
   disc or a long rounded end at a coarse scale) is not chopped into corners: a corner is turning
   concentrated with respect to its surroundings, as in curvature scale space corner detectors
   (Mokhtarian and Suomela 1998 compare a curvature maximum with its neighbouring minima). The
   chosen window is then widened by up to half a window on each side (keeping at least a third of
   each piece between corners), because a corner's rounding by pixels, anti-aliasing and smoothing
   spills past the window and belongs to the corner, not to its neighbours. A corner turning at
   least ``cusp_angle`` (125 degrees), also after removing its background over its span, is a cusp,
   otherwise an angle (the widened span holds some of the neighbouring curves' turning, which must
   not make a right angle next to an arc a cusp at coarse scales): the thin tip of a cusp is lost at
   image resolution and smoothing blunts it, so imaged cusps measure about 140 to 170 degrees, while
   an angle of 125 degrees has an interior angle of 55 degrees. Corners closer than a window merge
   (scale-space semantics: rounded corners and notches smaller than the window are corners);
4. between corners, a piece shorter than a window is a corner if it turns at least
   ``corner_angle``, else a straight link. In longer pieces each sample is straight if
   ``abs(kappa) * P / (2 pi) < straight`` (0.25: the curvature relative to that of a disc of the
   same perimeter), else convex or concave by its sign; runs shorter than a window join their
   longer neighbour; a run turning less than ``flat_angle`` (10 degrees) in total is straight,
   one turning more is a curve of that sign;
5. repair into a well-formed string: merge equal line-like neighbours; merge neighbouring corners
   that turn the same way (summing their turning); separate neighbouring corners that turn
   opposite ways (a step narrower than a window) by a short straight link where the turning
   changes sign; a merged corner turning less than ``corner_angle`` joins the preceding element; a
   cusp with no curve neighbour becomes an angle (two straight lines cannot meet in a cusp; its
   turning may then exceed pi, e.g. the blunt tip of a leg narrower than the window); when neither
   ``)`` nor three convex points remain, the line-like element turning most positively becomes
   ``)`` (or, when none turns positively, the largest convex corner with its two neighbours);
   finally, when the symbols cannot add up to 2 pi (a string counts a cusp as exactly +-pi and an
   angle as less, while a measured cusp turns 140 to 170 degrees and a blunt angle may exceed
   pi: ``>({/>/>/``), the weakest inward (outward) cusp becomes an angle until they can.

Resolution: features need a few windows (0.02 P each) of contour; the built-in objects keep their
strings from 0.5x to 2x (objects 100 to 450 pixels across) with pixel noise up to 20 grey levels
for a contrast of 200.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np
from scipy import ndimage

from ..errors import ContourError, OutlineError
from .contour import ImageSource, extract_contour, signed_area
from .grammar import (CONVEX_POINTS, CURVE_SET, LINE_SET, NAMES, POINT_SET, canonical, check_turnings,
                      least_rotation, turning_range, validate)

__all__ = ["DEFAULT_SCALE", "WINDOW", "SCALE_MAX", "SCALE_MIN", "Segment", "Outline", "resample", "check_scale",
           "prepare_contour", "outline_contour", "outline_image", "canonical_at", "tls_line", "outline_to_dict"]

DEFAULT_SCALE = 0.004
"""Default scale: Gaussian standard deviation of the smoothing, fraction of the perimeter."""

WINDOW = 5.0
"""Corner window (also the shortest run and the corner merging distance), in scales."""

SCALE_MIN = DEFAULT_SCALE / 4
"""Finest scale synthesis and grasp fields accept (fraction of the perimeter)."""

SCALE_MAX = 0.032
"""Coarsest scale (fraction of the perimeter): 8 times the default, the coarse end of the hierarchy.

The corner window is then ``WINDOW * 0.032 = 0.16`` of the perimeter: six windows go round the
contour, just enough for the three corners and three sides of a triangle. Coarser, corner windows
would cover most of the contour and the description degenerates.
"""


# --------------------------------------------------------------------------------------------------
# Outline data


def _frozen(array) -> np.ndarray:
    array = np.array(array, dtype=np.float64)
    array.setflags(write=False)
    return array


@dataclass(frozen=True, eq=False)
class Segment:
    """One element of an outline.

    Attributes
    ----------
    symbol : str
        Curvature type, one of :data:`~qualgrasp.qualitative.vision.grammar.SYMBOLS`.
    start, stop : int
        Span ``[start, stop)`` of samples of :attr:`Outline.contour`; ``0 <= start < n`` and
        ``start < stop <= start + n``: indices past ``n`` wrap around. Point-like elements span the
        corner window of the extraction.
    arc : (float, float)
        The same span as arc length along the contour from ``contour[0]``, pixels
        (``start * h``, ``stop * h``; may exceed the perimeter when the span wraps).
    turning : float
        Signed tangent turning over the span, radians (positive = convex).
    points : numpy.ndarray
        ``(k, 2)`` contour samples of the span (x, y), pixels.
    position : numpy.ndarray or None
        Point-like elements: the apex (x, y): intersection of the tangent lines fitted on either
        side for an angle, the sharpest sample for a cusp. None for line-like ones.
    endpoints : numpy.ndarray or None
        Straight lines: ``(2, 2)`` end points of the total-least-squares line through the span,
        in the direction of travel. None otherwise.
    """

    symbol: str
    start: int
    stop: int
    arc: tuple[float, float]
    turning: float
    points: np.ndarray
    position: np.ndarray | None = None
    endpoints: np.ndarray | None = None

    @property
    def name(self) -> str:
        """Name of the curvature type."""
        return NAMES[self.symbol]

    @property
    def is_point(self) -> bool:
        """True for point-like elements (angles and cusps)."""
        return self.symbol in POINT_SET

    @property
    def length(self) -> float:
        """Arc length of the span, pixels."""
        return self.arc[1] - self.arc[0]

    @property
    def radius(self) -> float:
        """Mean radius of curvature over the span, ``length / abs(turning)``, pixels (inf if flat)."""
        return self.length / abs(self.turning) if self.turning else math.inf


@dataclass(frozen=True, eq=False)
class Outline:
    """A qualitative outline extracted from a contour.

    Attributes
    ----------
    segments : tuple of Segment
        The elements in contour order, starting where the canonical string starts.
    contour : numpy.ndarray
        ``(n, 2)`` contour resampled evenly by arc length, positive orientation, pixels.
    smoothed : numpy.ndarray
        ``(n, 2)`` the same smoothed at the outline's scale (source of tangents and turnings).
    perimeter : float
        Length of the contour, pixels.
    size : float
        Diameter of the contour's minimum enclosing circle, pixels (the object's size).
    scale : float
        Standard deviation of the Gaussian smoothing it was computed at, fraction of the perimeter.
    """

    segments: tuple[Segment, ...]
    contour: np.ndarray
    smoothed: np.ndarray
    perimeter: float
    size: float
    scale: float = DEFAULT_SCALE

    @property
    def raw_string(self) -> str:
        """Symbols of :attr:`segments` in order (equal to :attr:`string` for extracted outlines)."""
        return "".join(seg.symbol for seg in self.segments)

    @property
    def string(self) -> str:
        """The canonical cyclic string."""
        return canonical(self.raw_string)

    @property
    def spacing(self) -> float:
        """Arc length between consecutive contour samples, pixels."""
        return self.perimeter / len(self.contour)

    def tangents(self) -> np.ndarray:
        """``(n, 2)`` unit tangents of the smoothed contour, in the direction of travel."""
        return _unit_tangents(self.smoothed)

    def normals(self) -> np.ndarray:
        """``(n, 2)`` inward unit normals ``(-t_y, t_x)`` of the smoothed contour."""
        t = self.tangents()
        return np.column_stack([-t[:, 1], t[:, 0]])

    def pixel_normals(self, sigma: float = 1.0) -> np.ndarray:
        """``(n, 2)`` inward unit normals of the contour smoothed over only ``sigma`` pixels (a
        Gaussian's standard deviation): the contour's own normals at the image's resolution,
        which :meth:`normals` averages over the outline's scale."""
        t = _unit_tangents(ndimage.gaussian_filter1d(self.contour, sigma / self.spacing, axis=0, mode="wrap"))
        return np.column_stack([-t[:, 1], t[:, 0]])

    def turning(self) -> np.ndarray:
        """``(n,)`` turning angle of the smoothed contour at every sample, radians (sum 2 pi)."""
        return _turning(self.smoothed)

    def __str__(self) -> str:
        return self.string


# --------------------------------------------------------------------------------------------------
# Extraction


def _unit_tangents(points: np.ndarray) -> np.ndarray:
    d = np.roll(points, -1, axis=0) - np.roll(points, 1, axis=0)
    return d / np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-12)


def resample(contour: np.ndarray, samples: int) -> tuple[np.ndarray, float]:
    """Resample a closed contour at ``samples`` points evenly spaced by arc length.

    Parameters
    ----------
    contour : numpy.ndarray
        ``(m, 2)`` closed contour (closing point not repeated), pixels.
    samples : int
        Number of output points.

    Returns
    -------
    points : numpy.ndarray
        ``(samples, 2)``, starting at ``contour[0]``.
    perimeter : float
        Length of the closed polyline, pixels.
    """
    closed = np.vstack([contour, contour[:1]])
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(closed, axis=0), axis=1))])
    perimeter = float(s[-1])
    if perimeter <= 0:
        raise ContourError("the contour has zero length")
    t = np.arange(samples) * (perimeter / samples)
    points = np.column_stack([np.interp(t, s, closed[:, 0]), np.interp(t, s, closed[:, 1])])
    return points, perimeter


def _turning(smoothed: np.ndarray) -> np.ndarray:
    """Turning angle at every sample, between the chords arriving and leaving (radians)."""
    chord = np.roll(smoothed, -1, axis=0) - smoothed
    angle = np.arctan2(chord[:, 1], chord[:, 0])
    return np.angle(np.exp(1j * (angle - np.roll(angle, 1))))


def _window_sums(phi: np.ndarray, half: int) -> np.ndarray:
    """Sum of ``phi`` over the cyclic window ``[i - half, i + half)`` for every ``i``."""
    n = len(phi)
    c = np.concatenate([[0.0], np.cumsum(np.concatenate([phi, phi, phi]))])
    i = np.arange(n) + n
    return c[i + half] - c[i - half]


def _flank_minima(a: np.ndarray, width: int) -> np.ndarray:
    """``m[j] = min(a[j:j + width])``, cyclically."""
    wrapped = np.concatenate([a, a[:width - 1]])
    return np.lib.stride_tricks.sliding_window_view(wrapped, width).min(axis=1)


def _background(phi: np.ndarray, half: int) -> tuple[np.ndarray, np.ndarray]:
    """Turning of the surrounding curve that a window centred at each sample would carry anyway.

    For the window ``[i - half, i + half)``, the smallest same-signed turning per sample on each of
    its flanks ``[i - 3 half, i - half)`` and ``[i + half, i + 3 half)``, the larger of the two, times
    the window's length; for convex (first array) and concave turning (second). Zero next to a
    straight line or a change of sign.
    """
    n, width = len(phi), 2 * half
    out = []
    for a in (np.maximum(phi, 0.0), np.maximum(-phi, 0.0)):
        m = _flank_minima(a, width)
        i = np.arange(n)
        out.append(width * np.maximum(m[(i - 3 * half) % n], m[(i + half) % n]))
    return out[0], out[1]


def _find_corners(phi: np.ndarray, half: int, threshold: float,
                  background: tuple[np.ndarray, np.ndarray]) -> list[tuple[int, int]]:
    """Greedy corner windows ``[start, start + 2 half)`` (start may be negative: cyclic).

    A window's strength is its turning in excess of its :func:`_background`: turning concentrated
    in the window, not the steady turning of a curve that is tight for the window's size (a disc
    at a coarse scale, a long rounded end) and would otherwise be chopped into corners.
    """
    n = len(phi)
    convex, concave = background
    sums = _window_sums(phi, half)
    strength = np.abs(sums) - np.where(sums > 0, convex, concave)
    free = np.ones(n, bool)
    corners = []
    while True:
        i = int(np.argmax(strength))
        if strength[i] < threshold:
            return sorted(corners)
        # Centre the window on the sharpest sample when that window is still free.
        span = np.arange(i - half, i + half) % n
        c = int(span[np.argmax(np.abs(phi[span]))])
        window = np.arange(c - half, c + half) % n
        start = c - half if free[window].all() else i - half
        free[np.arange(start, start + 2 * half) % n] = False
        corners.append((start % n, start % n + 2 * half))
        # Windows overlapping the corner are out; the others do not contain it, so their sums
        # stand.
        strength[np.arange(start - half + 1, start + 3 * half) % n] = 0.0


def _label_runs(kappa: np.ndarray, straight: float) -> list[list]:
    """Runs ``[label, start, stop)`` of curvature sign (0 straight, 1 convex, -1 concave)."""
    labels = np.where(kappa > straight, 1, np.where(kappa < -straight, -1, 0))
    edges = np.flatnonzero(np.diff(labels)) + 1
    bounds = np.concatenate([[0], edges, [len(labels)]])
    return [[int(labels[a]), int(a), int(b)] for a, b in zip(bounds[:-1], bounds[1:])]


def _coalesce(runs: list[list]) -> list[list]:
    out = []
    for run in runs:
        if out and out[-1][0] == run[0]:
            out[-1][2] = run[2]
        else:
            out.append(list(run))
    return out


def _classify_piece(phi: np.ndarray, samples: int, straight: float, min_run: int,
                    flat_angle: float) -> list[list]:
    """Line-like runs ``[label, start, stop)`` of one piece (indices relative to the piece)."""
    kappa = phi * samples / (2 * np.pi)  # curvature relative to a disc of the same perimeter
    runs = _coalesce(_label_runs(kappa, straight))
    while len(runs) > 1:
        lengths = [b - a for _, a, b in runs]
        j = int(np.argmin(lengths))
        if lengths[j] >= min_run:
            break
        neighbours = [k for k in (j - 1, j + 1) if 0 <= k < len(runs)]
        k = max(neighbours, key=lambda m: lengths[m])
        runs[j][0] = runs[k][0]
        runs = _coalesce(runs)
    for run in runs:
        run[0] = {"/": 0, ")": 1, "(": -1}[_line_symbol(float(phi[run[1]:run[2]].sum()), flat_angle)]
    return _coalesce(runs)


def _line_symbol(turning: float, flat_angle: float) -> str:
    """Line-like symbol agreeing with a run's total turning: small turning is straight."""
    if abs(turning) < flat_angle:
        return "/"
    return ")" if turning > 0 else "("


def _point_symbol(turning: float, corner_angle: float, cusp_angle: float) -> str:
    """Symbol of a concentrated turning; ``""`` when it is too small to be a corner."""
    if abs(turning) < corner_angle:
        return ""
    if abs(turning) >= cusp_angle:
        return "}" if turning > 0 else "{"
    return ">" if turning > 0 else "<"


def _repair(items: list[list], phi: np.ndarray, corner_angle: float, cusp_angle: float,
            flat_angle: float) -> list[list]:
    """Make a cyclic list of ``[symbol, start, stop, turning]`` well formed (see module notes)."""
    n = len(phi)

    def merge(i: int, symbol: str) -> None:  # items[i] absorbs its successor
        j = (i + 1) % len(items)
        a, b = items[i], items[j]
        items[i] = [symbol, a[1], a[2] + (b[2] - b[1]), a[3] + b[3]]
        del items[j]

    def link(i: int) -> None:
        # A short straight link between items[i] and its successor, centred where the turning
        # changes sign (the extremum of the cumulative turning), so that it turns little itself.
        a, b = items[i], items[(i + 1) % len(items)]
        b_stop = a[2] + (b[2] - b[1])
        cumulative = np.cumsum(phi[np.arange(a[1], b_stop) % n])
        q = max(1, (b_stop - a[1]) // 16)
        m = a[1] + 1 + int(np.argmax(cumulative) if a[3] > 0 else np.argmin(cumulative))
        m = min(max(m, a[1] + q + 1), b_stop - q - 1)
        turning = lambda lo, hi: float(phi[np.arange(lo, hi) % n].sum())  # noqa: E731
        items[i] = [a[0], a[1], m - q, turning(a[1], m - q)]
        middle = ["/", m - q, m + q, turning(m - q, m + q)]
        items[(i + 1) % len(items)] = [b[0], m + q, b_stop, turning(m + q, b_stop)]
        for item in (items[i], items[(i + 1) % len(items)]):
            item[0] = _point_symbol(item[3], corner_angle, cusp_angle)
        items.insert(i + 1, middle)

    while len(items) > 1:
        for i, a in enumerate(items):
            prev, b = items[i - 1], items[(i + 1) % len(items)]
            if a[0] in LINE_SET and a[0] == b[0]:
                merge(i, a[0])
            elif a[0] in POINT_SET and b[0] in POINT_SET and (a[3] > 0) == (b[3] > 0):
                merge(i, _point_symbol(a[3] + b[3], corner_angle, cusp_angle))
            elif a[0] in POINT_SET and b[0] in POINT_SET:
                # Opposite turnings closer than a window (a step): keep both, with a link between;
                # summing them would erase the feature.
                link(i)
            elif a[0] == "":  # a corner too weak to count: its span joins the preceding element
                turning = prev[3] + a[3]
                if prev[0] in POINT_SET or prev[0] == "":
                    symbol = _point_symbol(turning, corner_angle, cusp_angle)
                else:
                    symbol = _line_symbol(turning, flat_angle)
                merge((i - 1) % len(items), symbol)
            elif a[0] in "}{" and prev[0] not in CURVE_SET and b[0] not in CURVE_SET:
                # Two straight lines cannot meet in a cusp: at this resolution it is a sharp angle.
                a[0] = ">" if a[0] == "}" else "<"
            else:
                continue
            break
        else:
            break
    if len(items) == 1:  # a single smooth element (a disc)
        items[0][0] = ")" if items[0][3] > 0 else "("
    symbols = [item[0] for item in items]
    if ")" not in symbols and sum(s in CONVEX_POINTS for s in symbols) < 3:
        # Bounded outlines need a convex curve or three convex points; the turning must then be
        # carried by some line-like element that was judged straight or concave.
        best = max((item for item in items if item[0] in LINE_SET), key=lambda it: it[3], default=None)
        if best is not None and best[3] > 0:
            best[0] = ")"
            return _repair(items, phi, corner_angle, cusp_angle, flat_angle)
        # Otherwise the turning sits in one or two huge corners (more than pi each: a blob whose
        # corner windows cover most of it at a coarse scale): the largest convex corner and its
        # neighbours become one convex curve.
        corners = [i for i, item in enumerate(items) if item[0] in CONVEX_POINTS]
        if not corners:
            raise ContourError("the contour cannot be described by a well-formed outline at this scale "
                               "(it is too thin or too small)")
        i = max(corners, key=lambda k: items[k][3])
        items[:] = items[i - 1:] + items[:i - 1] if i else items[-1:] + items[:-1]  # corner at 1
        for _ in range(min(2, len(items) - 1)):  # the predecessor absorbs the corner, then the successor
            merge(0, ")")
        if items[0][3] <= 0:
            raise ContourError("the contour cannot be described by a well-formed outline at this scale "
                               "(it is too thin or too small)")
        items[0][0] = ")"
        return _repair(items, phi, corner_angle, cusp_angle, flat_angle)
    _close_up(items)
    return items


def _close_up(items: list[list]) -> None:
    """Make the symbols allow a total turning of 2 pi, changing cusps into angles if they do not.

    A string counts a cusp as exactly +-pi and an angle as strictly less, while a measured cusp
    turns about 140 to 170 degrees and a blunt angle (a cusp without a curve neighbour, see
    :func:`_repair`) may turn more than pi. Without a convex curve, ``{`` then leaves too little
    turning for the rest (``>({/>/>/``: less than 3 pi - pi); without a concave one, ``}`` too
    much. The weakest such cusp becomes an angle of the same sign until 2 pi is allowed: an angle
    takes any turning up to pi, and rule 1 (three convex points) guarantees this ends.
    """
    target = 2 * math.pi
    while True:
        lo, lo_closed, hi, hi_closed = turning_range("".join(item[0] for item in items))
        if not (target < hi or (hi_closed and math.isclose(target, hi))):
            cusp, angle = "{", "<"  # too little turning allowed
        elif not (target > lo or (lo_closed and math.isclose(target, lo))):
            cusp, angle = "}", ">"  # too much
        else:
            return
        cusps = [item for item in items if item[0] == cusp]
        if not cusps:
            return  # cannot happen with rule 1 satisfied; validate() would report it
        min(cusps, key=lambda item: abs(item[3]))[0] = angle


def tls_line(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Total-least-squares line through ``(m, 2)`` points: a point on it (their mean) and its unit
    direction (along the points' order).

    Examples
    --------
    >>> p, t = tls_line(np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]]))
    >>> p.tolist(), np.round(t, 4).tolist()
    ([1.0, 1.0], [0.7071, 0.7071])
    """
    mean = points.mean(axis=0)
    direction = np.linalg.svd(points - mean, full_matrices=False)[2][0]
    if np.dot(points[-1] - points[0], direction) < 0:
        direction = -direction
    return mean, direction


def _apex(points: np.ndarray, phi: np.ndarray, item: list, half: int, spacing: float) -> np.ndarray:
    """Position of a corner: tangent lines fitted on either side intersected, or the sharpest sample."""
    n = len(points)
    symbol, start, stop = item[0], item[1], item[2]
    span = np.arange(start, stop) % n
    sharpest = points[span[np.argmax(np.abs(phi[span]))]]
    if symbol in "}{" or half < 2:
        return sharpest
    p1, u1 = tls_line(points[np.arange(start - half, start) % n])
    p2, u2 = tls_line(points[np.arange(stop, stop + half) % n])
    cross = u1[0] * u2[1] - u1[1] * u2[0]
    if abs(cross) < math.sin(math.radians(10)):
        return sharpest
    # p1 + a u1 = p2 + b u2
    d = p2 - p1
    a = (d[0] * u2[1] - d[1] * u2[0]) / cross
    apex = p1 + a * u1
    if np.linalg.norm(apex - sharpest) > 2 * half * spacing:
        return sharpest
    return apex


def _segment(item: list, points: np.ndarray, phi: np.ndarray, half: int, spacing: float) -> Segment:
    n = len(points)
    symbol, start, stop, turning = item
    start, stop = start % n, start % n + (stop - start)
    span = points[np.arange(start, stop) % n]
    position = endpoints = None
    if symbol in POINT_SET:
        position = _frozen(_apex(points, phi, [symbol, start, stop], half, spacing))
    elif symbol == "/":
        mean, direction = tls_line(span)
        ends = (span[[0, -1]] - mean) @ direction
        endpoints = _frozen(mean + ends[:, None] * direction)
    return Segment(symbol, int(start), int(stop), (start * spacing, stop * spacing), float(turning),
                   _frozen(span), position, endpoints)


def check_scale(scale: float, name: str = "scale") -> float:
    """``scale`` as a float in ``(0, SCALE_MAX]``, or ValueError naming it (``name``) and its units."""
    try:
        value = float(scale)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number (a fraction of the perimeter), got {scale!r}") from None
    if not (math.isfinite(value) and 0 < value <= SCALE_MAX):
        raise ValueError(f"{name} must be a fraction of the perimeter in (0, {SCALE_MAX:g}], got {scale!r}")
    return value


def prepare_contour(contour: np.ndarray, samples: int) -> tuple[np.ndarray, float, float]:
    """Checked, positively oriented contour resampled by arc length: points, perimeter, size (pixels)."""
    contour = np.asarray(contour, dtype=np.float64)
    if contour.ndim != 2 or contour.shape[1] != 2 or len(contour) < 3:
        raise ContourError(f"expected an (m, 2) contour with m >= 3 points, got shape {contour.shape}")
    if not np.all(np.isfinite(contour)):
        raise ContourError("the contour has NaN or infinite coordinates")
    area = signed_area(contour)
    if area == 0:
        raise ContourError("the contour encloses no area")
    if area < 0:
        contour = contour[::-1]
    points, perimeter = resample(contour, samples)
    size = 2.0 * cv2.minEnclosingCircle(points.astype(np.float32))[1]
    return points, perimeter, float(size)


@dataclass(frozen=True)
class _Params:
    """Extraction parameters at one scale; lengths in samples, angles in radians."""

    sigma: float  # Gaussian standard deviation
    half: int  # half the corner window
    corner_angle: float
    cusp_angle: float
    straight: float
    flat_angle: float


def _params(scale: float, samples: int, corner_window: float | None, corner_angle: float,
            cusp_angle: float, straight: float, flat_angle: float) -> _Params:
    window = WINDOW * scale if corner_window is None else corner_window
    return _Params(scale * samples, max(1, round(window * samples / 2)), corner_angle, cusp_angle,
                   straight, flat_angle)


def _describe(points: np.ndarray, p: _Params) -> tuple[np.ndarray, np.ndarray, list[list]]:
    """Smoothed contour, turning per sample and well-formed items ``[symbol, start, stop, turning]``.

    The items are in contour order (not yet rotated to the canonical start).
    """
    smoothed = ndimage.gaussian_filter1d(points, p.sigma, axis=0, mode="wrap")
    phi = _turning(smoothed)
    winding = phi.sum() / (2 * np.pi)
    if abs(winding - 1) > 1e-6:
        raise ContourError(f"the contour is not a simple closed curve: its tangent turns {winding:.3g} times")
    items = _items(phi, p.half, len(points), p.corner_angle, p.cusp_angle, p.straight, p.flat_angle)
    items = _repair(items, phi, p.corner_angle, p.cusp_angle, p.flat_angle)
    return smoothed, phi, items


def outline_contour(contour: np.ndarray, *, scale: float = DEFAULT_SCALE, samples: int = 1024,
                    corner_window: float | None = None, corner_angle: float = math.radians(30),
                    cusp_angle: float = math.radians(125), straight: float = 0.25,
                    flat_angle: float = math.radians(10)) -> Outline:
    """The qualitative outline of a closed contour at one scale.

    Parameters
    ----------
    contour : numpy.ndarray
        ``(m, 2)`` closed contour (x, y), pixels, closing point not repeated; either orientation
        (it is reversed when its shoelace area is negative).
    scale : float
        Standard deviation of the Gaussian smoothing, as a fraction of the perimeter, in
        ``(0, SCALE_MAX]`` (default :data:`DEFAULT_SCALE`, 0.004). Features narrower than about
        two scales are smoothed away; the corner window follows it (see ``corner_window``).
        :func:`~qualgrasp.qualitative.vision.scales.finger_scale` converts a finger pad's width into a scale.
    samples : int
        Number of samples after resampling by arc length.
    corner_window : float, optional
        Width of the window in which concentrated turning makes a corner, fraction of the
        perimeter. Default ``WINDOW * scale`` (5 scales: 0.02 at the default scale); it is also
        the shortest line-like run and the distance under which corners merge.
    corner_angle : float
        Smallest turning (radians) within a window that makes an angle (default 30 degrees).
    cusp_angle : float
        Smallest turning (radians) that makes a cusp rather than an angle (default 125 degrees).
    straight : float
        Largest ``abs(curvature) * perimeter / (2 pi)`` of a straight sample (default 0.25: radius
        of curvature above four times that of a disc of the same perimeter).
    flat_angle : float
        A curve run turning less than this (radians) in total is straight (default 10 degrees).

    Returns
    -------
    Outline
        Well formed (checked with :func:`~qualgrasp.qualitative.vision.grammar.validate`), segments in
        canonical order, with the
        ``scale`` it was computed at.

    Raises
    ------
    ContourError
        Degenerate or self-intersecting contour, or one without a well-formed description.
    ValueError
        ``scale`` not in ``(0, SCALE_MAX]``.

    Examples
    --------
    >>> import numpy as np
    >>> square = np.array([[0, 0], [100, 0], [100, 100], [0, 100]], float)
    >>> outline_contour(square).string
    '/>/>/>/>'
    >>> outline_contour(square, scale=0.01).scale
    0.01
    """
    scale = check_scale(scale)
    points, perimeter, size = prepare_contour(contour, samples)
    p = _params(scale, samples, corner_window, corner_angle, cusp_angle, straight, flat_angle)
    smoothed, phi, items = _describe(points, p)
    string = "".join(item[0] for item in items)
    r = least_rotation(string)
    items = items[r:] + items[:r]
    spacing = perimeter / samples
    segments = tuple(_segment(item, points, phi, p.half, spacing) for item in items)
    outline = Outline(segments, _frozen(points), _frozen(smoothed), perimeter, size, scale)
    validate(outline)
    return outline


def _corner_spans(corners: list[tuple[int, int]], half: int, n: int) -> list[tuple[int, int]]:
    """Corner windows widened by up to ``half`` samples on each side, into the pieces between them.

    A corner's rounding (pixels, anti-aliasing, smoothing) spills past its detection window; that
    turning belongs to the corner, not to the line-like neighbours it would otherwise bend. Each
    piece keeps at least a third of its length.
    """
    m = len(corners)
    spans = []
    for k, (start, stop) in enumerate(corners):
        before = start - (corners[k - 1][1] - (n if k == 0 else 0))
        after = corners[(k + 1) % m][0] + (n if k + 1 == m else 0) - stop
        spans.append((start - min(half, before // 3), stop + min(half, after // 3)))
    return spans


def _items(phi: np.ndarray, half: int, samples: int, corner_angle: float, cusp_angle: float,
           straight: float, flat_angle: float) -> list[list]:
    """Corners and classified runs between them, ``[symbol, start, stop, turning]`` in contour order."""
    n = len(phi)
    symbol_of = {0: "/", 1: ")", -1: "("}
    background = _background(phi, half)
    corners = _find_corners(phi, half, corner_angle, background)
    if not corners:
        runs = _classify_piece(phi, samples, straight, 2 * half, flat_angle)
        if len(runs) > 1 and runs[0][0] == runs[-1][0]:  # the first run continues the last one
            runs[-1][2] = n + runs[0][2]
            runs = runs[1:]
        return [[symbol_of[lab], a, b, float(phi[np.arange(a, b) % n].sum())] for lab, a, b in runs]
    spans = _corner_spans(corners, half, n)
    items = []
    for k, (start, stop) in enumerate(spans):
        turning = float(phi[np.arange(start, stop) % n].sum())
        # A cusp by its own turning: the widened span also holds some of the neighbouring curves'
        # (their background rate times its length), which must not make a corner next to an arc
        # a cusp at coarse scales.
        rate = background[0 if turning > 0 else 1][(corners[k][0] + half) % n] / (2 * half)
        own = abs(turning) - rate * (stop - start)
        symbol = _point_symbol(turning, corner_angle, cusp_angle)
        if symbol and own < cusp_angle:
            symbol = ">" if turning > 0 else "<"
        items.append([symbol, start, stop, turning])
        nxt = spans[(k + 1) % len(spans)][0] + (n if k + 1 == len(spans) else 0)
        if nxt - stop >= 2 * half:
            idx = np.arange(stop, nxt) % n
            for lab, a, b in _classify_piece(phi[idx], samples, straight, 2 * half, flat_angle):
                items.append([symbol_of[lab], stop + a, stop + b, float(phi[idx[a:b]].sum())])
        elif nxt > stop:  # shorter than a window: a corner if it turns enough, else a straight link
            turning = float(phi[np.arange(stop, nxt) % n].sum())
            items.append([_point_symbol(turning, corner_angle, cusp_angle) or "/", stop, nxt, turning])
    return items


def outline_image(src: ImageSource, *, scale: float = DEFAULT_SCALE, threshold: float | None = None,
                  largest: bool = False, subpixel: bool = True, method: str = "otsu",
                  mask: ImageSource | None = None, rect: tuple[int, int, int, int] | None = None,
                  **options) -> Outline:
    """The qualitative outline of the object in an image at one scale.

    Parameters
    ----------
    src : str, pathlib.Path or numpy.ndarray
        Image file or array (see :func:`qualgrasp.qualitative.vision.contour.read_image`).
    scale : float
        Standard deviation of the Gaussian smoothing, fraction of the perimeter, in
        ``(0, SCALE_MAX]`` (default :data:`DEFAULT_SCALE`, 0.004; see :func:`outline_contour`).
    threshold : float, optional
        Grey level separating object and background, in the input's units; default Otsu's.
    largest : bool
        With several objects, describe the largest instead of raising.
    subpixel : bool
        Refine the contour to sub-pixel accuracy.
    method : str
        Segmentation method (:data:`qualgrasp.qualitative.vision.contour.METHODS`): ``"otsu"`` (default),
        ``"multiotsu"`` (a soft shadow), ``"adaptive"`` (uneven lighting), ``"grabcut"`` (a
        textured background); see :func:`qualgrasp.qualitative.vision.contour.segment`.
    mask : str, pathlib.Path or numpy.ndarray, optional
        A user's mask of the object (non-zero pixels), instead of a method.
    rect : (int, int, int, int), optional
        GrabCut's rectangle ``(x, y, width, height)``, pixels (default: around Otsu's object).
    **options
        Other extraction parameters of :func:`outline_contour`.

    Returns
    -------
    Outline
        Coordinates in pixels of the input image (x = column, y = row).

    Examples
    --------
    >>> from qualgrasp.qualitative.objects import render
    >>> outline_image(render("figure3")).string
    '/}(</{)>'
    """
    scale = check_scale(scale)
    contour = extract_contour(src, threshold=threshold, largest=largest, subpixel=subpixel, method=method,
                              mask=mask, rect=rect)
    return outline_contour(contour, scale=scale, **options)


def canonical_at(points: np.ndarray, scale: float, options: dict) -> str:
    """The canonical string of a prepared contour (:func:`prepare_contour`) at one scale, checked
    well formed (string and measured turnings); ``options`` are the extraction's angles and
    thresholds, as for :func:`outline_contour`."""
    p = _params(scale, len(points), None, **options)
    try:
        items = _describe(points, p)[2]
    except ContourError as err:
        raise ContourError(f"at scale {scale:.6g}: {err}") from None
    raw = "".join(item[0] for item in items)
    try:
        validate(raw)
        check_turnings(raw, [item[3] for item in items])
    except OutlineError as err:  # a bug of the extraction: the repair must prevent it
        raise OutlineError(f"at scale {scale:.6g}: {err}") from None
    return canonical(raw)


def outline_to_dict(outline: Outline) -> dict:
    """JSON-ready description of an outline.

    Keys: ``string`` (canonical), ``scale`` (fraction of the perimeter), ``size`` and ``perimeter``
    (pixels) and ``segments``, in canonical order, each with ``symbol``, ``name``, ``start``/``stop``
    (samples of the resampled contour), ``arc`` (pixels along the contour), ``turning`` (radians),
    ``points`` (list of [x, y]) and, for point-like elements, ``position`` ([x, y]) or, for straight
    lines, ``endpoints``.
    """
    segments = []
    for seg in outline.segments:
        row = {"symbol": seg.symbol, "name": seg.name, "start": seg.start, "stop": seg.stop,
               "arc": list(seg.arc), "turning": seg.turning, "points": seg.points.tolist()}
        if seg.position is not None:
            row["position"] = seg.position.tolist()
        if seg.endpoints is not None:
            row["endpoints"] = seg.endpoints.tolist()
        segments.append(row)
    return {"string": outline.string, "scale": outline.scale, "size": outline.size,
            "perimeter": outline.perimeter, "segments": segments}

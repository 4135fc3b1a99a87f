"""The scales of an outline: the scale a finger feels (:func:`finger_scale`), the scale every
command reads an outline at (:func:`planning_scale`), and the hierarchy of strings over scales
(:func:`outline_scales`).

A finger pad of width ``W`` feels the outline at the scale ``W / (4 P)`` (a Gaussian whose
+-2 sigma span is the pad, :func:`finger_scale`); for the project's pad of 0.08 of the object's
size ``D``, that is ``0.02 D / P``: 0.0064 for a disc, less for objects whose perimeter is long
for their size (0.004 to 0.009 for the study's silhouettes), never more than 0.01 (``P >= 2 D``).

:func:`outline_scales` (an image) and :func:`outline_contour_scales` (a contour) give the
**hierarchy** (curvature scale space, Mokhtarian and Mackworth 1992): the intervals of scale over
which the string stays the same (:class:`ScaleInterval`), from the default scale 0.004 (fine) to
:data:`~qualgrasp.qualitative.vision.outline.SCALE_MAX` (coarse: there 21 of the 24 study cells have no
concave symbol left, while deep
concavities such as the polygon's notch, figure 3's slot or the horse's legs remain), found on a
geometric grid (4 scales per octave) and located by bisection to 1 %. The image is segmented and
the contour resampled once; only the smoothing and the classification are repeated per scale.
Real silhouettes give many short intervals at fine scales, where wiggles hover around the angle
thresholds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .contour import ImageSource, extract_contour
from .grammar import POINT_SET
from .outline import DEFAULT_SCALE, SCALE_MAX, Outline, canonical_at, check_scale, prepare_contour

__all__ = ["ScaleInterval", "finger_scale", "planning_scale", "outline_contour_scales", "outline_scales"]


@dataclass(frozen=True)
class ScaleInterval:
    """A range of scales over which an object's outline string does not change.

    Attributes
    ----------
    lo, hi : float
        Bounds of the range, scales (Gaussian standard deviations as fractions of the perimeter).
        Inner bounds are located to a relative tolerance (see :func:`outline_contour_scales`).
    string : str
        The canonical outline string over the range.
    corners : int
        Number of point-like symbols (angles and cusps) in the string.
    """

    lo: float
    hi: float
    string: str
    corners: int

    @property
    def middle(self) -> float:
        """Geometric middle of the range, ``sqrt(lo * hi)`` (the grid is geometric)."""
        return math.sqrt(self.lo * self.hi)

    @property
    def convex(self) -> bool:
        """True when the string has no concave symbol (``(``, ``<`` or ``{``)."""
        return not any(s in "(<{" for s in self.string)


def finger_scale(outline: Outline | np.ndarray, finger_width: float, *, samples: int = 1024) -> float:
    """The scale at which a finger pad of a given width feels the object's outline.

    A pad of width ``W`` pressed on the contour averages it over ``W``; the Gaussian that does the
    same has its +-2 sigma span equal to the pad, ``sigma = W / 4`` (close to the standard
    deviation ``W / sqrt(12) = 0.29 W`` of the pad's own box average). Bumps and dents narrower
    than about three quarters of a pad are then smoothed away, wider ones remain (measured on the
    built-in square: a semicircular bump is gone up to 0.8 pad, kept from 0.85). With
    ``W = finger_width * D`` (``D`` the object's size, the diameter of its minimum enclosing
    circle, as in :mod:`qualgrasp.qualitative.synthesis.regions`) and ``P`` the perimeter, the scale is
    ``finger_width * D / (4 * P)``.

    Parameters
    ----------
    outline : Outline or numpy.ndarray
        An extracted outline (its :attr:`~Outline.size` and :attr:`~Outline.perimeter`), or an
        ``(m, 2)`` closed contour in pixels (resampled like
        :func:`~qualgrasp.qualitative.vision.outline.outline_contour` does).
    finger_width : float
        Pad width, fraction of the object's size (the project's default is
        :data:`qualgrasp.qualitative.synthesis.regions.FINGER_WIDTH`, 0.08).
    samples : int
        Resampling of a contour given as an array.

    Returns
    -------
    float
        Scale, fraction of the perimeter (pass it as ``scale`` to
        :func:`~qualgrasp.qualitative.vision.outline.outline_contour`); for a
        disc and the default pad, ``0.08 / (4 pi) = 0.0064``.

    Raises
    ------
    ValueError
        ``finger_width`` not positive and finite.
    ContourError
        Unusable contour.

    Examples
    --------
    >>> import numpy as np
    >>> square = np.array([[0, 0], [100, 0], [100, 100], [0, 100]], float)
    >>> round(finger_scale(square, 0.08), 5)  # 0.08 * 100 sqrt(2) / (4 * 400)
    0.00707
    """
    width = float(finger_width)
    if not (math.isfinite(width) and width > 0):
        raise ValueError(
            f"finger_width must be a positive fraction of the object's size, got {finger_width!r}")
    if isinstance(outline, Outline):
        size, perimeter = outline.size, outline.perimeter
    else:
        _, perimeter, size = prepare_contour(outline, samples)
    return width * size / (4.0 * perimeter)


def planning_scale(outline: Outline | np.ndarray, finger_width: float, *, samples: int = 1024) -> float:
    """The scale every qualitative command reads an object's outline at by default: the finger's
    (:func:`finger_scale`), never finer than :data:`~qualgrasp.qualitative.vision.outline.DEFAULT_SCALE` nor
    coarser than
    :data:`~qualgrasp.qualitative.vision.outline.SCALE_MAX`.

    ``qualgrasp outline``, ``regions``, ``synthesize``, ``independent-regions``, ``compare`` and the
    figures all start from it, so the string shown and the regions the grasps are planned on are
    those of one outline. The built-in objects keep their strings there (figure 3's ``/}(</{)>``
    among them): their features are several pads wide.

    Parameters
    ----------
    outline : Outline or numpy.ndarray
        As for :func:`finger_scale`.
    finger_width : float
        Pad width, fraction of the object's size.
    samples : int
        Resampling of a contour given as an array.

    Returns
    -------
    float
        Scale, fraction of the perimeter.

    Examples
    --------
    >>> import numpy as np
    >>> square = np.array([[0, 0], [100, 0], [100, 100], [0, 100]], float)
    >>> round(planning_scale(square, 0.08), 5), planning_scale(square, 0.01), planning_scale(square, 1.0)
    (0.00707, 0.004, 0.032)
    """
    return min(SCALE_MAX, max(DEFAULT_SCALE, finger_scale(outline, finger_width, samples=samples)))



def outline_contour_scales(contour: np.ndarray, *, fine: float = DEFAULT_SCALE, coarse: float = SCALE_MAX,
                           per_octave: int = 4, tolerance: float = 0.01, samples: int = 1024,
                           corner_angle: float = math.radians(30), cusp_angle: float = math.radians(125),
                           straight: float = 0.25,
                           flat_angle: float = math.radians(10)) -> tuple[ScaleInterval, ...]:
    """The scale hierarchy of a contour's outline (curvature scale space), from fine to coarse.

    The contour is resampled once; at each scale only the smoothing and the classification of
    :func:`~qualgrasp.qualitative.vision.outline.outline_contour` are repeated. The string is computed on a
    geometric grid of
    ``per_octave`` scales per doubling from ``fine`` to ``coarse`` (both included); where two
    neighbouring scales differ, the change is located by bisection (geometric middles) until the
    bracket is narrower than a factor ``1 + tolerance``, and a boundary is put at the bracket's
    geometric middle. Strings seen inside a bracket become intervals of their own. A change that
    reverts within one grid step is not seen.

    Parameters
    ----------
    contour : numpy.ndarray
        ``(m, 2)`` closed contour (x, y), pixels, either orientation.
    fine, coarse : float
        Scale range covered, fractions of the perimeter, ``0 < fine < coarse <= SCALE_MAX``. Default
        from :data:`~qualgrasp.qualitative.vision.outline.DEFAULT_SCALE` (0.004, the fine end: the first interval's string is the default
        outline) to :data:`~qualgrasp.qualitative.vision.outline.SCALE_MAX` (0.032, where the built-in
        objects and most real cells have
        become convex blobs: no concave symbol).
    per_octave : int
        Grid scales per doubling of the scale (4: neighbours about 19 % apart).
    tolerance : float
        Relative accuracy of the inner bounds: each lies within a factor ``sqrt(1 + tolerance)`` of
        the true change (for the extraction's own, deterministic string).
    samples : int
        Number of samples after resampling by arc length.
    corner_angle, cusp_angle, straight, flat_angle : float
        As for :func:`~qualgrasp.qualitative.vision.outline.outline_contour` (the corner window is ``WINDOW``
        scales at every scale).

    Returns
    -------
    tuple of ScaleInterval
        Contiguous (``hi`` of one is ``lo`` of the next), increasing, from ``fine`` to ``coarse``;
        consecutive strings differ; every string is well formed.

    Raises
    ------
    ContourError
        Unusable contour, or no well-formed description at some scale (naming it).
    ValueError
        Bad range, grid or tolerance.

    Examples
    --------
    >>> import numpy as np
    >>> square = np.array([[0, 0], [100, 0], [100, 100], [0, 100]], float)
    >>> [(round(i.lo, 4), round(i.hi, 4), i.string) for i in outline_contour_scales(square)]
    [(0.004, 0.032, '/>/>/>/>')]
    """
    fine, coarse = check_scale(fine, "fine"), check_scale(coarse, "coarse")
    if not fine < coarse:
        raise ValueError(f"fine ({fine:g}) must be smaller than coarse ({coarse:g})")
    if int(per_octave) != per_octave or per_octave < 1:
        raise ValueError(f"per_octave must be a positive integer, got {per_octave!r}")
    if not 0 < tolerance < 1:
        raise ValueError(f"tolerance must be in (0, 1), got {tolerance!r}")
    options = {"corner_angle": corner_angle, "cusp_angle": cusp_angle, "straight": straight,
               "flat_angle": flat_angle}
    points = prepare_contour(contour, samples)[0]
    steps = max(1, math.ceil(per_octave * math.log2(coarse / fine) - 1e-9))
    grid = fine * (coarse / fine) ** (np.arange(steps + 1) / steps)
    grid[-1] = coarse
    seen = [(float(s), canonical_at(points, float(s), options)) for s in grid]

    def refine(lo: float, a: str, hi: float, b: str) -> list[tuple[float, str]]:
        # Scales strictly between lo and hi, with their strings, until every change is bracketed.
        if a == b or hi / lo <= 1 + tolerance:
            return []
        mid = math.sqrt(lo * hi)
        m = canonical_at(points, mid, options)
        return refine(lo, a, mid, m) + [(mid, m)] + refine(mid, m, hi, b)

    sampled = [seen[0]]
    for (lo, a), (hi, b) in zip(seen, seen[1:]):
        sampled += refine(lo, a, hi, b) + [(hi, b)]
    intervals: list[ScaleInterval] = []
    lo = fine
    for (s, a), (t, b) in zip(sampled, sampled[1:] + [(coarse, None)]):
        if a != b:
            hi = coarse if b is None else math.sqrt(s * t)
            intervals.append(ScaleInterval(lo, hi, a, sum(c in POINT_SET for c in a)))
            lo = hi
    return tuple(intervals)


def outline_scales(src: ImageSource, *, threshold: float | None = None, largest: bool = False,
                   subpixel: bool = True, method: str = "otsu", mask: ImageSource | None = None,
                   rect: tuple[int, int, int, int] | None = None, **options) -> tuple[ScaleInterval, ...]:
    """The scale hierarchy of the outline of the object in an image, from fine to coarse.

    The image is segmented and its contour extracted once (see
    :func:`~qualgrasp.qualitative.vision.outline.outline_image`); the
    hierarchy is that of :func:`outline_contour_scales`.

    Parameters
    ----------
    src : str, pathlib.Path or numpy.ndarray
        Image file or array (see :func:`qualgrasp.qualitative.vision.contour.read_image`).
    threshold : float, optional
        Grey level separating object and background, in the input's units; default Otsu's.
    largest : bool
        With several objects, describe the largest instead of raising.
    subpixel : bool
        Refine the contour to sub-pixel accuracy.
    method, mask, rect
        Segmentation, as for :func:`~qualgrasp.qualitative.vision.outline.outline_image`.
    **options
        Range, grid and extraction parameters of :func:`outline_contour_scales`.

    Returns
    -------
    tuple of ScaleInterval
        From ``fine`` (default 0.004) to ``coarse`` (default
        :data:`~qualgrasp.qualitative.vision.outline.SCALE_MAX`, 0.032).

    Examples
    --------
    >>> from qualgrasp.qualitative.objects import render
    >>> outline_scales(render("disc"))[0].string
    ')'
    """
    contour = extract_contour(src, threshold=threshold, largest=largest, subpixel=subpixel, method=method,
                              mask=mask, rect=rect)
    return outline_contour_scales(contour, **options)

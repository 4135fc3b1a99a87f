"""Feasible grasp regions (paper, definitions 1 and 2) on a qualitative outline.

Graspable elements are the line-like curvature types ``/``, ``)`` and ``(``; no finger goes on an
angle or a cusp. A point of a graspable element is a **feasible contact** when a finger pad of
width ``finger_width`` centred there lies on the element at least ``margin`` away from both of its
ends, and, on a curve, the contour under the pad is flat enough: the diameter ``rho`` of its
bounding circle exceeds ``alpha``. A region is a maximal run of feasible contacts on one element.

Readings and units
------------------
* **Minimum bounding circle.** The paper's circle "centred on the curve segment, the diameter of
  which is a qualitative measure of the curvature" is read as the circle of curvature over the
  finger pad: ``rho = 2 * w / abs(dtheta)``, with ``w`` the pad's arc length and ``dtheta`` the
  tangent turning under it (the circle on which an arc of length ``w`` turns by ``dtheta``). Large
  ``rho`` means flat. The turning is the element's own, averaged over a pad's length within the
  element (so pixel noise averages out and the neighbouring corners cannot leak in); a region's
  ends are therefore located to about a pad. Straight lines are not checked (paper, footnote 5).
* **Points.** A region's points are the contour samples (spacing ``P / 1024``) where the centre of
  the finger pad may go; the pad covers ``finger_width`` of contour around each of them.
* **Units.** ``alpha``, ``finger_width`` and ``margin`` are fractions of the object's size ``D``,
  the diameter of its minimum enclosing circle in pixels (:attr:`Outline.size`), so regions do not
  depend on the object's scale in the image. Defaults: ``alpha = 0.5`` (a curve is graspable where
  its radius of curvature exceeds a quarter of the object's size: a disc is graspable all round,
  a bump of a tenth of the size is not), ``finger_width = 0.08``, ``margin = 0.02``. Multiply by
  ``Outline.size`` for pixels.
* **Geometry.** Points are in pixels of the input image (x = column, y = row). On a straight
  line the points are projected on the total-least-squares line of the element and share its
  inward normal; on a curve they are the contour samples and the normals come from the contour
  smoothed at the outline's scale. Normals are unit vectors pointing **into** the object,
  ``n = (-t_y, t_x)`` for the unit tangent ``t`` of the positively oriented contour.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import ndimage

from .outline import Outline, outline_image
from .vision import ImageSource

__all__ = ["ALPHA", "ALPHA_MAX", "FINGER_WIDTH", "MARGIN", "GRASPABLE", "Region", "feasible_regions",
           "regions_image", "regions_to_dict"]

ALPHA = 0.5
#: Largest curvature threshold the command line and grasp fields accept (fraction of the size).
ALPHA_MAX = 100.0
FINGER_WIDTH = 0.08
MARGIN = 0.02
GRASPABLE = "/)("


@dataclass(frozen=True, eq=False)
class Region:
    """A feasible grasp region: a run of feasible finger positions on one graspable element.

    Attributes
    ----------
    type : str
        The element's symbol: ``/``, ``)`` or ``(``.
    segment : int
        Index of the element in :attr:`Outline.segments`.
    start, stop : int
        Samples ``[start, stop)`` of :attr:`Outline.contour` (indices past ``n`` wrap around).
    arc : (float, float)
        Arc length along the contour from ``contour[0]`` of the first and last point, pixels
        (the second may exceed the perimeter when the region wraps).
    points : numpy.ndarray
        ``(k, 2)`` feasible contact points (x, y), pixels.
    normals : numpy.ndarray
        ``(k, 2)`` inward unit normals at the points.
    rho : float
        Smallest bounding-circle diameter over the region, pixels (``inf`` on a straight line).
    """

    type: str
    segment: int
    start: int
    stop: int
    arc: tuple[float, float]
    points: np.ndarray
    normals: np.ndarray
    rho: float

    @property
    def length(self) -> float:
        """Arc length from the first to the last point, pixels."""
        return self.arc[1] - self.arc[0]


def _frozen(array: np.ndarray) -> np.ndarray:
    array = np.ascontiguousarray(array, dtype=np.float64)
    array.setflags(write=False)
    return array


def _runs(flags: np.ndarray) -> list[tuple[int, int]]:
    """Maximal runs ``[a, b)`` of True."""
    edges = np.diff(np.concatenate([[0], flags.astype(np.int8), [0]]))
    return list(zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)))


def _pad_diameter(phi: np.ndarray, centres: np.ndarray, pad: float, spacing: float,
                  closed: bool) -> np.ndarray:
    """Bounding-circle diameter ``2 w / abs(dtheta)`` of the pad ``[c - pad, c + pad)`` at each centre.

    ``phi`` holds the turning of one element's samples (``centres`` index into it). It is first
    smoothed over ``pad`` samples, within the element only (its ends extended, or wrapped round
    for a closed element), so that pixel noise averages out and the neighbouring corners' turning
    cannot leak in.
    """
    smooth = ndimage.gaussian_filter1d(phi, pad, mode="wrap" if closed else "nearest")
    if closed:
        smooth = np.tile(smooth, 3)
        centres = centres + len(phi)
    cumulative = np.concatenate([[0.0], np.cumsum(smooth)])
    grid = np.arange(len(cumulative))
    dtheta = np.abs(np.interp(centres + pad, grid, cumulative) - np.interp(centres - pad, grid, cumulative))
    with np.errstate(divide="ignore"):
        return np.where(dtheta > 0, 2 * (2 * pad * spacing) / dtheta, np.inf)


def feasible_regions(outline: Outline, alpha: float = ALPHA, finger_width: float = FINGER_WIDTH,
                     margin: float = MARGIN) -> list[Region]:
    """The feasible grasp regions of an outline.

    Parameters
    ----------
    outline : Outline
        A qualitative outline (:func:`qualgrasp.qualitative.outline.outline_image`).
    alpha : float
        Threshold on the bounding-circle diameter ``rho`` of curves, fraction of the object's size
        ``outline.size``; a curve point is feasible when ``rho > alpha * size``.
    finger_width : float
        Width of the finger pad, fraction of the object's size.
    margin : float
        Smallest distance from the pad to either end of its element, fraction of the object's size.

    Returns
    -------
    list of Region
        In contour order, starting with the outline's first segment.
    """
    if not (alpha >= 0 and finger_width > 0 and margin >= 0):
        raise ValueError("need alpha >= 0, finger_width > 0 and margin >= 0; "
                         f"got {alpha}, {finger_width} and {margin}")
    n, h = len(outline.contour), outline.spacing
    pad = finger_width * outline.size / h / 2  # half pad, samples
    keep = margin * outline.size / h + pad  # a centre's distance to its element's ends, samples
    phi = outline.turning()
    normals = outline.normals()
    closed = len(outline.segments) == 1  # a single smooth element has no ends
    regions = []
    for k, seg in enumerate(outline.segments):
        if seg.symbol not in GRASPABLE:
            continue
        length = seg.stop - seg.start
        lo, hi = (0, length) if closed else (math.ceil(keep), math.floor(length - keep) + 1)
        if hi <= lo:
            continue  # too short for a finger and its margins
        centres = np.arange(lo, hi)  # relative to the element's start
        if seg.symbol == "/":
            rho = np.full(len(centres), np.inf)
        else:
            rho = _pad_diameter(phi[np.arange(seg.start, seg.stop) % n], centres, pad, h, closed)
        runs = _runs(rho > alpha * outline.size)
        if closed and len(runs) > 1 and runs[0][0] == 0 and runs[-1][1] == len(centres):
            # on a closed element the first run continues the last one
            runs = [(runs[-1][0], runs[0][1] + len(centres))] + runs[1:-1]
        for a, b in runs:
            pick = np.arange(a, b) % len(centres)
            regions.append(_region(outline, k, seg.start + centres[pick], rho[pick], normals))
    return regions


def _region(outline: Outline, k: int, idx: np.ndarray, rho: np.ndarray, normals: np.ndarray) -> Region:
    n, h = len(outline.contour), outline.spacing
    seg = outline.segments[k]
    start = int(idx[0] % n)
    stop = start + len(idx)
    if seg.symbol == "/":
        a, b = seg.endpoints
        t = (b - a) / np.linalg.norm(b - a)
        points = a + np.outer((outline.contour[idx % n] - a) @ t, t)
        nrm = np.tile([-t[1], t[0]], (len(idx), 1))
    else:
        points = outline.contour[idx % n]
        nrm = normals[idx % n]
    return Region(seg.symbol, k, start, stop, (start * h, (stop - 1) * h), _frozen(points), _frozen(nrm),
                  float(rho.min()) if len(rho) else math.inf)


def regions_image(src: ImageSource, *, alpha: float = ALPHA, finger_width: float = FINGER_WIDTH,
                  margin: float = MARGIN, threshold: float | None = None, largest: bool = False,
                  **options) -> list[Region]:
    """Feasible grasp regions of the object in an image.

    Parameters
    ----------
    src : str, pathlib.Path or numpy.ndarray
        Image file or array (see :func:`qualgrasp.qualitative.vision.read_image`).
    alpha, finger_width, margin : float
        See :func:`feasible_regions` (fractions of the object's size).
    threshold, largest, **options
        See :func:`qualgrasp.qualitative.outline.outline_image`.

    Returns
    -------
    list of Region
        Points and normals in pixels of the input image (x = column, y = row).
    """
    outline = outline_image(src, threshold=threshold, largest=largest, **options)
    return feasible_regions(outline, alpha, finger_width, margin)


def regions_to_dict(outline: Outline, regions: list[Region], alpha: float = ALPHA,
                    finger_width: float = FINGER_WIDTH, margin: float = MARGIN) -> dict[str, Any]:
    """JSON-ready description: ``string``, ``size`` (pixels), the parameters and ``regions``.

    Each region has ``type``, ``segment``, ``start``, ``stop``, ``arc`` (pixels), ``rho`` (pixels,
    null on straight lines), ``points`` and ``normals`` (lists of [x, y]).
    """
    return {
        "string": outline.string,
        "size": outline.size,
        "perimeter": outline.perimeter,
        "alpha": alpha,
        "finger_width": finger_width,
        "margin": margin,
        "regions": [
            {
                "type": r.type,
                "segment": r.segment,
                "start": r.start,
                "stop": r.stop,
                "arc": list(r.arc),
                "rho": r.rho if math.isfinite(r.rho) else None,
                "points": r.points.tolist(),
                "normals": r.normals.tolist(),
            }
            for r in regions
        ],
    }

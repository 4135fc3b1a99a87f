"""Feasible grasp regions (paper, definitions 1 and 2) on a qualitative outline.

Graspable elements are the line-like curvature types ``/``, ``)`` and ``(``; no finger goes on an
angle or a cusp. A point of a graspable element is a **feasible contact** when a finger pad of
width ``finger_width`` centred there lies on the element at least ``margin`` away from both of its
ends (a straight edge's ends are its corners, and a pad may overhang an outward one: notes
below), and, on a curve, the contour under the pad is flat enough: the diameter ``rho`` of its
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
* **Straight edges.** A straight element ends where its edge does: at a neighbouring angle (``>``
  or ``<``), the edge runs on into the angle's window in the outline for as long as the contour
  stays within :data:`ON_LINE` pixels of the element's fitted line, so the edge's end is where
  the contour leaves it, whatever the outline's scale (at the finger's scale the windows are
  wider). A pad's centre keeps ``margin`` from an end at an outward angle (the pad may overhang
  it: nothing is there) and ``margin`` plus half a pad from an end at an inward angle (the other
  face blocks the pad) or at any other element. The region's points and normal are those of the
  line fitted (total least squares) to the whole edge, end to end (not to the element's own
  samples alone, which at a coarse scale may be a short link between two corner windows). An edge
  shorter than a pad has no region: a pad would rest on nothing. So an edge several pads long
  gets a region of its length less the margins (a quarter of a pad at an outward corner with the
  defaults).
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
from dataclasses import dataclass, replace
from typing import Any, Sequence

import numpy as np
from scipy import ndimage

from ..vision.outline import Outline, outline_contour, tls_line
from ..vision.scales import planning_scale
from ..vision.contour import ImageSource, extract_contour

__all__ = ["ALPHA", "ALPHA_MAX", "FINGER_WIDTH", "MARGIN", "GRASPABLE", "ON_LINE", "Region", "feasible_regions",
           "on_fine_outline", "planning_regions", "regions_image", "regions_to_dict"]

ALPHA = 0.5
#: Largest curvature threshold the command line and grasp fields accept (fraction of the size).
ALPHA_MAX = 100.0
FINGER_WIDTH = 0.08
MARGIN = 0.02
GRASPABLE = "/)("
#: Largest distance (pixels) of the contour from a straight element's line where the edge runs on
#: into a neighbouring angle's span: the image's resolution.
ON_LINE = 1.0


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
        A qualitative outline (:func:`qualgrasp.qualitative.vision.outline.outline_image`).
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
        if seg.symbol == "/" and not closed:
            regions += _edge_regions(outline, k, finger_width, margin)
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


def _edge_end(outline: Outline, k: int, side: int, a: np.ndarray, normal: np.ndarray, half_pad: float,
              margin: float) -> tuple[int, float]:
    """One end of the straight element ``k`` (``side`` -1: its start, +1: its stop): how many
    samples of a neighbouring angle's window the edge runs on into (the raw contour within
    :data:`ON_LINE` pixels of the element's line through ``a`` with unit ``normal``, without a
    break), and what a pad's centre keeps from that end, pixels (module notes, straight edges)."""
    n, segs = len(outline.contour), outline.segments
    seg, neighbour = segs[k], segs[(k + side) % len(segs)]
    reach = 0
    if neighbour.symbol in "><":
        own = seg.start if side < 0 else seg.stop - 1
        span = neighbour.stop - neighbour.start
        off = np.abs((outline.contour[(own + side * np.arange(1, span + 1)) % n] - a) @ normal) > ON_LINE
        reach = int(np.argmax(off)) if off.any() else span
    return reach, margin if neighbour.symbol == ">" else margin + half_pad  # a pad may overhang an outward angle


def _edge_regions(outline: Outline, k: int, finger_width: float, margin: float) -> list[Region]:
    """Feasible regions of the straight element ``k`` (module notes, straight edges), on the line
    fitted to the whole edge."""
    n, seg = len(outline.contour), outline.segments[k]
    a, b = seg.endpoints
    if not np.linalg.norm(b - a) > 0:
        return []
    t = (b - a) / np.linalg.norm(b - a)
    half_pad, keep = finger_width * outline.size / 2, margin * outline.size
    before, first = _edge_end(outline, k, -1, a, np.array([-t[1], t[0]]), half_pad, keep)
    after, last = _edge_end(outline, k, +1, a, np.array([-t[1], t[0]]), half_pad, keep)
    idx = np.arange(seg.start - before, seg.stop + after)
    mean, t = tls_line(outline.contour[idx % n])
    along = (outline.contour[idx % n] - mean) @ t
    if along[-1] - along[0] < 2 * half_pad:
        return []  # an edge shorter than the pad: nothing for a pad to rest on
    regions = []
    for i, j in _runs((along >= along[0] + first) & (along <= along[-1] - last)):
        regions.append(_region(outline, k, idx[i:j], np.full(j - i, np.inf), np.zeros((0, 2)), (mean, t)))
    return regions


def _region(outline: Outline, k: int, idx: np.ndarray, rho: np.ndarray, normals: np.ndarray,
            line: tuple[np.ndarray, np.ndarray] | None = None) -> Region:
    n, h = len(outline.contour), outline.spacing
    seg = outline.segments[k]
    start = int(idx[0] % n)
    stop = start + len(idx)
    if seg.symbol == "/":
        a, t = line  # a point on the edge's fitted line and its unit direction
        points = a + np.outer((outline.contour[idx % n] - a) @ t, t)
        nrm = np.tile([-t[1], t[0]], (len(idx), 1))
    else:
        points = outline.contour[idx % n]
        nrm = normals[idx % n]
    return Region(seg.symbol, k, start, stop, (start * h, (stop - 1) * h), _frozen(points), _frozen(nrm),
                  float(rho.min()) if len(rho) else math.inf)


def on_fine_outline(regions: Sequence[Region], fine: Outline, outline: Outline) -> tuple[Region, ...]:
    """Regions of ``outline`` (a coarser scale of ``fine``; the contour is the same at every scale)
    with the fine outline's normals on curves and, on straight regions, the contour's own points
    (a coarse fitted line may pass pixels away from a bumpy edge) with the line's normal: the
    contacts and normals the procedures reason on and certification sees (module notes)."""
    if outline is fine:
        return tuple(regions)
    normals = np.asarray(fine.normals())
    n = len(fine.contour)
    out = []
    for r in regions:
        idx = np.arange(r.start, r.stop) % n
        out.append(replace(r, points=fine.contour[idx]) if r.type == "/" else replace(r, normals=normals[idx]))
    return tuple(out)


def planning_regions(contour: np.ndarray, *, scale: float | None = None, alpha: float = ALPHA,
                     finger_width: float = FINGER_WIDTH, margin: float = MARGIN,
                     fine: Outline | None = None) -> tuple[Outline, tuple[Region, ...]]:
    """The outline and feasible regions grasps are planned on (module notes, scale).

    Parameters
    ----------
    contour : numpy.ndarray
        ``(m, 2)`` closed contour as extracted from the image
        (:func:`qualgrasp.qualitative.vision.contour.extract_contour`), pixels.
    scale : float, optional
        Outline scale, fraction of the perimeter; default
        :func:`qualgrasp.qualitative.vision.scales.planning_scale` of ``finger_width`` (the finger's).
    alpha, finger_width, margin : float
        As for :func:`feasible_regions`.
    fine : Outline, optional
        The contour's outline at the default scale (computed when not given).

    Returns
    -------
    outline : Outline
        The outline at ``scale``.
    regions : tuple of Region
        Its feasible regions, carrying the fine outline's normals on curves and the contour's own
        points on straight lines (:func:`on_fine_outline`).

    Examples
    --------
    >>> import numpy as np
    >>> square = np.array([[0, 0], [100, 0], [100, 100], [0, 100]], float)
    >>> outline, regions = planning_regions(square)
    >>> outline.string, round(outline.scale, 5), len(regions)
    ('/>/>/>/>', 0.00707, 4)
    """
    fine = outline_contour(contour) if fine is None else fine
    scale = planning_scale(fine, finger_width) if scale is None else scale
    outline = fine if scale == fine.scale else outline_contour(contour, scale=scale)
    return outline, on_fine_outline(feasible_regions(outline, alpha, finger_width, margin), fine, outline)


def regions_image(src: ImageSource, *, alpha: float = ALPHA, finger_width: float = FINGER_WIDTH,
                  margin: float = MARGIN, scale: float | None = None, threshold: float | None = None,
                  largest: bool = False, **options) -> list[Region]:
    """Feasible grasp regions of the object in an image, on the outline at the finger's scale.

    Parameters
    ----------
    src : str, pathlib.Path or numpy.ndarray
        Image file or array (see :func:`qualgrasp.qualitative.vision.contour.read_image`).
    alpha, finger_width, margin : float
        See :func:`feasible_regions` (fractions of the object's size).
    scale : float, optional
        Outline scale (default the finger's, :func:`planning_regions`).
    threshold, largest, **options
        Segmentation (:func:`qualgrasp.qualitative.vision.contour.extract_contour`).

    Returns
    -------
    list of Region
        Points and normals in pixels of the input image (x = column, y = row).
    """
    contour = extract_contour(src, threshold=threshold, largest=largest, **options)
    return list(planning_regions(contour, scale=scale, alpha=alpha, finger_width=finger_width, margin=margin)[1])


def regions_to_dict(outline: Outline, regions: list[Region], alpha: float = ALPHA,
                    finger_width: float = FINGER_WIDTH, margin: float = MARGIN) -> dict[str, Any]:
    """JSON-ready description: ``string``, ``size`` and ``perimeter`` (pixels), the outline's
    ``scale`` (fraction of the perimeter), the parameters and ``regions``.

    Each region has ``type``, ``segment``, ``start``, ``stop``, ``arc`` (pixels), ``rho`` (pixels,
    null on straight lines), ``points`` and ``normals`` (lists of [x, y]).
    """
    return {
        "string": outline.string,
        "size": outline.size,
        "perimeter": outline.perimeter,
        "scale": outline.scale,
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

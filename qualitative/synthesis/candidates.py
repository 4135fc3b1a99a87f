"""Candidate contact points on feasible grasp regions, and the object's reference frame.

FormGrasp (paper 5.1.2, step 1: "the set S of non-singular points on feasible grasp regions") and
ForceGrasp choose their contacts among these points. Each region is sampled evenly along its arc,
keeping an **inset** from both of its ends, so that a finger placed a little off its nominal point
still lands on the same smooth element with the same normal: a grasp built on these points does not
hinge on a region's exact extent. The samples run from inset to inset, both ends included
(a grasp may need a region's extremes, e.g. to hold a short edge against a long one); a region
too short for the inset on both sides gives its middle point. A closed region (a disc's single
convex curve) has no ends.

Each candidate also carries its **normal spread**: the largest angle between its normal and the
contour's own normals at the image's resolution (:meth:`Outline.pixel_normals`) within ``window``
pixels of arc either side, the position error a grasp must survive (:data:`ERROR`). A clean edge
or curve has a spread of a few degrees; where the contour is lumpy below the finger's scale (a
cell's membrane), a finger landing a pixel or two off its point meets a normal tens of degrees
away, which no grasp planned from the image can count on (``smooth``).

Units: pixels of the input image, x = column, y = row; normals are inward unit vectors; angles in
radians.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from ..errors import SynthesisError
from ..vision.outline import Outline
from .regions import Region

__all__ = ["STEP", "INSET", "PER_REGION", "GAP", "ERROR", "Candidates", "candidates", "object_frame",
           "separated"]

STEP = 0.03
INSET = 0.02
PER_REGION = 16
#: Smallest distance between two fingers, fraction of the object's size.
GAP = 0.08
#: Position error a grasp must survive, pixels (the normal spread's window; FormGrasp's depth).
ERROR = 2.0


@dataclass(frozen=True, eq=False)
class Candidates:
    """Candidate contacts: points, inward normals, the region each lies on, its clearance.

    Attributes
    ----------
    points : numpy.ndarray
        ``(m, 2)`` contact points (x, y), pixels.
    normals : numpy.ndarray
        ``(m, 2)`` inward unit normals.
    region : numpy.ndarray
        ``(m,)`` index of each point's region in the regions list.
    clearance : numpy.ndarray
        ``(m,)`` arc length from the point to the nearer end of its region, pixels (``inf`` on a
        closed region).
    spread : numpy.ndarray or None
        ``(m,)`` normal spread of each point, radians (module notes); None when not known.
    """

    points: np.ndarray
    normals: np.ndarray
    region: np.ndarray
    clearance: np.ndarray
    spread: np.ndarray | None = None

    def __len__(self) -> int:
        return len(self.points)

    def smooth(self, limit: float) -> "Candidates":
        """The candidates whose normal spread is at most ``limit`` radians (all of them when the
        spread is not known)."""
        if self.spread is None:
            return self
        keep = self.spread <= limit
        return Candidates(*(_frozen(a[keep], a.dtype) for a in (self.points, self.normals, self.region,
                                                                 self.clearance, self.spread)))

    def of_region(self, r: int) -> np.ndarray:
        """Indices of the candidates on region ``r``."""
        return np.flatnonzero(self.region == r)


def _frozen(array, dtype=np.float64) -> np.ndarray:
    array = np.ascontiguousarray(array, dtype=dtype)
    array.setflags(write=False)
    return array


def candidates(outline: Outline, regions: Sequence[Region], step: float = STEP,
               inset: float = INSET, per_region: int = PER_REGION, window: float = ERROR) -> Candidates:
    """Sample candidate contacts on feasible regions.

    Parameters
    ----------
    outline : Outline
        The outline the regions belong to (gives the object's size and the sample spacing).
    regions : sequence of Region
        Feasible regions (:func:`qualgrasp.qualitative.synthesis.regions.feasible_regions`).
    step : float
        Spacing of the candidates along a region, fraction of the object's size.
    inset : float
        Arc length kept free at each end of a region, fraction of the object's size (at most a
        quarter of the region's length, so a short region still gives its middle part).
    per_region : int
        Largest number of candidates on one region (the spacing grows on longer regions), which
        bounds the cost of the searches (FormGrasp examines every set of four candidates).
    window : float
        Arc length either side of a point over which its normal spread is taken, pixels.

    Returns
    -------
    Candidates
        In region order, along each region.
    """
    if not (step > 0 and inset >= 0 and math.isfinite(step) and math.isfinite(inset) and per_region >= 1
            and 0 <= window < math.inf):
        raise SynthesisError(f"need step > 0, inset >= 0, per_region >= 1 and window >= 0, got {step}, {inset}, "
                             f"{per_region} and {window}")
    h = outline.spacing
    full = len(outline.contour)
    rows = []
    for r, region in enumerate(regions):
        k = len(region.points)
        if k == 0:
            continue
        closed = k >= full  # the region runs all round the contour: it has no ends
        if closed:
            count = min(per_region, max(1, int(round(k * h / (step * outline.size)))))
            pick = (np.arange(count) * k / count).astype(int)
            clear = np.full(count, math.inf)
        else:
            length = (k - 1) * h
            keep = min(inset * outline.size, 0.25 * length)
            usable = length - 2 * keep
            # from inset to inset, both ends included: a grasp may need a region's extremes
            count = min(per_region, 1 + math.ceil(usable / (step * outline.size))) if usable > 0 else 1
            arc = keep + np.linspace(0.0, usable, count) if count > 1 else np.array([length / 2])
            pick = np.clip(np.round(arc / h).astype(int), 0, k - 1)
            clear = np.minimum(pick, k - 1 - pick) * h
        rows.append((region.points[pick], region.normals[pick], np.full(len(pick), r), clear,
                     (region.start + pick) % full))
    if not rows:
        empty = np.zeros((0, 2))
        return Candidates(_frozen(empty), _frozen(empty), _frozen([], np.intp), _frozen([]), _frozen([]))
    points, normals, region, clear, sample = (np.concatenate(parts) for parts in zip(*rows))
    normals = normals / np.linalg.norm(normals, axis=1, keepdims=True)
    spread = _spread(outline, sample, normals, window)
    return Candidates(_frozen(points), _frozen(normals), _frozen(region, np.intp), _frozen(clear), _frozen(spread))


def _spread(outline: Outline, sample: np.ndarray, normals: np.ndarray, window: float) -> np.ndarray:
    """Normal spread (module notes) of points at contour samples ``sample`` with ``normals``."""
    w = int(math.ceil(window / outline.spacing))
    near = (sample[:, None] + np.arange(-w, w + 1)[None]) % len(outline.contour)
    cosine = np.einsum("mkd,md->mk", outline.pixel_normals()[near], normals)
    return np.arccos(np.clip(cosine, -1.0, 1.0)).max(axis=1)


def object_frame(contour: np.ndarray) -> tuple[np.ndarray, float]:
    """Area centroid of a closed contour and its radius (largest distance from the centroid).

    Parameters
    ----------
    contour : numpy.ndarray
        ``(n, 2)`` closed contour (x, y), pixels, closing point not repeated, positive area.

    Returns
    -------
    center : numpy.ndarray
        ``(2,)`` area centroid, pixels.
    radius : float
        Largest distance from the centroid to a contour point, pixels.
    """
    x, y = contour[:, 0], contour[:, 1]
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    cross = x * yn - xn * y
    area = cross.sum() / 2
    if not area > 0:
        raise SynthesisError("the contour encloses no positive area")
    center = np.array([((x + xn) * cross).sum(), ((y + yn) * cross).sum()]) / (6 * area)
    return center, float(np.linalg.norm(contour - center, axis=1).max())


def separated(points, gap: float, size: float) -> np.ndarray:
    """``(n, n)`` bool: points ``i`` and ``j`` are at least ``gap * size`` apart, so that two
    fingers can hold both."""
    P = np.asarray(points, dtype=float)
    return np.linalg.norm(P[:, None] - P[None], axis=2) >= gap * size

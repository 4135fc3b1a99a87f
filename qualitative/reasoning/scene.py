"""Grasp scenes as RCC-8 networks: object, approach zone, finger discs and feasible grasp regions.

Region names, used by :mod:`qualgrasp.qualitative.reasoning.phases` and in ST0 formulas:

========  ===============================================================================
``O``     the object (a polygon, pixel coordinates)
``A``     the approach zone: the object dilated by ``margin`` (``O.buffer(margin)``), so
          that ``O`` is ``NTPP`` of ``A``; a finger inside it is near the object
``F1..``  the fingers, discs of radius ``radius`` about the given centres (``F1`` is the
          first centre)
``R1..``  the feasible grasp regions: each polyline (points along the object boundary)
          thickened into the object, ``O & polyline.buffer(region_width)``: the points of
          the object within ``region_width`` of the polyline, a tangential proper part
          (``TPP``) of ``O``; a finger resting on the region is ``EC`` with it
========  ===============================================================================

Finger discs are polygons with ``4 * quad_segs`` vertices inscribed in the circle, so a disc
tangent to the object can miss it by up to ``radius * (1 - cos(pi / (4 * quad_segs)))``
(0.0012 ``radius`` for the default 16); use a tolerance ``tol`` larger than this (and than the
noise of vision polygons) for tangent fingers to read as ``EC``. The tolerance must stay below
``region_width`` and the finger diameter, which it cannot resolve (see
:func:`qualgrasp.qualitative.reasoning.rcc8.relation`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import shapely
from shapely.geometry import LineString, Point, Polygon
from shapely.geometry.base import BaseGeometry

from ..errors import RegionError
from .rcc8 import relations_among

__all__ = ["finger_disc", "approach_zone", "grasp_region", "scene_regions", "grasp_scene"]


def finger_disc(centre: Sequence[float], radius: float, quad_segs: int = 16) -> Polygon:
    """A finger as a disc polygon of ``4 * quad_segs`` vertices inscribed in the circle."""
    c = np.asarray(centre, dtype=float)
    if c.shape != (2,) or not np.all(np.isfinite(c)):
        raise RegionError(f"a finger centre must be two finite coordinates, got {centre!r}")
    if not radius > 0:
        raise RegionError(f"finger radius must be > 0, got {radius!r}")
    return Point(c).buffer(radius, quad_segs=quad_segs)


def approach_zone(obj: BaseGeometry, margin: float) -> Polygon:
    """The object dilated by ``margin`` (pixels; round joins)."""
    if not margin > 0:
        raise RegionError(f"approach margin must be > 0, got {margin!r}")
    return obj.buffer(margin)


def grasp_region(obj: BaseGeometry, polyline: Sequence[Sequence[float]], width: float) -> BaseGeometry:
    """A feasible grasp region: the points of ``obj`` within ``width`` of the polyline.

    Parameters
    ----------
    obj : shapely Polygon
    polyline : sequence of (x, y)
        At least two points along the boundary of ``obj`` (pixels).
    width : float
        Depth of the region into the object (pixels), > 0.
    """
    pts = np.asarray(polyline, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 2 or len(pts) < 2 or not np.all(np.isfinite(pts)):
        raise RegionError("a grasp region polyline must be at least two finite (x, y) points")
    if not width > 0:
        raise RegionError(f"region width must be > 0, got {width!r}")
    region = obj.intersection(LineString(pts).buffer(width))
    # keep the areal part: an intersection can also hold stray points or segments
    parts = [g for g in shapely.get_parts(region) if g.geom_type in ("Polygon", "MultiPolygon")]
    return shapely.union_all(parts) if parts else Polygon()


def scene_regions(obj: Polygon, centres: np.ndarray, radius: float, *, margin: float,
                  regions: Sequence[Sequence[Sequence[float]]] = (), region_width: float = 1.0,
                  quad_segs: int = 16) -> dict[str, BaseGeometry]:
    """The named regions of a grasp scene at one moment: ``O``, ``A``, ``F1..Fk``, ``R1..Rm``.

    Parameters
    ----------
    obj : shapely Polygon
        The object, pixel coordinates.
    centres : array_like, shape (k, 2)
        Finger centres (pixels); finger ``F{i+1}`` is centre ``i``.
    radius : float
        Finger radius (pixels).
    margin : float
        Width of the approach zone around the object (pixels), > 0.
    regions : sequence of polylines
        Feasible grasp regions, each a sequence of (x, y) points along the object's boundary;
        region ``R{j+1}`` is polyline ``j``.
    region_width : float
        Depth of the grasp regions into the object (pixels).

    Returns
    -------
    dict
        Name -> shapely geometry, in the order O, A, F1.., R1...
    """
    if not isinstance(obj, Polygon) or obj.is_empty or not obj.is_valid or not obj.area > 0:
        raise RegionError("the object must be a valid, non-empty shapely Polygon")
    centres = np.asarray(centres, dtype=float).reshape(-1, 2)
    out: dict[str, BaseGeometry] = {"O": obj, "A": approach_zone(obj, margin)}
    for i, c in enumerate(centres):
        out[f"F{i + 1}"] = finger_disc(c, radius, quad_segs)
    for j, line in enumerate(regions):
        region = grasp_region(obj, line, region_width)
        if region.is_empty or not region.area > 0:
            raise RegionError(f"grasp region R{j + 1} does not meet the object: its polyline "
                              f"must run along the object's boundary")
        out[f"R{j + 1}"] = region
    return out


def grasp_scene(obj: Polygon, centres: np.ndarray, radius: float, *, margin: float,
                regions: Sequence[Sequence[Sequence[float]]] = (), region_width: float = 1.0,
                tol: float = 0.0, quad_segs: int = 16) -> dict[tuple[str, str], str]:
    """The RCC-8 relations among the regions of a grasp scene (see :func:`scene_regions`).

    Returns
    -------
    dict
        Every ordered pair of distinct names ``(x, y)`` mapped to the base relation name with
        ``r(x, y)`` (computed with :func:`qualgrasp.qualitative.reasoning.rcc8.relation` at tolerance ``tol``,
        pixels). It is a consistent RCC-8 network (accepted as is by
        :func:`qualgrasp.qualitative.reasoning.rcc8.path_consistency`) and a frame of an ST0 trace.
    """
    return relations_among(scene_regions(obj, centres, radius, margin=margin, regions=regions,
                                         region_width=region_width, quad_segs=quad_segs), tol)

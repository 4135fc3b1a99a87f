"""Built-in test objects: the paper's shapes as exact geometry and as synthetic camera images.

The objects follow the paper (Sinha et al., figures 3 and 4):

``"polygon"``
    An irregular concave heptagon (six convex corners, one reflex corner), like figure 4a.
``"nut"``
    A regular hexagonal nut with a circular hole, like figure 4b. The hole is part of the exact
    geometry and is drawn in the image, but outlines describe the **outer** contour only: fingers
    grasp the nut from outside, so the hole is ignored by :mod:`qualgrasp.qualitative.vision.contour`.
``"disc"``
    A circular contour, like figure 4c.
``"figure3"``
    An object like figure 3: two straight segments and one of each other curvature type. Running
    along the positively oriented contour: a straight edge ending in an inward cusp (where a disc
    rests tangentially on the edge), a convex curve (the disc, then a flatter arc around the base),
    an outward angle, a straight edge ending in an outward cusp (a thorn whose other side is a
    concave arc), the concave curve and an inward angle. Canonical string ``/}(</{)>``.
``"square"``
    A square, the simplest polygon (``/>/>/>/>``).

Beyond the paper's shapes, :func:`gear` gives a spur gear with trapezoidal teeth in pixel
coordinates (not one of :data:`NAMES`): many small regions, the hard case of three-finger
synthesis; draw it with :func:`render_polygon`.

Conventions
-----------
Coordinates are pixels of the image: x = column, y = row (y points down), pixel centres at
integer coordinates (pixel ``(row i, column j)`` covers ``[j - 0.5, j + 0.5] x [i - 0.5, i + 0.5]``).
At ``scale=1`` every object fits in a circle of radius ``RADIUS * size`` centred on the image centre
``((size - 1) / 2, (size - 1) / 2)`` plus ``offset``; ``rotation`` is in degrees and turns +x towards
+y (clockwise as displayed, with y pointing down). At ``scale=2`` and no offset the object still
fits in the image with a margin of ``0.08 * size``.
"""

from __future__ import annotations

from functools import cache

import cv2
import numpy as np
import shapely
from shapely.geometry import Polygon

from .errors import QualitativeError

__all__ = ["NAMES", "RADIUS", "BACKGROUND", "FOREGROUND", "shape", "render", "render_polygon",
           "normalise", "place", "gear"]

NAMES = ("polygon", "nut", "disc", "figure3", "square")
RADIUS = 0.21
BACKGROUND = 230
FOREGROUND = 30
_SUPERSAMPLE = 8
_ARC_STEP = np.radians(0.25)  # vertex spacing of arcs: sagitta below 1e-3 px at scale 2


def _arc(center, radius, start, stop):
    """Points of a circular arc from angle ``start`` to ``stop`` (radians, either direction)."""
    count = max(2, int(np.ceil(abs(stop - start) / _ARC_STEP)) + 1)
    angle = np.linspace(start, stop, count)
    return np.column_stack([center[0] + radius * np.cos(angle), center[1] + radius * np.sin(angle)])


def _figure3() -> Polygon:
    # Unit: radius of the disc. Built in the positive orientation (interior on the left of travel).
    x_t, rho, d = 1.9, 2.5, np.radians(45.0)
    y_t = rho * np.sin(d)  # thorn tip height such that the concave arc ends on the line y = 0
    disc = _arc((0.0, 1.0), 1.0, -np.pi / 2, np.pi)  # from the inward cusp (0, 0) round to (-1, 1)
    base = _arc((x_t, 1.0), 1.0 + x_t, np.pi, 1.5 * np.pi)  # flatter convex arc down to (x_t, -x_t)
    concave = _arc((x_t - rho, y_t), rho, 0.0, -d)  # from the thorn tip, turning clockwise
    ring = np.vstack([disc, base[1:], [[x_t, y_t]], concave[1:]])  # then back along y = 0 to (0, 0)
    return Polygon(ring)


@cache
def _template(name: str) -> Polygon:
    """The object in its own unit, normalised to a unit minimum bounding circle at the origin."""
    if name == "polygon":
        raw = Polygon([(-1.0, -0.35), (-0.1, -0.95), (0.95, -0.45), (0.75, 0.45), (0.15, 0.2),
                       (-0.05, 0.95), (-0.85, 0.55)])
    elif name == "nut":
        angle = np.arange(6) * np.pi / 3
        hole = _arc((0.0, 0.0), 0.5, 0.0, 2 * np.pi)[:-1]
        raw = Polygon(np.column_stack([np.cos(angle), np.sin(angle)]), [hole[::-1]])
    elif name == "disc":
        raw = Polygon(_arc((0.0, 0.0), 1.0, 0.0, 2 * np.pi)[:-1])
    elif name == "figure3":
        raw = _figure3()
    elif name == "square":
        raw = Polygon([(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)])
    else:
        raise QualitativeError(f"unknown object {name!r}; built-in objects: {', '.join(NAMES)}")
    return normalise(raw)


def normalise(raw: Polygon) -> Polygon:
    """A polygon scaled and shifted to a unit minimum bounding circle centred at the origin.

    Parameters
    ----------
    raw : shapely.geometry.Polygon
        Any valid polygon, any unit, any orientation.

    Returns
    -------
    shapely.geometry.Polygon
        Exterior oriented so that the shoelace area on (x, y) is positive, holes kept. This is the
        template that :func:`place` puts into an image.
    """
    circle = shapely.minimum_bounding_circle(raw.exterior)
    center = np.array(circle.centroid.coords[0])
    radius = shapely.minimum_bounding_radius(raw.exterior)
    poly = shapely.affinity.affine_transform(
        raw, [1 / radius, 0, 0, 1 / radius, -center[0] / radius, -center[1] / radius])
    return shapely.geometry.polygon.orient(poly, sign=1.0)


def place(template: Polygon, size: int = 512, rotation: float = 0.0, scale: float = 1.0,
          offset: tuple[float, float] = (0.0, 0.0)) -> Polygon:
    """A template (unit bounding circle at the origin, :func:`normalise`) in pixel coordinates.

    Parameters are those of :func:`shape`: rotation in degrees about the template's origin (the
    centre of its bounding circle) turning +x towards +y, bounding-circle radius
    ``RADIUS * size * scale`` pixels, centre at the image centre plus ``offset`` pixels.
    """
    angle = np.radians(rotation)
    k = RADIUS * size * scale
    c, s = k * np.cos(angle), k * np.sin(angle)
    center = (size - 1) / 2.0
    return shapely.affinity.affine_transform(
        template, [c, -s, s, c, center + offset[0], center + offset[1]])


def shape(name: str, size: int = 512, rotation: float = 0.0, scale: float = 1.0,
          offset: tuple[float, float] = (0.0, 0.0)) -> Polygon:
    """Exact geometry of a built-in object in pixel coordinates.

    Parameters
    ----------
    name : str
        One of :data:`NAMES`.
    size : int
        Side of the (square) image in pixels.
    rotation : float
        Rotation in degrees about the centre of the object's bounding circle, turning +x towards +y.
    scale : float
        Scale factor; at 1 the object's minimum bounding circle has radius ``RADIUS * size`` pixels.
    offset : (float, float)
        Shift of the object's centre from the image centre, pixels (x, y).

    Returns
    -------
    shapely.geometry.Polygon
        Exterior oriented so that the shoelace area on (x, y) is positive (the project's
        orientation); the nut has one interior ring (its hole).
    """
    return place(_template(name), size, rotation, scale, offset)


def gear(teeth: int = 20, outer: float = 100.0, depth: float = 15.0, size: int = 512,
         rotation: float = 0.0) -> Polygon:
    """A spur gear with trapezoidal teeth, centred in a ``size x size`` image (pixels).

    Each tooth pitch (``360 / teeth`` degrees) is, in angle: a root land of 35 %, a rising flank
    of 10 %, a tip land of 45 % and a falling flank of 10 %; the tips lie on the circle of radius
    ``outer``, the roots on radius ``outer - depth``. With the defaults, a finger of the default
    width (0.08 of the object's size) fits on every tip land and root land: 40 feasible regions.

    Parameters
    ----------
    teeth : int
        Number of teeth, at least 3.
    outer : float
        Tip radius, pixels.
    depth : float
        Tooth depth, pixels, in ``(0, outer)``.
    size : int
        Side of the (square) image, pixels; the gear must fit inside it.
    rotation : float
        Rotation in degrees about the centre, turning +x towards +y.

    Returns
    -------
    shapely.geometry.Polygon
        Exterior oriented so that the shoelace area on (x, y) is positive; draw it with
        :func:`render_polygon`.

    Raises
    ------
    QualitativeError
        Fewer than 3 teeth, a depth outside ``(0, outer)`` or a gear that does not fit the image.

    Examples
    --------
    >>> g = gear(20)
    >>> len(g.exterior.coords) - 1, round(g.bounds[2] - g.bounds[0])
    (80, 200)
    """
    if teeth < 3 or not (0 < depth < outer) or not (0 < outer < (size - 1) / 2):
        raise QualitativeError(f"a gear needs at least 3 teeth, 0 < depth < outer < (size - 1) / 2; got "
                               f"{teeth} teeth, depth {depth}, outer {outer}, size {size}")
    pitch = 2 * np.pi / teeth
    # corners of one tooth as (fraction of the pitch, radius): root land, flank, tip land, flank
    corners = [(0.0, outer - depth), (0.35, outer - depth), (0.45, outer), (0.9, outer)]
    angle = np.array([(k + f) * pitch for k in range(teeth) for f, _ in corners]) + np.radians(rotation)
    radius = np.array([r for _ in range(teeth) for _, r in corners])
    center = (size - 1) / 2.0
    ring = np.column_stack([center + radius * np.cos(angle), center + radius * np.sin(angle)])
    return shapely.geometry.polygon.orient(Polygon(ring), sign=1.0)


def render(name: str, size: int = 512, rotation: float = 0.0, scale: float = 1.0,
           offset: tuple[float, float] = (0.0, 0.0), noise: float = 0.0, seed: int = 0) -> np.ndarray:
    """A synthetic camera image of a built-in object: dark object on a light, plain background.

    The object's exact geometry (:func:`shape`) drawn by :func:`render_polygon`.

    Parameters
    ----------
    name, size, rotation, scale, offset
        As in :func:`shape`.
    noise, seed
        As in :func:`render_polygon`.

    Returns
    -------
    numpy.ndarray
        ``(size, size)`` ``uint8`` image.
    """
    return render_polygon(shape(name, size, rotation, scale, offset), size, noise=noise, seed=seed)


def render_polygon(poly: Polygon, size: int = 512, *, noise: float = 0.0, seed: int = 0) -> np.ndarray:
    """A synthetic camera image of any polygon: dark object on a light, plain background.

    Anti-aliased by supersampling (``8 x 8`` samples per pixel, area-averaged), so the grey level
    of an edge pixel is proportional to the fraction of it the object covers. Grey levels are
    :data:`FOREGROUND` on the object and :data:`BACKGROUND` elsewhere.

    Parameters
    ----------
    poly : shapely.geometry.Polygon
        The object in pixel coordinates of the image (x = column, y = row, pixel centres at
        integer coordinates); its interior rings are drawn as holes. It should lie inside the
        image with some background around it.
    size : int
        Side of the (square) image, pixels.
    noise : float
        Standard deviation of additive Gaussian pixel noise, in grey levels (0 to 255); the
        object/background contrast is ``BACKGROUND - FOREGROUND = 200`` grey levels.
    seed : int
        Seed of the noise generator.

    Returns
    -------
    numpy.ndarray
        ``(size, size)`` ``uint8`` image.
    """
    f = _SUPERSAMPLE
    shift = 8  # fixed-point bits of cv2.fillPoly coordinates
    big = np.full((size * f, size * f), 255, np.uint8)

    def fill(ring, value):
        # cv2.fillPoly also fills the subsamples the boundary passes through, which dilates the
        # filled area by half a subsample: erode it by as much so that coverage is unbiased.
        eroded = Polygon(ring).buffer(-0.5 / f, join_style="mitre")
        for part in getattr(eroded, "geoms", [eroded]):
            # Subsample centres sit at ((J + 0.5) / f - 0.5) in pixel coordinates.
            xy = (np.asarray(part.exterior.coords) + 0.5) * f - 0.5
            cv2.fillPoly(big, [np.round(xy * (1 << shift)).astype(np.int32)], value, cv2.LINE_8, shift)

    fill(poly.exterior, 0)
    for hole in poly.interiors:
        fill(hole, 255)
    coverage = 1.0 - cv2.resize(big, (size, size), interpolation=cv2.INTER_AREA) / 255.0
    image = BACKGROUND + (FOREGROUND - BACKGROUND) * coverage
    if noise > 0:
        image = image + np.random.default_rng(seed).normal(0.0, noise, image.shape)
    return np.clip(np.round(image), 0, 255).astype(np.uint8)

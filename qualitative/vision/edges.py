"""Edge evidence at contacts: does the image show the object's edge where a finger is placed?

A segmentation can follow things that are not the object's edge: the soft boundary of a shadow
merged with the object, the blotches of a textured background. A contact placed there is a
grasp of the shadow, not of the object, however well the grasp is certified on the contour. The
image says so: across the object's true edge the grey level steps sharply from the object's to
the background's, across a shadow's boundary or a texture's blotch it changes slowly or little.

Strength of an edge
-------------------
At a contact point ``p`` with inward unit normal ``n``, the grey image, blurred with a Gaussian
of :data:`EDGE_BLUR` (1 pixel, to average pixel noise), is sampled along the normal from
``p - EDGE_REACH n`` to ``p + EDGE_REACH n`` (+-2 pixels: the contour's own error) and
differentiated along it. The **strength** is the largest rate of change towards the object's
grey level, times ``sqrt(2 pi) EDGE_BLUR`` (the width over which the blur spreads a step: a step
edge of height ``h`` blurred by ``sigma`` has a largest slope ``h / (sqrt(2 pi) sigma)``), divided
by the image's **contrast**: the object's median grey level minus the background's
(:func:`edge_contrast`: inside the contour, and in a ring :data:`RING` of the object's size wide
outside it). A sharp edge carrying the whole object/background contrast reads about 1 (0.8 to
0.9 on the built-in renders: anti-aliasing softens it a little); a soft edge reads far less than
its step (a shadow's boundary blurred over 8 pixels, about a tenth of its step); no edge reads
about 0, an edge of the opposite sign below 0.

Weak edges
----------
A contact whose strength is below :data:`WEAK_EDGE` (0.3) is on a **weak edge**: the image does not
show the object's edge there. Calibration (``tests/test_perception.py``, rendered scenes of
``tests/scenes.py``; percentiles over every contour point):

* the object's true edge: 0.72 or more on the built-in renders (every point; their grasps'
  contacts 0.8 or more), 0.48 or more on plain, unevenly lit and blotchy backgrounds (1st
  percentile), 0.35 next to its own shadow or a dark stripe of a textured background, whose
  grey lies between the object's and the background's;
* the boundary of a soft shadow (20 pixels off, blurred by 8) merged into the object: 0.10 or
  less;
* boundaries of a blotchy background texture merged into the object: median 0.1 to 0.2, 95th
  percentile 0.26 to 0.33: most, not all, read weak.

A texture with sharp edges as strong as the object's (bold stripes) reads strong where the
contour follows it: edge evidence is local and cannot tell such a texture from the object.
"""

from __future__ import annotations

import math

import cv2
import numpy as np
from scipy import ndimage

from ..errors import ContourError
from .contour import ImageSource, gaussian_blur, read_image

__all__ = ["EDGE_BLUR", "EDGE_REACH", "RING", "WEAK_EDGE", "SHARPNESS", "edge_contrast", "edge_strength",
           "edge_evidence", "weak_edge"]

EDGE_BLUR = 1.0
"""Standard deviation of the Gaussian blur before differentiating, pixels."""

EDGE_REACH = 2.0
"""Distance either side of a contact searched for the steepest change, pixels."""

RING = 0.05
"""Width of the ring outside the contour holding the background's grey levels, fraction of the
object's size (its bounding box's larger side), at least 4 pixels."""

WEAK_EDGE = 0.3
"""Strength below which a contact is on a weak edge (module notes): the image shows less than
30 % of the object/background contrast as a sharp step there."""

_STEP = 0.25  # sampling step along the normal, pixels


def edge_contrast(image: ImageSource | np.ndarray, contour: np.ndarray) -> float:
    """The object's median grey level minus the background's around it, in the image's units.

    Parameters
    ----------
    image : str, pathlib.Path or numpy.ndarray
        The image (see :func:`qualgrasp.qualitative.vision.contour.read_image`).
    contour : numpy.ndarray
        ``(m, 2)`` closed contour (x, y) of the object, pixels (as extracted from ``image``).

    Returns
    -------
    float
        Median inside the contour minus median in the ring :data:`RING` of the object's size
        outside it: negative for a dark object on a light background.

    Raises
    ------
    ImageError
        Unusable image.
    ContourError
        A contour that is not an ``(m, 2)`` finite array of at least 3 points, or that holds no
        pixel, or no pixel around it inside the image.

    Examples
    --------
    >>> from qualgrasp.qualitative.objects import render
    >>> from qualgrasp.qualitative.vision.contour import extract_contour
    >>> image = render("disc")
    >>> edge_contrast(image, extract_contour(image))
    -200.0
    """
    grey = read_image(image)
    contour = np.asarray(contour, dtype=np.float64)
    if contour.ndim != 2 or contour.shape[1] != 2 or len(contour) < 3 or not np.isfinite(contour).all():
        raise ContourError(f"expected an (m, 2) finite contour of at least 3 points, got shape {contour.shape}")
    inside = np.zeros(grey.shape, np.uint8)
    cv2.fillPoly(inside, [np.round(contour * 16).astype(np.int32)], 1, cv2.LINE_8, 4)
    width = max(4, int(round(RING * np.ptp(contour, axis=0).max())))
    disc = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * width + 1, 2 * width + 1))
    ring = cv2.dilate(inside, disc).astype(bool) & ~inside.astype(bool)
    inside = inside.astype(bool)
    if not inside.any() or not ring.any():
        raise ContourError("the contour holds no pixel of the image, or leaves none around it")
    return float(np.median(grey[inside]) - np.median(grey[ring]))


def edge_strength(image: ImageSource | np.ndarray, points, normals, contrast: float) -> np.ndarray:
    """The edge evidence at contact points (module notes): 1 for a sharp edge of the full contrast.

    Parameters
    ----------
    image : str, pathlib.Path or numpy.ndarray
        The image (see :func:`qualgrasp.qualitative.vision.contour.read_image`).
    points : array_like
        ``(n, 2)`` contact points (x, y), pixels, on the object's contour.
    normals : array_like
        ``(n, 2)`` inward normals at the points (normalised here).
    contrast : float
        The object's grey level minus the background's (:func:`edge_contrast`).

    Returns
    -------
    numpy.ndarray
        ``(n,)`` strengths; below :data:`WEAK_EDGE` a contact is on a weak edge. All 0 when
        ``contrast`` is 0 (nothing in the image supports the contour).

    Raises
    ------
    ImageError
        Unusable image.
    ContourError
        Points and normals not ``(n, 2)`` finite arrays of one length, a zero normal, or a
        contrast that is not finite.

    Examples
    --------
    >>> import numpy as np
    >>> from qualgrasp.qualitative.objects import render, shape
    >>> x = shape("square").bounds[0]  # the square's left side, upright
    >>> points, normals = [[x, 255.5], [x - 50, 255.5]], [[1.0, 0.0], [1.0, 0.0]]
    >>> np.round(edge_strength(render("square"), points, normals, -200.0), 2)  # on the edge; off it
    array([1., 0.])
    """
    points = np.asarray(points, dtype=np.float64)
    normals = np.asarray(normals, dtype=np.float64)
    if (points.ndim != 2 or points.shape[1:] != (2,) or normals.shape != points.shape
            or not (np.isfinite(points).all() and np.isfinite(normals).all())):
        raise ContourError(f"points and normals must be (n, 2) finite arrays of one shape, got "
                           f"{points.shape} and {normals.shape}")
    length = np.linalg.norm(normals, axis=1)
    if (length == 0).any():
        raise ContourError("a contact has a zero normal")
    if not math.isfinite(contrast):
        raise ContourError(f"the contrast must be a finite grey level difference, got {contrast}")
    if contrast == 0 or not len(points):
        return np.zeros(len(points))
    grey = read_image(image)
    normals = normals / length[:, None]
    # Blur only the window the samples need: a few contacts on a large image.
    margin = int(math.ceil(EDGE_REACH + 4 * EDGE_BLUR)) + 2
    rows, cols = grey.shape
    x0, y0 = np.clip(np.floor(points.min(axis=0)).astype(int) - margin, 0, (cols - 1, rows - 1))
    x1, y1 = np.clip(np.ceil(points.max(axis=0)).astype(int) + margin + 1, (x0 + 1, y0 + 1), (cols, rows))
    smooth = gaussian_blur(grey[y0:y1, x0:x1], EDGE_BLUR)
    offsets = np.arange(-EDGE_REACH, EDGE_REACH + _STEP / 2, _STEP)
    xy = points[:, None, :] - (x0, y0) + offsets[None, :, None] * normals[:, None, :]
    profile = ndimage.map_coordinates(smooth, [xy[..., 1].ravel(), xy[..., 0].ravel()], order=1,
                                      mode="nearest").reshape(xy.shape[:2])
    # slope along the inward normal over the contrast: positive where the grey moves towards the object's
    rate = np.gradient(profile, _STEP, axis=1) / contrast
    return rate.max(axis=1) * math.sqrt(2 * math.pi) * EDGE_BLUR


SHARPNESS = 90
"""Percentile of the edge strengths along the object's whole contour that measures how sharp the
image's edges are (:func:`edge_evidence`)."""


def edge_evidence(image: ImageSource | np.ndarray, contour, contour_normals, points, normals) -> np.ndarray:
    """Edge strength at contact points relative to the sharpness of the image's own edges.

    The strength at each contact (:func:`edge_strength`) divided by the :data:`SHARPNESS`-th
    percentile of the strengths along the object's whole ``contour``: a contact on the object's
    edge reads about 1 however blurred or noisy the whole image is (a blurred image is not a
    shadow), a contact on a shadow's boundary or a texture's blotch far less than the object's
    own edges elsewhere on the contour. Below :data:`WEAK_EDGE` a contact is on a weak edge.

    Parameters
    ----------
    image : str, pathlib.Path or numpy.ndarray
        The image (see :func:`qualgrasp.qualitative.vision.contour.read_image`).
    contour, contour_normals : array_like
        ``(m, 2)`` the object's contour as segmented (pixels) and its inward normals.
    points, normals : array_like
        ``(n, 2)`` contact points and inward normals.

    Returns
    -------
    numpy.ndarray
        ``(n,)`` relative strengths; all 0 when no edge supports the contour anywhere.

    Examples
    --------
    >>> import numpy as np
    >>> from qualgrasp.qualitative.objects import render
    >>> from qualgrasp.qualitative.vision.outline import outline_image
    >>> o = outline_image(render("square"))
    >>> bool(edge_evidence(render("square"), o.contour, o.normals(), o.contour[:5], o.normals()[:5]).min() > WEAK_EDGE)
    True
    """
    grey = read_image(image)
    contrast = edge_contrast(grey, np.asarray(contour, dtype=np.float64))
    sharpness = np.percentile(edge_strength(grey, contour, contour_normals, contrast), SHARPNESS)
    if not sharpness > 0:
        return np.zeros(len(np.asarray(points)))
    return edge_strength(grey, points, normals, contrast) / sharpness


def weak_edge(strengths) -> bool:
    """Whether some contact of a grasp is on a weak edge: a strength of :func:`edge_evidence`
    below :data:`WEAK_EDGE` (an empty or missing list: no)."""
    return any(v < WEAK_EDGE for v in (strengths or ()))

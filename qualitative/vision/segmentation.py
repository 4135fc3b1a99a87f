"""Segmentation methods other than a global threshold, for backgrounds that defeat one.

:func:`qualgrasp.qualitative.vision.contour.segment` chooses among these by name (its ``method``); the
default there stays Otsu's global threshold. The functions here work on a grey image already
slightly blurred (``smooth``, float64, any units) and return the object's pixels as a boolean
mask; the choice of one object, the contour and its sub-pixel refinement are
:mod:`qualgrasp.qualitative.vision.contour`'s.

``"multiotsu"`` (a soft shadow)
    Otsu's method with three classes (:func:`skimage.filters.threshold_multiotsu`): the object is
    the class at the other end of the grey scale from the background (the class holding the
    median of the border pixels), so a shadow, lighter than the object and darker than the
    background, falls in the middle class with the background. Measured on an object with a soft
    shadow 20 pixels off (``tests/scenes.py``): the outline within 1 pixel of the true shape, where
    Otsu's threshold takes the shadow in (25 pixels off). An object with two grey levels of its
    own loses one of them.
``"adaptive"`` (uneven lighting)
    Each pixel is compared with the mean of the :data:`ADAPTIVE_BLOCK` x :data:`ADAPTIVE_BLOCK`
    block of the image's smaller side around it (a box mean, as ``cv2.adaptiveThreshold``'s
    ``ADAPTIVE_THRESH_MEAN_C``, borders replicated), so that light falling off across the image
    moves the comparison with it; the offset from the local mean (``cv2.adaptiveThreshold``'s
    ``C``) is not a constant but Otsu's threshold of the differences, so it adapts to the
    contrast. The object is the side of that threshold away from the border's median difference
    (the background), and holes in the mask are filled: an object wider than half the block is
    darker than its own local mean only near its edge. Measured on a scene lit from 0.45 to 1.15
    across the image (``tests/scenes.py``): the outline within 1.3 pixels of the true shape, where
    Otsu's threshold takes half the background as object.
``"grabcut"`` (textured or cluttered background)
    OpenCV's GrabCut (:func:`cv2.grabCut`, :data:`GRABCUT_ITERATIONS` iterations): grey-level
    mixtures of the object and of the background, cut along strong edges, started from a
    rectangle that holds the object (pixels outside it are background). The default rectangle
    (:func:`grabcut_rect`) is the bounding box of the default (Otsu) segmentation's largest object
    inside the frame, grown by :data:`GRABCUT_MARGIN` of its size on every side (leaving at least
    the image's outermost pixels out); when every object
    of that segmentation touches the border, the image less :data:`GRABCUT_MARGIN` / 2 of its
    size on every side. GrabCut runs on the rectangle grown by the same margin again (its
    background samples), so its time grows with the object, not with the image (about 0.3 s for
    a 300 x 300 pixel window). Its mixtures start from k-means, which draws from OpenCV's random
    generator: the generator is seeded (:data:`GRABCUT_SEED`) before each call so that a
    segmentation is reproducible.

Measured outline errors on the rendered scenes of ``tests/scenes.py`` (Hausdorff distance to the
true polygon, pixels) are in the tests (``tests/test_perception.py``).
"""

from __future__ import annotations

import cv2
import numpy as np
from scipy import ndimage
from skimage.filters import threshold_multiotsu, threshold_otsu

from ..errors import SegmentationError

__all__ = ["METHODS", "multiotsu_mask", "ADAPTIVE_BLOCK", "GRABCUT_MARGIN", "GRABCUT_ITERATIONS", "GRABCUT_SEED",
           "border_pixels", "adaptive_mask", "grabcut_rect", "grabcut_mask"]

METHODS = ("otsu", "multiotsu", "adaptive", "grabcut")
"""Segmentation methods by name: Otsu's global threshold (the default), Otsu's method with three
classes, adaptive thresholding, GrabCut."""

ADAPTIVE_BLOCK = 0.5
"""Side of the adaptive threshold's block, fraction of the image's smaller side (made odd, at
least 3 pixels): wider than the objects the toolkit describes, so that an object's local mean
holds background."""

GRABCUT_MARGIN = 0.1
"""Margin added on every side of the object's bounding box to make GrabCut's rectangle, fraction
of the box's larger side (at least 4 pixels)."""

GRABCUT_ITERATIONS = 5
"""Iterations of :func:`cv2.grabCut`."""

GRABCUT_SEED = 0
"""Seed of OpenCV's random generator before each GrabCut (its k-means start)."""


def border_pixels(image: np.ndarray) -> np.ndarray:
    """The pixels on the edge of an image, each once (the background's sample)."""
    return np.concatenate([image[0], image[-1], image[1:-1, 0], image[1:-1, -1]])


def multiotsu_mask(smooth: np.ndarray) -> tuple[np.ndarray, bool]:
    """The class of three (Otsu's multi-level thresholds) at the other end from the background.

    Parameters
    ----------
    smooth : numpy.ndarray
        ``(H, W)`` grey image, float, slightly blurred.

    Returns
    -------
    mask : numpy.ndarray
        Boolean ``(H, W)``, True on object pixels.
    dark : bool
        True when the object is the darkest class.

    Raises
    ------
    SegmentationError
        Fewer than three grey levels to split.

    Examples
    --------
    >>> import numpy as np
    >>> image = np.full((60, 60), 210.0)
    >>> image[20:40, 26:46] = 150.0  # a shadow
    >>> image[16:36, 20:40] = 80.0  # the object
    >>> mask, dark = multiotsu_mask(image)
    >>> dark, int(mask.sum())
    (True, 400)
    """
    if len(np.unique(smooth)) < 3:
        raise SegmentationError("three grey classes need at least three grey levels")
    low, high = threshold_multiotsu(smooth, classes=3)
    background = np.median(border_pixels(smooth))
    dark = bool(background > 0.5 * (low + high))
    return (smooth < low) if dark else (smooth > high), dark


def adaptive_mask(smooth: np.ndarray, block: int | None = None) -> tuple[np.ndarray, bool]:
    """Adaptive thresholding against the local mean, offset chosen by Otsu's method (module notes).

    Parameters
    ----------
    smooth : numpy.ndarray
        ``(H, W)`` grey image, float, slightly blurred.
    block : int, optional
        Side of the block, pixels, odd, at least 3; default :data:`ADAPTIVE_BLOCK` of the
        smaller side.

    Returns
    -------
    mask : numpy.ndarray
        Boolean ``(H, W)``, True on object pixels (holes filled).
    dark : bool
        True when the object is darker than its surroundings.

    Raises
    ------
    SegmentationError
        A bad block; an image whose local differences are constant.

    Examples
    --------
    >>> import numpy as np
    >>> light = np.linspace(60, 240, 100)[None, :] * np.ones((100, 1))  # lit from the right
    >>> image = light.copy()
    >>> image[40:60, 30:50] *= 0.6  # a dark square, as light as the background on the left
    >>> mask, dark = adaptive_mask(image)
    >>> dark, int(mask.sum()), bool(mask[40:60, 30:50].all())
    (True, 400, True)
    """
    rows, cols = smooth.shape
    if block is None:
        block = max(3, int(ADAPTIVE_BLOCK * min(rows, cols)) // 2 * 2 + 1)
    if int(block) != block or block < 3 or block % 2 == 0:
        raise SegmentationError(f"the adaptive block must be an odd number of pixels >= 3, got {block!r}")
    local = cv2.blur(smooth, (int(block), int(block)), borderType=cv2.BORDER_REPLICATE)
    difference = smooth - local
    if difference.max() == difference.min():
        raise SegmentationError("no object found: the image does not differ from its local mean anywhere")
    level = threshold_otsu(difference)
    dark = bool(np.median(border_pixels(difference)) > level)
    mask = difference < level if dark else difference > level
    return ndimage.binary_fill_holes(mask), dark


def grabcut_rect(mask: np.ndarray | None, shape: tuple[int, int]) -> tuple[int, int, int, int]:
    """GrabCut's default rectangle (module notes): around the object of ``mask``, or inside the frame.

    Parameters
    ----------
    mask : numpy.ndarray or None
        Boolean mask of the default segmentation's object (None when every object touches the
        border).
    shape : (int, int)
        The image's ``(rows, cols)``.

    Returns
    -------
    (int, int, int, int)
        ``(x, y, width, height)``, pixels (x = column, y = row), inside the image and leaving
        at least its outermost pixels out.

    Examples
    --------
    >>> import numpy as np
    >>> mask = np.zeros((100, 200), bool)
    >>> mask[40:60, 50:90] = True
    >>> grabcut_rect(mask, mask.shape)
    (46, 36, 48, 28)
    >>> grabcut_rect(None, (100, 200))
    (10, 10, 180, 80)
    """
    rows, cols = shape
    if mask is None:
        pad = int(round(GRABCUT_MARGIN / 2 * max(rows, cols)))
        return pad, pad, cols - 2 * pad, rows - 2 * pad
    ys, xs = np.nonzero(mask)
    x0, x1, y0, y1 = xs.min(), xs.max() + 1, ys.min(), ys.max() + 1
    pad = max(4, int(round(GRABCUT_MARGIN * max(x1 - x0, y1 - y0))))
    # a frame of at least a pixel stays outside: GrabCut's first background (the object, inside
    # the frame, does not touch the border)
    x0, y0 = max(x0 - pad, 1), max(y0 - pad, 1)
    x1, y1 = min(x1 + pad, cols - 1), min(y1 + pad, rows - 1)
    return int(x0), int(y0), int(x1 - x0), int(y1 - y0)


def _check_rect(rect, shape: tuple[int, int]) -> tuple[int, int, int, int]:
    rows, cols = shape
    try:
        values = [float(v) for v in rect]
    except (TypeError, ValueError):
        values = []
    if len(values) != 4 or not all(np.isfinite(v) and v == int(v) for v in values):
        raise SegmentationError(f"the GrabCut rectangle must be four integers x, y, width, height; got {rect!r}")
    x, y, w, h = (int(v) for v in values)
    if w < 2 or h < 2 or x < 0 or y < 0 or x + w > cols or y + h > rows:
        raise SegmentationError(f"the GrabCut rectangle (x {x}, y {y}, width {w}, height {h}) must hold at least "
                                f"2 x 2 pixels inside the {cols} x {rows} image")
    if w == cols and h == rows:
        raise SegmentationError("the GrabCut rectangle covers the whole image: GrabCut needs background "
                                "outside it; give a smaller rectangle")
    return x, y, w, h


def grabcut_mask(smooth: np.ndarray, rect) -> np.ndarray:
    """GrabCut from a rectangle (module notes).

    Parameters
    ----------
    smooth : numpy.ndarray
        ``(H, W)`` grey image, float, slightly blurred.
    rect : (int, int, int, int)
        ``(x, y, width, height)``, pixels: the object lies inside, the pixels outside are
        background (see :func:`grabcut_rect` for the default).

    Returns
    -------
    numpy.ndarray
        Boolean ``(H, W)``, True on object pixels (definite or probable foreground).

    Raises
    ------
    SegmentationError
        A rectangle not inside the image, smaller than 2 x 2 pixels or covering all of it.

    Examples
    --------
    >>> import numpy as np
    >>> image = np.full((80, 80), 200.0)
    >>> image[30:50, 25:55] = 60.0
    >>> int(grabcut_mask(image, (15, 20, 50, 40)).sum())
    600
    """
    rows, cols = smooth.shape
    x, y, w, h = _check_rect(rect, (rows, cols))
    pad = max(4, int(round(GRABCUT_MARGIN * max(w, h))))
    x0, y0 = max(x - pad, 0), max(y - pad, 0)
    x1, y1 = min(x + w + pad, cols), min(y + h + pad, rows)
    window = smooth[y0:y1, x0:x1]
    low, high = float(window.min()), float(window.max())
    grey = np.round((window - low) * (255.0 / max(high - low, 1e-12))).astype(np.uint8)
    labels = np.zeros(grey.shape, np.uint8)
    cv2.setRNGSeed(GRABCUT_SEED)
    cv2.grabCut(cv2.merge([grey, grey, grey]), labels, (x - x0, y - y0, w, h), np.zeros((1, 65)),
                np.zeros((1, 65)), GRABCUT_ITERATIONS, cv2.GC_INIT_WITH_RECT)
    cut = (labels == cv2.GC_FGD) | (labels == cv2.GC_PR_FGD)
    mask = np.zeros((rows, cols), bool)
    if cut.any() and not cut.all():
        # GrabCut's cut runs up to a few pixels outside the edge (its object mixture keeps some of
        # the background's grey): keep the cut's pixels on the object's side of the level half-way
        # between the two sides' medians, where an edge lies (as the sub-pixel refinement does).
        inner, outer = np.median(window[cut]), np.median(window[~cut])
        level = 0.5 * (inner + outer)
        mask[y0:y1, x0:x1] = cut & ((window < level) if inner < outer else (window > level))
    return mask

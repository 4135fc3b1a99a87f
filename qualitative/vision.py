"""From an image to the object's outer contour.

Pipeline: read the image (file or array) as a grey image (a file's size is checked from its
header before it is decoded: :mod:`qualgrasp.qualitative.headers`), blur it slightly (1 pixel) and threshold
it (Otsu by default), decide which side of the threshold is the object from the pixels on the image
border (the background), keep exactly one connected object (8-connected; specks below 1 % of the
largest component are noise), take its outer contour with :func:`cv2.findContours`
(``RETR_EXTERNAL``, ``CHAIN_APPROX_NONE``) and refine every contour point to sub-pixel accuracy
along the contour's normal (:func:`refine_contour`; on the built-in anti-aliased images the median
error is about 0.03 pixel).

Conventions
-----------
* Coordinates are pixels of the input image: x = column, y = row (y points down), pixel centres at
  integer coordinates.
* Contours are returned as ``(n, 2)`` float arrays of (x, y) points, the closing point not
  repeated, ordered so that the shoelace area computed on the (x, y) values is **positive**. Along
  such a contour the object lies on the side of the tangent ``t`` turned by +90 degrees: the inward
  unit normal is ``(-t_y, t_x)``.
* Holes are ignored: only the outer boundary of the object is returned (fingers grasp from
  outside). An object lying inside another one's hole counts as a separate object.
* Thresholds are grey levels in the input's own units (0 to 255 for 8-bit images, 0 to 1 for
  boolean masks, the array's values for float images; colour is first converted to luminance).
  A given threshold is also the level of the sub-pixel edge; by default the edge is placed
  half-way between the object's and the background's grey levels.
* Errors: :class:`~qualgrasp.qualitative.errors.ImageError` (missing, unreadable, empty, constant or too large image),
  :class:`~qualgrasp.qualitative.errors.SegmentationError` (no object, several objects, object cut by the
  border), :class:`~qualgrasp.qualitative.errors.ContourError` (object smaller than :data:`MIN_AREA`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Union

import cv2
import numpy as np
from scipy import ndimage
from skimage.filters import threshold_otsu

from .errors import ContourError, ImageError, SegmentationError
from .headers import header_size

__all__ = [
    "MIN_AREA",
    "MAX_PIXELS",
    "MAX_CONTOUR",
    "Segmentation",
    "read_image",
    "segment",
    "object_mask",
    "extract_contour",
    "refine_contour",
    "signed_area",
]

ImageSource = Union[str, Path, np.ndarray]

MIN_AREA = 400
"""Smallest object, in pixels, that can be described (about 20 x 20 pixels)."""

MAX_PIXELS = 40_000_000
"""Largest image read, in pixels (about 6,300 x 6,300): a larger one is refused with a message
saying how to downsample it (memory and time stay bounded)."""

MAX_CONTOUR = 1_000_000
"""Longest object contour described, in contour pixels: a longer one (a huge or very wiggly
object) is refused with a message saying by how much to downsample the image."""


def _check_size(size, what: str) -> None:
    if size is None:
        return
    width, height = int(size[0]), int(size[1])
    if width * height > MAX_PIXELS:
        factor = int(np.ceil(np.sqrt(width * height / MAX_PIXELS)))
        raise ImageError(f"{what} is {width} x {height} pixels, more than the limit of {MAX_PIXELS:,} "
                         f"(about 6,300 x 6,300): downsample it by {factor} or more, e.g. "
                         f"`convert in.png -resize {100 // factor}% out.png` (ImageMagick)")

_SPECK = 0.01
"""Connected components smaller than this fraction of the largest one are noise, not objects."""

_LUMA = np.array([0.299, 0.587, 0.114])  # ITU-R BT.601, as cv2.cvtColor


@dataclass(frozen=True, eq=False)
class Segmentation:
    """A thresholded grey image.

    Attributes
    ----------
    image : numpy.ndarray
        Grey image, float64, in the input's units.
    mask : numpy.ndarray
        Boolean image, True on object pixels (every component).
    level : float
        Grey level used as threshold.
    dark : bool
        True when the object is darker than the background (pixels below ``level``).
    """

    image: np.ndarray
    mask: np.ndarray
    level: float
    dark: bool


def _to_grey(array: np.ndarray, bgr: bool) -> np.ndarray:
    if array.ndim == 3 and array.shape[2] == 1:
        array = array[:, :, 0]
    if array.ndim == 3 and array.shape[2] in (3, 4):
        colour = array[:, :, :3].astype(np.float64)
        weights = _LUMA[::-1] if bgr else _LUMA
        return colour @ weights
    if array.ndim != 2:
        raise ImageError(f"expected a grey (H, W) or colour (H, W, 3 or 4) image, got shape {array.shape}")
    return array.astype(np.float64)


def read_image(src: ImageSource) -> np.ndarray:
    """Read an image file or accept an array, and return it as a grey float64 image.

    Parameters
    ----------
    src : str, pathlib.Path or numpy.ndarray
        A file OpenCV can read (PNG, JPEG, TIFF, ...; colour files are BGR on disk order), or an
        array: ``(H, W)`` grey, ``(H, W, 3)`` RGB or ``(H, W, 4)`` RGBA (alpha ignored), of any
        numeric or boolean dtype.

    Returns
    -------
    numpy.ndarray
        ``(H, W)`` float64 grey levels in the input's units (colour converted to BT.601 luminance).

    Raises
    ------
    ImageError
        Missing or unreadable file, empty array, wrong shape, non-finite values, constant image.
    """
    if isinstance(src, (str, Path)):
        path = Path(src)
        if not path.is_file():
            raise ImageError(f"no such image file: {path}" if not path.exists() else
                             f"{path} is not a regular file (a folder or a device)")
        _check_size(header_size(path, MAX_PIXELS), str(path))
        try:
            raw = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
        except cv2.error as err:
            raise ImageError(f"cannot read {path} as an image ({str(err).strip().splitlines()[-1]})") from None
        if raw is None:
            raise ImageError(f"cannot read {path} as an image (OpenCV cannot decode it)")
        _check_size(raw.shape[1::-1], str(path))
        grey = _to_grey(raw, bgr=True)
    else:
        array = np.asarray(src)
        if array.dtype == object or not (np.issubdtype(array.dtype, np.number) or array.dtype == bool):
            raise ImageError(f"expected a numeric image array, got dtype {array.dtype}")
        if array.ndim >= 2:
            _check_size(array.shape[1::-1] if array.ndim == 2 else array.shape[1::-1][-2:], "the image array")
        grey = _to_grey(array, bgr=False)
    if grey.size == 0:
        raise ImageError(f"empty image (shape {grey.shape})")
    if not np.all(np.isfinite(grey)):
        raise ImageError("the image holds NaN or infinite values")
    if grey.max() == grey.min():
        raise ImageError(f"constant image: every pixel has grey level {grey.flat[0]:g}; nothing to segment")
    return grey


def _gaussian(image: np.ndarray, sigma: float) -> np.ndarray:
    """Gaussian blur of a float image (OpenCV's is several times faster than scipy's)."""
    if sigma <= 0:
        return image
    return cv2.GaussianBlur(image, (0, 0), sigma, borderType=cv2.BORDER_REFLECT)


def _border(image: np.ndarray) -> np.ndarray:
    return np.concatenate([image[0], image[-1], image[1:-1, 0], image[1:-1, -1]])


def segment(src: ImageSource, threshold: float | None = None, blur: float = 1.0) -> Segmentation:
    """Threshold an image into object and background.

    Parameters
    ----------
    src : str, pathlib.Path or numpy.ndarray
        Image (see :func:`read_image`).
    threshold : float, optional
        Grey level separating object and background, in the input's units. Default: Otsu's.
    blur : float
        Standard deviation, pixels, of a Gaussian applied before thresholding (0 for none). It
        averages pixel noise, which otherwise breaks Otsu's threshold on small objects (the noisy
        background becomes bimodal) and scatters specks along the edge.

    Returns
    -------
    Segmentation
        The object is the side of the threshold **not** holding the median of the image's border
        pixels (the background): dark-on-light and light-on-dark images both work.

    Raises
    ------
    ImageError, SegmentationError
        Unusable image; no pixel on the object's side of the threshold.
    """
    image = read_image(src)
    smooth = _gaussian(image, blur)
    level = float(threshold_otsu(smooth)) if threshold is None else float(threshold)
    dark = bool(np.median(_border(smooth)) > level)
    mask = smooth < level if dark else smooth > level
    if not mask.any():
        side = "below" if dark else "above"
        raise SegmentationError(f"no object found: no pixel is {side} the threshold {level:g}")
    return Segmentation(image, mask, level, dark)


def object_mask(seg: Segmentation, largest: bool = False) -> np.ndarray:
    """The one object of a segmentation, as a boolean mask.

    Components (8-connected) smaller than 1 % of the largest one are treated as noise.

    Parameters
    ----------
    seg : Segmentation
        Thresholded image.
    largest : bool
        With several objects, keep the largest one that the image border does not cut, instead of
        raising (in a photograph of many objects, background regions touching the border are
        often segmented as objects too).

    Raises
    ------
    SegmentationError
        Several objects (says how many) and not ``largest``; the object touches the image border
        (with ``largest``: every object does).
    ContourError
        The object covers fewer than :data:`MIN_AREA` pixels.
    """
    _, labels, stats, _ = cv2.connectedComponentsWithStats(seg.mask.astype(np.uint8), connectivity=8)
    areas = stats[1:, cv2.CC_STAT_AREA]
    objects = np.flatnonzero(areas >= _SPECK * areas.max()) + 1
    rows, cols = seg.mask.shape
    x, y, w, h = (stats[objects, i] for i in range(4))
    whole = (x > 0) & (y > 0) & (x + w < cols) & (y + h < rows)
    if len(objects) > 1 and not largest:
        raise SegmentationError(
            f"found {len(objects)} objects (largest {areas.max()} pixels); "
            "pass largest=True (--largest) to keep the largest one")
    if not whole.any():
        k = int(np.argmax(stats[objects, cv2.CC_STAT_AREA]))
        what = "every object touches" if len(objects) > 1 else "the object touches"
        raise SegmentationError(
            f"{what} the border of the {cols} x {rows} image (bounding box x {x[k]}..{x[k] + w[k] - 1}, "
            f"y {y[k]}..{y[k] + h[k] - 1}): it is cut off; frame the whole object with some background "
            "around it")
    candidates = objects[whole]
    label = int(candidates[np.argmax(stats[candidates, cv2.CC_STAT_AREA])])
    area = int(stats[label, cv2.CC_STAT_AREA])
    if area < MIN_AREA:
        raise ContourError(f"the object is too small to describe: {area} pixels, the minimum is {MIN_AREA} "
                           "(about 20 x 20 pixels)")
    return labels == label


def signed_area(contour: np.ndarray) -> float:
    """Shoelace area of a closed contour on its (x, y) values (positive in the project's orientation)."""
    x, y = contour[:, 0], contour[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def _inward_normals(contour: np.ndarray, sigma: float) -> np.ndarray:
    smooth = ndimage.gaussian_filter1d(contour, sigma, axis=0, mode="wrap")
    tangent = np.roll(smooth, -1, axis=0) - np.roll(smooth, 1, axis=0)
    tangent /= np.maximum(np.linalg.norm(tangent, axis=1, keepdims=True), 1e-12)
    return np.column_stack([-tangent[:, 1], tangent[:, 0]])


def refine_contour(contour: np.ndarray, seg: Segmentation, level: float | None = None, reach: float = 1.5,
                   step: float = 0.05, blur: float = 0.7) -> np.ndarray:
    """Move each contour point to the sub-pixel edge, where the grey level crosses ``level``.

    The pixel contour runs through the centres of the object's boundary pixels; the true edge lies
    about half a pixel further out. The edge is taken where the grey image, blurred with a Gaussian
    of ``blur`` pixels (which makes the edge profile smooth and symmetric, so that interpolation is
    unbiased, and averages noise), crosses ``level``: by default half-way between the object's and
    the background's median grey levels near the contour, where an area-sampled edge lies whatever
    the contrast. Each point moves along its outward normal (estimated from
    the contour smoothed over about 2 points) to the crossing, within ``[-reach, reach]`` pixels,
    nearest to the expected half pixel; points without a crossing move by half a pixel.

    Parameters
    ----------
    contour : numpy.ndarray
        ``(n, 2)`` positively oriented contour of pixel centres (x, y).
    seg : Segmentation
        The segmentation the contour comes from (grey image, mask, polarity).
    level : float, optional
        Grey level of the edge, in the image's units; default half-way (see above).
    reach, step, blur : float
        Search distance, step along the normal and blur scale, pixels.

    Returns
    -------
    numpy.ndarray
        ``(n, 2)`` refined contour, pixels.
    """
    # Work in a window around the contour: the grey levels of the object and of the background
    # next to it, and the blur, are only needed there.
    margin = int(np.ceil(reach + 4 * blur)) + 2
    rows, cols = seg.image.shape
    x0, y0 = np.maximum(np.floor(contour.min(axis=0)).astype(int) - margin, 0)
    x1, y1 = np.minimum(np.ceil(contour.max(axis=0)).astype(int) + margin + 1, (cols, rows))
    image, mask = seg.image[y0:y1, x0:x1], seg.mask[y0:y1, x0:x1]
    if level is None:
        level = 0.5 * (np.median(image[mask]) + np.median(image[~mask]))
    level = _gaussian((level - image) if seg.dark else (image - level), blur)  # > 0 on the object's side
    contour = contour - (x0, y0)
    outward = -_inward_normals(contour, 2.0)
    offsets = np.arange(-reach, reach + step / 2, step)
    distance = np.empty(len(contour))
    block = 1 << 15  # points per block: memory stays bounded whatever the contour's length
    for k in range(0, len(contour), block):
        c, o = contour[k:k + block], outward[k:k + block]
        xy = c[:, None, :] + offsets[None, :, None] * o[:, None, :]
        profile = ndimage.map_coordinates(level, [xy[..., 1].ravel(), xy[..., 0].ravel()], order=1,
                                          mode="nearest").reshape(xy.shape[:2])
        g0, g1 = profile[:, :-1], profile[:, 1:]
        crossing = (g0 > 0) & (g1 <= 0)  # leaving the object, going outward
        where = offsets[:-1] + step * g0 / np.where(crossing, g0 - g1, 1.0)
        score = np.where(crossing, np.abs(where - 0.5), np.inf)
        best = np.argmin(score, axis=1)
        index = np.arange(len(c))
        distance[k:k + block] = np.where(np.isfinite(score[index, best]), where[index, best], 0.5)
    return contour + distance[:, None] * outward + (x0, y0)


def extract_contour(src: ImageSource, threshold: float | None = None, largest: bool = False,
                    subpixel: bool = True) -> np.ndarray:
    """The outer contour of the one object in an image.

    Parameters
    ----------
    src : str, pathlib.Path or numpy.ndarray
        Image (see :func:`read_image`).
    threshold : float, optional
        Grey level in the input's units; default Otsu's.
    largest : bool
        With several objects, describe the largest.
    subpixel : bool
        Refine the pixel contour to sub-pixel accuracy (:func:`refine_contour`: at the given
        ``threshold``, or half-way between the object's and background's grey levels when Otsu's
        threshold is used); otherwise the contour runs through the centres of the object's
        boundary pixels.

    Returns
    -------
    numpy.ndarray
        ``(n, 2)`` float64 (x, y) contour, pixels, positive shoelace area, not closed.

    Raises
    ------
    ImageError, SegmentationError, ContourError
        See :func:`read_image`, :func:`segment` and :func:`object_mask`.
    """
    seg = segment(src, threshold)
    mask = object_mask(seg, largest)
    found, _ = cv2.findContours(mask.astype(np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    contour = max(found, key=len)[:, 0, :].astype(np.float64)
    if len(contour) < 8:
        raise ContourError(f"degenerate contour of {len(contour)} points")
    if len(contour) > MAX_CONTOUR:
        factor = int(np.ceil(len(contour) / MAX_CONTOUR))
        raise ContourError(f"the object's contour has {len(contour):,} pixels, more than the limit of "
                           f"{MAX_CONTOUR:,}: downsample the image by {factor} or more")
    if signed_area(contour) < 0:
        contour = contour[::-1].copy()
    if subpixel:
        contour = refine_contour(contour, seg, threshold)
    return contour

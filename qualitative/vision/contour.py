"""From an image to the object's outer contour.

Pipeline: read the image (file or array) as a grey image (a file's size is checked from its
header before it is decoded: :mod:`qualgrasp.qualitative.vision.headers`), blur it slightly (1 pixel)
and segment it, keep exactly one connected object (8-connected; specks below 1 % of the largest
component are noise), take its outer contour with :func:`cv2.findContours` (``RETR_EXTERNAL``,
``CHAIN_APPROX_NONE``) and refine every contour point to sub-pixel accuracy along the contour's
normal (:func:`refine_contour`; on the built-in anti-aliased images the median error is about
0.03 pixel).

Segmentation (:func:`segment`): by default Otsu's global threshold, the object's side decided
from the pixels on the image border (the background). Backgrounds that defeat one global
threshold have their methods (:data:`METHODS`, :mod:`qualgrasp.qualitative.vision.segmentation`):
``"multiotsu"`` (three grey classes: an object with its soft shadow), ``"adaptive"`` (against
the local mean: uneven lighting), ``"grabcut"`` (from a rectangle: a textured background); or the
user gives the object's mask (:func:`read_mask`). When no object lies inside the frame, the
error names the objects touching the border and the options that help.

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
* Errors: :class:`~qualgrasp.qualitative.errors.ImageError` (missing, unreadable, empty, constant or
  too large image), :class:`~qualgrasp.qualitative.errors.SegmentationError` (no object, several
  objects, object cut by the border, a bad mask or method), :class:`~qualgrasp.qualitative.errors.ContourError`
  (object smaller than :data:`MIN_AREA`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Union

import cv2
import numpy as np
from scipy import ndimage
from skimage.filters import threshold_otsu

from ..errors import ContourError, ImageError, SegmentationError
from .headers import header_size
from .segmentation import METHODS, adaptive_mask, border_pixels, grabcut_mask, grabcut_rect, multiotsu_mask

__all__ = [
    "MIN_AREA",
    "MAX_PIXELS",
    "MAX_CONTOUR",
    "METHODS",
    "Segmentation",
    "read_image",
    "read_mask",
    "gaussian_blur",
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

_LISTED = 3  # objects a border message lists
_HELPS = {"multiotsu": "a shadow", "adaptive": "uneven lighting", "grabcut": "a textured background"}

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
        Grey level used as threshold (Otsu's or the one given); NaN for the methods without one
        global level (``multiotsu``, ``adaptive``, ``grabcut``, a user's mask).
    dark : bool
        True when the object is darker than the background (pixels below ``level``; without a
        level, its median grey level below the background's).
    method : str
        How the mask was made: one of :data:`METHODS`, or ``"mask"`` for a user's mask.
    """

    image: np.ndarray
    mask: np.ndarray
    level: float
    dark: bool
    method: str = "otsu"


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


def _decode(path: Path) -> np.ndarray:
    """The pixels of an image file as OpenCV decodes them, after the size in its header is checked."""
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
    return raw


def _array(src, what: str) -> np.ndarray:
    array = np.asarray(src)
    if array.dtype == object or not (np.issubdtype(array.dtype, np.number) or array.dtype == bool):
        raise ImageError(f"expected a numeric {what} array, got dtype {array.dtype}")
    if array.ndim >= 2:
        _check_size(array.shape[1::-1] if array.ndim == 2 else array.shape[1::-1][-2:], f"the {what} array")
    return array


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
        grey = _to_grey(_decode(Path(src)), bgr=True)
    else:
        grey = _to_grey(_array(src, "image"), bgr=False)
    if grey.size == 0:
        raise ImageError(f"empty image (shape {grey.shape})")
    if not np.all(np.isfinite(grey)):
        raise ImageError("the image holds NaN or infinite values")
    if grey.max() == grey.min():
        raise ImageError(f"constant image: every pixel has grey level {grey.flat[0]:g}; nothing to segment")
    return grey


def gaussian_blur(image: np.ndarray, sigma: float) -> np.ndarray:
    """Gaussian blur of a float image, ``sigma`` pixels, borders reflected (0: the image itself;
    OpenCV's is several times faster than scipy's)."""
    if sigma <= 0:
        return image
    return cv2.GaussianBlur(image, (0, 0), sigma, borderType=cv2.BORDER_REFLECT)


def read_mask(src: ImageSource, shape: tuple[int, int]) -> np.ndarray:
    """A user's mask of the object: any image whose non-zero pixels are the object.

    Parameters
    ----------
    src : str, pathlib.Path or numpy.ndarray
        An image file OpenCV can read (a pixel is the object when any of its channels is
        non-zero) or an array (grey, colour or boolean; likewise).
    shape : (int, int)
        ``(rows, cols)`` of the image the mask belongs to.

    Returns
    -------
    numpy.ndarray
        Boolean ``(rows, cols)``, True on the object.

    Raises
    ------
    ImageError
        Unreadable file or array (see :func:`read_image`).
    SegmentationError
        A mask of another size than the image, empty (no object pixel) or full (no background),
        or holding NaN.

    Examples
    --------
    >>> import numpy as np
    >>> mask = np.zeros((4, 6), np.uint8)
    >>> mask[1:3, 2:4] = 255
    >>> int(read_mask(mask, (4, 6)).sum())
    4
    """
    raw = _decode(Path(src)) if isinstance(src, (str, Path)) else _array(src, "mask")
    if raw.ndim not in (2, 3):
        raise ImageError(f"expected a grey (H, W) or colour (H, W, C) mask, got shape {raw.shape}")
    if raw.dtype.kind == "f" and np.isnan(raw).any():
        raise SegmentationError("the mask holds NaN values")
    mask = np.any(raw != 0, axis=2) if raw.ndim == 3 else raw != 0
    rows, cols = shape
    if mask.shape != (rows, cols):
        raise SegmentationError(f"the mask is {mask.shape[1]} x {mask.shape[0]} pixels and the image "
                                f"{cols} x {rows}: they must be the same size")
    if not mask.any():
        raise SegmentationError("the mask is empty: no pixel is non-zero (the object's pixels must be)")
    if mask.all():
        raise SegmentationError("the mask covers the whole image: no pixel is zero (the background's must be)")
    return mask


def _components(mask: np.ndarray):
    """Labels and statistics of the 8-connected components, the objects among them (specks
    dropped) and which objects lie inside the frame (not touching the border)."""
    _, labels, stats, _ = cv2.connectedComponentsWithStats(mask.astype(np.uint8), connectivity=8)
    areas = stats[1:, cv2.CC_STAT_AREA]
    objects = np.flatnonzero(areas >= _SPECK * areas.max()) + 1 if len(areas) else np.zeros(0, int)
    rows, cols = mask.shape
    x, y, w, h = (stats[objects, i] for i in range(4))
    whole = (x > 0) & (y > 0) & (x + w < cols) & (y + h < rows)
    return labels, stats, objects, whole


def _default_rect(smooth: np.ndarray) -> tuple[int, int, int, int]:
    """GrabCut's default rectangle: around Otsu's largest object inside the frame, if any."""
    level = threshold_otsu(smooth)
    otsu = smooth < level if np.median(border_pixels(smooth)) > level else smooth > level
    labels, stats, objects, whole = _components(otsu)
    inside = objects[whole]
    if not len(inside):
        return grabcut_rect(None, smooth.shape)
    return grabcut_rect(labels == inside[np.argmax(stats[inside, cv2.CC_STAT_AREA])], smooth.shape)


def segment(src: ImageSource, threshold: float | None = None, blur: float = 1.0, *, method: str = "otsu",
            mask: ImageSource | None = None, rect: tuple[int, int, int, int] | None = None) -> Segmentation:
    """Segment an image into object and background.

    Parameters
    ----------
    src : str, pathlib.Path or numpy.ndarray
        Image (see :func:`read_image`).
    threshold : float, optional
        Grey level separating object and background, in the input's units (``method="otsu"``
        only). Default: Otsu's.
    blur : float
        Standard deviation, pixels, of a Gaussian applied before segmenting (0 for none). It
        averages pixel noise, which otherwise breaks Otsu's threshold on small objects (the noisy
        background becomes bimodal) and scatters specks along the edge.
    method : str
        One of :data:`METHODS`: ``"otsu"`` (the default: one global threshold), ``"multiotsu"``
        (three grey classes: a soft shadow), ``"adaptive"`` (against the local mean: uneven
        lighting) or ``"grabcut"`` (from a rectangle: textured backgrounds); see
        :mod:`qualgrasp.qualitative.vision.segmentation`.
    mask : str, pathlib.Path or numpy.ndarray, optional
        A user's mask of the object instead of a method (:func:`read_mask`).
    rect : (int, int, int, int), optional
        GrabCut's rectangle ``(x, y, width, height)``, pixels, holding the object; default
        :func:`qualgrasp.qualitative.vision.segmentation.grabcut_rect` around Otsu's object.

    Returns
    -------
    Segmentation
        With Otsu's method, the object is the side of the threshold **not** holding the median
        of the image's border pixels (the background): dark-on-light and light-on-dark images
        both work. With the others, ``level`` is NaN and ``dark`` says whether the object's median
        grey level is below the background's.

    Raises
    ------
    ImageError, SegmentationError
        Unusable image or mask; an unknown method, or options that do not go together (a
        threshold with another method than Otsu's, a rectangle without GrabCut, a mask with a
        method, threshold or rectangle); no object pixel.

    Examples
    --------
    >>> from qualgrasp.qualitative.objects import render
    >>> image = render("disc")
    >>> [int(segment(image, method=m).mask.sum()) for m in ("otsu", "multiotsu", "adaptive", "grabcut")]
    [36300, 35872, 36172, 36264]
    """
    image = read_image(src)
    if mask is not None:
        if method != "otsu" or threshold is not None or rect is not None:
            raise SegmentationError("a mask is the segmentation: give it without a method, threshold or rectangle")
        return _masked(image, read_mask(mask, image.shape), "mask")
    if method not in METHODS:
        raise SegmentationError(f"unknown segmentation method {method!r}: use one of {', '.join(METHODS)}")
    if threshold is not None and method != "otsu":
        raise SegmentationError(f"a threshold is a level of Otsu's (global) method, not of {method!r}")
    if rect is not None and method != "grabcut":
        raise SegmentationError(f"a rectangle starts GrabCut (method 'grabcut'), not {method!r}")
    smooth = gaussian_blur(image, blur)
    if method in ("adaptive", "multiotsu"):
        found, _ = (adaptive_mask if method == "adaptive" else multiotsu_mask)(smooth)
        return _masked(image, found, method)
    if method == "grabcut":
        return _masked(image, grabcut_mask(smooth, _default_rect(smooth) if rect is None else rect), method)
    level = float(threshold_otsu(smooth)) if threshold is None else float(threshold)
    dark = bool(np.median(border_pixels(smooth)) > level)
    found = smooth < level if dark else smooth > level
    if not found.any():
        side = "below" if dark else "above"
        raise SegmentationError(f"no object found: no pixel is {side} the threshold {level:g}")
    return Segmentation(image, found, level, dark)


def _masked(image: np.ndarray, mask: np.ndarray, method: str) -> Segmentation:
    if not mask.any() or mask.all():
        raise SegmentationError(f"no object found: the {method} segmentation has "
                                f"{'no object' if not mask.any() else 'no background'} pixel")
    dark = bool(np.median(image[mask]) < np.median(image[~mask]))
    return Segmentation(image, mask, float("nan"), dark, method)


def _border_message(seg: Segmentation, stats: np.ndarray, objects: np.ndarray) -> str:
    """Why no object of ``seg`` lies inside the frame, and what would help."""
    rows, cols = seg.mask.shape
    order = objects[np.argsort(-stats[objects, cv2.CC_STAT_AREA], kind="stable")]
    boxes = [f"{stats[k, cv2.CC_STAT_AREA]:,} px (x {stats[k, 0]}..{stats[k, 0] + stats[k, 2] - 1}, "
             f"y {stats[k, 1]}..{stats[k, 1] + stats[k, 3] - 1})" for k in order[:_LISTED]]
    more = f" and {len(order) - _LISTED} more" if len(order) > _LISTED else ""
    if len(order) == 1:
        text = f"the object touches the border of the {cols} x {rows} image: {boxes[0]}"
    else:
        text = f"every object touches the border of the {cols} x {rows} image: {len(order)} objects, " \
               + ", ".join(boxes) + more
    inside = [k for k in range(1, len(stats)) if stats[k, 0] > 0 and stats[k, 1] > 0
              and stats[k, 0] + stats[k, 2] < cols and stats[k, 1] + stats[k, 3] < rows]
    if inside:
        area = max(stats[k, cv2.CC_STAT_AREA] for k in inside)
        text += f"; the largest component inside the frame has {area:,} px (noise: under {_SPECK:.0%} of the largest)"
    else:
        text += "; no component lies inside the frame"
    if seg.method == "mask":
        return text + ". The mask must leave background around the whole object"
    others = [m for m in METHODS if m not in ("otsu", seg.method)]
    hint = ", ".join(f"{m} ({_HELPS[m]})" for m in others[:-1]) + f" or {others[-1]} ({_HELPS[others[-1]]})"
    return (text + ". If the object is cut off, frame it with some background around it; if it lies inside "
            f"the frame, the background is taken for the object: try --segmentation {hint}, or give the "
            "object's mask with --mask")


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
        (with ``largest``: every object does). The border message names the objects touching it
        (count, areas and bounding boxes, largest first), the largest component inside the frame
        if any, and the options that help when the object is in fact inside the frame (another
        segmentation method, or a mask).
    ContourError
        The object covers fewer than :data:`MIN_AREA` pixels.
    """
    labels, stats, objects, whole = _components(seg.mask)
    if len(objects) > 1 and not largest:
        raise SegmentationError(
            f"found {len(objects)} objects (largest {stats[objects, cv2.CC_STAT_AREA].max()} pixels); "
            "pass largest=True (--largest) to keep the largest one")
    if not whole.any():
        raise SegmentationError(_border_message(seg, stats, objects))
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
    level = gaussian_blur((level - image) if seg.dark else (image - level), blur)  # > 0 on the object's side
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
                    subpixel: bool = True, *, method: str = "otsu", mask: ImageSource | None = None,
                    rect: tuple[int, int, int, int] | None = None) -> np.ndarray:
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
        boundary pixels. A user's ``mask`` is the object: its contour is refined as that of a
        binary image (half a pixel out, the staircase smoothed), not moved to the image's edges.
    method, mask, rect
        Segmentation (see :func:`segment`); default Otsu's threshold.

    Returns
    -------
    numpy.ndarray
        ``(n, 2)`` float64 (x, y) contour, pixels, positive shoelace area, not closed.

    Raises
    ------
    ImageError, SegmentationError, ContourError
        See :func:`read_image`, :func:`segment` and :func:`object_mask`.
    """
    seg = segment(src, threshold, method=method, mask=mask, rect=rect)
    found, _ = cv2.findContours(object_mask(seg, largest).astype(np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    contour = max(found, key=len)[:, 0, :].astype(np.float64)
    if len(contour) < 8:
        raise ContourError(f"degenerate contour of {len(contour)} points")
    if len(contour) > MAX_CONTOUR:
        factor = int(np.ceil(len(contour) / MAX_CONTOUR))
        raise ContourError(f"the object's contour has {len(contour):,} pixels, more than the limit of "
                           f"{MAX_CONTOUR:,}: downsample the image by {factor} or more")
    if signed_area(contour) < 0:
        contour = contour[::-1].copy()
    if subpixel and seg.method == "mask":
        contour = refine_contour(contour, Segmentation(seg.mask.astype(np.float64), seg.mask, 0.5, False, "mask"))
    elif subpixel:
        contour = refine_contour(contour, seg, threshold)
    return contour

"""Image to contour: reading, segmentation, errors, sub-pixel accuracy against the exact geometry."""

import cv2
import numpy as np
import pytest
import shapely
from skimage import data

from qualgrasp.qualitative.errors import ContourError, ImageError, QualitativeError, SegmentationError
from qualgrasp.qualitative.objects import render, shape
from qualgrasp.qualitative.vision.contour import MIN_AREA, extract_contour, read_image, segment, signed_area


def _distances(contour, polygon):
    return shapely.distance(polygon.exterior, shapely.points(contour))


def _two_discs(size=256):
    image = np.full((size, size), 220, np.uint8)
    cv2.circle(image, (70, 128), 40, 30, -1, cv2.LINE_AA)
    cv2.circle(image, (180, 128), 25, 30, -1, cv2.LINE_AA)
    return image


# ---------------------------------------------------------------------------------------- reading


def test_missing_file(tmp_path):
    with pytest.raises(ImageError, match="no such image file"):
        read_image(tmp_path / "nothing.png")


def test_unreadable_file(tmp_path):
    path = tmp_path / "notes.png"
    path.write_text("not an image")
    with pytest.raises(ImageError, match="cannot read"):
        read_image(path)


@pytest.mark.parametrize("array, message", [
    (np.zeros((0, 5)), "empty"),
    (np.full((20, 20), 7, np.uint8), "constant"),
    (np.array([[0.0, np.nan], [1.0, 0.0]]), "NaN"),
    (np.zeros((4, 4, 2)), "shape"),
    (np.array([["a", "b"]]), "dtype"),
])
def test_bad_arrays(array, message):
    with pytest.raises(ImageError, match=message):
        read_image(array)


def test_errors_share_the_base_class():
    with pytest.raises(QualitativeError):
        read_image(np.ones((5, 5)))


def test_file_and_array_agree(tmp_path):
    image = render("polygon", rotation=12)
    path = tmp_path / "polygon.png"
    cv2.imwrite(str(path), image)
    np.testing.assert_array_equal(read_image(path), image.astype(float))
    np.testing.assert_allclose(extract_contour(path), extract_contour(image))


def test_colour_is_luminance(tmp_path):
    grey = render("square")
    rgb = np.dstack([grey, grey, grey])
    np.testing.assert_allclose(read_image(rgb), grey, atol=1e-9)
    # on disk colour images are BGR; a pure red object must read like an RGB red array
    red = np.zeros((64, 64, 3), np.uint8)
    red[16:48, 16:48] = (255, 0, 0)  # RGB
    path = tmp_path / "red.png"
    cv2.imwrite(str(path), red[:, :, ::-1])
    np.testing.assert_allclose(read_image(path), read_image(red))
    assert read_image(red)[32, 32] == pytest.approx(0.299 * 255)


def test_jpeg(tmp_path):
    path = tmp_path / "disc.jpg"
    cv2.imwrite(str(path), render("disc"), [cv2.IMWRITE_JPEG_QUALITY, 90])
    d = _distances(extract_contour(path), shape("disc"))
    assert np.median(d) < 0.15 and d.max() < 0.6


# ------------------------------------------------------------------------------------ segmentation


def test_polarity_decided_from_the_border():
    image = render("figure3", rotation=40)
    dark = extract_contour(image)
    light = extract_contour(255 - image)
    assert segment(image).dark and not segment(255 - image).dark
    # the same curve (pixels exactly at the threshold may fall either way)
    d = shapely.distance(shapely.LinearRing(dark), shapely.points(light))
    assert np.percentile(d, 99) < 0.05 and d.max() < 1.0


def test_float_and_bool_images():
    image = render("square", rotation=5)
    as_float = extract_contour(image / 255.0)
    np.testing.assert_allclose(as_float, extract_contour(image), atol=1e-6)
    mask = image < 128
    d = _distances(extract_contour(mask), shape("square", rotation=5))
    assert np.median(d) < 0.35  # a binary mask has no sub-pixel information left


@pytest.mark.parametrize("subpixel", [False, True])
def test_threshold_option(subpixel):
    image = render("disc")
    # the contour of a threshold closer to the object's grey level lies further inside
    inner = extract_contour(image, threshold=60, subpixel=subpixel)
    outer = extract_contour(image, threshold=200, subpixel=subpixel)
    assert signed_area(inner) < signed_area(outer)
    if subpixel:  # half-way between object (30) and background (230) is the default edge level
        middle = extract_contour(image, threshold=130)
        d = shapely.distance(shapely.LinearRing(extract_contour(image)), shapely.points(middle))
        assert d.max() < 0.02


def test_no_object():
    with pytest.raises(SegmentationError, match="no object"):
        segment(render("disc"), threshold=0)


def test_several_objects():
    image = _two_discs()
    with pytest.raises(SegmentationError, match="found 2 objects"):
        extract_contour(image)
    big = extract_contour(image, largest=True)
    assert signed_area(big) == pytest.approx(np.pi * 40.5 ** 2, rel=0.03)  # the radius-40 disc


def test_cut_off_by_the_border():
    image = render("disc", offset=(200, 0))
    with pytest.raises(SegmentationError, match="border"):
        extract_contour(image)


def test_too_small():
    image = np.full((128, 128), 220, np.uint8)
    cv2.circle(image, (64, 64), 9, 30, -1, cv2.LINE_AA)  # about 254 pixels
    with pytest.raises(ContourError, match=f"minimum is {MIN_AREA}"):
        extract_contour(image)


# ----------------------------------------------------------------------------------------- contour


@pytest.mark.parametrize("name", ["polygon", "nut", "disc", "figure3", "square"])
@pytest.mark.parametrize("scale", [0.5, 2.0])
def test_subpixel_contour_matches_exact_geometry(name, scale):
    poly = shape(name, rotation=33, scale=scale)
    image = render(name, rotation=33, scale=scale)
    contour = extract_contour(image)
    outer = shapely.Polygon(poly.exterior)  # the nut's hole is ignored: outer contour only
    assert signed_area(contour) > 0  # the project's orientation
    assert signed_area(contour) == pytest.approx(outer.area, rel=0.01)
    d = _distances(contour, outer)
    assert np.median(d) < 0.08
    assert np.percentile(d, 95) < 0.25
    raw = _distances(extract_contour(image, subpixel=False), outer)
    assert np.median(raw) > 2 * np.median(d)  # refinement helps


def test_noisy_contour():
    poly = shape("polygon", rotation=70, scale=0.7)
    contour = extract_contour(render("polygon", rotation=70, scale=0.7, noise=20, seed=3))
    d = _distances(contour, poly)
    assert np.median(d) < 0.12 and np.percentile(d, 95) < 0.35


# ------------------------------------------------------------------------------------- real images


def test_horse_silhouette():
    horse = data.horse()  # True = background
    contour = extract_contour(horse)
    mask = ~horse
    assert signed_area(contour) == pytest.approx(mask.sum(), rel=0.02)
    # every contour point lies on the boundary of the silhouette (within a pixel)
    inside = cv2.pointPolygonTest
    ring = contour.astype(np.float32)
    ys, xs = np.nonzero(mask)
    pick = np.random.default_rng(0).choice(len(xs), 200)
    assert all(inside(ring, (float(x), float(y)), False) >= 0 for x, y in zip(xs[pick], ys[pick]))


def test_coins_largest():
    coins = data.coins()
    with pytest.raises(SegmentationError, match="objects"):
        extract_contour(coins)
    contour = extract_contour(coins, largest=True)
    x0, y0 = contour.min(axis=0)
    x1, y1 = contour.max(axis=0)
    h, w = coins.shape
    assert x0 > 0 and y0 > 0 and x1 < w - 1 and y1 < h - 1
    # a coin: nearly round (isoperimetric ratio close to 1)
    perimeter = np.linalg.norm(np.diff(np.vstack([contour, contour[:1]]), axis=0), axis=1).sum()
    assert 4 * np.pi * signed_area(contour) / perimeter ** 2 > 0.85

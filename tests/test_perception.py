"""Perception on difficult backgrounds (issue 22 part 3): segmentation methods, a user's mask, the
border message and the edge evidence at contacts, on rendered scenes whose true shape is known
(tests/scenes.py)."""

import re

import cv2
import numpy as np
import pytest
import shapely
from skimage import data

from qualgrasp.qualitative.vision.edges import WEAK_EDGE, edge_contrast, edge_strength
from qualgrasp.qualitative.errors import ContourError, ImageError, SegmentationError
from qualgrasp.qualitative.objects import NAMES, render
from qualgrasp.qualitative.vision.outline import outline_image
from qualgrasp.qualitative.vision.scales import outline_scales
from qualgrasp.qualitative.vision.segmentation import METHODS, grabcut_rect
from qualgrasp.qualitative.plots.segmentation import segmentation_figure
from qualgrasp.qualitative.synthesis.pipeline import synthesize
from qualgrasp.qualitative.vision.contour import extract_contour, read_mask, segment

from scenes import SCENES, coverage, plain, shadow, textured, uneven


def _hausdorff(contour, poly):
    return shapely.hausdorff_distance(shapely.LinearRing(contour), poly.exterior)


def _strengths(image, grasp, contrast):
    return edge_strength(image, [c.p for c in grasp.contacts], [c.n for c in grasp.contacts], contrast)


# ------------------------------------------------------------------------- the default is unchanged

# (points, sum of x, sum of y) of the default contour of each built-in render, measured with the
# code before the segmentation methods were added (commit 60df363).
BEFORE = {
    "polygon": (605, 153087.669396, 157688.030299),
    "nut": (584, 149211.977980, 149211.387796),
    "disc": (608, 155342.106780, 155344.054718),
    "figure3": (656, 169816.216286, 172950.456756),
    "square": (600, 153300.000000, 153300.000000),
}


@pytest.mark.parametrize("name", NAMES)
def test_default_contour_of_the_builtin_renders_is_unchanged(name):
    contour = extract_contour(render(name))
    count, sx, sy = BEFORE[name]
    assert len(contour) == count
    assert contour[:, 0].sum() == pytest.approx(sx, abs=1e-5)
    assert contour[:, 1].sum() == pytest.approx(sy, abs=1e-5)
    np.testing.assert_array_equal(extract_contour(render(name), method="otsu"), contour)


# --------------------------------------------------------------------------------- rendered scenes

# The option that finds the object on each scene, and the largest outline error it may have
# (Hausdorff distance to the true polygon, pixels).
RIGHT = [("plain", {}), ("shadow", {"method": "multiotsu"}), ("textured", {"method": "grabcut"}),
         ("textured", {"method": "multiotsu"}), ("uneven", {"method": "adaptive"}),
         ("uneven", {"method": "multiotsu"})]


@pytest.mark.parametrize("scene, options", RIGHT)
def test_the_right_option_finds_the_true_shape(scene, options):
    image, poly = SCENES[scene]()
    assert _hausdorff(extract_contour(image, largest=True, **options), poly) < 2.0


@pytest.mark.parametrize("scene", sorted(SCENES))
def test_a_users_mask_gives_the_true_shape(scene, tmp_path):
    image, poly = SCENES[scene]()
    path = tmp_path / "mask.png"
    cv2.imwrite(str(path), np.where(coverage(poly) > 0.5, 255, 0).astype(np.uint8))
    contour = extract_contour(image, mask=path)
    assert _hausdorff(contour, poly) < 1.0
    # the mask is the object, whatever the image shows: the same contour on any image
    np.testing.assert_allclose(contour, extract_contour(render("disc", size=400), mask=path))


def test_the_default_takes_the_shadow_in():
    image, poly = shadow()
    assert _hausdorff(extract_contour(image), poly) > 15  # the issue: the shadow merged


@pytest.mark.parametrize("method", METHODS)
def test_every_method_finds_an_object_on_a_plain_background(method):
    image, poly = plain()
    assert _hausdorff(extract_contour(image, method=method), poly) < 2.5


def test_outline_image_and_scales_pass_the_method_on():
    image, poly = uneven()
    with pytest.raises(SegmentationError, match="touches the border"):
        outline_image(image)
    outline = outline_image(image, method="adaptive")
    assert _hausdorff(outline.contour, poly) < 2.0
    assert outline_scales(image, method="adaptive")[0].string == outline.string


def test_grabcut_is_reproducible_and_takes_a_rectangle():
    image, poly = textured()
    first = segment(image, method="grabcut").mask
    np.testing.assert_array_equal(segment(image, method="grabcut").mask, first)
    x0, y0, x1, y1 = np.round(poly.bounds).astype(int)
    rect = (x0 - 10, y0 - 10, x1 - x0 + 20, y1 - y0 + 20)
    assert _hausdorff(extract_contour(image, method="grabcut", rect=rect), poly) < 2.0


def test_grabcut_default_rectangle():
    # around Otsu's object on a plain scene; the frame less a margin when every object touches the border
    image, poly = plain()
    x, y, w, h = grabcut_rect(segment(image).mask, image.shape)
    x0, y0, x1, y1 = poly.bounds
    assert x < x0 and y < y0 and x + w > x1 and y + h > y1 and w < 1.3 * (x1 - x0) + 10
    assert grabcut_rect(None, (400, 400)) == (20, 20, 360, 360)


# ----------------------------------------------------------------------------------- bad options


@pytest.mark.parametrize("options, message", [
    ({"method": "watershed"}, "unknown segmentation method 'watershed'"),
    ({"method": "adaptive", "threshold": 100}, "threshold"),
    ({"method": "otsu", "rect": (1, 1, 50, 50)}, "rectangle starts GrabCut"),
    ({"method": "grabcut", "rect": (0, 0, 512, 512)}, "whole image"),
    ({"method": "grabcut", "rect": (500, 10, 50, 50)}, "inside the 512 x 512 image"),
    ({"method": "grabcut", "rect": (1.5, 10, 50, 50)}, "four integers"),
    ({"method": "grabcut", "rect": "everything"}, "four integers"),
    ({"method": "adaptive", "mask": np.ones((2, 2))}, "without a method"),
])
def test_bad_segmentation_options(options, message):
    with pytest.raises(SegmentationError, match=message):
        segment(render("disc"), **options)


def test_bad_masks(tmp_path):
    image = render("disc", size=64)
    with pytest.raises(SegmentationError, match="the mask is 32 x 48 pixels and the image 64 x 64"):
        extract_contour(image, mask=np.ones((48, 32)))
    with pytest.raises(SegmentationError, match="the mask is empty"):
        extract_contour(image, mask=np.zeros((64, 64)))
    with pytest.raises(SegmentationError, match="covers the whole image"):
        extract_contour(image, mask=np.full((64, 64), 7, np.uint8))
    nan = np.zeros((64, 64))
    nan[0, 0] = np.nan
    with pytest.raises(SegmentationError, match="NaN"):
        extract_contour(image, mask=nan)
    with pytest.raises(ImageError, match="no such image file"):
        extract_contour(image, mask=tmp_path / "missing.png")
    with pytest.raises(SegmentationError, match="touches the border"):  # a mask cut by the frame
        mask = np.zeros((64, 64), bool)
        mask[:30, 10:40] = True
        extract_contour(image, mask=mask)


def test_colour_mask_file(tmp_path):
    mask = np.zeros((64, 80, 3), np.uint8)
    mask[20:40, 30:60, 2] = 1  # any non-zero channel
    path = tmp_path / "mask.png"
    cv2.imwrite(str(path), mask)
    assert read_mask(path, (64, 80)).sum() == 600


# --------------------------------------------------------------------------------- border message


def test_border_message_on_a_textured_background():
    image, poly = textured()
    with pytest.raises(SegmentationError) as err:
        extract_contour(image, largest=True)
    message = str(err.value)
    assert "\n" not in message
    assert message.startswith("every object touches the border of the 400 x 400 image: ")
    count = int(message.split("image: ")[1].split(" objects")[0])
    assert count > 3 and f"and {count - 3} more" in message
    areas = [int(a.replace(",", "")) for a in
             [part.split(" px")[0].split(", ")[-1] for part in message.split(" px (")[:-1]]]
    assert areas == sorted(areas, reverse=True) and len(areas) >= 3
    assert "--segmentation multiotsu (a shadow), adaptive (uneven lighting) or grabcut (a textured background)" \
        in message and "--mask" in message
    # and the option suggested finds the object
    assert _hausdorff(extract_contour(image, largest=True, method="grabcut"), poly) < 2.0


def test_border_message_names_the_object_and_what_helps():
    image, _ = uneven()
    with pytest.raises(SegmentationError) as err:
        extract_contour(image)
    message = str(err.value)
    assert message.startswith("the object touches the border of the 400 x 400 image: 80,624 px (x 0..283, y 0..399)")
    assert re.search(r"; the largest component inside the frame has \d+ px \(noise", message)
    assert "adaptive (uneven lighting)" in message
    # a method in use is not suggested again
    with pytest.raises(SegmentationError) as err:
        extract_contour(render("disc", offset=(200, 0)), method="adaptive")
    assert "no component lies inside the frame" in str(err.value)
    assert "--segmentation multiotsu (a shadow) or grabcut (a textured background)" in str(err.value)


def test_border_message_reports_specks_inside_the_frame():
    image = np.full((200, 200), 220, np.uint8)
    image[:, :60] = 30  # an object cut by the frame
    cv2.circle(image, (150, 100), 4, 30, -1)  # a speck inside it
    with pytest.raises(SegmentationError, match=r"the largest component inside the frame has \d+ px \(noise"):
        extract_contour(image, largest=True)


# ---------------------------------------------------------------------------------- edge evidence


def test_edge_strength_on_the_true_edge_and_on_the_shadow():
    image, poly = shadow()
    outline = outline_image(image)  # the default: the shadow merged in
    normals = np.asarray(outline.normals())
    strength = edge_strength(image, outline.contour, normals, edge_contrast(image, outline.contour))
    off = shapely.distance(poly.exterior, shapely.points(outline.contour))
    assert (off > 3).sum() > 100 and (off < 1).sum() > 300
    assert strength[off > 3].max() < WEAK_EDGE / 2  # the shadow's boundary: weak
    assert np.percentile(strength[off < 1], 1) > WEAK_EDGE  # the object's true edge: strong


def test_edge_strength_of_the_builtin_contours():
    for name in NAMES:
        image = render(name, rotation=20)
        outline = outline_image(image)
        contrast = edge_contrast(image, outline.contour)
        assert contrast == pytest.approx(-200, abs=1)
        strength = edge_strength(image, outline.contour, np.asarray(outline.normals()), contrast)
        # every point but those at a cusp's thin tip (figure 3), where both bands hold the object
        assert np.percentile(strength, 1 if name == "figure3" else 0) > 0.6


def test_edge_strength_is_signed_and_unit_free():
    image = render("square", rotation=10)
    outline = outline_image(image)
    points, normals = outline.contour[::50], np.asarray(outline.normals())[::50]
    strength = edge_strength(image, points, normals, edge_contrast(image, outline.contour))
    # the same edge in a light-on-dark image at another contrast reads the same
    inverse = 1.0 - image / 255.0
    np.testing.assert_allclose(edge_strength(inverse, points, normals, edge_contrast(inverse, outline.contour)),
                               strength, atol=0.01)
    # normals pointing out of the object: the edge runs the wrong way
    assert (edge_strength(image, points, -normals, edge_contrast(image, outline.contour)) < 0.05).all()
    assert not edge_strength(image, points, normals, 0.0).any()


@pytest.mark.parametrize("points, normals, message", [
    ([[1.0, 2.0]], [[0.0, 0.0]], "zero normal"),
    ([[1.0, 2.0]], [[1.0, 0.0], [0.0, 1.0]], "one shape"),
    ([[np.nan, 2.0]], [[1.0, 0.0]], "finite"),
])
def test_edge_strength_bad_input(points, normals, message):
    with pytest.raises(ContourError, match=message):
        edge_strength(render("disc"), points, normals, -200.0)


def test_default_synthesis_on_the_shadow_flags_the_grasp():
    # the issue: a certified grasp with a finger on the shadow, 20 px off the real edge
    image, poly = shadow()
    result = synthesize(image, fingers=4, quality=False, tolerance=False)
    contrast = edge_contrast(image, result.outline.contour)
    flagged = 0
    for grasp, certified in zip(result.grasps, result.certified):
        strength = _strengths(image, grasp, contrast)
        off = shapely.distance(poly.exterior, shapely.points([c.p for c in grasp.contacts]))
        assert (strength[off > 5] < WEAK_EDGE).all() and (strength[off < 1] >= WEAK_EDGE).all()
        flagged += certified and bool((off > 5).any())
    assert flagged > 0  # such grasps exist (certified on the contour) and are flagged
    # with the right option, no contact lies on the shadow and none is flagged
    right = synthesize(image, fingers=4, quality=False, tolerance=False, threshold=125)
    contrast = edge_contrast(image, right.outline.contour)
    assert right.grasps and all((_strengths(image, g, contrast) >= WEAK_EDGE).all() for g in right.grasps)


@pytest.mark.parametrize("name", NAMES)
def test_no_false_flags_on_the_builtin_grasps(name):
    image = render(name)
    for fingers in (2, 3, 4):
        result = synthesize(image, fingers=fingers, certify=False, tolerance=False)
        contrast = edge_contrast(image, result.outline.contour)
        for grasp in result.grasps:
            assert (_strengths(image, grasp, contrast) > 0.75).all()


def test_segmentation_figure_shows_the_contour_and_the_weak_contacts(tmp_path):
    image, poly = shadow()
    result = synthesize(image, fingers=4, certify=False, tolerance=False)
    grasp = result.grasps[0]
    points = np.array([c.p for c in grasp.contacts])
    strengths = _strengths(image, grasp, edge_contrast(image, result.outline.contour))
    fig = segmentation_figure(image, result.outline.contour, points, strengths, title="shadow")
    ax = fig.axes[0]
    np.testing.assert_allclose(ax.lines[0].get_xydata()[:-1], result.outline.contour)
    shown = [c.get_offsets() for c in ax.collections]
    weak = points[strengths < WEAK_EDGE]
    assert len(weak) and any(np.allclose(s, weak) for s in shown)
    fig.savefig(tmp_path / "segmentation.png")
    assert (tmp_path / "segmentation.png").stat().st_size > 10_000


def test_grabcut_default_rectangle_leaves_a_frame():
    # the horse silhouette nearly fills the image: the grown box is clipped inside the frame
    horse = data.horse()
    x, y, w, h = grabcut_rect(~horse, horse.shape)
    assert x >= 1 and y >= 1 and x + w <= horse.shape[1] - 1 and y + h <= horse.shape[0] - 1
    contour = extract_contour(horse, method="grabcut")
    assert shapely.Polygon(contour).area == pytest.approx((~horse).sum(), rel=0.03)


# ------------------------------------------------------------------- wired into synthesis and the CLI

from typer.testing import CliRunner  # noqa: E402

from qualgrasp.cli import app  # noqa: E402
from qualgrasp.experiments.baseline import baseline  # noqa: E402
from qualgrasp.qualitative.synthesis.pipeline import on_weak_edge  # noqa: E402


def test_synthesis_records_edge_evidence_and_does_not_count_grasps_on_the_shadow():
    """Default segmentation on the shadow scene: the grasps with a contact off the true edge carry
    weak edge evidence and are not counted as resolved; with --segmentation multiotsu every
    certified grasp is on the object and counted."""
    image, poly = shadow()
    result = synthesize(image, fingers=4, quality=False, tolerance=False)
    offs = [shapely.distance(poly.exterior, shapely.points([c.p for c in g.contacts])).max() for g in result.grasps]
    for g, off, why, ok in zip(result.grasps, offs, result.not_counted, result.certified):
        assert len(g.meta["edge_strength"]) == len(g.contacts)
        assert on_weak_edge(g, 1.0) == (off > 5)
        assert ("weak_edge" in why) == (ok and off > 5)
    assert any(off > 5 for off in offs) and result.summary()["weak_edge"] > 0
    right = synthesize(image, fingers=4, quality=False, tolerance=False, method="multiotsu")
    assert right.grasps and right.summary()["weak_edge"] == 0
    far = [shapely.distance(poly.exterior, shapely.points([c.p for c in g.contacts])).max() for g in right.grasps]
    assert max(far) < 3


def test_a_blurred_image_is_not_a_shadow():
    """Edge evidence is relative to the image's own edges: a uniformly blurred image flags nothing."""
    image = cv2.GaussianBlur(render("polygon").astype(np.float64), (0, 0), 4.0)
    result = synthesize(np.clip(np.round(image), 0, 255).astype(np.uint8), fingers=2, quality=False,
                        tolerance=False)
    assert result.grasps and result.summary()["weak_edge"] == 0


def test_the_baseline_is_judged_by_the_same_edge_rule():
    image, _ = shadow()
    found = baseline(image, 2, name="shadow")
    assert all(len(g.meta["edge_strength"]) == 2 for g in found.grasps)


def test_segmentation_options_on_the_command_line(tmp_path):
    image, poly = shadow()
    path = tmp_path / "shadow.png"
    cv2.imwrite(str(path), image)
    run = CliRunner().invoke
    out = run(app, ["synthesize", str(path), "--fingers", "4", "-o", str(tmp_path / "g.jsonl"), "--no-tolerance"])
    assert out.exit_code == 0 and "ON A WEAK EDGE" in out.output and "--segmentation" in out.output
    out = run(app, ["synthesize", str(path), "--fingers", "4", "-o", str(tmp_path / "g.jsonl"), "--no-tolerance",
                    "--segmentation", "multiotsu"])
    assert out.exit_code == 0 and "WEAK EDGE" not in out.output
    mask = tmp_path / "mask.png"
    cv2.imwrite(str(mask), (coverage(poly) > 0.5).astype(np.uint8) * 255)
    out = run(app, ["outline", str(path), "--mask", str(mask)])
    assert out.exit_code == 0 and out.stdout.strip() == outline_image(image, mask=mask, scale=scale_of(out)).string
    for args, message in ((["--segmentation", "nope"], "unknown segmentation method"),
                          (["--mask", str(mask), "--segmentation", "adaptive"], "mask is the segmentation"),
                          (["--rect", "1,2,3"], "--rect must be four whole numbers"),
                          (["--rect", "10,10,200,200"], "rectangle starts GrabCut")):
        out = run(app, ["regions", str(path), *args])
        assert out.exit_code == 2 and message in out.output, (args, out.output)
    out = run(app, ["regions", str(path), "--segmentation", "grabcut", "--rect", "40,40,320,320"])
    assert out.exit_code == 0, out.output


def scale_of(result) -> float:
    """The outline scale ``qualgrasp outline`` reports on standard error."""
    return float(re.search(r"outline at scale ([0-9.e-]+)", result.stderr).group(1))

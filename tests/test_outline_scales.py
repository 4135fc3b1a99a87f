"""Outlines at a chosen scale, the finger's scale, and the scale hierarchy (curvature scale space)."""

import json
import math

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from shapely.geometry import Point
from skimage import data
from typer.testing import CliRunner

from qualgrasp.cli import app
from qualgrasp.qualitative.errors import QualitativeError
from qualgrasp.qualitative.objects import NAMES, render, render_polygon, shape
from qualgrasp.qualitative.vision.outline import DEFAULT_SCALE, SCALE_MAX, Outline, outline_contour, outline_image
from qualgrasp.qualitative.vision.grammar import POINT_LIKE, validate
from qualgrasp.qualitative.vision.scales import ScaleInterval, finger_scale, outline_contour_scales, outline_scales
from qualgrasp.qualitative.synthesis.regions import FINGER_WIDTH
from qualgrasp.qualitative.vision.contour import extract_contour
from test_outline import EXPECTED, least_rotation

runner = CliRunner()
SQUARE = "/>/>/>/>"


def string_at(hierarchy, scale):
    """The string of the interval holding ``scale``."""
    (string,) = [i.string for i in hierarchy if i.lo <= scale <= i.hi][:1]
    return string


def noisy_square(bumps, rotation=0.0, scale=1.0, offset=(0.0, 0.0), noise=0.0, seed=0):
    """The built-in square with semicircular bumps (``+``) and dents (``-``) on its edges.

    ``bumps``: tuples ``(edge 0..3, position along it 0..1, diameter as a fraction of the side,
    sign)``. Drawn exactly (discs added to or cut from the square) and rendered like the built-in
    objects; also returns the side in pixels.
    """
    square = shape("square", rotation=rotation, scale=scale, offset=offset)
    v = np.asarray(square.exterior.coords)[:-1]
    side = float(np.linalg.norm(v[1] - v[0]))
    geometry = square
    for edge, t, diameter, sign in bumps:
        disc = Point(v[edge] + t * (v[(edge + 1) % 4] - v[edge])).buffer(diameter * side / 2, quad_segs=32)
        geometry = geometry.union(disc) if sign > 0 else geometry.difference(disc)
    return render_polygon(geometry, noise=noise, seed=seed), side


# The finger pad is 0.08 of the object's size, the square's diagonal: 11.3 % of the side. Six bumps
# and dents of 5 to 7 % of the side (0.44 to 0.62 pads), a quarter of a side apart: smaller than
# the pad, large enough to be read at the default scale. (Bumps of 1 to 3 % are not: the default
# Gaussian, 0.4 % of the perimeter, is 1.6 % of the side, and smooths them below every threshold,
# so a test with them could not fail.)
BUMPS = [(0, 0.25, 0.07, +1), (0, 0.75, 0.06, -1), (1, 0.5, 0.07, -1), (2, 0.25, 0.05, +1),
         (2, 0.5, 0.07, +1), (3, 0.75, 0.06, -1)]
PAD = FINGER_WIDTH * math.sqrt(2)  # pad width, fraction of the square's side


def check_hierarchy(hierarchy, fine=DEFAULT_SCALE, coarse=SCALE_MAX):
    """Contiguous, increasing, covering [fine, coarse], consecutive strings differ, all well formed."""
    assert hierarchy and all(isinstance(i, ScaleInterval) for i in hierarchy)
    assert hierarchy[0].lo == pytest.approx(fine, rel=1e-12)
    assert hierarchy[-1].hi == pytest.approx(coarse, rel=1e-12)
    for a, b in zip(hierarchy, hierarchy[1:]):
        assert a.hi == b.lo
        assert a.string != b.string
    for i in hierarchy:
        assert i.lo < i.hi
        validate(i.string)
        assert i.string == least_rotation(i.string)  # canonical
        assert i.corners == sum(s in POINT_LIKE for s in i.string)
        assert i.convex == (not set(i.string) & set("(<{"))


# ------------------------------------------------------------------------------------ the default


def test_default_scale_is_todays():
    assert DEFAULT_SCALE == 0.004
    outline = outline_image(render("square"))
    assert outline.scale == DEFAULT_SCALE
    assert outline_image(render("square"), scale=0.01).scale == 0.01
    # the field has a default, so outlines built without it keep working
    points = np.zeros((4, 2))
    assert Outline((), points, points, 1.0, 1.0).scale == DEFAULT_SCALE


@pytest.mark.parametrize("name", NAMES)
def test_builtin_strings_at_the_default_scale(name):
    image = render(name)
    assert outline_image(image, scale=DEFAULT_SCALE).string == EXPECTED[name]
    hierarchy = outline_scales(image)
    assert hierarchy[0].string == EXPECTED[name]  # the fine end is the default scale
    ring = np.asarray(shape(name, rotation=30).exterior.coords)[:-1]
    assert outline_contour(ring, scale=DEFAULT_SCALE).string == EXPECTED[name]


@pytest.mark.parametrize("bad", [0.0, -0.004, math.nan, math.inf, SCALE_MAX * 1.01])
def test_bad_scales(bad):
    ring = np.asarray(shape("square").exterior.coords)[:-1]
    with pytest.raises(ValueError, match="fraction of the perimeter"):
        outline_contour(ring, scale=bad)
    with pytest.raises(ValueError, match="fraction of the perimeter"):
        outline_image(render("square"), scale=bad)


def test_bad_ranges():
    ring = np.asarray(shape("square").exterior.coords)[:-1]
    with pytest.raises(ValueError, match="smaller"):
        outline_contour_scales(ring, fine=0.01, coarse=0.01)
    with pytest.raises(ValueError, match="coarse"):
        outline_contour_scales(ring, coarse=2 * SCALE_MAX)
    with pytest.raises(ValueError, match="tolerance"):
        outline_contour_scales(ring, tolerance=0.0)


# --------------------------------------------------------------------------------- finger's scale


def test_finger_scale_conversion():
    """Pad = +-2 sigma: sigma = w D / 4, as a fraction of the perimeter, from exact geometry."""
    r = 100.0
    t = np.linspace(0, 2 * np.pi, 4000, endpoint=False)
    circle = np.column_stack([r * np.cos(t), r * np.sin(t)])
    # D = 2 r, P = 2 pi r
    assert finger_scale(circle, 0.08) == pytest.approx(0.08 * 2 * r / (4 * 2 * np.pi * r), rel=1e-3)
    square = np.array([[0, 0], [100, 0], [100, 100], [0, 100]], float)
    assert finger_scale(square, 0.08) == pytest.approx(0.08 * 100 * math.sqrt(2) / (4 * 400), rel=1e-3)
    assert finger_scale(square, 0.16) == pytest.approx(2 * finger_scale(square, 0.08))
    outline = outline_image(render("nut"))
    contour = extract_contour(render("nut"))
    assert finger_scale(outline, FINGER_WIDTH) == pytest.approx(finger_scale(contour, FINGER_WIDTH))
    for bad in (0.0, -0.1, math.nan, math.inf):
        with pytest.raises(ValueError, match="finger_width"):
            finger_scale(square, bad)


def test_noisy_square_at_the_fingers_scale():
    """Bumps smaller than the pad are read at the default scale and gone at the finger's."""
    image, _ = noisy_square(BUMPS)
    assert max(d for _, _, d, _ in BUMPS) < 0.65 * PAD
    fine = outline_image(image)
    assert fine.string != SQUARE
    assert len(fine.string) > len(SQUARE)
    scale = finger_scale(fine, FINGER_WIDTH)
    assert scale > DEFAULT_SCALE
    assert outline_image(image, scale=scale).string == SQUARE
    hierarchy = outline_scales(image)
    check_hierarchy(hierarchy)
    assert string_at(hierarchy, scale) == SQUARE
    assert hierarchy[0].string == fine.string


@st.composite
def bumpy_squares(draw):
    # up to one bump or dent in each of three slots per edge, a quarter of a side apart, of 1 to
    # 6 % of the side (at most about half a pad)
    slots = [(e, t) for e in range(4) for t in (0.25, 0.5, 0.75)]
    used = draw(st.lists(st.sampled_from(slots), min_size=1, max_size=12, unique=True))
    bumps = [(e, t, draw(st.floats(0.01, 0.06)), draw(st.sampled_from([-1, 1]))) for e, t in used]
    return {"bumps": bumps, "rotation": draw(st.floats(0.0, 90.0)), "scale": draw(st.floats(0.6, 2.0)),
            "offset": (draw(st.floats(-30.0, 30.0)), draw(st.floats(-30.0, 30.0))),
            "noise": draw(st.sampled_from([0.0, 5.0, 10.0])), "seed": draw(st.integers(0, 1000))}


@settings(max_examples=25)
@given(pose=bumpy_squares())
def test_bumpy_squares_are_squares_for_a_finger(pose):
    """Any bumps and dents of 1 to 6 % of the side, any pose and pixel noise: a square for a finger."""
    image, _ = noisy_square(**pose)
    outline = outline_image(image)
    assert outline_image(image, scale=finger_scale(outline, FINGER_WIDTH)).string == SQUARE


def test_a_bump_as_wide_as_the_pad_is_felt():
    """The other side of the conversion: a bump as wide as the pad is still there for the finger."""
    image, _ = noisy_square([(0, 0.5, PAD, +1)])
    outline = outline_image(image)
    assert outline_image(image, scale=finger_scale(outline, FINGER_WIDTH)).string != SQUARE


# ------------------------------------------------------------------------------------- hierarchy


POSES = [{"rotation": 30.0}, {"rotation": 45.0}, {"offset": (40.0, -25.0)}, {"scale": 0.5}, {"scale": 2.0},
         {"rotation": 45.0, "scale": 0.5, "offset": (-60.0, 30.0)}]


@pytest.fixture(scope="module")
def hierarchies():
    return {name: outline_scales(render(name)) for name in NAMES}


@pytest.mark.parametrize("name", NAMES)
def test_hierarchies_of_the_builtins(name, hierarchies):
    check_hierarchy(hierarchies[name])


def test_square_and_disc_do_not_change():
    """A square has nothing but its corners, which stay apart at the coarsest scale (the corner
    window, 0.16 of the perimeter, is shorter than a side, 0.25); a disc has nothing at all."""
    assert [(i.lo, i.hi, i.string) for i in outline_scales(render("square"))] == [(DEFAULT_SCALE, SCALE_MAX, SQUARE)]
    assert [i.string for i in outline_scales(render("disc"))] == [")"]


@pytest.mark.parametrize("name", NAMES)
def test_hierarchy_agrees_with_single_scales(name, hierarchies):
    """Each interval's string is the outline at its middle; its bounds are located to 1 %."""
    image = render(name)
    for i in hierarchies[name]:
        assert outline_image(image, scale=i.middle).string == i.string
        if i.hi / i.lo > 1.01 ** 2:  # past the bracket of each bound (the true change is within 1 %)
            assert outline_image(image, scale=i.lo * 1.01).string == i.string
            assert outline_image(image, scale=i.hi / 1.01).string == i.string


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("pose", POSES, ids=lambda p: ",".join(f"{k}={v}" for k, v in p.items()))
def test_hierarchy_invariance(name, pose, hierarchies):
    """Rotated, translated, half and twice the size: the same string at every scale of the original.

    Checked at the geometric middle of each interval of the original hierarchy at least 1.3 times
    as wide as it is low (``hi / lo >= 1.3``): near a bound, a pixel's difference in the image may
    move the change by a few percent, which is not a change of description.
    """
    moved = outline_scales(render(name, **pose))
    check_hierarchy(moved)
    wide = [i for i in hierarchies[name] if i.hi / i.lo >= 1.3]
    assert wide  # every built-in has at least one
    for i in wide:
        assert string_at(moved, i.middle) == i.string


def test_finer_grids_and_ranges():
    """Another range and grid give the same strings where they overlap."""
    image = render("figure3")
    default = outline_scales(image)
    other = outline_scales(image, fine=0.002, coarse=0.02, per_octave=6, tolerance=0.005)
    check_hierarchy(other, fine=0.002, coarse=0.02)
    for i in default:
        if i.hi / i.lo >= 1.3 and i.middle < 0.02:
            assert string_at(other, i.middle) == i.string


def test_horse_hierarchy_is_well_formed():
    """A real silhouette: many changes at fine scales, every string well formed."""
    hierarchy = outline_scales(data.horse())
    check_hierarchy(hierarchy)
    assert len(hierarchy) > 5
    assert hierarchy[0].string == outline_image(data.horse()).string
    assert hierarchy[-1].corners < hierarchy[0].corners  # legs merge at coarse scales


def test_repeated_outlines_are_identical():
    """The same image and scale give the same outline every time (no state carried between
    calls); how long an outline takes is not a test's business."""
    image = render("figure3")
    first = outline_image(image, scale=0.01)
    for _ in range(2):
        again = outline_image(image, scale=0.01)
        assert again.string == first.string
        assert np.array_equal(again.contour, first.contour)


# ------------------------------------------------------------------------------------------- CLI


@pytest.fixture(scope="module")
def images(tmp_path_factory):
    folder = tmp_path_factory.mktemp("scales")
    paths = {}
    for name in ("figure3", "square", "disc"):
        paths[name] = folder / f"{name}.png"
        cv2.imwrite(str(paths[name]), render(name, rotation=15))
    paths["noisy"] = folder / "noisy.png"
    cv2.imwrite(str(paths["noisy"]), noisy_square(BUMPS)[0])
    return paths


def test_cli_scale(images):
    noisy = str(images["noisy"])
    fine = runner.invoke(app, ["outline", noisy, "--scale", repr(DEFAULT_SCALE)])
    assert fine.exit_code == 0, fine.output
    assert fine.stdout.strip() != SQUARE
    assert f"scale {DEFAULT_SCALE:.4g} (--scale)" in fine.stderr
    scale = finger_scale(outline_image(noisy_square(BUMPS)[0]), FINGER_WIDTH)
    result = runner.invoke(app, ["outline", noisy, "--scale", repr(scale)])
    assert result.exit_code == 0, result.output
    assert result.stdout.strip() == SQUARE
    # by default at the finger's scale, as regions and synthesize read it, and saying so
    result = runner.invoke(app, ["outline", noisy])
    assert result.exit_code == 0, result.output
    assert result.stdout.strip() == SQUARE and f"scale {scale:.4g} (the finger's" in result.stderr
    result = runner.invoke(app, ["outline", str(images["figure3"]), "--scale", "0.004"])
    assert result.stdout.strip() == EXPECTED["figure3"]
    result = runner.invoke(app, ["outline", noisy, "--scale", repr(scale), "--json"])
    out = json.loads(result.stdout)
    assert out["string"] == SQUARE and out["scale"] == scale
    assert "".join(seg["symbol"] for seg in out["segments"]) == SQUARE


def test_cli_scales(images):
    result = runner.invoke(app, ["outline", str(images["square"]), "--scales"])
    assert result.exit_code == 0, result.output
    assert result.stdout.splitlines() == [f"{DEFAULT_SCALE:.4g}..{SCALE_MAX:.4g}\t{SQUARE}"]
    result = runner.invoke(app, ["outline", str(images["figure3"]), "--scales"])
    assert result.exit_code == 0, result.output
    lines = [line.split("\t") for line in result.stdout.splitlines()]
    expected = outline_scales(cv2.imread(str(images["figure3"]), cv2.IMREAD_GRAYSCALE))
    assert [s for _, s in lines] == [i.string for i in expected]
    assert lines[0][1] == EXPECTED["figure3"]
    bounds = [tuple(map(float, r.split(".."))) for r, _ in lines]
    assert bounds[0][0] == DEFAULT_SCALE and bounds[-1][1] == SCALE_MAX
    assert all(a[1] == b[0] for a, b in zip(bounds, bounds[1:]))


def test_cli_scales_json(images):
    result = runner.invoke(app, ["outline", str(images["disc"]), "--scales", "--json"])
    assert result.exit_code == 0, result.output
    assert json.loads(result.stdout) == [{"lo": DEFAULT_SCALE, "hi": SCALE_MAX, "string": ")", "corners": 0,
                                          "convex": True}]
    result = runner.invoke(app, ["outline", str(images["noisy"]), "--scales", "--json", "--threshold", "130"])
    assert result.exit_code == 0, result.output
    rows = json.loads(result.stdout)
    hierarchy = tuple(ScaleInterval(r["lo"], r["hi"], r["string"], r["corners"]) for r in rows)
    check_hierarchy(hierarchy)
    assert {"lo", "hi", "string", "corners", "convex"} <= set(rows[0])
    assert rows[-1]["string"] == SQUARE and rows[-1]["convex"]


@pytest.mark.parametrize("value", ["0", "-0.01", "nan", "inf", "-inf", "0.05"])
def test_cli_bad_scale(images, value):
    result = runner.invoke(app, ["outline", str(images["square"]), "--scale", value])
    assert result.exit_code == 2
    assert isinstance(result.exception, SystemExit)  # no traceback
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert len(lines) == 1
    assert "--scale" in lines[0] and "fraction of the object's perimeter" in lines[0]


def test_cli_scale_and_scales_exclusive(images):
    result = runner.invoke(app, ["outline", str(images["square"]), "--scale", "0.01", "--scales"])
    assert result.exit_code == 2 and "--scales" in result.output


def test_cli_errors_unchanged(images, tmp_path):
    result = runner.invoke(app, ["outline", str(tmp_path / "missing.png"), "--scales"])
    assert result.exit_code == 2 and "no such image file" in result.output
    with pytest.raises(QualitativeError):
        outline_scales(str(tmp_path / "missing.png"))

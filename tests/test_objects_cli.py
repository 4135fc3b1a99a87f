"""Built-in objects, the ``outline`` and ``regions`` commands, and the plots."""

import json

import cv2
import numpy as np
import pytest
import shapely
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from skimage import data
from typer.testing import CliRunner

from qualgrasp.cli import app
from qualgrasp.qualitative.errors import QualitativeError
from qualgrasp.qualitative.objects import BACKGROUND, FOREGROUND, NAMES, RADIUS, render, shape
from qualgrasp.qualitative.vision.outline import outline_image
from qualgrasp.qualitative.plots.outline import outline_figure, plot_outline, plot_regions
from qualgrasp.qualitative.synthesis.regions import feasible_regions

runner = CliRunner()


# ----------------------------------------------------------------------------------------- objects


@pytest.mark.parametrize("name", NAMES)
def test_shape(name):
    poly = shape(name)
    assert poly.is_valid and poly.exterior.is_ccw  # positive shoelace area on (x, y)
    centre = (512 - 1) / 2
    assert shapely.minimum_bounding_radius(poly) == pytest.approx(RADIUS * 512, rel=1e-3)
    moved = shape(name, rotation=70, scale=1.7, offset=(12.0, -30.0))
    assert moved.area == pytest.approx(poly.area * 1.7 ** 2, rel=1e-9)
    circle = shapely.minimum_bounding_circle(moved).centroid
    assert (circle.x, circle.y) == pytest.approx((centre + 12, centre - 30), abs=1e-6)


def test_rotation_direction():
    """Positive rotation turns +x towards +y (image frame)."""
    a = np.asarray(shape("square", rotation=0).exterior.coords)
    b = np.asarray(shape("square", rotation=90).exterior.coords)
    c = (512 - 1) / 2
    # a point right of the centre moves below it
    k = int(np.argmax(a[:, 0]))
    x, y = a[k] - c
    assert np.min(np.linalg.norm(b - (c + np.array([-y, x])), axis=1)) < 1e-9


@pytest.mark.parametrize("name", NAMES)
def test_render_is_area_weighted(name):
    """Each pixel's grey level is the fraction of it the exact shape covers."""
    image = render(name, rotation=21, scale=0.9)
    assert image.dtype == np.uint8 and image.shape == (512, 512)
    coverage = (BACKGROUND - image.astype(float)) / (BACKGROUND - FOREGROUND)
    poly = shape(name, rotation=21, scale=0.9)
    assert coverage.sum() == pytest.approx(poly.area, rel=2e-3)
    # an edge pixel: compare with the exact overlap of the pixel's square
    box = shapely.box(*np.add.outer([-0.5, 0.5], [0, 0]).ravel())
    ys, xs = np.nonzero((coverage > 0.1) & (coverage < 0.9))
    for x, y in list(zip(xs, ys))[::97]:
        cell = shapely.affinity.translate(box, x, y)
        # 8 x 8 subsamples: an edge along the subsample grid can flip one row of them, 1/8
        assert coverage[y, x] == pytest.approx(cell.intersection(poly).area, abs=0.13)


def test_nut_hole_is_drawn():
    image = render("nut")
    c = 256
    assert image[c, c] == BACKGROUND and len(shape("nut").interiors) == 1


def test_noise():
    a = render("disc", noise=10, seed=1)
    assert np.array_equal(a, render("disc", noise=10, seed=1))
    assert not np.array_equal(a, render("disc", noise=10, seed=2))
    residual = a.astype(float) - render("disc")
    assert residual[:50, :50].std() == pytest.approx(10, rel=0.1)


def test_unknown_object():
    with pytest.raises(QualitativeError, match="unknown object"):
        shape("teapot")


# --------------------------------------------------------------------------------------------- CLI


@pytest.fixture(scope="module")
def images(tmp_path_factory):
    folder = tmp_path_factory.mktemp("images")
    paths = {}
    for name in NAMES:
        paths[name] = folder / f"{name}.png"
        cv2.imwrite(str(paths[name]), render(name, rotation=15))
    two = np.full((200, 300), 220, np.uint8)
    cv2.circle(two, (70, 100), 45, 30, -1, cv2.LINE_AA)
    cv2.rectangle(two, (170, 60), (260, 140), 30, -1, cv2.LINE_AA)
    paths["two"] = folder / "two.png"
    cv2.imwrite(str(paths["two"]), two)
    paths["horse"] = folder / "horse.png"
    cv2.imwrite(str(paths["horse"]), data.horse().astype(np.uint8) * 255)
    paths["text"] = folder / "text.png"
    paths["text"].write_text("hello")
    return paths


def test_outline_command(images):
    result = runner.invoke(app, ["outline", str(images["figure3"])])
    assert result.exit_code == 0, result.output
    assert result.stdout.strip() == "/}(</{)>"
    result = runner.invoke(app, ["outline", str(images["square"])])
    assert result.stdout.strip() == "/>/>/>/>"


def test_outline_json(images):
    result = runner.invoke(app, ["outline", str(images["polygon"]), "--json"])
    assert result.exit_code == 0, result.output
    out = json.loads(result.stdout)
    assert out["string"] == "".join(seg["symbol"] for seg in out["segments"])
    poly = shape("polygon", rotation=15)
    for seg in out["segments"]:
        if seg["symbol"] in "<>":
            # corners in pixels of the input image, x = column, y = row
            assert shapely.distance(poly.exterior, shapely.Point(seg["position"])) < 0.6


def test_regions_command(images, tmp_path):
    result = runner.invoke(app, ["regions", str(images["nut"])])
    assert result.exit_code == 0, result.output
    assert result.stdout.count("\n/") == 6  # one straight region per side of the hexagon
    plot = tmp_path / "nut.png"
    result = runner.invoke(app, ["regions", str(images["disc"]), "--json", "--alpha", "0.8",
                                 "--plot", str(plot)])
    assert result.exit_code == 0, result.output
    out = json.loads(result.stdout)
    (region,) = out["regions"]
    assert region["type"] == ")" and out["alpha"] == 0.8
    points, normals = np.array(region["points"]), np.array(region["normals"])
    centre = (512 - 1) / 2
    inward = (centre - points) / np.linalg.norm(centre - points, axis=1, keepdims=True)
    assert np.degrees(np.arccos((inward * normals).sum(axis=1).clip(-1, 1))).max() < 3
    assert cv2.imread(str(plot)) is not None
    # a disc's bounding circle has the disc's diameter: alpha above 1 leaves nothing
    result = runner.invoke(app, ["regions", str(images["disc"]), "--json", "--alpha", "1.2"])
    assert json.loads(result.stdout)["regions"] == []


@pytest.mark.parametrize("args, message", [
    (["outline", "missing.png"], "no such image file"),
    (["regions", "missing.png"], "no such image file"),
    (["outline", "TEXT"], "cannot read"),
    (["outline", "TWO"], "found 2 objects"),
    (["regions", "DISC", "--finger-width", "0"], "--finger-width"),  # the flag, in its units (issue 17)
])
def test_command_errors(images, args, message):
    args = [str(images[a.lower()]) if a.isupper() else a for a in args]
    result = runner.invoke(app, args)
    assert result.exit_code == 2
    assert message in result.output


def test_largest_and_threshold(images):
    result = runner.invoke(app, ["outline", str(images["two"]), "--largest"])
    assert result.exit_code == 0 and result.stdout.strip() == "/>/>/>/>"  # the square is larger
    result = runner.invoke(app, ["outline", str(images["figure3"]), "--threshold", "100"])
    assert result.exit_code == 0 and result.stdout.strip() == "/}(</{)>"


def test_horse_file(images):
    result = runner.invoke(app, ["outline", str(images["horse"])])
    assert result.exit_code == 0
    assert result.stdout.strip() == outline_image(data.horse()).string


# ------------------------------------------------------------------------------------------- plots


def test_plots_use_the_image_frame():
    image = render("figure3", rotation=30)
    outline = outline_image(image)
    regions = feasible_regions(outline)
    fig = Figure()
    FigureCanvasAgg(fig)
    ax1, ax2 = fig.subplots(1, 2)
    plot_outline(ax1, outline, image)
    plot_regions(ax2, outline, regions, image)
    for ax in (ax1, ax2):
        bottom, top = ax.get_ylim()
        assert bottom > top  # y axis pointing down
        assert ax.get_aspect() == 1.0
        assert ax.get_legend() is not None
    labels = {t.get_text() for t in ax1.texts}
    assert labels == set(outline.string)
    fig.canvas.draw()


def test_outline_figure(tmp_path):
    image = render("nut")
    outline = outline_image(image)
    fig = outline_figure(outline, feasible_regions(outline), image)
    path = tmp_path / "nut.png"
    fig.savefig(path)
    assert cv2.imread(str(path)).shape[1] > cv2.imread(str(path)).shape[0]  # two panels

"""The study's real objects (issue 15, part 4): 61 silhouettes of three kinds, shipped with their
licences, loaded offline, rendered so that the toolkit reads back their shape."""

import tomllib
from collections import Counter
from pathlib import Path

import cv2
import numpy as np
import pytest
import shapely
from shapely.geometry import Polygon
from typer.testing import CliRunner

from qualgrasp.cli import app
from qualgrasp.experiments.silhouettes import (available_wings, read_wings, select_wings, silhouettes,
                                               wing_outline, write_wing_data)
from qualgrasp.qualitative.vision.outline import outline_image
from qualgrasp.qualitative.vision.contour import extract_contour

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def objects():
    return silhouettes(24, True, 36)


def test_sixty_one_real_objects_of_three_kinds(objects):
    assert len(objects) == 61 and len({o.name for o in objects}) == 61
    assert Counter(o.kind for o in objects) == {"cell": 24, "wing": 36, "animal": 1}
    for o in objects:
        poly = o.template
        assert poly.is_valid and poly.geom_type == "Polygon"
        assert shapely.minimum_bounding_radius(poly.exterior) == pytest.approx(1.0)
        x, y = np.asarray(poly.exterior.coords).T
        assert np.sum(x[:-1] * y[1:] - x[1:] * y[:-1]) > 0  # the project's orientation


def test_wings_are_varied_and_deterministic():
    wings = select_wings(36)
    genera = Counter(w.name.split("-")[2] for w in wings)
    assert len(genera) == 11  # every genus; the largest ones several times
    assert max(genera.values()) - min(genera.values()) <= 4
    assert [w.name for w in select_wings(36)] == [w.name for w in wings]
    assert available_wings() == 126
    with pytest.raises(ValueError, match="wings pass"):
        select_wings(127)


def test_wing_outline_interpolates_its_points():
    _, xy, _ = read_wings()[0]
    smooth = wing_outline(xy)
    assert Polygon(smooth).is_valid
    # every given point lies on the interpolating curve (to its sampling)
    gap = np.min(np.linalg.norm(xy[:, None] - smooth[None], axis=2), axis=1)
    assert gap.max() < 0.02 * np.ptp(xy[:, 0])


def test_shipped_wings_regenerate_from_the_source_layout(tmp_path):
    """ktch's CSV layout (specimen_id, coord_id, x, y; specimen_id, genus) written from the
    shipped data and read back by write_wing_data gives the shipped file again."""
    wings = read_wings()
    with (tmp_path / "data_outline_mosquito_wings.csv").open("w") as fh:
        fh.write("specimen_id,coord_id,x,y\n")
        for k, xy, _ in wings:
            for j, (x, y) in enumerate(xy):
                fh.write(f"{k},{j},{float(x)!r},{float(y)!r}\n")
    (tmp_path / "meta_outline_mosquito_wings.csv").write_text(
        "specimen_id,genus\n" + "".join(f"{k},{g}\n" for k, _, g in wings))
    assert write_wing_data(tmp_path, tmp_path / "wings.npz") == 126
    with np.load(tmp_path / "wings.npz") as new, np.load(ROOT / "experiments" / "data" / "wings.npz") as old:
        assert np.array_equal(new["outlines"], old["outlines"]) and np.array_equal(new["genus"], old["genus"])


def test_licences_ship_with_the_data():
    text = (ROOT / "experiments" / "data" / "LICENSE-ktch.md").read_text()
    assert "Apache License" in text and "ktch" in text
    data = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]
    assert {"data/*.npz", "data/*.md"} <= set(data["qualgrasp.experiments"])


@pytest.mark.parametrize("index", [0, 20, 35])
def test_rendered_wings_are_read_as_their_polygon(index):
    wing = select_wings(36)[index]
    image = wing.image()
    seen = Polygon(extract_contour(image))
    truth = wing.polygon()
    assert seen.symmetric_difference(truth).area < 0.01 * truth.area
    assert outline_image(image).string  # the toolkit reads an outline


def test_silhouettes_command_writes_wings_and_checks_the_count(tmp_path):
    runner = CliRunner()
    result = runner.invoke(app, ["silhouettes", "--out", str(tmp_path / "w"), "--n", "0", "--no-horse",
                                 "--wings", "3"])
    assert result.exit_code == 0, result.output
    written = sorted(p.name for p in (tmp_path / "w").glob("*.png"))
    assert written == sorted(f"{w.name}.png" for w in select_wings(3))
    image = cv2.imread(str(tmp_path / "w" / written[0]), cv2.IMREAD_GRAYSCALE)
    assert image.shape == (512, 512)
    result = runner.invoke(app, ["compare", "--wings", "1000", "--out", str(tmp_path / "c")])
    assert result.exit_code == 2 and "--wings" in result.output

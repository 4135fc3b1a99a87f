"""One scale rule for every qualitative command (issue 28, part 1): outline, regions, synthesize
and independent-regions read the outline at the finger's scale by default, take --scale and
--finger-width with the same meaning, and print the scale and string they used; the regions
shown are those the grasps were planned on."""

import json
import re

import cv2
import numpy as np
import pytest
from shapely.geometry import Point
from typer.testing import CliRunner

from qualgrasp.cli import app
from qualgrasp.qualitative.objects import render, render_polygon, shape
from qualgrasp.qualitative.vision.outline import DEFAULT_SCALE, outline_image
from qualgrasp.qualitative.vision.scales import planning_scale
from qualgrasp.qualitative.synthesis.regions import FINGER_WIDTH, regions_image
from qualgrasp.qualitative.synthesis.pipeline import synthesize

runner = CliRunner()
SQUARE = "/>/>/>/>"


def bumpy_square(per_side: int = 3, diameters=(0.05, 0.06, 0.04)) -> np.ndarray:
    """The square with ``per_side`` semicircular bumps and dents on every side, 4 to 6 % of the side
    across (about half a finger pad): read as angles at the pixel scale."""
    square = shape("square")
    v = np.asarray(square.exterior.coords)[:-1]
    side = float(np.linalg.norm(v[1] - v[0]))
    geometry = square
    for e in range(4):
        for j in range(per_side):
            centre = v[e] + (j + 1) / (per_side + 1) * (v[(e + 1) % 4] - v[e])
            disc = Point(centre).buffer(diameters[(e + j) % len(diameters)] * side / 2, quad_segs=32)
            geometry = geometry.union(disc) if (e + j) % 2 == 0 else geometry.difference(disc)
    return render_polygon(geometry)


@pytest.fixture(scope="module")
def bumpy(tmp_path_factory):
    path = tmp_path_factory.mktemp("bumpy") / "bumpy.png"
    cv2.imwrite(str(path), bumpy_square())
    return path


def test_the_bumpy_square_at_the_pixel_scale_has_no_square(bumpy):
    fine = outline_image(str(bumpy))
    assert len(fine.string) > 20 and fine.string != SQUARE
    assert len(regions_image(str(bumpy), scale=DEFAULT_SCALE)) != 4


def test_outline_reads_the_square_by_default(bumpy):
    result = runner.invoke(app, ["outline", str(bumpy)])
    assert result.exit_code == 0, result.output
    assert result.stdout.strip() == SQUARE
    scale = planning_scale(outline_image(str(bumpy)), FINGER_WIDTH)
    assert f"outline at scale {scale:.4g} (the finger's: pad 0.08" in result.stderr
    out = json.loads(runner.invoke(app, ["outline", str(bumpy), "--json"]).stdout)
    assert out["string"] == SQUARE and out["scale"] == pytest.approx(scale)
    # a wider pad feels a coarser outline
    out = json.loads(runner.invoke(app, ["outline", str(bumpy), "--json", "--finger-width", "0.16"]).stdout)
    assert out["scale"] == pytest.approx(2 * scale)


def test_regions_gives_the_four_sides_by_default(bumpy):
    result = runner.invoke(app, ["regions", str(bumpy)])
    assert result.exit_code == 0, result.output
    header, *rows = result.stdout.splitlines()
    assert header.startswith(f"outline {SQUARE}  at scale ") and "the finger's" in header
    assert "4 feasible region(s)" in header and len(rows) == 4 and all(r.startswith("/") for r in rows)
    # each side's region spans most of the side (150 px; the margins take 4.3 px at each end)
    assert all(float(b) - float(a) > 120 for a, b in (re.search(r"arc ([\d.]+)\.\.([\d.]+)", r).groups()
                                                       for r in rows))
    out = json.loads(runner.invoke(app, ["regions", str(bumpy), "--json"]).stdout)
    assert out["string"] == SQUARE and out["scale"] > DEFAULT_SCALE
    result = runner.invoke(app, ["regions", str(bumpy), "--scale", str(DEFAULT_SCALE)])
    assert result.exit_code == 0 and "(--scale)" in result.stdout and SQUARE not in result.stdout.split("  ")[0]
    result = runner.invoke(app, ["regions", str(bumpy), "--scale", "0.5"])
    assert result.exit_code == 2 and "--scale" in result.output


def test_synthesize_plans_on_the_regions_shown(bumpy, tmp_path):
    """The string and regions synthesize prints are those 'regions' lists with the scale and alpha
    it names: the grasps' region indices point into that list."""
    out = runner.invoke(app, ["synthesize", str(bumpy), "--fingers", "2", "-o", str(tmp_path / "g.jsonl"),
                              "--no-tolerance"])
    assert out.exit_code == 0, out.output
    assert f"({SQUARE}), alpha 0.5, on 4 feasible region(s)" in out.stdout
    command = re.search(r"'qualgrasp regions (.*)' \(same", out.stdout).group(1).split()
    listed = json.loads(runner.invoke(app, ["regions", *command, "--json"]).stdout)
    s = synthesize(str(bumpy), 2, certify=False)
    assert listed["string"] == s.outline.string and listed["scale"] == s.scale
    assert [(r["start"], r["stop"]) for r in listed["regions"]] == [(r.start, r.stop) for r in s.regions]
    for line in (tmp_path / "g.jsonl").read_text().splitlines():
        grasp = json.loads(line)
        for p, r in zip(grasp["contacts"], grasp["regions"]):
            points = np.array(listed["regions"][r]["points"])
            assert np.linalg.norm(points - np.array(p["p"][:2]), axis=1).min() < 1.0


def test_independent_regions_says_its_outline(bumpy, tmp_path):
    grasps = tmp_path / "g.jsonl"
    assert runner.invoke(app, ["synthesize", str(bumpy), "--fingers", "2", "-o", str(grasps),
                               "--no-tolerance"]).exit_code == 0
    out = runner.invoke(app, ["independent-regions", str(bumpy), str(grasps), "-o", str(tmp_path / "r.jsonl")])
    assert out.exit_code == 0, out.output
    assert re.search(rf"feasible regions on the outline at scale [\d.]+: {re.escape(SQUARE)}", out.stdout)
    out = runner.invoke(app, ["independent-regions", str(bumpy), str(grasps), "-o", str(tmp_path / "r.jsonl"),
                              "--scale", "0.9"])
    assert out.exit_code == 2 and "--scale" in out.output


def test_builtin_strings_hold_at_the_finger_scale():
    """The paper's figures keep their strings under the scale rule (figure 3's among them)."""
    expected = {"polygon": "/>/>/>/>/>/>/<", "nut": "/>/>/>/>/>/>", "disc": ")", "figure3": "/}(</{)>",
                "square": SQUARE}
    for name, string in expected.items():
        fine = outline_image(render(name))
        assert outline_image(render(name), scale=planning_scale(fine, FINGER_WIDTH)).string == string

"""Synthesis at the finger's scale (issue 15, parts 2 and 3): regions and procedures on the
outline at the pad's scale, contacts and normals of the fine contour, coarser scales and then
curves as round as the finger when nothing is found, the scale and threshold reported, and why
nothing was found, in numbers."""

import json
import re

import cv2
import numpy as np
import pytest
from shapely.geometry import LineString, Point, Polygon
from typer.testing import CliRunner

from qualgrasp.certify import force_closure
from qualgrasp.cli import app
from qualgrasp.experiments.silhouettes import select_cells
from qualgrasp.qualitative.synthesis import procedures
from qualgrasp.experiments.baseline import boundary_of_polygon, screen_grasps
from qualgrasp.experiments.study import execute
from qualgrasp.qualitative.synthesis.candidates import Candidates, candidates
from qualgrasp.qualitative.errors import SynthesisError
from qualgrasp.qualitative.synthesis.forcegrasp import best_triplet_margins, triplet_grasps
from qualgrasp.qualitative.synthesis.formgrasp import deepest_closure
from qualgrasp.qualitative.objects import render, render_polygon, shape
from qualgrasp.qualitative.vision.outline import DEFAULT_SCALE, outline_image
from qualgrasp.qualitative.vision.scales import finger_scale
from qualgrasp.qualitative.synthesis.procedures import SearchInput
from qualgrasp.qualitative.synthesis.regions import ALPHA, FINGER_WIDTH, feasible_regions
from qualgrasp.qualitative.synthesis.pipeline import FALLBACK_STEP, synthesize


def _bumpy_square():
    """The square with six semicircular bumps and dents of 5 to 7 % of its side (about half a
    finger pad), read as angles at the default scale (as in tests/test_outline_scales.py)."""
    square = shape("square")
    v = np.asarray(square.exterior.coords)[:-1]
    side = float(np.linalg.norm(v[1] - v[0]))
    geometry = square
    for edge, t, diameter, sign in [(0, 0.25, 0.07, +1), (0, 0.75, 0.06, -1), (1, 0.5, 0.07, -1),
                                    (2, 0.25, 0.05, +1), (2, 0.5, 0.07, +1), (3, 0.75, 0.06, -1)]:
        disc = Point(v[edge] + t * (v[(edge + 1) % 4] - v[edge])).buffer(diameter * side / 2, quad_segs=32)
        geometry = geometry.union(disc) if sign > 0 else geometry.difference(disc)
    return render_polygon(geometry)


def test_bumps_smaller_than_the_finger_are_ignored():
    clean = synthesize(render("square"), 2, quality=False, tolerance=False)
    bumpy = _bumpy_square()
    fine = outline_image(bumpy)
    assert fine.string != "/>/>/>/>"  # at the default scale the bumps are read as angles
    s = synthesize(bumpy, 2, quality=False, tolerance=False)
    assert s.outline.string == "/>/>/>/>" and s.scale == pytest.approx(finger_scale(fine, FINGER_WIDTH))
    assert len(s.grasps) == len(clean.grasps) > 0 and all(s.certified)


def test_contacts_are_on_the_fine_contour_with_its_normals():
    cell = select_cells(24)
    image = next(c for c in cell if c.name == "cell-057-dlm8-control").image()
    s = synthesize(image, 2, quality=False, tolerance=False, largest=True)
    assert s.grasps and all(s.certified) and s.scale > DEFAULT_SCALE
    fine = outline_image(image, largest=True)
    normals = np.asarray(fine.normals())
    curved = 0
    for found in s.found:
        assert len(found.regions) == len(found.points)
        for p, n, r in zip(found.points, found.normals, found.regions):
            d = np.linalg.norm(fine.contour - p, axis=1)
            assert d.min() < 1.0  # on the contour the image gives
            if s.regions[r].type != "/":  # a curve's normal is the fine outline's
                curved += 1
                assert np.dot(n, normals[int(np.argmin(d))]) > np.cos(np.radians(2))
    assert curved


@pytest.mark.parametrize("name", ["cell-057-dlm8-control", "cell-586-dunn-jasp"])
def test_lumpy_cells_get_certified_grasps_at_the_finger_scale(name):
    # These two cells had nothing at the pixel scale while straight regions stopped at the ends of
    # the corner windows; since issue 28 a straight edge's region reaches its corners at any scale.
    image = next(c for c in select_cells(24) if c.name == name).image()
    s = synthesize(image, 2, quality=False, tolerance=False, largest=True)
    assert s.scale > DEFAULT_SCALE
    assert s.grasps and all(s.certified)
    assert all(force_closure(g).status == "closure" for g in s.grasps)
    tried = s.scales_tried
    assert tried[-1] == s.scale and all(b >= a * FALLBACK_STEP for a, b in zip(tried, tried[1:]) if b > a)


def test_a_given_scale_is_the_only_one_tried():
    s = synthesize(render("polygon"), 2, quality=False, tolerance=False, scale=0.01)
    assert s.scales_tried == (0.01,) and s.scale == 0.01 and s.outline.scale == 0.01
    with pytest.raises(SynthesisError, match="scale"):
        synthesize(render("polygon"), 2, scale=0.5)


def test_why_nothing_was_found():
    disc = synthesize(render("disc"), procedure="formgrasp", quality=False, tolerance=False)
    assert not disc.grasps and "zones of freedom" in disc.reason and "FormGrasp" in disc.reason
    square = synthesize(render("square"), procedure="forcegrasp3", quality=False, tolerance=False)
    assert not square.grasps and "positively span" in square.reason
    blank = np.full((200, 200), 230, np.uint8)
    cv2.circle(blank, (100, 100), 60, 30, -1)
    two = synthesize(blank, procedure="forcegrasp2", mu=0.01, quality=False, tolerance=False)
    assert two.grasps or "friction cones" in two.reason
    assert synthesize(render("polygon"), 2, quality=False, tolerance=False).reason is None


def test_two_fingers_on_a_triangle_say_the_best_angle():
    """On an equilateral triangle two fingers on different edges see each other at best 30
    degrees off their normals (the normals are 120 degrees apart), so with mu = 0.3 (theta_min
    16.7 degrees) there is no grasp, and the reason gives that angle."""
    a = np.radians([90, 210, 330])
    image = render_polygon(Polygon(np.c_[256 + 150 * np.cos(a), 256 + 150 * np.sin(a)]), 512)
    s = synthesize(image, procedure="forcegrasp2", mu=0.3, quality=False, tolerance=False)
    assert not s.grasps
    angle = float(re.search(r"larger angle to the grasp line is ([0-9.]+) degrees", s.reason).group(1))
    assert angle == pytest.approx(30.0, abs=1.0)
    assert "theta_min 16.7" in s.reason
    assert synthesize(image, procedure="forcegrasp2", mu=1.0, quality=False, tolerance=False).grasps


def test_synthesize_command_reports_the_scale_and_the_reason(tmp_path):
    image = tmp_path / "disc.png"
    cv2.imwrite(str(image), render("disc"))
    runner = CliRunner()
    out = runner.invoke(app, ["synthesize", str(image), "--fingers", "2", "-o", str(tmp_path / "g.jsonl")])
    assert out.exit_code == 0 and "at outline scale" in out.output
    out = runner.invoke(app, ["synthesize", str(image), "--fingers", "4", "-o", str(tmp_path / "g.jsonl")])
    assert out.exit_code == 0 and "no grasp found" in out.output and "zones of freedom" in out.output
    out = runner.invoke(app, ["synthesize", str(image), "--fingers", "2", "--scale", "0.01",
                              "-o", str(tmp_path / "g.jsonl")])
    assert out.exit_code == 0 and "at outline scale 0.01" in out.output
    out = runner.invoke(app, ["synthesize", str(image), "--fingers", "2", "--scale", "1",
                              "-o", str(tmp_path / "g.jsonl")])
    assert out.exit_code == 2 and "scale" in out.output


def _stadium():
    """A stadium 260 px long and 60 px wide: two parallel straight sides and two half discs whose
    bounding circle (0.23 of the size) is below ALPHA (0.5) but wider than a finger pad (0.08)."""
    return render_polygon(LineString([(156, 256), (356, 256)]).buffer(30, quad_segs=64))


def test_three_fingers_on_an_elongated_object_use_its_rounded_ends():
    image = _stadium()
    flat = synthesize(image, procedure="forcegrasp3", alpha=ALPHA, quality=False, tolerance=False)
    assert not flat.grasps and set(flat.alphas_tried) == {ALPHA}
    assert "normals never positively span" in flat.reason and "gap of 180.0 degrees" in flat.reason
    s = synthesize(image, procedure="forcegrasp3", quality=False)
    assert s.grasps and all(s.certified) and s.alpha == FINGER_WIDTH
    assert s.alphas_tried[0] == ALPHA and s.alphas_tried[-1] == FINGER_WIDTH
    assert len(s.alphas_tried) == len(s.scales_tried)
    for grasp, found in zip(s.grasps, s.found):
        assert grasp.meta["alpha"] == FINGER_WIDTH and grasp.meta["scale"] == s.scale
        assert any(s.regions[r].type == ")" for r in found.regions)  # a finger on a rounded end
        assert force_closure(grasp).status == "closure"
        assert grasp.meta["delta_fraction"] > 0
    # the flat sides come first: two fingers need no rounded end
    assert synthesize(image, procedure="forcegrasp2", quality=False, tolerance=False).alpha == ALPHA


def test_relaxing_is_skipped_where_no_curve_changes():
    s = synthesize(render("square"), procedure="forcegrasp3", quality=False, tolerance=False)
    assert not s.grasps and set(s.alphas_tried) == {ALPHA} and "alpha 0.08" not in s.reason


def test_independent_regions_command_keeps_the_grasps_regions(tmp_path):
    """A grasp on a relaxed region (the stadium's end) gets from ``qualgrasp independent-regions``
    the tolerance synthesis gave it: the same regions (its fields scale and alpha)."""
    image = tmp_path / "stadium.png"
    cv2.imwrite(str(image), _stadium())
    runner = CliRunner()
    out = runner.invoke(app, ["synthesize", str(image), "--fingers", "3", "-o", str(tmp_path / "g.jsonl")])
    assert out.exit_code == 0 and "alpha 0.08 (relaxed from 0.5: curves as round as the finger)" in out.output
    rows = [json.loads(line) for line in (tmp_path / "g.jsonl").read_text().splitlines()]
    out = runner.invoke(app, ["independent-regions", str(image), str(tmp_path / "g.jsonl"),
                              "-o", str(tmp_path / "r.jsonl")])
    assert out.exit_code == 0, out.output
    again = [json.loads(line) for line in (tmp_path / "r.jsonl").read_text().splitlines()]
    assert [r["delta"] for r in again] == pytest.approx([r["delta"] for r in rows], rel=1e-9)
    out = runner.invoke(app, ["independent-regions", str(image), str(tmp_path / "g.jsonl"),
                              "-o", str(tmp_path / "r.jsonl"), "--alpha", "-1"])
    assert out.exit_code == 2 and "--alpha" in out.output


def test_three_fingers_say_how_far_the_cones_are_from_meeting():
    """Three sides of an equilateral triangle, one candidate near a corner of each (the normals
    span with 30 degrees to spare): with cones of 10 degrees the forces cannot meet; the
    diagnosis gives the spanning margin and the cones' shortfall, and agrees with the search."""
    a = np.radians([90, 210, 330])
    n = -np.c_[np.cos(a), np.sin(a)]  # inward normals of the sides
    t = np.c_[-n[:, 1], n[:, 0]]
    feet = -100 * n
    c = Candidates(feet + 60 * t, n, np.arange(3), np.full(3, 10.0))
    contour = np.array([-100 * n[i] + s * 173 * t[i] for i in range(3) for s in (-1, 1)])
    theta = np.radians(10)
    normals, best = best_triplet_margins(c, contour, theta, 200)
    assert np.degrees(normals) == pytest.approx(30.0)
    assert best < 0 and not triplet_grasps(c, contour, theta, 200, margin=0.0)
    why = procedures.get("forcegrasp3").diagnose(SearchInput(c, contour, np.zeros(2), 100.0, 200.0, theta, 2.0, 0.25))
    assert "no three contacts have friction cones with a common point inside their triangle" in why
    # normals 174 degrees apart and a third across: they span, with 3 degrees to spare, not the margin
    u = np.c_[np.cos(np.radians([0, 174, 270])), np.sin(np.radians([0, 174, 270]))]
    three = Candidates(-100 * u, u, np.arange(3), np.full(3, 10.0))
    why = procedures.get("forcegrasp3").diagnose(SearchInput(three, -150 * u, np.zeros(2), 100.0, 200.0,
                                                             np.radians(26.57), 2.0, 0.25))
    assert "span the plane without the margin" in why and "gap of 174.0 degrees" in why
    # at the feet of the perpendiculars from the centre the cones meet whatever their width
    c = Candidates(feet, n, np.arange(3), np.full(3, 10.0))
    normals, best = best_triplet_margins(c, contour, theta, 200)
    found = triplet_grasps(c, contour, theta, 200, margin=0.0)
    assert found and best == pytest.approx(max(g.margin for g in found)) and best > 0.9 * theta


def test_formgrasp_says_how_deep_its_best_zone_is():
    disc = synthesize(render("disc"), procedure="formgrasp", quality=False, tolerance=False)
    m = re.search(r"closes the zone by ([0-9.e-]+) .*against ([0-9.e-]+) for 2 px", disc.reason)
    assert m and 0 < float(m.group(1)) < float(m.group(2))
    # four candidates, two of them closer than a finger's gap: no set of four to try
    n = np.array([[0, 1], [-1, 0], [0, -1], [1, 0]], float)
    p = np.array([[30, -100], [100, -30], [-30, 100], [-29, 100]], float)
    c = Candidates(p, n, np.arange(4), np.full(4, 10.0))
    assert deepest_closure(c, np.zeros(2), 141.4, 283) is None
    why = procedures.get("formgrasp").diagnose(SearchInput(c, p, np.zeros(2), 141.4, 283.0, None, 2.0, 0.25))
    assert why == "no four candidate contacts are far enough apart for four fingers"


def test_independent_regions_reports_bad_scale_and_alpha_fields_per_row(tmp_path):
    image = tmp_path / "square.png"
    cv2.imwrite(str(image), render("square"))
    grasps = tmp_path / "g.jsonl"
    runner = CliRunner()
    assert runner.invoke(app, ["synthesize", str(image), "--fingers", "2", "-o", str(grasps)]).exit_code == 0
    good = json.loads(grasps.read_text().splitlines()[0])
    bad = [dict(good, scale="abc"), dict(good, alpha=-1), dict(good, scale=5.0), dict(good, alpha=True),
           dict(good, alpha=10 ** 400), dict(good, alpha=1e308)]
    grasps.write_text("\n".join(json.dumps(g) for g in [good, *bad]) + "\n")
    out = runner.invoke(app, ["independent-regions", str(image), str(grasps), "-o", str(tmp_path / "r.jsonl")])
    assert out.exit_code == 1, out.output
    rows = [json.loads(line) for line in (tmp_path / "r.jsonl").read_text().splitlines()]
    assert rows[0]["status"] == "robust" and rows[0]["delta"] > 0
    assert [r["status"] for r in rows[1:]] == ["error"] * len(bad)
    for row, field in zip(rows[1:], ["scale", "alpha", "scale", "alpha", "alpha", "alpha"]):
        assert f"field {field}" in row["error"] and row["error"].startswith(f"line {row['line']}")
        assert len(row["error"]) < 200


def _lumpy_square():
    """The square 200 px wide with its bottom edge a square wave of 1.5 px amplitude every 6 px:
    a straight edge at the finger's scale whose normal, at the pixel's scale, turns by 90
    degrees every 3 px."""
    x = np.linspace(356, 156, 201)
    bottom = np.c_[x, 356 + 1.5 * np.sign(np.sin(2 * np.pi * (x - 156) / 6))]
    return Polygon(np.vstack([[156, 156], [356, 156], [356, 356], bottom[1:-1], [156, 356]]))


def test_candidate_normal_spread():
    for name in ("polygon", "disc", "figure3"):
        outline = outline_image(render(name))
        c = candidates(outline, feasible_regions(outline, FINGER_WIDTH))
        assert len(c) and np.degrees(c.spread).max() < 5  # clean edges and curves
    image = render_polygon(_lumpy_square())
    outline = outline_image(image, scale=finger_scale(outline_image(image), FINGER_WIDTH))
    assert outline.string == "/>/>/>/>"  # the lumps are below the finger's scale
    c = candidates(outline, feasible_regions(outline))
    bottom = np.abs(c.points[:, 1] - 356) < 3
    assert bottom.any() and np.degrees(c.spread[bottom]).min() > 30 and np.degrees(c.spread[~bottom]).max() < 5
    smooth = c.smooth(np.radians(10))
    assert len(smooth) == (~bottom).sum() and not (np.abs(smooth.points[:, 1] - 356) < 3).any()


def test_contacts_avoid_a_lumpy_edge_and_hold_on_the_true_polygon():
    """Two fingers on the lumpy square: the first pass leaves the lumpy edge out and its grasp
    holds on the exact polygon; searching every candidate at once also pinches the lumpy edge,
    and that grasp does not hold where the finger really lands."""
    poly = _lumpy_square()
    image, truth = render_polygon(poly), boundary_of_polygon(poly)
    s = synthesize(image, procedure="forcegrasp2", quality=False, tolerance=False)
    assert s.grasps and s.smooth and all(s.certified)
    assert not any(abs(c.p[1] - 356) < 3 for g in s.grasps for c in g.contacts)
    assert all(screen_grasps([execute(g, truth, 0.1, s.outline.contour)[0]])[0][0] for g in s.grasps)
    every = synthesize(image, procedure="forcegrasp2", quality=False, tolerance=False, normal_spread=None)
    lumpy = [g for g in every.grasps if any(abs(c.p[1] - 356) < 3 for c in g.contacts)]
    assert lumpy and not every.smooth
    assert not any(screen_grasps([execute(g, truth, 0.1, every.outline.contour)[0]])[0][0] for g in lumpy)


def test_lumpy_contacts_are_the_last_resort():
    """A disc whose whole outline is lumpy below the finger's scale: no smooth contact exists, so
    the second pass takes every candidate and says so."""
    angles = np.linspace(0, 2 * np.pi, 721)[:-1]
    r = 100 + 1.5 * np.sign(np.sin(angles * 120))
    image = render_polygon(Polygon(np.c_[256 + r * np.cos(angles), 256 + r * np.sin(angles)]))
    s = synthesize(image, procedure="forcegrasp2", quality=False, tolerance=False)
    assert s.grasps and not s.smooth and all(s.certified)
    assert np.degrees(s.candidates.spread).min() > 10
    out = synthesize(image, procedure="forcegrasp2", mu=0.01, quality=False, tolerance=False)
    assert not out.grasps and "with contacts of any normal spread" in out.reason
    for bad in (-0.1, float("nan"), 4.0):
        with pytest.raises(SynthesisError, match="normal_spread"):
            synthesize(image, procedure="forcegrasp2", normal_spread=bad)


def test_synthesize_command_says_when_contacts_are_lumpy(tmp_path):
    angles = np.linspace(0, 2 * np.pi, 721)[:-1]
    r = 100 + 1.5 * np.sign(np.sin(angles * 120))
    image = tmp_path / "lumpy.png"
    cv2.imwrite(str(image), render_polygon(Polygon(np.c_[256 + r * np.cos(angles), 256 + r * np.sin(angles)])))
    out = CliRunner().invoke(app, ["synthesize", str(image), "--fingers", "2", "-o", str(tmp_path / "g.jsonl")])
    assert out.exit_code == 0 and ", contacts of any normal spread, on " in out.output

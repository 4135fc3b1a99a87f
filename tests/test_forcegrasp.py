"""ForceGrasp: Nguyen's condition and the angular-gap rule against certify, grasps on the objects."""

import math

import numpy as np
import pytest
import shapely

from qualgrasp.certify import Contact, Grasp, force_closure, positive_span
from helpers import nguyen
from qualgrasp.qualitative.synthesis.candidates import candidates, object_frame
from qualgrasp.qualitative.errors import SynthesisError
from qualgrasp.qualitative.synthesis.forcegrasp import (GAP, MARGIN, friction, friction_cone, friction_zone, nguyen_angles,
                                                        pair_grasps, positively_spans, span_margin, triplet_grasps)
from qualgrasp.qualitative.objects import render
from qualgrasp.qualitative.vision.outline import outline_image
from qualgrasp.qualitative.synthesis.regions import feasible_regions

THETA = math.atan(0.5)


@pytest.fixture(scope="module")
def objects():
    out = {}
    for name in ("polygon", "nut", "figure3", "disc", "square"):
        outline = outline_image(render(name))
        out[name] = outline, candidates(outline, feasible_regions(outline))
    return out


def test_friction_parameters():
    assert friction(mu=0.5) == pytest.approx((0.5, math.atan(0.5)))
    assert friction(theta_min=math.radians(30)) == pytest.approx((math.tan(math.radians(30)), math.radians(30)))
    for kwargs in ({}, {"mu": 0.5, "theta_min": 0.3}, {"mu": 0.0}, {"mu": -1.0}, {"theta_min": 0.0},
                   {"theta_min": math.pi / 2}, {"mu": float("inf")}):
        with pytest.raises(SynthesisError):
            friction(**kwargs)


def test_nguyen_condition_agrees_with_certify():
    """Independent routes: the two-finger angle test and certify's force-closure LP."""
    rng = np.random.default_rng(11)
    agree = boundary = 0
    for _ in range(600):
        mu = float(rng.uniform(0.05, 1.5))
        p = rng.uniform(-1, 1, (2, 2))
        d = (p[1] - p[0]) / np.linalg.norm(p[1] - p[0])
        # normals near the grasp line so that both verdicts occur
        base = np.arctan2(d[1], d[0])
        a1 = base + rng.normal(scale=0.8)
        a2 = base + np.pi + rng.normal(scale=0.8)
        n = np.array([[math.cos(a1), math.sin(a1)], [math.cos(a2), math.sin(a2)]])
        t1, t2 = nguyen_angles(p[0], n[0], p[1], n[1])
        qualitative = bool(max(t1, t2) < math.atan(mu))
        grasp = Grasp((Contact(tuple(p[0]), tuple(n[0]), "point", mu), Contact(tuple(p[1]), tuple(n[1]), "point", mu)))
        ok, slack = nguyen(grasp)  # the tests' own route (squeezing or spreading)
        verdict = force_closure(grasp)
        if slack < 1e-6 or verdict.status == "degenerate":
            boundary += 1
            continue
        assert verdict.closure == ok
        if qualitative:  # squeezing inside both cones implies closure
            assert verdict.closure
        agree += 1
    assert agree > 500


def test_angular_gap_rule_agrees_with_positive_span():
    rng = np.random.default_rng(12)
    checked = 0
    for _ in range(600):
        k = int(rng.integers(1, 6))
        a = rng.uniform(0, 2 * np.pi, k)
        v = np.column_stack([np.cos(a), np.sin(a)]) * rng.uniform(0.5, 2.0, (k, 1))
        m = float(span_margin(v))
        verdict = positive_span(v)
        if abs(m) < 1e-6 or verdict.status == "degenerate":
            continue
        assert positively_spans(v) == verdict.closure
        checked += 1
    assert checked > 500


def test_span_margin_values():
    three = np.array([[1.0, 0], [-0.5, math.sqrt(3) / 2], [-0.5, -math.sqrt(3) / 2]])
    assert span_margin(three) == pytest.approx(np.pi / 6)  # gaps of 120 degrees
    assert span_margin(three[:2]) < 0
    assert span_margin(np.array([[1.0, 0], [-1.0, 0], [0, 1.0]])) == pytest.approx(0.0, abs=1e-15)


@pytest.mark.parametrize("name", ["polygon", "nut", "figure3", "disc", "square"])
def test_two_finger_grasps(objects, name):
    outline, cands = objects[name]
    found = pair_grasps(cands, THETA, outline.size)
    assert found
    assert len({frozenset(g.regions) for g in found}) == len(found)  # one per region pair
    center, length = object_frame(outline.contour)
    for g in found:
        t1, t2 = nguyen_angles(g.points[0], g.normals[0], g.points[1], g.normals[1])
        assert (t1, t2) == pytest.approx(g.angles)
        assert g.margin == pytest.approx(THETA - max(t1, t2))
        assert g.margin >= MARGIN * THETA
        assert np.linalg.norm(g.points[0] - g.points[1]) >= GAP * outline.size
        grasp = Grasp(tuple(Contact(tuple(p), tuple(n), "point", 0.5) for p, n in zip(g.points, g.normals)),
                      center=tuple(center), length=length)
        assert force_closure(grasp).status == "closure"
    if name == "disc":  # one region: both fingers on it, facing each other through the centre
        (g,) = found
        assert g.regions == (0, 0) and max(g.angles) < math.radians(2)


def test_two_fingers_prefer_region_middles(objects):
    """On parallel sides many point pairs face each other exactly: the one far from the ends wins."""
    outline, cands = objects["square"]
    for g in pair_grasps(cands, THETA, outline.size):
        clear = cands.clearance[list(g.contacts)]
        for r, c in zip(g.regions, clear):
            assert c >= 0.8 * cands.clearance[cands.of_region(r)].max()


@pytest.mark.parametrize("name", ["polygon", "nut", "figure3", "disc"])
def test_three_finger_grasps(objects, name):
    outline, cands = objects[name]
    found = triplet_grasps(cands, outline.contour, THETA, outline.size)
    assert found
    center, length = object_frame(outline.contour)
    for g in found:
        assert g.margin >= MARGIN * THETA
        # the paper's conditions: friction zone non-empty, normals positively spanning
        zone = friction_zone(g.points, g.normals, THETA, 3 * outline.size)
        assert not zone.is_empty and zone.contains(shapely.Point(g.point))
        assert positively_spans(g.normals)
        # ours: the meeting point inside the contact triangle, forces positively spanning
        assert shapely.Polygon(g.points).contains(shapely.Point(g.point))
        assert positively_spans(g.point - g.points)
        assert max(g.angles) <= THETA - g.margin + 1e-12
        grasp = Grasp(tuple(Contact(tuple(p), tuple(n), "point", 0.5) for p, n in zip(g.points, g.normals)),
                      center=tuple(center), length=length)
        assert force_closure(grasp).status == "closure"
    if name == "nut":  # only alternate sides of a hexagon have normals spanning the plane
        assert sorted(g.regions for g in found) == [(0, 2, 4), (1, 3, 5)]


def test_square_has_no_three_finger_grasp(objects):
    """Three sides of a square: two normals are opposite, the largest gap is exactly pi."""
    outline, cands = objects["square"]
    assert triplet_grasps(cands, outline.contour, THETA, outline.size) == []


def test_friction_cone():
    cone = friction_cone([0.0, 0.0], [0.0, 2.0], math.radians(30), 10.0)
    assert cone.area == pytest.approx(0.5 * 100 * math.sin(math.radians(60)))
    assert cone.contains(shapely.Point(0, 5)) and not cone.contains(shapely.Point(5, 5))


def test_bad_parameters(objects):
    outline, cands = objects["polygon"]
    with pytest.raises(SynthesisError):
        pair_grasps(cands, 2.0, outline.size)
    with pytest.raises(SynthesisError):
        triplet_grasps(cands, outline.contour, THETA, outline.size, margin=1.5)

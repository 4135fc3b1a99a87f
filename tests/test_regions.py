"""Feasible grasp regions: positions and inward normals against the exact geometry."""

import json
import math

import numpy as np
import pytest
import shapely
from shapely.geometry import LineString
from skimage import data

from qualgrasp.qualitative.objects import RADIUS, render, shape
from qualgrasp.qualitative.vision.outline import outline_image
from qualgrasp.qualitative.synthesis.regions import (ALPHA, FINGER_WIDTH, MARGIN, feasible_regions, regions_image,
                                                     regions_to_dict)


def exact_frame(ring, points, step=0.05):
    """Arc-length position and inward unit normal of the exact boundary nearest to each point.

    The exterior of ``objects.shape`` has positive shoelace area; the inward side is checked
    separately (``test_normals_point_into_the_object``), so the sign convention is not assumed.
    """
    line = LineString(ring.coords)
    s = line.project(shapely.points(points))
    a = np.array([line.interpolate(x - step).coords[0] for x in s])
    b = np.array([line.interpolate(x + step).coords[0] for x in s])
    t = (b - a) / np.linalg.norm(b - a, axis=1, keepdims=True)
    return s, np.column_stack([-t[:, 1], t[:, 0]])


def exact_rho(ring, s, width):
    """Diameter of the circle on which the exact boundary turns as it does over [s - w/2, s + w/2]."""
    line = LineString(ring.coords)

    def angle(x):
        p, q = np.array(line.interpolate(x - 0.05).coords[0]), np.array(line.interpolate(x + 0.05).coords[0])
        return math.atan2(q[1] - p[1], q[0] - p[0])

    out = []
    for x in s:
        turn = abs(math.remainder(angle(x + width / 2) - angle(x - width / 2), 2 * math.pi))
        out.append(2 * width / turn if turn else math.inf)
    return np.array(out)


POSES = [("polygon", 0.5, 17.0), ("nut", 1.0, 80.0), ("square", 2.0, 5.0), ("disc", 0.5, 0.0),
         ("disc", 1.8, 0.0), ("figure3", 0.6, 200.0), ("figure3", 1.9, 33.0)]


@pytest.mark.parametrize("name, scale, rotation", POSES)
def test_points_and_normals_match_exact_geometry(name, scale, rotation):
    poly = shape(name, rotation=rotation, scale=scale)
    regions = regions_image(render(name, rotation=rotation, scale=scale))
    assert regions
    for region in regions:
        assert region.type in "/)("
        assert region.points.shape == region.normals.shape == (len(region.points), 2)
        np.testing.assert_allclose(np.linalg.norm(region.normals, axis=1), 1.0)
        d = shapely.distance(poly.exterior, shapely.points(region.points))
        assert d.max() < 0.35  # pixels
        _, exact = exact_frame(poly.exterior, region.points)
        error = np.degrees(np.arccos(np.clip((exact * region.normals).sum(axis=1), -1, 1)))
        limit = 0.5 if region.type == "/" else 3.0  # degrees
        assert error.max() < limit


@pytest.mark.parametrize("name, scale, rotation", POSES)
def test_normals_point_into_the_object(name, scale, rotation):
    poly = shapely.Polygon(shape(name, rotation=rotation, scale=scale).exterior)
    for region in regions_image(render(name, rotation=rotation, scale=scale)):
        inside = shapely.contains_xy(poly, *(region.points + 2 * region.normals).T)
        outside = shapely.contains_xy(poly, *(region.points - 2 * region.normals).T)
        assert inside.all() and not outside.any()


@pytest.mark.parametrize("name, scale", [("polygon", 0.5), ("square", 1.3), ("nut", 2.0)])
def test_one_region_per_side_away_from_corners(name, scale):
    poly = shape(name, rotation=40, scale=scale)
    outline = outline_image(render(name, rotation=40, scale=scale))
    regions = feasible_regions(outline)
    vertices = np.asarray(poly.exterior.coords)[:-1]
    edges = [LineString([vertices[k], vertices[(k + 1) % len(vertices)]]) for k in range(len(vertices))]
    ring = shapely.geometry.polygon.orient(shapely.Polygon(vertices), 1.0)
    assert np.allclose(np.asarray(ring.exterior.coords)[:-1], vertices)  # shape() is positively oriented
    before, after = np.roll(vertices, 1, axis=0), np.roll(vertices, -1, axis=0)
    u, v = vertices - before, after - vertices
    outward = u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0] > 0
    keep = np.where(outward, MARGIN, MARGIN + FINGER_WIDTH / 2) * outline.size
    covered = []
    for region in regions:
        assert region.type == "/"
        d = np.array([shapely.distance(e, shapely.points(region.points)) for e in edges])
        (edge,) = np.flatnonzero(d.max(axis=1) < 0.3)  # every point on one and the same side
        covered.append(edge)
        # no finger on a corner: the margin stays off every outward vertex (the pad may overhang it),
        # the margin and half the pad off every inward one (the other face blocks the pad)
        gap = np.linalg.norm(region.points[:, None, :] - vertices[None], axis=2).min(axis=0)
        assert (gap > keep - 1.0).all()
    assert sorted(covered) == list(range(len(edges)))


def test_disc_alpha():
    outline = outline_image(render("disc", scale=1.2))
    n = len(outline.contour)
    (whole,) = feasible_regions(outline, alpha=0.9)  # rho = D for a disc: feasible all round
    assert len(whole.points) == n and whole.type == ")"
    assert whole.rho == pytest.approx(outline.size, rel=0.05)  # smallest over the contour: noise
    assert feasible_regions(outline, alpha=1.1) == []


def test_figure3_curves_follow_the_bounding_circle():
    """Curve regions are exactly where the exact boundary is flat enough over a finger's width."""
    scale, rotation = 1.5, 70.0
    poly = shape("figure3", rotation=rotation, scale=scale)
    outline = outline_image(render("figure3", rotation=rotation, scale=scale))
    size = 2 * RADIUS * 512 * scale
    width = FINGER_WIDTH * size
    regions = feasible_regions(outline)
    curves = [r for r in regions if r.type in ")("]
    assert {r.type for r in curves} == {")", "("}
    for region in curves:
        s, _ = exact_frame(poly.exterior, region.points)
        rho = exact_rho(poly.exterior, s, width)
        # the measured curvature is averaged over about a pad, which blurs the region's ends
        inner = np.abs(s - s[0]) > width  # farther than a pad from the region's start ...
        inner &= np.abs(s - s[-1]) > width  # ... and from its end
        assert (rho[inner] > 0.95 * ALPHA * size).all()
        assert rho.min() > 0.85 * ALPHA * size
    # ... and the convex element also holds points that are too curved (the small disc)
    (convex,) = [seg for seg in outline.segments if seg.symbol == ")"]
    s, _ = exact_frame(poly.exterior, convex.points[::10])
    rho = exact_rho(poly.exterior, s, width)
    tight = convex.points[::10][rho < 0.95 * ALPHA * size]
    assert len(tight) > 0.3 * len(rho)
    taken = np.vstack([r.points for r in curves])
    assert np.linalg.norm(tight[:, None] - taken[None], axis=2).min() > 1.0


def test_regions_are_scale_invariant():
    small = outline_image(render("figure3", scale=0.5, rotation=10))
    large = outline_image(render("figure3", scale=2.0, rotation=250))
    a, b = feasible_regions(small), feasible_regions(large)
    assert [r.type for r in a] == [r.type for r in b]
    for ra, rb in zip(a, b):
        # within resolution: at 0.5x the thorn's thin tip is lost, which moves the cusp's window
        assert ra.length / small.perimeter == pytest.approx(rb.length / large.perimeter, abs=0.025)


def test_parameters():
    outline = outline_image(render("figure3"))
    count = lambda **kw: sum(len(r.points) for r in feasible_regions(outline, **kw))  # noqa: E731
    assert count(alpha=0.3) >= count(alpha=0.5) >= count(alpha=1.0) > 0
    assert count(margin=0.0) > count(margin=0.05)
    assert count(finger_width=2.5) == 0  # no element is that long (the longest, ')', is about 1.9)
    with pytest.raises(ValueError):
        feasible_regions(outline, finger_width=0)


def test_json_ready():
    outline = outline_image(render("figure3"))
    regions = feasible_regions(outline)
    out = json.loads(json.dumps(regions_to_dict(outline, regions)))
    assert out["string"] == outline.string and len(out["regions"]) == len(regions)
    for row, region in zip(out["regions"], regions):
        assert row["type"] == region.type
        np.testing.assert_allclose(row["points"], region.points)
        np.testing.assert_allclose(row["normals"], region.normals)
        assert (row["rho"] is None) == (region.type == "/")


@pytest.mark.parametrize("image, largest", [(data.horse(), False), (data.coins(), True)])
def test_real_images(image, largest):
    regions = regions_image(image, largest=largest)
    assert regions
    grey = image.astype(float)
    for region in regions:
        np.testing.assert_allclose(np.linalg.norm(region.normals, axis=1), 1.0)
        # two pixels along the normal is object, two pixels against it is background
        inward = np.round(region.points + 2 * region.normals).astype(int)
        outward = np.round(region.points - 2 * region.normals).astype(int)
        a, b = grey[inward[:, 1], inward[:, 0]], grey[outward[:, 1], outward[:, 0]]
        dark_object = grey[0, 0] > grey.mean()
        if dark_object:
            a, b = -a, -b
        assert np.mean(a > b) > 0.95

"""FormGrasp: lines of action, the best completion per start point, closure checked independently."""

import itertools

import numpy as np
import pytest
import shapely

from qualgrasp.certify import Contact, Grasp, form_closure
from qualgrasp.qualitative.synthesis.candidates import Candidates, candidates, object_frame
from qualgrasp.qualitative.errors import SynthesisError
from qualgrasp.qualitative.synthesis.formgrasp import ERROR, GAP, closure_depth4, form_grasps, line_of_action_exit, zone_steps
from qualgrasp.qualitative.objects import render, shape
from qualgrasp.qualitative.vision.outline import outline_image
from qualgrasp.qualitative.synthesis.regions import feasible_regions
from qualgrasp.qualitative.synthesis.zones import free_depth, zones


def setup(name, **pose):
    image = render(name, **pose)
    outline = outline_image(image)
    regions = feasible_regions(outline)
    cands = candidates(outline, regions)
    center, length = object_frame(outline.contour)
    return outline, regions, cands, center, length


@pytest.fixture(scope="module")
def objects():
    return {name: setup(name) for name in ("polygon", "nut", "figure3", "disc")}


def test_line_of_action_exit():
    square = np.array([[0.0, 0], [10, 0], [10, 10], [0, 10]])
    np.testing.assert_allclose(line_of_action_exit(np.array([0.0, 3]), np.array([1.0, 0]), square), [10, 3])
    # a U shape: the line crosses the boundary three times beyond the start; the farthest counts
    u = np.array([[0.0, 0], [9, 0], [9, 9], [6, 9], [6, 3], [3, 3], [3, 9], [0, 9]])
    np.testing.assert_allclose(line_of_action_exit(np.array([0.0, 6]), np.array([1.0, 0]), u), [9, 6])
    assert line_of_action_exit(np.array([0.0, 3]), np.array([-1.0, 0]), square) is None


def test_object_frame_is_the_area_centroid():
    poly = shape("polygon", rotation=30)
    outline = outline_image(render("polygon", rotation=30))
    center, radius = object_frame(outline.contour)
    exterior = shapely.Polygon(poly.exterior)
    assert np.linalg.norm(center - np.array(exterior.centroid.coords[0])) < 0.5
    hausdorff = shapely.hausdorff_distance(exterior.exterior, shapely.Point(center))
    assert radius == pytest.approx(hausdorff, abs=1.0)  # corners are rounded by the pixels


@pytest.mark.parametrize("name, least", [("polygon", 10), ("nut", 10), ("figure3", 3)])
def test_form_closure_grasps_found_and_closed(objects, name, least):
    outline, regions, cands, center, length = objects[name]
    found = form_grasps(cands, outline.contour, center, length, outline.size)
    assert len(found) >= least
    keys = [frozenset(g.contacts) for g in found]
    assert len(set(keys)) == len(keys)  # duplicates removed
    assert len({g.start for g in found}) == len(found)  # one grasp per start point
    poly = shapely.Polygon(outline.contour)
    for g in found:
        assert len(g.contacts) == 4 and g.contacts[0] == g.start
        assert g.depth < -ERROR / length
        np.testing.assert_allclose(g.points, np.asarray(cands.points)[list(g.contacts)])
        assert g.regions == tuple(int(cands.region[i]) for i in g.contacts)
        d = np.linalg.norm(g.points[:, None] - g.points[None], axis=2)
        assert d[np.triu_indices(4, 1)].min() >= GAP * outline.size
        # normals point into the object
        assert shapely.contains_xy(poly, *(g.points + 3 * g.normals).T).all()
        # independent routes: the zones of freedom, and certify's linear programme
        assert zones(g.points, g.normals, center=center, length=length).status == "closure"
        grasp = Grasp(tuple(Contact(tuple(p), tuple(n)) for p, n in zip(g.points, g.normals)))
        assert form_closure(grasp).status == "closure"
        # the zone shrinks as contacts are added, and only the fourth empties it
        assert all(a >= b - 1e-12 for a, b in zip(g.depths, g.depths[1:]))
        assert min(g.depths[:3]) >= 0 > g.depths[3]


def test_the_disc_cannot_be_immobilised(objects):
    """Every normal of a disc passes through its centre: rotation about it stays free. Estimated
    normals miss the centre by a fraction of a degree, which is below the required depth."""
    outline, regions, cands, center, length = objects["disc"]
    assert form_grasps(cands, outline.contour, center, length, outline.size) == []
    # with no robustness asked, near-misses appear, but their zones are barely empty
    loose = form_grasps(cands, outline.contour, center, length, outline.size, error=0.0)
    assert all(g.depth > -ERROR / length for g in loose)
    for scale, noise in [(0.5, 10.0), (1.7, 0.0)]:
        image = render("disc", scale=scale, noise=noise, seed=3)
        o = outline_image(image)
        c = candidates(o, feasible_regions(o))
        ctr, rad = object_frame(o.contour)
        assert form_grasps(c, o.contour, ctr, rad, o.size) == []


def test_best_completion_per_start_is_exhaustive():
    """On a small candidate set, each start point's grasp is the deepest set of four containing it."""
    outline, regions, cands, center, length = setup("polygon", scale=0.8, rotation=25)
    keep = np.arange(len(cands))[::3]
    small = Candidates(*(np.asarray(a)[keep] for a in (cands.points, cands.normals, cands.region, cands.clearance)))
    found = form_grasps(small, outline.contour, center, length, outline.size, error=0.0)
    assert found
    P, N = np.asarray(small.points), np.asarray(small.normals)
    far = np.linalg.norm(P[:, None] - P[None], axis=2) >= GAP * outline.size
    sets = [s for s in itertools.combinations(range(len(P)), 4)
            if all(far[i, j] for i, j in itertools.combinations(s, 2))]
    depth = free_depth(P[np.array(sets)], N[np.array(sets)], center, length)
    for g in found:
        best = min(d for s, d in zip(sets, depth) if g.start in s)
        assert g.depth == pytest.approx(best, abs=1e-12)


def test_zone_steps_end_empty(objects):
    outline, regions, cands, center, length = objects["polygon"]
    g = form_grasps(cands, outline.contour, center, length, outline.size)[0]
    steps = zone_steps(g, center, length)
    assert [z.status for z in steps] == ["no_closure"] * 3 + ["closure"]
    assert not steps[0].translations.empty and steps[-1].translations.empty


def test_closure_depth4_rejects_open_sets():
    a = np.array([[[1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0], [-1.0, 0, 0]]])
    assert closure_depth4(a)[0] == np.inf
    b = np.array([[[1.0, 1, 1], [-1.0, -1, 1], [-1.0, 1, -1], [1.0, -1, -1]]]) / np.sqrt(3)
    assert closure_depth4(b)[0] == pytest.approx(-1 / 3)  # regular tetrahedron: inradius 1/3


def test_bad_parameters(objects):
    outline, regions, cands, center, length = objects["polygon"]
    with pytest.raises(SynthesisError):
        form_grasps(cands, outline.contour, center, length, outline.size, error=-1)
    with pytest.raises(SynthesisError):
        candidates(outline, regions, step=0)

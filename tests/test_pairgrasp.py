"""Three fingers beyond the paper's condition (issue 28, part 3): ``pairgrasp3``, an opposed pair
in force closure (Nguyen) and a third finger, finds certified grasps on polygons with parallel
faces, where the paper's condition (``forcegrasp3``) excludes every triplet."""

import re

import numpy as np
import pytest
import shapely
from shapely import affinity
from shapely.geometry import Polygon

from qualgrasp.certify import Contact, Grasp, force_closure
from qualgrasp.experiments.design import ROUTES
from qualgrasp.qualitative.synthesis import procedures
from qualgrasp.qualitative.objects import render_polygon
from qualgrasp.qualitative.synthesis.pipeline import synthesize


def _regular(n, r=150.0):
    a = np.pi / 2 + 2 * np.pi * np.arange(n) / n
    return Polygon(np.c_[r * np.cos(a), r * np.sin(a)])


# convex polygons with at least one pair of parallel faces, and the L-shape
PARALLEL = {
    "rectangle": Polygon([(-150, -60), (150, -60), (150, 60), (-150, 60)]),
    "square": _regular(4),
    "hexagon": _regular(6),
    "octagon": _regular(8),
    "parallelogram": Polygon([(-150, -70), (90, -70), (150, 70), (-90, 70)]),
    "trapezoid": Polygon([(-150, -70), (150, -70), (70, 70), (-70, 70)]),
    "L-shape": Polygon([(-150, -110), (-20, -110), (-20, -10), (150, -10), (150, 110), (-150, 110)]),
}


def _place(poly, rotation):
    return affinity.translate(affinity.rotate(poly, rotation, origin=(0, 0)), 256, 256)


def _exact(poly, grasp):
    """The grasp with each contact moved to the nearest point of the exact polygon and given that
    edge's inward normal (the true object)."""
    ring = shapely.geometry.polygon.orient(poly, 1.0).exterior
    V = np.asarray(ring.coords)
    contacts = []
    for c in grasp.contacts:
        p = np.asarray(c.p[:2])
        k = int(np.argmin([shapely.distance(shapely.LineString(V[i:i + 2]), shapely.Point(p))
                           for i in range(len(V) - 1)]))
        a, b = V[k], V[k + 1]
        t = (b - a) / np.linalg.norm(b - a)
        q = a + np.clip((p - a) @ t, 0, np.linalg.norm(b - a)) * t
        assert np.linalg.norm(q - p) < 1.0  # on the true edge
        contacts.append(Contact(tuple(q), (-t[1], t[0]), c.model, c.mu))
    return Grasp(tuple(contacts), center=grasp.center, length=grasp.length)


@pytest.mark.parametrize("name", sorted(PARALLEL))
@pytest.mark.parametrize("rotation", [0.0, 23.0])
def test_polygons_with_parallel_faces_get_certified_three_finger_grasps(name, rotation):
    poly = _place(PARALLEL[name], rotation)
    s = synthesize(render_polygon(poly), procedure="pairgrasp3", quality=False)
    assert s.grasps and all(s.certified) and s.fingers == 3
    for grasp, found in zip(s.grasps, s.found):
        assert grasp.meta["procedure"] == "PairGrasp" and grasp.meta["opposed"] == [0, 1]
        assert force_closure(_exact(poly, grasp)).status == "closure"  # holds on the true polygon
        # the pair alone is in force closure (Nguyen): the third finger adds to a closure grasp
        pair = Grasp(grasp.contacts[:2], center=grasp.center, length=grasp.length)
        assert force_closure(pair).status == "closure"
        assert max(found.angles[:2]) <= (1 - 0.25) * np.arctan(0.5) + 1e-9


def test_the_papers_condition_excludes_them():
    """On the rectangle the three normals of any triplet leave a gap of 180 degrees: forcegrasp3
    finds nothing and says so in numbers; pairgrasp3 finds grasps, the third finger across the
    grasp line."""
    image = render_polygon(_place(PARALLEL["rectangle"], 0.0))
    paper = synthesize(image, procedure="forcegrasp3", quality=False, tolerance=False)
    assert not paper.grasps and "gap of 180.0 degrees" in paper.reason
    s = synthesize(image, procedure="pairgrasp3", quality=False, tolerance=False)
    assert s.grasps
    for grasp in s.grasps:
        assert abs(np.degrees(grasp.meta["third_angle"]) - 90) < 2  # perpendicular to the grasp line


def test_why_nothing_was_found_in_numbers():
    """An equilateral triangle at mu = 0.3: two fingers on different edges see each other at best
    30 degrees off their normals (closed form: the normals are 120 degrees apart), against
    theta_min = atan(0.3) = 16.7 degrees less the margin (12.5)."""
    a = np.radians([90, 210, 330])
    image = render_polygon(Polygon(np.c_[256 + 150 * np.cos(a), 256 + 150 * np.sin(a)]), 512)
    s = synthesize(image, procedure="pairgrasp3", mu=0.3, quality=False, tolerance=False)
    assert not s.grasps
    angle = float(re.search(r"larger angle to the grasp line is ([0-9.]+) degrees", s.reason).group(1))
    assert angle == pytest.approx(30.0, abs=1.0)
    assert "theta_min 16.7 less the margin (12.5)" in s.reason


def test_registered_and_in_the_study():
    assert "pairgrasp3" in procedures.names()
    assert procedures.get("pairgrasp3").fingers == 3 and procedures.for_fingers(3).name == "forcegrasp3"
    assert ("PairGrasp", 3) in ROUTES and ("ForceGrasp", 3) in ROUTES

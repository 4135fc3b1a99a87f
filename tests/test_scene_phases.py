"""Grasp scenes as RCC-8 networks, and grasp phases as ST0 formulas checked on generated traces."""

import itertools

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from shapely.geometry import Polygon, box

from qualgrasp.qualitative.errors import FormulaError, RegionError
from qualgrasp.qualitative.reasoning.phases import (PHASES, grasp_trace, no_penetration, phase_formulas, phase_sequence,
                                                    phases_of, placement_order)
from qualgrasp.qualitative.reasoning.rcc8 import path_consistency
from qualgrasp.qualitative.reasoning.scene import grasp_scene, scene_regions
from qualgrasp.qualitative.reasoning.st0 import evaluate_file, parse, write_trace

RADIUS = 4.0
SQUARE = box(0, 0, 100, 100)
HEXAGON = Polygon([(50 + 40 * np.cos(a), 50 + 40 * np.sin(a))
                   for a in np.radians(np.arange(0, 360, 60))])


def side_contacts(poly, sides, t):
    """Points at fraction ``t`` along the given sides (counter-clockwise) and inward normals."""
    xy = np.asarray(poly.exterior.coords)
    if not poly.exterior.is_ccw:
        xy = xy[::-1]
    p, n = [], []
    for side, frac in zip(sides, np.broadcast_to(t, (len(sides),))):
        a, b = xy[side], xy[side + 1]
        d = (b - a) / np.linalg.norm(b - a)
        p.append(a + frac * (b - a))
        n.append([-d[1], d[0]])  # left of a counter-clockwise edge is inside
    return np.array(p), np.array(n)


def side_region(poly, side, lo=0.25, hi=0.75):
    xy = np.asarray(poly.exterior.coords)
    if not poly.exterior.is_ccw:
        xy = xy[::-1]
    a, b = xy[side], xy[side + 1]
    return [tuple(a + lo * (b - a)), tuple(a + hi * (b - a))]


def runs(labels):
    return [label for label, _ in itertools.groupby(labels)]


# -------------------------------------------------------------------------------- scenes

def test_scene_relations_of_known_finger_placements():
    p, n = side_contacts(SQUARE, [0, 1, 2, 3], 0.5)
    centres = np.array([
        p[0] - RADIUS * n[0],          # tangent to the bottom side at its middle
        p[1] - (RADIUS - 2) * n[1],    # pressed 2 px into the right side
        p[2] - 2 * RADIUS * n[2],      # 4 px above the top side, inside the zone
        p[3] - 30 * n[3],              # far to the left, outside the zone
        p[3] - 16 * n[3],              # straddling the zone's edge (margin 16)
    ])
    regions = [side_region(SQUARE, 0), side_region(SQUARE, 2)]
    net = grasp_scene(SQUARE, centres, RADIUS, margin=16, regions=regions, tol=RADIUS / 100)
    expected = {("O", "A"): "NTPP", ("R1", "O"): "TPP", ("R2", "O"): "TPP", ("R1", "A"): "NTPP",
                ("F1", "O"): "EC", ("F1", "R1"): "EC", ("F1", "A"): "NTPP",
                ("F2", "O"): "PO", ("F2", "A"): "NTPP",
                ("F3", "O"): "DC", ("F3", "R2"): "DC", ("F3", "A"): "NTPP",
                ("F4", "O"): "DC", ("F4", "A"): "DC",
                ("F5", "O"): "DC", ("F5", "A"): "PO", ("R1", "R2"): "DC"}
    assert {pair: net[pair] for pair in expected} == expected
    names = ["O", "A", "F1", "F2", "F3", "F4", "F5", "R1", "R2"]
    assert set(net) == {(x, y) for x in names for y in names if x != y}


def test_tolerance_makes_noisy_vision_polygons_usable():
    rng = np.random.default_rng(5)
    ring = np.asarray(SQUARE.segmentize(2.0).exterior.coords)[:-1]
    noisy = Polygon(ring + rng.uniform(-0.3, 0.3, ring.shape))
    assert noisy.is_valid
    p, n = side_contacts(SQUARE, [0, 2], 0.5)
    centres = p - RADIUS * n                          # tangent to the clean square
    regions = [side_region(SQUARE, 0), side_region(SQUARE, 2)]
    kwargs = dict(margin=16, regions=regions, region_width=3.0)
    clean = grasp_scene(SQUARE, centres, RADIUS, tol=1.0, **kwargs)
    assert clean[("F1", "O")] == clean[("F2", "O")] == "EC"
    assert grasp_scene(noisy, centres, RADIUS, tol=1.0, **kwargs) == clean
    exact = grasp_scene(noisy, centres, RADIUS, tol=0.0, **kwargs)
    assert {exact[("F1", "O")], exact[("F2", "O")]} != {"EC"}  # noise breaks exact tangency


@settings(max_examples=30)
@given(st.lists(st.tuples(st.floats(0, 100), st.floats(0, 100)), min_size=1, max_size=4),
       st.floats(2, 20), st.floats(1, 30))
def test_scene_networks_are_consistent(centres, radius, margin):
    regions = [side_region(HEXAGON, 0), side_region(HEXAGON, 3)]
    net = grasp_scene(HEXAGON, np.array(centres), radius, margin=margin, regions=regions)
    assert path_consistency(net) == {pair: frozenset({r}) for pair, r in net.items()}


def test_scene_errors():
    with pytest.raises(RegionError, match="R1 does not meet the object"):
        scene_regions(SQUARE, [[50, -10]], RADIUS, margin=16, regions=[[(200, 200), (210, 200)]])
    with pytest.raises(RegionError, match="radius"):
        scene_regions(SQUARE, [[50, -10]], 0.0, margin=16)
    with pytest.raises(RegionError, match="margin"):
        scene_regions(SQUARE, [[50, -10]], RADIUS, margin=0)
    with pytest.raises(RegionError, match="polyline"):
        scene_regions(SQUARE, [[50, -10]], RADIUS, margin=16, regions=[[(0, 0)]])
    with pytest.raises(RegionError, match="finite"):
        scene_regions(SQUARE, [[np.nan, -10]], RADIUS, margin=16)


# ------------------------------------------------------------------------------- formulas

def test_phase_formulas_are_the_documented_ones():
    f = phase_formulas(2)
    assert list(f) == list(PHASES)
    assert f["idle"] == parse("DC(F1,A) & DC(F2,A)")
    assert f["pregrasp"] == parse("{TPP,NTPP}(F1,A) & {TPP,NTPP}(F2,A) & DC(F1,O) & DC(F2,O)")
    assert f["grasp"] == parse("EC(F1,O) & EC(F2,O)")
    assert placement_order([0, 1, 2]) == parse("G(EC(F2,O) -> O(EC(F1,O))) & G(EC(F3,O) -> O(EC(F2,O)))")
    assert no_penetration(1) == parse("G(!{PO,TPP,NTPP,EQ,TPPi,NTPPi}(F1,O))")
    with pytest.raises(FormulaError):
        placement_order([0, 0])
    with pytest.raises(FormulaError):
        phase_formulas(0)


# ---------------------------------------------------------------------------------- traces

CASES = {
    "square, 4 fingers": (SQUARE, [0, 1, 2, 3], [0, 2, 1, 3]),
    "hexagon, 3 fingers": (HEXAGON, [0, 2, 4], [2, 0, 1]),
    "hexagon, 1 finger": (HEXAGON, [1], [0]),
}


@pytest.mark.parametrize("name", CASES)
def test_planned_grasp_satisfies_phases_order_and_no_penetration(name):
    obj, sides, order = CASES[name]
    p, n = side_contacts(obj, sides, 0.5)
    regions = [side_region(obj, s) for s in sides]
    trace = grasp_trace(obj, p, n, RADIUS, order=order, regions=regions)
    k = len(sides)
    assert len(trace) == 1 + 2 * k * 4
    expected_runs = ["idle", "approach", "pregrasp", "placing", "grasp"] if k > 1 else \
        ["idle", "approach", "pregrasp", "grasp"]
    assert runs(phases_of(trace, k)) == expected_runs
    assert phase_sequence(k).holds(trace)
    assert no_penetration(k).holds(trace)
    if k > 1:
        assert placement_order(order).holds(trace)
        assert not placement_order(sorted(order, reverse=True)).holds(trace)
    # every finger ends on its feasible grasp region, and only touches the object at the end
    for i in range(k):
        assert parse(f"F G EC(F{i + 1},R{i + 1}) & (DC(F{i + 1},O) U G EC(F{i + 1},O))").holds(trace)


def test_phases_are_exclusive_and_exhaustive_on_generated_traces():
    p, n = side_contacts(SQUARE, [0, 1, 2, 3], 0.3)
    for depth in (0.0, [0, 2, 0, 0]):
        trace = grasp_trace(SQUARE, p, n, RADIUS, depth=depth)
        values = np.array([f.evaluate(trace) for f in phase_formulas(4).values()])
        assert values.sum(axis=0).max() <= 1
        if depth == 0.0:
            assert values.sum(axis=0).min() == 1


def test_wrong_order_violates_the_order_formula():
    p, n = side_contacts(HEXAGON, [0, 2, 4], 0.5)
    trace = grasp_trace(HEXAGON, p, n, RADIUS, order=[1, 0, 2])
    assert not placement_order([0, 1, 2]).holds(trace)
    assert placement_order([1, 0, 2]).holds(trace)
    assert phase_sequence(3).holds(trace)   # the phases do not care about the order


def test_penetrating_finger_violates_no_penetration():
    p, n = side_contacts(SQUARE, [0, 1, 2, 3], 0.5)
    trace = grasp_trace(SQUARE, p, n, RADIUS, depth=[0, 0, 1.5, 0])
    assert not no_penetration(4).holds(trace)
    assert no_penetration(4).evaluate(trace).tolist() == [False] * len(trace)
    # the culprit is finger 3, and only at the end of its move
    assert parse("G {DC,EC}(F3,O)").evaluate(trace)[-1] == False  # noqa: E712
    assert parse("F PO(F3,O)").holds(trace)
    assert parse("G !{PO,TPP,NTPP,EQ,TPPi,NTPPi}(F1,O)").holds(trace)
    assert not phase_sequence(4).holds(trace)


@settings(max_examples=12)
@given(st.permutations([0, 1, 2]), st.permutations([0, 1, 2]), st.floats(0.2, 0.8))
def test_order_formula_holds_exactly_for_the_executed_order(executed, claimed, t):
    p, n = side_contacts(HEXAGON, [1, 3, 5], t)
    trace = grasp_trace(HEXAGON, p, n, RADIUS, order=executed, steps=2)
    assert placement_order(claimed).holds(trace) == (list(claimed) == list(executed))
    assert phase_sequence(3).holds(trace) and no_penetration(3).holds(trace)


def test_generated_trace_checked_end_to_end_from_a_file(tmp_path):
    p, n = side_contacts(SQUARE, [0, 2], 0.5)
    trace = grasp_trace(SQUARE, p, n, RADIUS, order=[1, 0])
    path = tmp_path / "grasp.json"
    write_trace(trace, path)
    assert evaluate_file(str(phase_sequence(2)), path)[0]
    assert evaluate_file(str(placement_order([1, 0])), path)[0]
    assert not evaluate_file(placement_order([0, 1]), path)[0]


def test_generator_errors():
    p, n = side_contacts(SQUARE, [0, 2], 0.5)
    with pytest.raises(RegionError, match="margin"):
        grasp_trace(SQUARE, p, n, RADIUS, margin=2 * RADIUS)
    with pytest.raises(RegionError, match="permutation"):
        grasp_trace(SQUARE, p, n, RADIUS, order=[0, 0])
    with pytest.raises(RegionError, match="normal"):
        grasp_trace(SQUARE, p, n[:1], RADIUS)

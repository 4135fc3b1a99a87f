"""Regions a finger can use (issue 28, part 2): on polygons with known edges, every straight edge
at least two finger widths long gets a feasible region of nearly its length less the margins.

A pad centre may come within ``margin`` of an outward corner (the pad overhangs it) and within
``margin`` plus half a pad of an inward one (the other face blocks the pad), measured from the
corner itself, not from the end of the corner's window in the outline. The table of every edge
is printed (``pytest -s``)."""

import numpy as np
import pytest
import shapely
from shapely import affinity
from shapely.geometry import Polygon

from qualgrasp.qualitative.objects import render_polygon
from qualgrasp.qualitative.synthesis.regions import FINGER_WIDTH, MARGIN, regions_image


def _regular(n: int, r: float = 150.0) -> Polygon:
    a = np.pi / 2 + 2 * np.pi * np.arange(n) / n
    return Polygon(np.c_[r * np.cos(a), r * np.sin(a)])


SHAPES = {
    "rectangle 2:1": Polygon([(-150, -75), (150, -75), (150, 75), (-150, 75)]),
    "rectangle, short side 2.2 W": Polygon([(-150, -26.85), (150, -26.85), (150, 26.85), (-150, 26.85)]),
    "L-shape": Polygon([(-150, -110), (-20, -110), (-20, -10), (150, -10), (150, 110), (-150, 110)]),
    "thin L-shape": Polygon([(-150, -130), (-80, -130), (-80, 70), (150, 70), (150, 130), (-150, 130)]),
    **{f"regular {n}-gon": _regular(n) for n in (3, 4, 5, 6, 8)},
}
POSES = [(0.6, 0.0), (1.0, 17.0), (1.0, 45.0), (1.3, 200.0)]


def edge_coverage(poly: Polygon, size: int = 512) -> list[dict]:
    """Per edge of ``poly`` (pixels): its length in finger widths, the straight region on it
    (contact positions along the edge), the share of the edge its contacts span (``contacts``),
    the share its pads cover (``pads``: contacts +- half a pad, within the edge) and the contact
    span expected, the edge less the margins (``expected``)."""
    regions = [r for r in regions_image(render_polygon(poly, size)) if r.type == "/"]
    D = 2 * shapely.minimum_bounding_radius(poly)
    W, m = FINGER_WIDTH * D, MARGIN * D
    ring = shapely.geometry.polygon.orient(poly, 1.0)
    V = np.asarray(ring.exterior.coords)[:-1]
    rows = []
    for k in range(len(V)):
        a, b = V[k], V[(k + 1) % len(V)]
        L = float(np.linalg.norm(b - a))
        t = (b - a) / L
        # an end's keep: the margin at an outward corner, the margin and half a pad at an inward one
        keeps = []
        for p, q, r in ((V[k - 1], a, b), (a, b, V[(k + 2) % len(V)])):
            turn = (q - p)[0] * (r - q)[1] - (q - p)[1] * (r - q)[0]
            keeps.append(m if turn > 0 else m + W / 2)
        span = (0.0, 0.0)
        for reg in regions:
            s = (reg.points - a) @ t
            on = (np.abs((reg.points - a) @ np.array([-t[1], t[0]])) < 1.5) & (s > -1) & (s < L + 1)
            if on.sum() >= 2 and s[on].max() - s[on].min() > span[1] - span[0]:
                span = (float(s[on].min()), float(s[on].max()))
        lo, hi = span
        pads = (min(L, hi + W / 2) - max(0.0, lo - W / 2)) / L if hi > lo else 0.0
        rows.append({"length_w": L / W, "length": L, "contacts": (hi - lo) / L, "pads": pads,
                     "expected": (L - sum(keeps)) / L})
    return rows


def _table() -> list[tuple[str, float, float, dict]]:
    out = []
    for name, poly in SHAPES.items():
        for scale, rotation in POSES:
            placed = affinity.translate(affinity.rotate(affinity.scale(poly, scale, scale, origin=(0, 0)),
                                                        rotation, origin=(0, 0)), 256, 256)
            out += [(name, scale, rotation, row) for row in edge_coverage(placed)]
    return out


@pytest.fixture(scope="module")
def table():
    rows = _table()
    print("\nshape | size x | rotation | edge (finger widths) | contacts / edge | expected | pads / edge")
    for name, scale, rotation, r in rows:
        print(f"{name} | {scale:g} | {rotation:g} | {r['length_w']:.1f} | {r['contacts']:.3f} | "
              f"{r['expected']:.3f} | {r['pads']:.3f}")
    return rows


def test_every_edge_two_fingers_long_is_covered(table):
    long = [r for *_, r in table if r["length_w"] >= 2]
    assert len(long) > 100
    assert min(r["pads"] for r in long) >= 0.8
    # contacts run over the whole edge less the margins, within three pixels at each end (the image
    # blunts a corner by a pixel or two: the edge is taken to end where the contour leaves its line)
    assert all(r["contacts"] >= r["expected"] - 6.0 / r["length"] for r in long)


def test_long_edges_lose_only_the_margins(table):
    """Edges of five finger widths and more: contacts over at least 80 % of every one and 90 % of
    most (the margins take a quarter of a pad at an outward corner, three quarters at an inward one)."""
    long = [r for *_, r in table if r["length_w"] >= 5]
    assert min(r["contacts"] for r in long) >= 0.8
    assert np.median([r["contacts"] for r in long]) >= 0.9

"""Zones of freedom: geometry against independent half-plane clipping, emptiness against certify's LP."""

import collections
import itertools
import math

import numpy as np
import pytest
import shapely
from scipy.optimize import minimize
from shapely.geometry import Polygon

from qualgrasp.certify import Contact, Grasp, form_closure
from qualgrasp.qualitative.errors import QualitativeError, ZoneError
from qualgrasp.qualitative.synthesis.formgrasp import closure_depth4
from qualgrasp.qualitative.synthesis.zones import TOL, free_depth, grasp_zones, twist_constraints, zones

# Band used when one route calls a grasp degenerate: the other must be degenerate too, or the case
# must lie within this band on its own scale (zone depth, or the LP's min-weight margin).
BAND = 1e-4


def unit(angle):
    return np.array([math.cos(angle), math.sin(angle)])


def cross2(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def random_grasp(rng, k):
    p = rng.uniform(-1.0, 1.0, (k, 2))
    a = rng.uniform(0.0, 2 * np.pi, k)
    return p, np.column_stack([np.cos(a), np.sin(a)])


def half_plane(p, n, sign, box, big):
    """Independent route: the closed half-plane {c : sign * cross(p - c, n) >= 0} clipped to a box.

    With ``c = p + s * left``, ``left = (-n_y, n_x)``: ``cross(p - c, n) = -s cross(left, n) = s``,
    so the positive side is the one ``left`` points to.
    """
    left = np.array([-n[1], n[0]])
    side = left if sign > 0 else -left
    a, b = p - big * n, p + big * n
    return Polygon([a, b, b + big * side, a + big * side]).intersection(box)


# ------------------------------------------------------------------------------------ geometry


@pytest.mark.parametrize("k", [1, 2, 3, 4, 5])
def test_zones_match_half_plane_clipping(k):
    rng = np.random.default_rng(k)
    bounds = (-6.0, -6.0, 6.0, 6.0)
    box = shapely.box(*bounds)
    for _ in range(40):
        p, n = random_grasp(rng, k)
        z = zones(p, n)
        for zone in (z.plus, z.minus):
            expected = box
            for pi, ni in zip(p, n):
                expected = expected.intersection(half_plane(pi, ni, zone.sign, box, 1e3))
            got = zone.polygon(bounds)
            assert got.symmetric_difference(expected).area <= 1e-6 * box.area
            # every vertex and every far point along a direction satisfies all the constraints
            for v in zone.vertices:
                assert (zone.sign * cross2(p - v, n) >= -1e-9).all()
                for d in zone.directions:
                    far = v + 1e3 * d
                    assert (zone.sign * cross2(p - far, n) >= -1e-6).all()


def test_sign_convention_on_screen():
    """A finger pushing left (inward normal -x) at p: rotations with w > 0 (turning +x towards +y,
    clockwise on screen) are allowed about centres above p on screen (smaller y)."""
    z = zones([[10.0, 5.0]], [[-1.0, 0.0]])
    above, below = np.array([10.0, 0.0]), np.array([10.0, 9.0])
    assert shapely.contains_xy(z.plus.polygon((0, -10, 20, 20)), *above)
    assert shapely.contains_xy(z.minus.polygon((0, -10, 20, 20)), *below)
    # velocity of p under w > 0 about `above`: w * (-(p - c)_y, (p - c)_x) points to -x, into the object
    p, c = np.array([10.0, 5.0]), above
    v = np.array([-(p - c)[1], (p - c)[0]])
    assert v @ np.array([-1.0, 0.0]) > 0


def test_translations_follow_the_angular_gap_rule():
    rng = np.random.default_rng(5)
    for _ in range(300):
        k = int(rng.integers(1, 6))
        _, n = random_grasp(rng, k)
        t = zones(np.zeros((k, 2)) + rng.normal(size=(k, 2)), n).translations
        angles = np.sort(np.arctan2(n[:, 1], n[:, 0]))
        gap = np.max(np.diff(np.concatenate([angles, angles[:1] + 2 * np.pi])))
        assert t.half_width == pytest.approx((gap - np.pi) / 2, abs=1e-12)
        if not t.empty:  # the arc's directions are free: v . n >= 0 for all normals
            for d in np.vstack([t.ends, t.centre]):
                assert (n @ d >= -1e-12).all()
        else:  # its centre is the least blocked direction, and is blocked
            assert (n @ t.centre).min() < 0


def test_recession_directions_are_translations():
    """Centres far along a direction d of Z+ are the translation (d_y, -d_x); of Z-, (-d_y, d_x)."""
    rng = np.random.default_rng(6)
    seen = 0
    for _ in range(300):
        p, n = random_grasp(rng, int(rng.integers(1, 4)))
        z = zones(p, n)
        for zone in (z.plus, z.minus):
            for d in zone.directions:
                v = zone.sign * np.array([d[1], -d[0]])
                assert (n @ v >= -1e-9).all()
                seen += 1
        if z.translations.empty:
            assert z.plus.bounded and z.minus.bounded
    assert seen > 100


def test_depth_is_the_largest_free_cap():
    """The enumerated depth is attained (a unit twist reaches it) and no sampled twist beats it."""
    rng = np.random.default_rng(7)
    samples = rng.normal(size=(40_000, 3))
    samples /= np.linalg.norm(samples, axis=1, keepdims=True)
    for _ in range(40):
        p, n = random_grasp(rng, int(rng.integers(1, 7)))
        a, c, L = twist_constraints(p, n)
        d = free_depth(p[None], n[None], c, L)[0]
        sampled = (samples @ a.T).min(axis=1).max()
        assert sampled <= d + 1e-12
        assert d - sampled < 0.03  # sample spacing is about 0.02 rad
        # independent optimiser: maximise s subject to a_i . y >= s, |y| = 1, from the best sample
        y0 = samples[np.argmax((samples @ a.T).min(axis=1))]
        res = minimize(lambda x: -x[3], np.append(y0, sampled), method="SLSQP",
                       constraints=[{"type": "ineq", "fun": lambda x: a @ x[:3] - x[3]},
                                    {"type": "eq", "fun": lambda x: x[:3] @ x[:3] - 1}],
                       options={"ftol": 1e-13, "maxiter": 500})
        y = res.x[:3] / np.linalg.norm(res.x[:3])
        assert (a @ y).min() <= d + 1e-12
        assert d - (a @ y).min() < 1e-7


def test_closed_form_depth_of_four_contacts():
    rng = np.random.default_rng(8)
    p = rng.uniform(-1, 1, (2000, 4, 2))
    angle = rng.uniform(0, 2 * np.pi, (2000, 4))
    n = np.stack([np.cos(angle), np.sin(angle)], axis=-1)
    d = free_depth(p, n, [0.0, 0.0], 1.0)
    u = p
    a = np.concatenate([n, (u[..., 0] * n[..., 1] - u[..., 1] * n[..., 0])[..., None]], axis=-1)
    closed = closure_depth4(a / np.linalg.norm(a, axis=-1, keepdims=True))
    inside = np.isfinite(closed)
    assert 100 < inside.sum() < 1900
    np.testing.assert_allclose(closed[inside], d[inside], atol=1e-12)
    assert (d[~inside] >= -1e-12).all()


def test_verdicts_do_not_depend_on_the_reference_frame():
    rng = np.random.default_rng(9)
    for _ in range(100):
        p, n = random_grasp(rng, int(rng.integers(3, 7)))
        a = zones(p, n)
        b = zones(p, n, center=rng.normal(size=2) * 3, length=float(rng.uniform(0.1, 10)))
        if min(abs(a.depth), abs(b.depth)) > 1e-6:
            assert a.status == b.status
            assert np.sign(a.depth) == np.sign(b.depth)
        assert a.plus.empty == b.plus.empty and a.minus.empty == b.minus.empty


def test_bad_input():
    with pytest.raises(ZoneError, match="shapes"):
        zones(np.zeros((3, 3)), np.ones((3, 3)))
    with pytest.raises(ZoneError, match="zero"):
        zones([[0, 0]], [[0, 0]])
    with pytest.raises(ZoneError, match="finite"):
        zones([[0, np.nan]], [[1, 0]])
    with pytest.raises(ZoneError, match="length"):
        zones([[0, 0]], [[1, 0]], length=0)
    with pytest.raises(QualitativeError):
        zones([], [])


# ------------------------------------------------------------------------- agreement with the LP


def near_boundary(rng, kind, eps):
    """Grasps on, or ``eps`` away from, the form-closure boundary."""
    if kind == "concurrent":  # three normal lines through one point, a fourth anywhere
        e = rng.uniform(-0.5, 0.5, 2)
        angles = rng.uniform(0, 2 * np.pi) + np.array([0, 2.1, 4.2]) + rng.uniform(-0.3, 0.3, 3)
        n = np.array([unit(a) for a in angles] + [unit(rng.uniform(0, 2 * np.pi))])
        p = np.vstack([e - rng.uniform(0.3, 1.5, (3, 1)) * n[:3], rng.uniform(-1, 1, (1, 2))])
        p[0] += eps * rng.choice([-1, 1]) * np.array([-n[0, 1], n[0, 0]])
    else:  # "opposed": two contacts pushing against each other along one line, plus two
        p1, a0 = rng.uniform(-1, 1, 2), rng.uniform(0, 2 * np.pi)
        n1 = unit(a0)
        t = np.array([-n1[1], n1[0]])
        p = np.array([p1, p1 + 1.5 * n1 + eps * rng.choice([-1, 1]) * t,
                      p1 + 0.75 * n1 + 0.6 * t, p1 + 0.4 * n1 - 0.6 * t])
        n = np.array([n1, -n1, -t, t])
        n[2:] = [unit(math.atan2(v[1], v[0]) + rng.uniform(-0.6, 0.6)) for v in n[2:]]
    return p, n


def exact_cases():
    """Exactly representable boundary cases (certify decides them in rational arithmetic)."""
    square = np.array([[1.0, 0], [-1.0, 0], [0, 1.0], [0, -1.0]])
    yield square, -square  # every normal line through the centre: rotation about it is free
    yield square[:3], -square[:3]
    p = np.array([[1.0, 0.5], [-1.0, -0.5], [-0.5, -1.0], [0.5, 1.0]])
    yield p, np.array([[-1.0, 0], [1.0, 0], [0, 1.0], [0, -1.0]])  # pinwheel: closure
    yield np.array([[0.0, 0], [1.0, 0], [2.0, 0], [3.0, 0]]), np.array([[0, 1.0]] * 4)  # one edge


def compare(p, n, counts, where):
    g = Grasp(tuple(Contact(tuple(pi), tuple(ni)) for pi, ni in zip(p, n)))
    lp = form_closure(g)
    z = grasp_zones(g)
    statuses = {z.plus.status, z.minus.status, z.translations.status}
    # closure iff all three zones are empty (and one non-empty zone is enough to say no)
    assert (z.status == "closure") == (statuses == {"empty"})
    assert (z.status == "no_closure") == ("nonempty" in statuses)
    counts[(where, lp.status, z.status)] += 1
    if "degenerate" not in (lp.status, z.status):
        return lp.status == z.status
    if lp.status == "degenerate" and z.status != "degenerate":
        return abs(z.depth) <= BAND
    if z.status == "degenerate" and lp.status == "closure":
        return lp.margin <= BAND
    return True  # both degenerate, or the LP proved no closure of a boundary case (margin 0)


def test_zones_agree_with_the_form_closure_lp(capsys):
    """Thousands of random and near-boundary grasps: zero disagreements outside the degenerate band."""
    rng = np.random.default_rng(2024)
    counts = collections.Counter()
    bad = []
    for _ in range(2000):
        p, n = random_grasp(rng, int(rng.integers(1, 8)))
        if not compare(p, n, counts, "random"):
            bad.append((p, n))
    for kind, eps in itertools.product(("concurrent", "opposed"),
                                       (0.0, 1e-13, 1e-10, 1e-8, 1e-7, 3e-7, 1e-6, 1e-5, 1e-3)):
        for _ in range(25):
            p, n = near_boundary(rng, kind, eps)
            if not compare(p, n, counts, kind):
                bad.append((p, n))
    for p, n in exact_cases():
        if not compare(p, n, counts, "exact"):
            bad.append((p, n))
    with capsys.disabled():
        print(f"\nzones vs form-closure LP (tol {TOL:g}, band {BAND:g}): (set, LP, zones): count")
        for key, value in sorted(counts.items()):
            print(f"  {key}: {value}")
        print(f"  disagreements: {len(bad)}")
    assert not bad
    total = sum(counts.values())
    assert total > 2400
    decided = sum(v for (w, a, b), v in counts.items() if a == b and a != "degenerate")
    assert decided > 0.85 * total
    # the boundary cases were really exercised: both routes called some of them degenerate
    assert sum(v for (w, a, b), v in counts.items() if a == "degenerate") > 50
    assert sum(v for (w, a, b), v in counts.items() if b == "degenerate") > 50


def test_exact_boundary_cases():
    square = np.array([[1.0, 0], [-1.0, 0], [0, 1.0], [0, -1.0]])
    z = zones(square, -square)
    assert z.status == "degenerate"
    # Z+ and Z- are exactly the centre, T is empty
    for zone in (z.plus, z.minus):
        np.testing.assert_allclose(zone.vertices, [[0.0, 0.0]], atol=1e-12)
        assert zone.bounded and abs(zone.depth) < 1e-12
    assert z.translations.empty
    p = np.array([[1.0, 0.5], [-1.0, -0.5], [-0.5, -1.0], [0.5, 1.0]])
    pinwheel = zones(p, [[-1.0, 0], [1.0, 0], [0, 1.0], [0, -1.0]])
    assert pinwheel.status == "closure" and pinwheel.plus.empty and pinwheel.minus.empty

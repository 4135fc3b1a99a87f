"""Region certificates (qualgrasp.certify.regions): closed forms, dense sampling, invariances,
pads, tampering, files and the command line.

The independent route used throughout is plain geometry written here: a planar grasp is in
force closure iff its generator wrenches positively span R^3, and they do not iff some
``y != 0`` has ``y . w <= 0`` for every generator -- and then ``y`` can be taken normal to a
plane through two generators (a facet of their cone), or the generators have rank below 3. So
``not closure`` iff the rank is below 3 or some ``y = +-(w_a x w_b)`` has ``max y . w <= 0``: a
vectorised test over thousands of sampled choices, with no solver and no qualgrasp code (a
sample it flags is then given to certify, which must agree before it counts).
"""

import itertools
import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from qualgrasp.certify import Contact, Grasp, GraspError, certify_grasp, force_closure, verify
from qualgrasp.certify.regions import (CurvedRegion, RegionTuple, StraightRegion, certify_region_file,
                                       certify_regions, in_region, independent_regions, region_from_dict,
                                       tuple_from_dict, tuple_to_dict, verify_region_file, verify_regions)
from qualgrasp.cli import app

runner = CliRunner()

# --------------------------------------------------------------------------------------------------
# Independent geometry


def generators(P, N, model, mu, width, center, length):
    """Generator wrenches (S, G, 3) of contacts at points P (S, 2) with unit normals N (S, 2)."""
    T = np.stack([-N[:, 1], N[:, 0]], axis=1)
    if model == "frictionless":
        gens = [(0.0, 0.0)]
    elif model == "point":
        gens = [(0.0, 1.0), (0.0, -1.0)]
    else:  # a pad: the friction edges at its two ends (its two end normals when mu = 0)
        gens = [(o, f) for o in (0.5, -0.5) for f in ((1.0, -1.0) if mu > 0 else (0.0,))]
    out = []
    for off, fr in gens:
        F = N + fr * mu * T
        Q = P + off * width * T - np.asarray(center)
        out.append(np.concatenate([F, ((Q[:, 0] * F[:, 1] - Q[:, 1] * F[:, 0]) / length)[:, None]], axis=1))
    return np.stack(out, axis=1)


def not_closure(W, slack=1e-9):
    """Per sample (W: (S, K, 3) generator wrenches): True when the generators do not positively
    span R^3, up to ``slack`` (a direction with max y . w / |w| <= slack, or rank below 3)."""
    W = W / np.linalg.norm(W, axis=2, keepdims=True)
    S, K, _ = W.shape
    flag = np.zeros(S, dtype=bool)
    rank_ok = np.zeros(S, dtype=bool)
    for a, b in itertools.combinations(range(K), 2):
        y = np.cross(W[:, a], W[:, b])
        norm = np.linalg.norm(y, axis=1)
        good = norm > 1e-9
        rank_ok |= good & (np.abs(np.einsum("skd,sd->sk", W, y / np.where(good, norm, 1)[:, None])) > 1e-9).any(axis=1)
        y = y / np.where(good, norm, 1)[:, None]
        vals = np.einsum("skd,sd->sk", W, y)
        flag |= good & ((vals.max(axis=1) <= slack) | ((-vals).max(axis=1) <= slack))
    return flag | ~rank_ok


def nguyen_pair(p1, n1, p2, n2, mu):
    """Two point contacts: closure iff the segment between them lies strictly inside both
    friction cones (Nguyen 1988)."""
    d = (np.asarray(p2, float) - p1) / np.linalg.norm(np.asarray(p2, float) - p1)
    half = math.atan(mu)
    return (math.acos(np.clip(np.dot(n1, d), -1, 1)) < half and math.acos(np.clip(np.dot(n2, -d), -1, 1)) < half)


# --------------------------------------------------------------------------------------------------
# Closed forms


SQUARE = [(1, -1), (1, 1), (1, 1), (-1, 1), (-1, 1), (-1, -1), (-1, -1), (1, -1)]
SQUARE_N = [(-1, 0), (-1, 0), (0, -1), (0, -1), (1, 0), (1, 0), (0, 1), (0, 1)]


def _square_pair(mu, y1, y2, d):
    return RegionTuple([StraightRegion((1, y1 - d), (1, y1 + d), (-1, 0), "point", mu=mu),
                        StraightRegion((-1, y2 - d), (-1, y2 + d), (1, 0), "point", mu=mu)], center=(0, 0), length=1)


def _worst_gap(y1, y2, d):
    """Largest |s1 - s2| with s_i in [y_i - d, y_i + d], clipped at the corners +-1."""
    lo1, hi1 = max(-1, y1 - d), min(1, y1 + d)
    lo2, hi2 = max(-1, y2 - d), min(1, y2 + d)
    return max(hi1 - lo2, hi2 - lo1)


@pytest.mark.parametrize("mu,y1,y2", [(0.5, 0.0, 0.0), (0.3, 0.2, -0.1), (0.8, 0.6, 0.5), (0.4, 0.9, 0.7),
                                      (1.2, 0.0, 0.0), (0.6, -0.9, 0.2)])
def test_two_fingers_on_opposite_sides_of_a_square(mu, y1, y2):
    """Point contacts with friction mu at (1, s1), normal (-1, 0), and (-1, s2), normal (1, 0), on
    the square [-1, 1]^2. The segment between them has direction (-2, s2 - s1): it makes the angle
    atan(|s1 - s2| / 2) with both normals, so by Nguyen's theorem the grasp is in force closure iff
    |s1 - s2| < 2 mu. With s_i anywhere in [y_i - d, y_i + d] clipped at the corners (-1 and 1),
    the worst pair is two opposite ends: g(d) = max(min(1, y1 + d) - max(-1, y2 - d),
    min(1, y2 + d) - max(-1, y1 - d)), and the regions are robust iff g(d) < 2 mu. Unclipped,
    g(d) = |y1 - y2| + 2 d, so the largest symmetric d is mu - |y1 - y2| / 2 (d < that, never
    equal: at equality the worst grasp line lies on the cones' edges, not in closure). Clipped at
    both corners, g = 2 at most: when 2 mu > 2 (mu > 1) the whole sides are robust and d is the
    distance to the farther corner. g is increasing in d, so the supremum d* solves g(d) = 2 mu.
    """
    if abs(y1 - y2) >= 2 * mu:
        pytest.skip("the grasp itself is not in closure")
    lo, hi = 0.0, 2.0  # d* by bisection on the closed form (independent of the code)
    for _ in range(60):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if _worst_gap(y1, y2, mid) < 2 * mu else (lo, mid)
    reach = max(1 - y1, y1 + 1, 1 - y2, y2 + 1)
    star = min(lo, reach)
    grasp = Grasp((Contact((1, y1), (-1, 0), "point", mu), Contact((-1, y2), (1, 0), "point", mu)),
                  center=(0, 0), length=1)
    tol = 1e-4
    r = independent_regions(SQUARE, SQUARE_N, grasp, tol=tol)
    assert r.status == "robust" and bool(verify_regions(r.regions, r.verdict))
    assert star - 2 * tol <= r.delta <= star + 1e-12
    assert r.delta_fraction == pytest.approx(r.delta / (2 * math.sqrt(2)))
    for frac, expect in ((0.9, "robust"), (1.1, "not_robust")):
        d = frac * star
        if frac > 1 and (star >= reach or _worst_gap(y1, y2, d) < 2 * mu):
            continue
        t = RegionTuple([StraightRegion((x, max(-1, y - d)), (x, min(1, y + d)), n, "point", mu=mu)
                         for (x, y, n) in ((1, y1, (-1, 0)), (-1, y2, (1, 0)))], center=(0, 0), length=1)
        v = certify_regions(t)
        assert v.status == expect and bool(verify_regions(t, v))
        if v.witness is not None:  # the witness is a real non-closure choice, by Nguyen's theorem
            (p, n), (q, m) = ((c.p, c.n) for c in v.witness.contacts)
            assert not nguyen_pair(p, n, q, m, mu)
            assert abs(p[1] - q[1]) >= 2 * mu - 1e-12


def _rectangle(A=2.0, B=1.0):
    pts = [(A, -B), (A, B), (A, B), (-A, B), (-A, B), (-A, -B), (-A, -B), (A, -B)]
    nrm = [(-1, 0), (-1, 0), (0, -1), (0, -1), (1, 0), (1, 0), (0, 1), (0, 1)]
    return pts, nrm


def test_four_frictionless_contacts_on_a_rectangle():
    """Frictionless contacts on the rectangle [-2, 2] x [-1, 1]: left (-2, y1) pushing +x, right
    (2, y2) pushing -x, bottom (x3, -1) pushing +y, top (x4, 1) pushing -y. With center 0 and
    length 1 their wrenches are (1, 0, -y1), (-1, 0, y2), (0, 1, x3), (0, -1, -x4); a strictly
    positive combination summing to 0 must weigh the two x contacts equally (a) and the two y
    contacts equally (b), leaving the torque a (y2 - y1) + b (x3 - x4) = 0: form closure iff
    (y2 - y1)(x3 - x4) < 0 (rank 3 follows from y2 != y1). At y1 = -0.25, y2 = 0.5, x3 = -1,
    x4 = 0.5 it is, with y2 > y1 and x3 < x4; sliding by d keeps y2 - d > y1 + d iff d < 0.375 and
    x3 + d < x4 - d iff d < 0.75 (no corner within reach): the largest symmetric d is 0.375. Per
    finger, grown in turn from 0.375 with the others fixed: the left and right fingers are tight
    (y1 + d1 < y2 - 0.375 = 0.125 iff d1 < 0.375), the bottom one may reach x3 + d3 < x4 - 0.375
    = 0.125, d3 < 1.125 (its own side reaches x = -2 at d3 = 1 and clips there), and the top one
    is then tight: (0.375, 0.375, 1.125, 0.375)."""
    pts, nrm = _rectangle()
    g = Grasp((Contact((-2, -0.25), (1, 0)), Contact((2, 0.5), (-1, 0)), Contact((-1, -1), (0, 1)),
               Contact((0.5, 1), (0, -1))), center=(0, 0), length=1)
    assert force_closure(g).status == "closure"
    r = independent_regions(pts, nrm, g, tol=1e-5)
    assert r.status == "robust" and 0.375 - 2e-5 <= r.delta < 0.375
    assert bool(verify_regions(r.regions, r.verdict))
    assert all(isinstance(x, StraightRegion) for x in r.regions.regions)
    a = independent_regions(pts, nrm, g, tol=1e-5, symmetric=False)
    assert a.deltas == pytest.approx((0.375, 0.375, 1.125, 0.375), abs=3e-5)
    # exactly: d3 < x4 - d4 - x3 = 1.5 - d4, with d4 the common delta (just under 0.375)
    assert 1.5 - a.deltas[3] - 2e-5 <= a.deltas[2] < 1.5 - a.deltas[3] and a.delta == min(a.deltas)
    assert bool(verify_regions(a.regions, a.verdict))


def test_pads_on_opposite_faces():
    """Two pads of width w with friction mu > 0 on the faces x = +1 (normal (-1, 0)) and x = -1
    (normal (1, 0)), centred at heights s1 and s2. A direction y = (y_x, y_y, y_tau) separates
    all eight generators (the friction edges (-1, +-mu) at (1, s1 +- w / 2) and (1, +-mu) at
    (-1, s2 +- w / 2)) iff -y_x + y_tau h + mu |y_y + y_tau| <= 0 for both right heights h and
    y_x - y_tau g + mu |y_y - y_tau| <= 0 for both left heights g. Adding the worst of each and
    |a + b| + |a - b| >= 2 |b| gives y_tau (s1 - s2) + |y_tau| (w + 2 mu) <= 0; y_tau = 0 forces
    y = 0. Hence closure iff |s1 - s2| < w + 2 mu, and the regions s_i in [y_i - d, y_i + d] are
    robust iff d < mu + w / 2 - |y1 - y2| / 2."""
    mu, w, y1, y2 = 0.4, 0.3, 0.1, -0.05
    star = mu + w / 2 - abs(y1 - y2) / 2

    def pads(d):
        return RegionTuple([StraightRegion((1, y1 - d), (1, y1 + d), (-1, 0), "pad", mu=mu, width=w),
                            StraightRegion((-1, y2 - d), (-1, y2 + d), (1, 0), "pad", mu=mu, width=w)],
                           center=(0, 0), length=1)

    for frac, expect in ((0.95, "robust"), (1.05, "not_robust")):
        v = certify_regions(pads(frac * star))
        assert v.status == expect and bool(verify_regions(pads(frac * star), v))
    v = certify_regions(pads(1.05 * star))
    s1, s2 = (c.p[1] for c in v.witness.contacts)
    assert abs(s1 - s2) >= w + 2 * mu - 1e-12 and all(c.model == "pad" for c in v.witness.contacts)
    # frictionless pads slide along the faces whatever their heights
    slide = RegionTuple([StraightRegion((1, -0.1), (1, 0.1), (-1, 0), "pad", mu=0.0, width=w),
                         StraightRegion((-1, -0.1), (-1, 0.1), (1, 0), "pad", mu=0.0, width=w)])
    assert certify_regions(slide).status == "not_robust"
    # with normal_tol (branch and bound): tilting the pads' normals by up to theta
    tilted = RegionTuple(pads(0.5 * star).regions, normal_tol=0.02, center=(0, 0), length=1)
    v = certify_regions(tilted)
    assert v.status == "robust" and v.route == "branch" and bool(verify_regions(tilted, v))


def _disc(mu, d, m, R=1.0, fingers=((0.0, 0.0), (math.pi, 0.0)), tol=0.0):
    regions = []
    for centre, shift in fingers:
        ang = np.linspace(centre + shift - d / R, centre + shift + d / R, m)
        P = R * np.c_[np.cos(ang), np.sin(ang)]
        regions.append(CurvedRegion(P, -P / R, "point", mu=mu))
    return RegionTuple(regions, normal_tol=tol, center=(0, 0), length=R)


def test_two_fingers_on_a_disc():
    """Point contacts on the circle of radius R at angles a1 (near 0) and pi + a2, normals to the
    centre. The chord between them subtends pi + a2 - a1 at the centre, so it makes the angle
    |a2 - a1| / 2 with each radius (an isosceles triangle): closure iff |a2 - a1| / 2 < atan(mu).
    Arcs of length d on each side of both give |a2 - a1| up to 2 d / R: robust iff
    d < R atan(mu). The curved route over-approximates the arcs between samples, so it may only
    certify less; with 41 samples per arc it certifies 0.9 of the limit, and finds a witness
    beyond it (the arcs' ends, exact samples)."""
    mu, R = 0.5, 2.0
    star = R * math.atan(mu)
    t = _disc(mu, 0.9 * star, 41, R)
    v = certify_regions(t)
    assert v.status == "robust" and v.route == "branch" and bool(verify_regions(t, v))
    t = _disc(mu, 1.1 * star, 41, R)
    v = certify_regions(t)
    assert v.status == "not_robust" and bool(verify_regions(t, v))
    (p, n), (q, m) = ((c.p, c.n) for c in v.witness.contacts)
    assert not nguyen_pair(p, n, q, m, mu)
    # independent_regions on the whole circle (fine polygon): certified d within 10 % below the limit
    ang = np.linspace(0, 2 * math.pi, 721)[:-1]
    circle = R * np.c_[np.cos(ang), np.sin(ang)]
    g = Grasp((Contact(circle[0], -circle[0] / R, "point", mu), Contact(circle[360], -circle[360] / R, "point", mu)))
    r = independent_regions(circle, -circle / R, g, limits=[(-1.5, 1.5), (math.pi * R - 1.5, math.pi * R + 1.5)],
                            tol=1e-3)
    assert r.status == "robust" and 0.9 * star <= r.delta <= star
    assert all(isinstance(x, CurvedRegion) for x in r.regions.regions)


def test_a_region_tuple_holding_a_known_non_closure_grasp_has_a_verified_witness():
    """Three frictionless fingers can never hold a planar object (form closure needs four); a
    tuple whose regions contain the textbook antipodal pair with friction but tilt one region's
    normal away by 40 degrees (beyond atan(0.5) = 26.6) contains a grasp out of closure."""
    tri = RegionTuple([StraightRegion((1, -0.2), (1, 0.2), (-1, 0)), StraightRegion((-1, -0.2), (-1, 0.2), (1, 0)),
                       StraightRegion((-0.2, 1), (0.2, 1), (0, -1))])
    tilt = (-math.cos(math.radians(40)), math.sin(math.radians(40)))
    bent = RegionTuple([StraightRegion((1, 0), (1, 0.1), tilt, "point", mu=0.5),
                        CurvedRegion([(-1, 0), (-1, 0.05)], [(1, 0), (1, 0)], "point", mu=0.5)])
    for t in (tri, bent):
        v = certify_regions(t)
        assert v.status == "not_robust", v.reason
        assert bool(verify_regions(t, v))
        w = force_closure(v.witness)
        assert w.status == "no_closure" and verify(v.witness, w.certificate, status="no_closure")
        for region, c in zip(t.regions, v.witness.contacts):
            assert in_region(region, c, t.normal_tol) is None


# --------------------------------------------------------------------------------------------------
# Dense sampling


def _model(rng):
    r = rng.random()
    if r < 0.5:
        return dict(model="point", mu=float(rng.uniform(0.2, 1.0)))
    if r < 0.75:
        return dict(model="pad", mu=float(rng.choice([0.0, rng.uniform(0.1, 0.8)])), width=float(rng.uniform(0.05, 0.3)))
    return dict(model="frictionless")


def _closure_grasp(rng, k, batch=64):
    """Contacts around the unit circle, normals roughly inward, in closure (clearly: the test of
    the module docstring with a slack of -1e-3 rejects every candidate near the boundary)."""
    while True:
        models = [_model(rng) for _ in range(k)]
        ang = rng.uniform(0, 2 * math.pi, (batch, k))
        tilt = rng.uniform(-0.3, 0.3, (batch, k))
        P = np.stack([np.cos(ang), np.sin(ang)], axis=2) * rng.uniform(0.6, 1.4, (batch, k, 1))
        N = -np.stack([np.cos(ang + tilt), np.sin(ang + tilt)], axis=2)
        W = np.concatenate([generators(P[:, i], N[:, i], m["model"], m.get("mu", 0.0), m.get("width", 0.0), (0, 0), 1.0)
                            for i, m in enumerate(models)], axis=1)
        ok = np.flatnonzero(~not_closure(W, slack=1e-3))
        if len(ok):
            return P[ok[0]], N[ok[0]], models


def _straight_tuple(rng, tol=0.0):
    k = int(rng.integers(2, 5))
    P, N, models = _closure_grasp(rng, k)
    regions = []
    for p, n, m in zip(P, N, models):
        t = np.array([-n[1], n[0]])
        lo, hi = (0.0, 0.0) if rng.random() < 0.1 else rng.uniform(0, 0.5, 2) * rng.choice([0.3, 1.0])
        regions.append(StraightRegion(p - lo * t, p + hi * t, n, **m))
    return RegionTuple(regions, normal_tol=tol)


def _straight_samples(t, rng, S):
    W = []
    for r in t.regions:
        lam = rng.random(S)
        lam[:2] = (0.0, 1.0)
        P = np.array(r.a) + lam[:, None] * (np.array(r.b) - np.array(r.a))
        ang = math.atan2(r.n[1], r.n[0]) + rng.uniform(-1, 1, S) * t.normal_tol
        N = np.c_[np.cos(ang), np.sin(ang)] if t.normal_tol else np.tile(r.n, (S, 1))
        W.append(generators(P, N, r.model, r.mu, r.width, t.center, t.length))
    return np.concatenate(W, axis=1)


def _ellipse(A, B, s):
    P = np.c_[A * np.cos(s), B * np.sin(s)]
    N = -np.c_[np.cos(s) / A, np.sin(s) / B]
    return P, N / np.linalg.norm(N, axis=1)[:, None]


def _curved_tuple(rng):
    """Regions on an ellipse: curved ones sampled at 2 to 24 points, some straight ones on its
    tangents; the true curve between samples is the ellipse (its normal turns monotonically,
    as the reading of curved regions assumes)."""
    A, B = rng.uniform(0.8, 1.5), rng.uniform(0.6, 1.2)
    tol = float(rng.choice([0.0, rng.uniform(0, 0.03)]))
    while True:
        k = int(rng.integers(2, 5))
        s = rng.uniform(0, 2 * math.pi, k)
        P, N = _ellipse(A, B, s)
        models = [dict(model="point", mu=float(rng.uniform(0.3, 1.0))) if rng.random() < 0.6 else
                  dict(model="pad", mu=float(rng.uniform(0.2, 0.8)), width=float(rng.uniform(0.05, 0.2))) for _ in range(k)]
        if force_closure(Grasp(tuple(Contact(p, n, **m) for p, n, m in zip(P, N, models)))).status == "closure":
            break
    regions, truth = [], []
    for si, p, n, m in zip(s, P, N, models):
        if rng.random() < 0.2:
            t = np.array([-n[1], n[0]])
            lo, hi = rng.uniform(0, 0.15, 2)
            regions.append(StraightRegion(p - lo * t, p + hi * t, n, **m))
            truth.append(None)
        else:
            span = rng.uniform(0.0, 0.5)
            ss = np.linspace(si - span, si + span, int(rng.integers(2, 25)))
            Q, M = _ellipse(A, B, ss)
            regions.append(CurvedRegion(Q, M, **m))
            truth.append((A, B, ss[0], ss[-1]))
    return RegionTuple(regions, normal_tol=tol), truth


def _curved_samples(t, truth, rng, S):
    W = []
    for r, tr in zip(t.regions, truth):
        if tr is None:
            lam = rng.random(S)
            P = np.array(r.a) + lam[:, None] * (np.array(r.b) - np.array(r.a))
            N = np.tile(r.n, (S, 1))
        else:
            P, N = _ellipse(tr[0], tr[1], rng.uniform(tr[2], tr[3], S))
        ang = np.arctan2(N[:, 1], N[:, 0]) + rng.uniform(-1, 1, S) * t.normal_tol
        N = np.c_[np.cos(ang), np.sin(ang)]
        W.append(generators(P, N, r.model, r.mu, r.width, t.center, t.length))
    return np.concatenate(W, axis=1)


def _check_witness(t, v):
    assert bool(verify_regions(t, v)), verify_regions(t, v).reason
    w = force_closure(v.witness)
    assert w.status == "no_closure"
    gens = [generators(np.array([c.p]), np.array([c.n]), c.model, c.mu, c.param("width", 0.0), v.witness.center,
                       v.witness.length) for c in v.witness.contacts]
    assert not_closure(np.concatenate(gens, axis=1), slack=1e-7)[0]
    for region, c in zip(t.regions, v.witness.contacts):
        assert in_region(region, c, t.normal_tol) is None


@pytest.mark.slow
def test_dense_sampling_never_finds_a_non_closure_choice_in_a_robust_tuple():
    """1,400 random straight tuples (1,200 on the exact route, 200 with normal_tol through the
    branch and bound) and 250 curved ones on ellipses, 200 sampled choices each (the segments'
    ends always among them): no sample of a robust tuple is out of closure (the independent test of
    the module docstring, with a slack of 1e-9: none is even near the boundary), every witness is
    a real non-closure choice in its regions, and every verdict re-checks."""
    rng = np.random.default_rng(20240614)
    S = 200
    counts = {"robust": 0, "not_robust": 0, "undecided": 0}
    samples = 0
    for n in range(1650):
        if n < 1200:
            t, truth = _straight_tuple(rng), None
        elif n < 1400:
            t, truth = _straight_tuple(rng, tol=float(rng.uniform(0, 0.05))), None
        else:
            t, truth = _curved_tuple(rng)
        v = certify_regions(t, budget=30_000)
        counts[v.status] += 1
        if v.status == "robust":
            assert bool(verify_regions(t, v))
            W = _straight_samples(t, rng, S) if truth is None else _curved_samples(t, truth, rng, S)
            bad = np.flatnonzero(not_closure(W))
            samples += S
            assert not len(bad), (tuple_to_dict(t), bad[:5])
        elif v.status == "not_robust":
            _check_witness(t, v)
        else:
            assert t.normal_tol > 0 or not t.straight, "straight regions with normal_tol 0 are decided exactly"
    assert counts["robust"] > 600 and counts["not_robust"] > 500 and samples >= 120_000
    assert counts["undecided"] <= 40


# --------------------------------------------------------------------------------------------------
# Invariances, points, pads


def _moved(t, angle, shift, order):
    R = np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])
    mv = lambda p: tuple(R @ np.asarray(p, float) + shift)
    rot = lambda n: tuple(R @ np.asarray(n, float))
    out = []
    for r in t.regions:
        if isinstance(r, StraightRegion):
            out.append(StraightRegion(mv(r.a), mv(r.b), rot(r.n), r.model, **dict(r.params)))
        else:
            out.append(CurvedRegion([mv(p) for p in r.points], [rot(n) for n in r.normals], r.model, **dict(r.params)))
    return RegionTuple([out[i] for i in order], t.normal_tol, center=mv(t.center), length=t.length)


BASES = {
    "square-robust": _square_pair(0.5, 0.1, -0.05, 0.3),
    "square-not": _square_pair(0.5, 0.1, -0.05, 0.6),
    "rectangle": RegionTuple([StraightRegion((-2, -0.5), (-2, 0), (1, 0)), StraightRegion((2, 0.3), (2, 0.7), (-1, 0)),
                              StraightRegion((-1.2, -1), (-0.8, -1), (0, 1)), StraightRegion((0.3, 1), (0.7, 1), (0, -1))]),
    "disc-robust": _disc(0.6, 0.35, 9),
    "disc-not": _disc(0.6, 0.75, 9),
    "tilted-robust": RegionTuple(_square_pair(0.5, 0.0, 0.0, 0.3).regions, normal_tol=0.05),
}


@settings(max_examples=12, deadline=None)
@given(st.sampled_from(sorted(BASES)), st.floats(-math.pi, math.pi), st.floats(-50, 50), st.floats(-50, 50),
       st.permutations(range(4)))
def test_verdicts_are_invariant_to_rigid_motions_and_to_the_order_of_regions(name, angle, dx, dy, perm):
    t = BASES[name]
    order = [i for i in perm if i < len(t.regions)]
    a = certify_regions(t)
    moved = _moved(t, angle, np.array([dx, dy]), order)
    b = certify_regions(moved)
    assert a.status == b.status and a.status in ("robust", "not_robust")
    assert bool(verify_regions(moved, b))


def test_a_region_of_length_zero_gives_the_point_grasps_verdict():
    """Regions of length 0 are the grasp: its verdict is certify_grasp's (closure: robust,
    no_closure: not robust with the grasp itself as witness); regions of length 1e-9 go through
    the exact LP route and agree wherever certify's margin is clear."""
    from qualgrasp.certify.batch import random_grasps
    mapping = {"closure": "robust", "no_closure": "not_robust", "degenerate": "undecided"}
    agree = tiny = 0
    grasps = random_grasps(5, 150, dim=2, n_contacts=3) + random_grasps(6, 100, dim=2, n_contacts=2, model="pad")
    for g in grasps:
        report = certify_grasp(g, quality=False)
        t = RegionTuple([StraightRegion(c.p, c.p, c.n, c.model, **dict(c.params)) for c in g.contacts],
                        center=g.center, length=g.length)
        v = certify_regions(t)
        assert v.route == "point" and v.status == mapping[report.force.status]
        assert bool(verify_regions(t, v))
        if v.witness is not None:
            assert [c.p for c in v.witness.contacts] == [c.p for c in g.contacts]
        agree += 1
        if report.force.status == "closure" and report.force.margin < 1e-4:
            continue
        if report.force.status == "no_closure":
            cert = report.force.certificate  # its Farkas direction, strictly separating with a margin?
            W = generators_of(g)[0]
            W = W / np.linalg.norm(W, axis=1)[:, None]
            if cert.tight or (W @ np.array(cert.y)).max() > -1e-6 * np.linalg.norm(cert.y):
                continue  # too near the boundary for a 1e-9 stretch to be sure to stay out
        grown = RegionTuple([StraightRegion(c.p, (c.p[0] + 1e-9 * c.n[1], c.p[1] - 1e-9 * c.n[0]), c.n, c.model,
                                            **dict(c.params)) for c in g.contacts], center=g.center, length=g.length)
        w = certify_regions(grown)
        if w.status != "undecided":
            assert w.route == "exact" and w.status == mapping[report.force.status]
            tiny += 1
    assert agree == len(grasps) and tiny > 150


def generators_of(g):
    return np.concatenate([generators(np.array([c.p]), np.array([c.n]), c.model, c.mu, c.param("width", 0.0),
                                      g.center, g.length) for c in g.contacts], axis=1)


# --------------------------------------------------------------------------------------------------
# Tampering


def test_the_exact_checker_rejects_tampered_certificates():
    t = _square_pair(0.5, 0.0, 0.0, 0.3)
    v = certify_regions(t)
    assert v.route == "exact" and bool(verify_regions(t, v))
    cert = json.loads(json.dumps(v.certificate))
    face = next(f for f in cert["faces"] if max(f["lambda"]) > 0.1)
    j = int(np.argmax(face["lambda"]))
    face["lambda"][j] = -face["lambda"][j]
    bad = verify_regions(t, {"status": "robust", "certificate": cert})
    assert not bad and "negative" in bad.reason
    cert = json.loads(json.dumps(v.certificate))
    for f in cert["faces"]:
        f["lambda"] = list(reversed(f["lambda"]))  # multipliers on the wrong rows
    assert not verify_regions(t, {"status": "robust", "certificate": cert})
    # a region moved: the same certificate no longer excludes the faces
    moved = _square_pair(0.5, 0.0, 0.0, 0.6)
    assert not verify_regions(moved, v)
    assert not verify_regions(t, {"status": "robust", "certificate": {"kind": "faces", "faces": cert["faces"][:9]}})
    # cells certificates: a region moved, a cell dropped, a piece's candidate changed
    c = _disc(0.5, 0.3, 9)
    vc = certify_regions(c)
    assert vc.route == "branch" and bool(verify_regions(c, vc))
    assert not verify_regions(_disc(0.5, 0.6, 9), vc)
    cert = json.loads(json.dumps(vc.certificate))
    cert["cells"] = cert["cells"][1:]
    assert "cover" in verify_regions(c, {"status": "robust", "certificate": cert}).reason
    cert = json.loads(json.dumps(vc.certificate))
    cert["cells"][0][-1][0][-1] = 1 - cert["cells"][0][-1][0][-1]
    assert not verify_regions(c, {"status": "robust", "certificate": cert})
    # witnesses: moved off the segment, or a Farkas direction changed sign
    n = certify_regions(_square_pair(0.5, 0.0, 0.0, 0.7))
    row = n.row(verified=True)
    row["witness"]["grasp"]["contacts"][0]["p"][0] += 1e-9
    assert "not exactly on the segment" in verify_regions(_square_pair(0.5, 0.0, 0.0, 0.7), row).reason
    row = n.row(verified=True)
    row["witness"]["certificate"]["y"] = [-v for v in row["witness"]["certificate"]["y"]]
    assert not verify_regions(_square_pair(0.5, 0.0, 0.0, 0.7), row)
    # a witness outside the (shrunk) regions
    assert "not exactly on the segment" in verify_regions(_square_pair(0.5, 0.0, 0.0, 0.65), n).reason


# --------------------------------------------------------------------------------------------------
# Validation, files and the command line


@pytest.mark.parametrize("value,message", [
    ({"a": [0, "x"], "b": [1, 0], "n": [0, 1]}, r'regions\[2\]\.a: expected 2 finite numbers, got \[0, "x"\]'),
    ({"a": [0, 0, 0], "b": [1, 0], "n": [0, 1]}, r"regions\[2\]\.a: .*spatial regions are not supported"),
    ({"a": [0, 0], "b": [1, 0], "n": [0, 0]}, r"regions\[2\]\.n: normal n is zero"),
    ({"a": [0, 0], "b": [1, 0], "n": [0, 1], "model": "point", "mu": -1}, r"regions\[2\]\.mu: .*must be >= 0"),
    ({"a": [0, 0], "b": [1, 0], "n": [0, 1], "model": "soft", "mu": 1, "torsion": 1}, r"regions\[2\]\.torsion"),
    ({"a": [0, 0], "b": [1, 0], "n": [0, 1], "model": "pad", "mu": 1}, r"regions\[2\]\.width: missing"),
    ({"points": [[0, 0], [1, 0]], "normals": [[0, 1]]}, r"regions\[2\]\.normals: 1 normals for 2 points"),
    ({"points": [[0, 0], [1, None]], "normals": [[0, 1], [0, 1]]}, r"regions\[2\]\.points\[1\]"),
    ({"points": [[0, 0], [1, 0]], "normals": [[0, 1], [1, 0]], "model": "glue"}, r"regions\[2\]\.model: unknown"),
    ({"a": [0, 0], "points": [[0, 0]]}, r"regions\[2\]: expected a straight region"),
])
def test_region_validation_names_the_field(value, message):
    with pytest.raises(GraspError, match=message):
        region_from_dict(value, 2)


def test_curved_regions_must_be_sampled_densely_enough():
    with pytest.raises(GraspError, match=r"regions\[0\]\.normals\[1\]: the curve turns by"):
        tuple_from_dict({"regions": [{"points": [[1, 0], [0, 1]], "normals": [[-1, 0], [0, -1]]}]})
    with pytest.raises(GraspError, match="normal_tol"):
        tuple_from_dict({"regions": [{"a": [1, 0], "b": [1, 1], "n": [-1, 0]}], "normal_tol": 2})


REGION_LINES = [
    {"id": "robust", "regions": [{"a": [1, -0.3], "b": [1, 0.3], "n": [-1, 0], "model": "point", "mu": 0.5},
                                 {"a": [-1, -0.3], "b": [-1, 0.3], "n": [1, 0], "model": "point", "mu": 0.5}]},
    {"id": "not", "regions": [{"a": [1, -0.7], "b": [1, 0.7], "n": [-1, 0], "model": "point", "mu": 0.5},
                              {"a": [-1, -0.7], "b": [-1, 0.7], "n": [1, 0], "model": "point", "mu": 0.5}],
     "normal_tol": 0.01},
    {"id": 7, "regions": [{"points": [[1, -0.1], [0.995, 0], [1, 0.1]], "normals": [[-1, 0.1], [-1, 0], [-1, -0.1]],
                           "model": "point", "mu": 0.6},
                          {"a": [-1, -0.1], "b": [-1, 0.1], "n": [1, 0], "model": "pad", "mu": 0.6, "width": 0.1}],
     "center": [0, 0], "length": 1.0},
]
BAD = ['{"id": "x", "regions": [{"a": [1, "x"], "b": [1, 0], "n": [-1, 0]}]}', '{"id": "y", "regions": [',
       '{"id": "z", "regions": [{"a": [1, 0], "b": [1, 1], "n": [-1, 0], "model": "pad", "mu": 0.5}]}']


@pytest.fixture
def region_file(tmp_path):
    path = tmp_path / "regions.jsonl"
    path.write_text("\n".join(json.dumps(d) for d in REGION_LINES) + "\n\n" + "\n".join(BAD) + "\n")
    return path


def test_region_files_round_trip_with_error_rows(region_file, tmp_path):
    out = tmp_path / "out.jsonl"
    summary = certify_region_file(region_file, out)
    rows = [json.loads(line) for line in out.read_text().splitlines()]
    assert [r["id"] for r in rows] == ["robust", "not", 7, "x", None, "z"]
    assert [r["line"] for r in rows] == [1, 2, 3, 5, 6, 7]
    assert [r["status"] for r in rows[:3]] == ["robust", "not_robust", "robust"]
    assert all(r["verified"] for r in rows[:3]) and summary.unverified == 0 and summary.errors == 3
    assert rows[1]["witness"]["grasp"]["contacts"][0]["model"] == "point"
    assert rows[3]["error"] == 'line 5: regions[0].a: expected 2 finite numbers, got [1, "x"]'
    assert rows[4]["error"].startswith("line 6: malformed JSON")
    assert rows[5]["error"].startswith("line 7: regions[0].width: missing")
    assert verify_region_file(out, region_file).failures == []
    # round trip of the tuples themselves
    for d in REGION_LINES:
        t = tuple_from_dict(d)
        assert tuple_from_dict(tuple_to_dict(t)) == t
    with pytest.raises(Exception, match="is the input"):
        certify_region_file(region_file, region_file)


def test_cli_certify_regions_and_verify(region_file, tmp_path):
    out = tmp_path / "out.jsonl"
    result = runner.invoke(app, ["certify-regions", str(region_file), "-o", str(out), "-q"])
    assert result.exit_code == 1  # some rows are errors
    result = runner.invoke(app, ["verify", str(out), "--regions", str(region_file)])
    assert result.exit_code == 0, result.output
    rows = [json.loads(line) for line in out.read_text().splitlines()]
    rows[0]["certificate"]["faces"][0]["lambda"] = [-v for v in rows[0]["certificate"]["faces"][0]["lambda"]]
    rows[1]["witness"]["grasp"]["contacts"][1]["p"] = [-1, 0.8]
    out.write_text("".join(json.dumps(r) + "\n" for r in rows))
    result = runner.invoke(app, ["verify", str(out), "--regions", str(region_file)])
    assert result.exit_code == 1
    failed = [line.split("\t")[0] for line in result.stdout.splitlines() if "\t" in line]
    assert failed == ["robust", "not"]
    assert runner.invoke(app, ["verify", str(out)]).exit_code == 2
    assert runner.invoke(app, ["verify", str(out), "--regions", str(region_file), "--grasps", str(region_file)]).exit_code == 2
    assert runner.invoke(app, ["certify-regions", str(tmp_path / "none.jsonl"), "-o", str(out), "-q"]).exit_code == 2
    assert runner.invoke(app, ["certify-regions", str(region_file), "-o", str(region_file), "-q"]).exit_code == 2
    clean = tmp_path / "clean.jsonl"
    clean.write_text("".join(json.dumps(d) + "\n" for d in REGION_LINES))
    assert runner.invoke(app, ["certify-regions", str(clean), "-o", str(out), "-q"]).exit_code == 0


def test_cli_independent_regions(tmp_path):
    import cv2

    from qualgrasp.qualitative.objects import render
    image = tmp_path / "square.png"
    cv2.imwrite(str(image), render("square"))
    grasps, out = tmp_path / "g.jsonl", tmp_path / "ind.jsonl"
    assert runner.invoke(app, ["synthesize", str(image), "--fingers", "2", "-o", str(grasps)]).exit_code == 0
    with grasps.open("a") as fh:
        fh.write('{"id": "off", "contacts": [{"p": [0, 0], "n": [1, 0], "mu": 0.5}, {"p": [9, 9], "n": [-1, 0], "mu": 0.5}]}\n')
        fh.write('{"id": "broken", "contacts": [\n')
    result = runner.invoke(app, ["independent-regions", str(image), str(grasps), "-o", str(out)])
    assert result.exit_code == 1, result.output
    rows = [json.loads(line) for line in out.read_text().splitlines()]
    good = [r for r in rows if r["status"] != "error"]
    assert good and all(r["status"] == "robust" and r["delta"] > 0 for r in good)
    for r in good:  # the regions are a region-set line, and their certificate re-checks
        t = tuple_from_dict(r["regions"])
        assert t.id == r["id"] and bool(verify_regions(t, {"status": "robust", "certificate": r["certificate"]}))
        assert 0 < r["delta_fraction"] < 0.5
    sizes = {round(r["delta"] / r["delta_fraction"], 6) for r in good}  # the object's size, in pixels
    assert len(sizes) == 1
    errors = [r for r in rows if r["status"] == "error"]
    assert [r["id"] for r in errors] == ["off", None]
    assert "from the outline" in errors[0]["error"] and errors[1]["error"].startswith(f"line {len(rows)}: malformed")
    assert runner.invoke(app, ["independent-regions", str(tmp_path / "none.png"), str(grasps), "-o", str(out)]).exit_code == 2
    assert runner.invoke(app, ["independent-regions", str(image), str(grasps), "-o", str(grasps)]).exit_code == 2


@settings(max_examples=60)
@given(st.integers(1, 40), st.integers(0, 2**32 - 1),
       st.sampled_from([("point", 0.5, None), ("frictionless", None, None), (None, 0.3, None), ("pad", 0.4, 0.02),
                        ("point", 0.0, None), ("soft", 0.5, None), ("point", -1.0, None), ("nope", None, None)]),
       st.sampled_from(["ok", "nan", "zero-normal", "far", "float32", "integers", "objects", "one-normal-less"]))
def test_curved_regions_from_arrays_are_those_from_lists(k, seed, model, twist):
    """A curved region given as arrays (the boundary's sub-curves) is the region given as lists,
    bit for bit, or fails with the same message."""
    rng = np.random.default_rng(seed)
    P, N = rng.normal(size=(k, 2)), rng.normal(size=(k, 2))
    if twist == "nan":
        P[rng.integers(k)] = np.nan
    elif twist == "zero-normal":
        N[rng.integers(k)] = 0.0
    elif twist == "far":
        P[rng.integers(k)] = 1e300
    elif twist == "float32":
        P, N = P.astype(np.float32), N.astype(np.float32)
    elif twist == "integers":
        P, N = np.round(10 * P).astype(np.int64), np.round(10 * N).astype(np.int64)
    elif twist == "objects":
        P, N = P.astype(object), N.astype(object)
    elif twist == "one-normal-less":
        N = N[1:]
    name, mu, width = model

    def make(points, normals):
        try:
            return CurvedRegion(points, normals, name, mu=mu, width=width)
        except GraspError as err:
            return str(err)

    a, b = make(P, N), make(P.tolist(), N.tolist())  # the reading of lists: the reference
    if isinstance(b, str):
        assert a == b
    else:
        assert a == b and a.points.tobytes() == b.points.tobytes() and a.normals.tobytes() == b.normals.tobytes()

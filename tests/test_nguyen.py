"""Two-finger grasps: the LP and the SOCP against Nguyen's condition (independent geometry)."""

import pytest

from qualgrasp.certify import Contact, Grasp, force_closure, verify
from qualgrasp.certify.batch import random_grasps
from qualgrasp.certify.solvers import make_solver

from helpers import nguyen

N = 10_000


def _two_finger(seed, n):
    return random_grasps(seed, n, dim=2, n_contacts=2, model="point", spread=0.5)


@pytest.mark.parametrize("n", [pytest.param(N // 5, id="2000"), pytest.param(N, id="10000", marks=pytest.mark.slow)])
@pytest.mark.parametrize("socp", [False, True], ids=["lp-edges", "socp-2d-cones"])
def test_planar_verdict_equals_nguyen(socp, n):
    """Force closure of two planar frictional fingers iff the grasp line is strictly inside both
    friction cones (Nguyen 1988). Grasps within 1e-6 rad of the boundary may be degenerate. The
    test command checks 2,000 grasps, the slow set 10,000 (the first 2,000 of them the same)."""
    solver = make_solver("fast")
    counts = {"agree": 0, "near_boundary": 0}
    closures = 0
    for g in _two_finger(11, n):
        expected, distance = nguyen(g)
        v = force_closure(g, solver=solver, socp=socp)
        if distance < 1e-6:
            counts["near_boundary"] += 1
            assert v.status != ("no_closure" if expected else "closure")
            continue
        assert v.status == ("closure" if expected else "no_closure"), (g, distance)
        counts["agree"] += 1
        closures += expected
    assert counts["agree"] >= n - n // 1000
    assert 0.1 * n < closures < 0.9 * n  # both verdicts well represented


def test_spatial_soft_fingers_close_when_nguyen_holds():
    """Two soft fingers on a planar grasp lifted into space: Nguyen's condition gives a squeeze
    strictly inside both exact cones and the soft contacts make G onto, so the SOCP must find
    force closure; with point contacts the grasp line rotation is free and it never closes."""
    solver = make_solver("fast")
    seen = 0
    for g in _two_finger(12, 2000):
        ok, distance = nguyen(g)
        if not ok or distance < 1e-6:
            continue
        lift = lambda v: (v[0], v[1], 0.0)
        soft = Grasp(tuple(Contact(lift(c.p), lift(c.n), "soft", c.mu, 0.05) for c in g.contacts))
        point = Grasp(tuple(Contact(lift(c.p), lift(c.n), "point", c.mu) for c in g.contacts))
        v = force_closure(soft, solver=solver)
        assert v.status == "closure" and verify(soft, v.certificate, status=v.status)
        assert force_closure(point, solver=solver).status == "no_closure"
        seen += 1
    assert seen > 200


def test_lp_and_socp_margins_relate_by_the_cone_scale():
    """With equal mu, the edge weights a, b of a contact give f_n = a + b and
    mu f_n - abs(f_t) = 2 mu min(a, b); so on a symmetric antipodal grasp t*_socp = 2 mu t*_lp."""
    mu = 0.4
    g = Grasp((Contact((1, 0), (-1, 0), "point", mu), Contact((-1, 0), (1, 0), "point", mu)))
    lp, socp = force_closure(g), force_closure(g, socp=True)
    assert lp.margin == pytest.approx(0.25)
    assert socp.margin == pytest.approx(2 * mu * lp.margin, rel=1e-6)

"""The compiled support points of spatial ``support`` evidence
(:func:`qualgrasp.certify._kernels.conic.support_points` through
:meth:`~qualgrasp.certify.quality.gws.ConicSupport.vertices`) against independent routes: each
point's exact wrench (exact rationals from the exact columns) within its stated error bound,
every force it uses exactly inside its cone, and its value along the direction equal to the
support function's exact bounds (the checker's :meth:`~ConicSupport.h_bounds`: the point maximises
``v . w``), for
point, soft and frictionless contacts and both norms; many directions at once give what one at a
time gives."""

from fractions import Fraction

import numpy as np
import pytest

from qualgrasp.certify.batch.samples import random_grasps
from qualgrasp.certify.quality.gws import ConicSupport, vertex_scale

KINDS = {
    "point": dict(model="point", n_contacts=3, spread=0.3),
    "soft": dict(model="soft", n_contacts=2, spread=0.15),
    "frictionless": dict(model="frictionless", n_contacts=7),
}


@pytest.mark.parametrize("kind", sorted(KINDS))
@pytest.mark.parametrize("norm", ["L1", "Linf"])
def test_support_points_are_proved_points_of_the_gws_on_its_support_planes(kind, norm):
    rng = np.random.default_rng(7)
    for grasp in random_grasps(3, 12, dim=3, **KINDS[kind]):
        sup = ConicSupport(grasp)
        P = rng.normal(size=(16, 6))
        index = np.arange(5, 21)
        W, EW, X, ok = sup.vertices(P, norm, index)
        assert ok.all()
        for q in range(len(P)):
            exact = sup.exact_vertex(X[q])
            assert all(abs(Fraction(float(W[q, r])) - exact[r]) <= Fraction(float(EW[q, r])) for r in range(6))
            for b, blk in enumerate(sup.blocks):
                x = X[q, list(blk.cols)]
                if x.any():
                    assert sup.inside(b, x)
            # the point is the support point along P[q], scaled: v . w = h(v) up to SHRINK and rounding
            # (h clamps at 0: an L1 point then is the best contact's, at or below 0; an L-infinity one the origin)
            lo, hi = sup.h_bounds(P[q], norm)
            h = float(lo + hi) / 2 * np.linalg.norm(P[q])
            if h > 0:
                assert P[q] @ W[q] == pytest.approx(vertex_scale(int(index[q])) * h, rel=1e-8, abs=1e-12)
            else:
                assert P[q] @ W[q] <= 1e-12 and (norm == "L1" or not X[q].any())
            one = sup.vertex(P[q], norm, int(index[q]))
            assert one is not None and np.array_equal(one[0], W[q]) and np.array_equal(one[2], X[q])


def test_an_l1_point_uses_the_contact_it_is_given():
    grasp = random_grasps(5, 1, dim=3, model="point", n_contacts=3, spread=0.3)[0]
    sup = ConicSupport(grasp)
    v = np.random.default_rng(0).normal(size=(3, 6))
    W, EW, X, ok = sup.vertices(v, "L1", np.arange(3), np.array([2, 0, 1]))
    for q, b in enumerate([2, 0, 1]):
        cols = list(sup.blocks[b].cols)
        assert X[q, cols].any() and not np.delete(X[q], cols).any()


@pytest.mark.parametrize("norm", ["L1", "Linf"])
def test_the_numpy_route_of_earlier_builds_gives_proved_points_near_the_kernels(norm):
    """The checker re-checks evidence of builds before the kernel by their numpy formula: its
    points are proved points of the GWS (exact wrenches within their error bounds), within
    rounding of the kernel's wherever no contact's support value is near 0."""
    rng = np.random.default_rng(3)
    for grasp in random_grasps(4, 8, dim=3, model="point", n_contacts=3, spread=0.3):
        sup = ConicSupport(grasp)
        P = rng.normal(size=(12, 6))
        W, EW, X, ok = sup.vertices(P, norm, np.arange(12))
        W2, EW2, X2, ok2 = sup.vertices_numpy(P, norm, np.arange(12))
        assert ok2.all()
        for q in range(len(P)):
            exact = sup.exact_vertex(X2[q])
            assert all(abs(Fraction(float(W2[q, r])) - exact[r]) <= Fraction(float(EW2[q, r])) for r in range(6))
        assert np.allclose(W2, W, rtol=0, atol=1e-12) and np.allclose(X2, X, rtol=0, atol=1e-12)

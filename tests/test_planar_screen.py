"""certify.batch.fastpath.planar_screen: the columnar kernels on arrays agree with certify_grasp."""

import numpy as np
import pytest

from qualgrasp.certify import Contact, Grasp, certify_grasp
from qualgrasp.certify.batch import planar_screen


def _random_batch(rng, m, count):
    angle = rng.uniform(0, 2 * np.pi, (count, m))
    P = np.stack([np.cos(angle), 0.7 * np.sin(angle)], axis=2)
    N = -P + rng.normal(0, 0.3, P.shape)  # roughly inward, with torque
    return P, N


@pytest.mark.parametrize("m,mu", [(2, 0.5), (3, 0.3), (4, 0.0)])
def test_agrees_with_certify_grasp(m, mu):
    rng = np.random.default_rng(m)
    P, N = _random_batch(rng, m, 60)
    out = planar_screen(P, N, np.full((60, m), mu), (0.05, -0.02), 1.3)
    assert out.closure.any() and (~out.closure).any()
    for b in range(60):
        g = Grasp(tuple(Contact(P[b, j], N[b, j], "point", mu) if mu else Contact(P[b, j], N[b, j])
                        for j in range(m)), center=(0.05, -0.02), length=1.3)
        report = certify_grasp(g)
        if out.settled[b]:
            assert out.closure[b] == (report.force.status == "closure")
        if out.closure[b]:
            assert report.verified
            assert out.eps_l1[b] == pytest.approx(report.epsilons["L1"].hi, abs=1e-12)
            assert out.eps_linf[b] == pytest.approx(report.epsilons["Linf"].hi, abs=1e-12)
        else:
            assert out.eps_l1[b] == 0.0


def test_rejects_mixed_patterns_and_bad_input():
    P = np.zeros((2, 2, 2))
    P[:, 1, 0] = 1
    N = np.tile([[1.0, 0.0], [-1.0, 0.0]], (2, 1, 1))
    with pytest.raises(ValueError, match="pattern"):
        planar_screen(P, N, [[0.5, 0.5], [0.5, 0.0]], (0.5, 0), 1.0)
    with pytest.raises(ValueError):
        planar_screen(P, np.zeros_like(N), 0.5, (0.5, 0), 1.0)
    assert len(planar_screen(np.zeros((0, 2, 2)), np.zeros((0, 2, 2)), 0.5, (0, 0), 1.0).closure) == 0

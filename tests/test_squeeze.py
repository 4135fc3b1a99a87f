"""The squeeze rule: two point contacts squeezing, a third contact that cannot stop the twist
about their line. The fast route proves no closure with the pair tight, in closed form."""

import numpy as np
import pytest

from qualgrasp.certify import Contact, Grasp, force_closure, verify
from qualgrasp.certify.core.problem import grasp_problem
from qualgrasp.certify.solvers.squeeze import squeeze_solution


def _grasp(R=np.eye(3), shift=np.zeros(3), mu=0.5):
    points = [(1, 0, 0), (-1, 0, 0), (0, 1, 0)]
    normals = [(-1, 0, 0), (1, 0, 0), (0, 0, -1)]  # the third pushes down, off the squeeze line
    return Grasp(tuple(Contact(R @ np.array(p, float) + shift, R @ np.array(n, float), "point", mu)
                       for p, n in zip(points, normals)))


def _rotation(seed):
    Q, _ = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    return Q * np.sign(np.linalg.det(Q))


@pytest.mark.parametrize("seed", range(5))
def test_squeeze_proves_no_closure_with_the_pair_tight(seed):
    grasp = _grasp(_rotation(seed), np.random.default_rng(seed).normal(size=3))
    sol = squeeze_solution(grasp_problem(grasp))
    assert sol is not None and sol.t == 0.0
    verdict = force_closure(grasp)
    assert verdict.status == "no_closure" and verdict.certificate.tight == (0, 1)
    assert verify(grasp, verdict.certificate, status="no_closure").ok
    # the twist about the squeeze line: orthogonal to both contacts' wrenches
    y = np.array(verdict.certificate.y)
    assert abs(np.linalg.norm(y) - 1) < 1e-12


def test_no_squeeze_direction_for_a_grasp_in_closure():
    # the third contact faces the squeeze line: its friction resists the twist about it
    grasp = Grasp(_grasp().contacts[:2] + (Contact((0, 1, 0), (0, -1, 0), "point", 0.5),))
    assert squeeze_solution(grasp_problem(grasp)) is None
    assert force_closure(grasp).status == force_closure(grasp, method="reference").status == "closure"

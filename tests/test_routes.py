"""Reference (cvxpy) and fast routes agree on 10,000 random grasps of each kind (fixed seeds)."""

import pytest

from qualgrasp.experiments.bench import KINDS, compare_routes
from qualgrasp.certify.batch import random_grasps

N = 10_000


@pytest.mark.slow
@pytest.mark.parametrize("kind", list(KINDS))
def test_fast_and_reference_routes_agree(kind):
    grasps = random_grasps(2024, N, **KINDS[kind])
    agreement = compare_routes(grasps, kind)
    print(kind, agreement.statuses, "agree", agreement.same_status, "max margin diff",
          agreement.max_margin_diff)
    assert not agreement.disagreements, agreement.disagreements[:10]
    # a route may decide, with an exactly re-checked certificate, a boundary grasp the other
    # leaves degenerate (the fast route's closed-form squeeze direction); that must stay rare
    assert agreement.same_status + len(agreement.resolved) == N
    assert len(agreement.resolved) <= N // 1000, agreement.resolved
    assert agreement.max_margin_diff < 1e-6
    # Both verdicts must be well represented, or agreement would say little.
    assert min(agreement.statuses.get("closure", 0), agreement.statuses.get("no_closure", 0)) > N // 20

"""Compiled helpers against their numpy meaning: the stable argsorts the kernels share (merge and
radix), and the
projection of a Farkas direction off its tight blocks, which must leave it orthogonal to every
tight column however dependent those columns are."""

import numpy as np
from hypothesis import given, settings, strategies as st
from hypothesis.extra.numpy import arrays

from qualgrasp.certify._kernels.cones import farkas_direction
from qualgrasp.certify._kernels.order import radix_argsort, stable_argsort


@settings(max_examples=200, deadline=None)
@given(arrays(np.float64, st.integers(0, 70), elements=st.sampled_from([-1.5, 0.0, 0.25, 2.0, 7.0]))
       | arrays(np.int64, st.integers(0, 70), elements=st.integers(-3, 3)))
def test_stable_argsort_is_numpys_stable_argsort(keys):
    assert stable_argsort(keys).tolist() == np.argsort(keys, kind="stable").tolist()


@settings(max_examples=100, deadline=None)
@given(st.integers(0, 3000), st.sampled_from([1, 2, 7, 2**11, 2**11 + 1, 2**40, 1280**5, 2**62]), st.integers(0, 2**32))
def test_radix_argsort_is_numpys_stable_argsort(n, top, seed):
    keys = np.random.default_rng(seed).integers(0, top, size=n, dtype=np.int64)
    assert radix_argsort(keys).tolist() == np.argsort(keys, kind="stable").tolist()


def test_farkas_direction_leaves_no_component_along_dependent_tight_columns():
    rng = np.random.default_rng(5)
    for _ in range(200):
        d = int(rng.choice([3, 6]))
        rank = int(rng.integers(1, d - 1))
        span = np.linalg.qr(rng.normal(size=(d, d)))[0]
        tight = span[:, :rank] @ rng.normal(size=(rank, 2 * rank))  # dependent columns, rank `rank`
        tight[:, 1] = tight[:, 0]  # and a repeated one
        y = span[:, rank:] @ rng.normal(size=d - rank)
        y /= np.linalg.norm(y)
        others = -(y[:, None] + 0.1 * rng.normal(size=(d, 3)))  # strictly separated: y . w < 0
        C = np.hstack([tight, others])
        k = C.shape[1]
        arrays_ = (np.zeros(k, np.int64), np.arange(k), np.ones(k, np.int64), np.zeros((k, d)), np.zeros(k),
                   np.zeros(k))
        noisy = y + 1e-10 * (tight @ rng.normal(size=tight.shape[1]))
        ok, out, is_tight = farkas_direction(C, *arrays_, noisy, 1e-7)
        assert ok and is_tight[: tight.shape[1]].all() and not is_tight[tight.shape[1]:].any()
        assert np.abs(tight.T @ out).max() <= 1e-13 * np.abs(C).max()

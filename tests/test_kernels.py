"""Compiled helpers against their numpy meaning: the stable argsorts the kernels share (merge and
radix) and the start of one, the
projection of a Farkas direction off its tight blocks, which must leave it orthogonal to every
tight column however dependent those columns are, and the planar epsilon enumeration against its
definition in plain Python floats; the planar LP's refusal of bases it cannot scan, and which
kernels are compiled into their callers."""

import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from hypothesis.extra.numpy import arrays

from qualgrasp.certify._kernels.cones import farkas_direction
from qualgrasp.certify._kernels.epsilon import planar_epsilon_one
from qualgrasp.certify._kernels.order import radix_argsort, stable_argsort, stable_smallest


@settings(max_examples=200, deadline=None)
@given(arrays(np.float64, st.integers(0, 70), elements=st.sampled_from([-1.5, 0.0, 0.25, 2.0, 7.0]))
       | arrays(np.int64, st.integers(0, 70), elements=st.integers(-3, 3)))
def test_stable_argsort_is_numpys_stable_argsort(keys):
    assert stable_argsort(keys).tolist() == np.argsort(keys, kind="stable").tolist()


@settings(max_examples=200, deadline=None)
@given(arrays(np.float64, st.integers(0, 70), elements=st.sampled_from([-1.5, -0.0, 0.0, 0.25, 2.0, 7.0])),
       st.integers(0, 8))
def test_stable_smallest_is_the_start_of_numpys_stable_argsort(keys, c):
    assert stable_smallest(keys, c).tolist() == np.argsort(keys, kind="stable")[:c].tolist()


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


def _support(W, owner, m, u, linf):
    """The planar GWS's support at ``u`` as the kernels define it: per contact the largest
    ``u . g`` of its generators (at least +0.0), in contact order summed (L-infinity) or maxed."""
    out = 0.0
    for i in range(m):
        top = 0.0
        for j in np.flatnonzero(owner == i):
            v = W[0, j] * u[0] + W[1, j] * u[1] + W[2, j] * u[2]
            top = v if v > top else top
        out = out + top if linf else (top if top > out else out)
    return out


def _epsilon_by_definition(W, owner, m, linf):
    """Every candidate normal (pairs of edges, L-infinity; triples of generators, L1) evaluated
    in full at ``+u`` then ``-u``, the least kept (a later equal value does not replace it)."""
    k = W.shape[1]
    E = [tuple(W[:, a]) for a in range(k)]
    if linf:
        E += [tuple(W[:, a] - W[:, c]) for a in range(k) for c in range(a + 1, k) if owner[a] == owner[c]]
        pairs = [(E[a], E[c]) for a in range(len(E)) for c in range(a + 1, len(E))]
    else:
        pairs = [(np.subtract(E[c], E[a]), np.subtract(E[q], E[a]))
                 for a in range(k) for c in range(a + 1, k) for q in range(c + 1, k)]
    scale = 0.0
    for e in E:
        scale = max(scale, abs(e[0]) + abs(e[1]) + abs(e[2]))
    tiny = 1e-12 * max(1.0, scale * scale)
    best, arg = math.inf, (0.0, 0.0, 0.0)
    for x, y in pairs:
        u = (x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0])
        nu = math.sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2])
        if nu <= tiny:
            continue
        u = (u[0] / nu, u[1] / nu, u[2] / nu)
        for w in (u, (-u[0], -u[1], -u[2])):
            value = _support(W, owner, m, w, linf)
            if value < best:
                best, arg = value, w
    return best, arg


_entries = st.integers(-3, 3).map(float) | st.floats(-1e3, 1e3, allow_nan=False, allow_subnormal=False)


@settings(max_examples=150, deadline=None)
@given(st.lists(st.integers(1, 3), min_size=1, max_size=4), st.data(), st.booleans())
def test_planar_epsilon_enumeration_is_its_definition_bit_for_bit(sizes, data, linf):
    """The enumeration (which stops a candidate's support early once it cannot win) gives the
    full enumeration's epsilon and direction exactly, ties and zeros included."""
    owner = np.repeat(np.arange(len(sizes)), sizes)
    W = np.array(data.draw(st.lists(_entries, min_size=3 * len(owner), max_size=3 * len(owner)))).reshape(3, -1)
    eps, arg = planar_epsilon_one(W, owner, len(sizes), linf)
    want, want_arg = _epsilon_by_definition(W, owner, len(sizes), linf)
    assert float(eps).hex() == want.hex()
    assert [x.hex() for x in arg.tolist()] == [float(x).hex() for x in want_arg]


def test_per_item_kernels_are_compiled_into_their_callers():
    # kernel(inline=True): numba compiles these into each caller's loop (the face checks of
    # face_bounds, the sums of the evidence, the barrier's Newton steps); the callers stay calls
    from qualgrasp.certify._kernels import barrier, epsilon, evidence, surface

    inline = [surface._edges, surface._normal3, surface._distance_bounds, evidence._pick_sum,
              barrier._barrier_terms, barrier._phi, epsilon._unit_cross]
    assert all(k.targetoptions.get("inline") == "always" for k in inline)
    assert all(k.targetoptions.get("inline", "never") == "never"
               for k in (surface.face_bounds, evidence.minkowski_sums, barrier.socp_dual_barrier,
                         epsilon.planar_epsilon_one))


def test_the_planar_lp_refuses_bases_that_are_not_every_3_subset():
    # its primal scan runs over the 3-subsets as nested loops and writes one entry per subset
    from qualgrasp.certify._kernels.lp import lp_planar
    from qualgrasp.certify.solvers.enumeration import bases

    W = np.random.default_rng(0).normal(size=(2, 3, 5))
    t = lp_planar(W, bases(5, 3), 1e-9)[0]
    assert t.shape == (2,)
    with pytest.raises(ValueError, match="bases"):
        lp_planar(W, bases(5, 3)[:-1], 1e-9)

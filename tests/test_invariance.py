"""Verdicts and margins do not depend on rigid motions, scale, contact order, center or length."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from qualgrasp.certify import Contact, Grasp, force_closure, form_closure
from qualgrasp.experiments.bench import KINDS
from qualgrasp.certify.batch import random_grasp
from helpers import rotation

kinds = st.sampled_from(list(KINDS))
seeds = st.integers(0, 2**32 - 1)


def _grasp(kind, seed):
    return random_grasp(np.random.default_rng(seed), **KINDS[kind])


def _moved(g, R, shift, scale=1.0, center=None, length=None, order=None):
    order = range(len(g.contacts)) if order is None else order
    contacts = []
    for i in order:
        c = g.contacts[i]
        contacts.append(Contact(scale * (R @ np.array(c.p)) + shift, R @ np.array(c.n), c.model,
                                c.mu, None if c.torsion is None else scale * c.torsion))
    if center is None:
        center = scale * (R @ np.array(g.center)) + shift
    return Grasp(tuple(contacts), center=center, length=scale * g.length if length is None else length)


def _same(v, w):
    if "degenerate" in (v.status, w.status):
        return True  # on the boundary a rounding may decide; never a wrong verdict
    return v.status == w.status and w.margin == pytest.approx(v.margin, rel=1e-5, abs=1e-8)


@given(kinds, seeds, seeds, st.floats(-100, 100), st.floats(0.5, 2.0))
def test_rigid_motion_and_scale(kind, seed, rseed, shift, scale):
    g = _grasp(kind, seed)
    rng = np.random.default_rng(rseed)
    R = rotation(rng, g.dim)
    moved = _moved(g, R, shift * np.ones(g.dim), scale)
    for test in (force_closure, form_closure):
        assert _same(test(g), test(moved))


@given(kinds, seeds, st.randoms(use_true_random=False))
def test_contact_order(kind, seed, random):
    g = _grasp(kind, seed)
    order = list(range(len(g.contacts)))
    random.shuffle(order)
    shuffled = _moved(g, np.eye(g.dim), np.zeros(g.dim), order=order)
    for test in (force_closure, form_closure):
        assert _same(test(g), test(shuffled))


@given(kinds, seeds, st.lists(st.floats(-5, 5), min_size=3, max_size=3), st.floats(0.01, 100))
def test_center_and_length_do_not_change_verdict_or_margin(kind, seed, center, length):
    g = _grasp(kind, seed)
    other = Grasp(g.contacts, center=center[: g.dim], length=length)
    for test in (force_closure, form_closure):
        assert _same(test(g), test(other))

"""Textbook closure facts, each re-derived by the solver and re-checked by the exact verifier."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from qualgrasp.certify import Contact, Grasp, certify_grasp, force_closure, form_closure, positive_span, verify
from qualgrasp.certify.batch.samples import CUBE_7, random_grasps, textbook_grasps

BOOK = {g.id: g for g in textbook_grasps()}


@pytest.mark.parametrize("gid, force, form", [
    ("square-form", "closure", "closure"),
    ("square-pinwheel", "no_closure", "no_closure"),
    ("disc-4", "no_closure", "no_closure"),
    ("antipodal-2d", "closure", "no_closure"),
    ("antipodal-3d-point", "no_closure", "no_closure"),
    ("antipodal-3d-soft", "closure", "no_closure"),
    ("cube-7", "closure", "closure"),
])
@pytest.mark.parametrize("method", ["fast", "reference"])
def test_textbook_verdicts(gid, force, form, method):
    g = BOOK[gid]
    report = certify_grasp(g, method=method)
    assert (report.force.status, report.form.status) == (force, form)
    assert report.verified


def test_square_margin_is_a_quarter():
    # Four contacts whose wrenches balance with equal weights: t* = 1/k = 1/4, the LP's maximum.
    assert form_closure(BOOK["square-form"]).margin == pytest.approx(0.25, abs=1e-12)


def test_pinwheel_certificate_is_the_free_rotation():
    cert = form_closure(BOOK["square-pinwheel"]).certificate
    y = np.array(cert.y)
    # All four torques have the same sign: the separating direction is a pure torque.
    assert abs(y[2]) == pytest.approx(1.0) and np.allclose(y[:2], 0, atol=1e-9)


def test_spatial_antipodal_point_contacts_leave_the_grasp_line_rotation_free():
    cert = force_closure(BOOK["antipodal-3d-point"]).certificate
    assert cert.null_space
    y = np.array(cert.y)
    assert np.allclose(np.abs(y), [0, 0, 0, 0, 0, 1], atol=1e-9)  # torque about z, the grasp line


@given(st.lists(st.floats(0, 2 * math.pi), min_size=1, max_size=10))
def test_frictionless_contacts_on_the_unit_disc_never_form_close(angles):
    contacts = tuple(Contact((math.cos(a), math.sin(a)), (-math.cos(a), -math.sin(a))) for a in angles)
    v = form_closure(Grasp(contacts, center=(0, 0)))
    assert v.status == "no_closure"  # exact: every normal passes through the centre
    assert verify(Grasp(contacts, center=(0, 0)), v.certificate, status=v.status, frictionless=True)


@given(st.lists(st.floats(0, 2 * math.pi), min_size=1, max_size=10), st.floats(0.1, 10))
def test_disc_of_any_radius_is_never_in_form_closure(angles, radius):
    # With rounded coordinates the normals miss the centre by ~1e-16: no_closure or degenerate,
    # never closure.
    contacts = tuple(Contact((radius * math.cos(a), radius * math.sin(a)),
                             (-math.cos(a), -math.sin(a))) for a in angles)
    assert form_closure(Grasp(contacts)).status != "closure"


@pytest.mark.parametrize("m", [1, 2, 3])
def test_planar_form_closure_needs_four_contacts(m):
    for g in random_grasps(m, 300, dim=2, n_contacts=m, model="frictionless"):
        assert form_closure(g).status != "closure"


def test_planar_four_contacts_can_form_close():
    statuses = [form_closure(g).status for g in random_grasps(4, 300, dim=2, n_contacts=4,
                                                               model="frictionless")]
    assert statuses.count("closure") > 10


@pytest.mark.parametrize("m", [1, 3, 5, 6])
def test_spatial_form_closure_needs_seven_contacts(m):
    for g in random_grasps(m, 100, dim=3, n_contacts=m, model="frictionless"):
        assert form_closure(g).status != "closure"


def test_cube_seven_contacts_are_minimal():
    g = Grasp(CUBE_7, center=(0, 0, 0))
    assert form_closure(g).status == "closure"
    for i in range(7):
        assert form_closure(Grasp(CUBE_7[:i] + CUBE_7[i + 1:])).status == "no_closure"


@given(st.floats(0.05, 2.0), st.floats(-0.3, 0.3))
def test_two_antipodal_frictional_contacts_close_in_the_plane(mu, shift):
    # Opposite normals along a common line: the squeeze is inside both cones for any mu > 0.
    g = Grasp((Contact((1, shift), (-1, 0), "point", mu), Contact((-1, shift), (1, 0), "point", mu)))
    assert force_closure(g).status == "closure"
    assert form_closure(g).status == "no_closure"


@given(st.lists(st.floats(0, 2 * math.pi), min_size=1, max_size=6))
def test_planar_normals_positively_span_iff_largest_gap_below_pi(angles):
    a = np.sort(np.mod(angles, 2 * math.pi))
    gaps = np.diff(np.concatenate([a, [a[0] + 2 * math.pi]]))
    if abs(gaps.max() - math.pi) < 1e-6:
        return  # on the boundary: degenerate by design
    v = positive_span(np.column_stack([np.cos(a), np.sin(a)]))
    assert v.status == ("closure" if gaps.max() < math.pi else "no_closure")

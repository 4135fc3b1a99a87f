"""The weight-holding task certificate (qualgrasp.certify.meshes.task): closed forms, both
certificates re-checked exactly, tampered certificates refused, every direction bracketed."""

import dataclasses
import math

import numpy as np
import pytest

pytest.importorskip("trimesh")

from qualgrasp.certify import Contact, Grasp
from qualgrasp.certify.meshes.contacts import jaw_contacts
from qualgrasp.certify.meshes.gripper import load_gripper
from qualgrasp.certify.meshes.mesh import mass_properties
from qualgrasp.certify.meshes.poses import grasp_of
from qualgrasp.certify.meshes.task import (G, check_every_direction, check_holds, check_slips, every_direction,
                                           hold_verdict, least_grip)

import trimesh


def box_grasp(mu, model="point", offset=(0.0, 0.0), torsion=0.004, a=0.05):
    """Two contacts on opposite faces x = +-a of a box centred at the origin."""
    kw = {"torsion": torsion} if model == "soft" else {"radius": 1.5 * torsion} if model == "patch" else {}
    y, z = offset
    return Grasp((Contact((a, y, z), (-1, 0, 0), model, mu, **kw), Contact((-a, y, z), (1, 0, 0), model, mu, **kw)),
                 center=(0, 0, 0), length=0.1)


def certified(grasp, m, d, budget):
    """The verdict at a budget, each way re-checked exactly."""
    b = least_grip(grasp, m, (0, 0, 0), d)
    v = hold_verdict(b.lo, b.hi, budget)
    if v == "holds":
        assert check_holds(grasp, m, (0, 0, 0), d, budget, b.forces)
    elif v == "slips":
        slip = dataclasses.replace(b.slip, budget=budget)
        assert check_slips(grasp, m, (0, 0, 0), d, slip)
    return v, b


@pytest.mark.parametrize("mu", [0.2, 0.5, 1.0])
@pytest.mark.parametrize("m", [0.1, 1.3])
@pytest.mark.parametrize("model", ["point", "soft", "patch"])
def test_box_across_faces_holds_iff_mu_F_at_least_half_its_weight(mu, m, model):
    grasp = box_grasp(mu, model)
    need = m * G / (2 * mu)
    for d in [(0, 0, -1), (0, 1, 0), (0, -0.6, 0.8)]:  # gravity along the faces
        for budget in (need * 1.01, need * 0.99, need * 1.3, need * 0.5):
            v, b = certified(grasp, m, d, budget)
            assert v == ("holds" if budget >= need else "slips"), (d, budget)
            assert b.lo <= need <= b.hi and b.hi / b.lo - 1 < 1e-5


def test_gravity_along_the_closing_axis_needs_the_whole_weight_on_one_pad():
    for mu in (0.2, 1.0):
        b = least_grip(box_grasp(mu), 0.5, (0, 0, 0), (1, 0, 0))
        assert b.lo <= 0.5 * G <= b.hi
        # in between: s*(a) = m g (|cos a| + |sin a| / (2 mu)) (the lower pad carries the x load)
        for a in np.linspace(0.1, 1.4, 5):
            b = least_grip(box_grasp(mu), 0.5, (0, 0, 0), (np.cos(a), 0, np.sin(a)))
            assert b.lo <= 0.5 * G * (np.cos(a) + np.sin(a) / (2 * mu)) <= b.hi


def test_point_contacts_cannot_hold_a_weight_off_their_line_at_any_grip_force_soft_ones_can():
    point = box_grasp(0.5, offset=(0.0, 0.01))  # the com lies 1 cm below the line of the contacts
    b = least_grip(point, 1.0, (0, 0, 0), (0, 1, 0))
    assert math.isinf(b.lo) and math.isinf(b.hi) and b.forces is None
    assert b.slip is not None and sum(b.slip.lam) == 0
    for budget in (1.0, 1e6):
        assert check_slips(point, 1.0, (0, 0, 0), (0, 1, 0), dataclasses.replace(b.slip, budget=budget))
    soft = box_grasp(0.5, "soft", offset=(0.0, 0.01), torsion=0.005)
    b = least_grip(soft, 1.0, (0, 0, 0), (0, 1, 0))
    # the torque m g 0.01 about the grasp axis needs 2 mu f_n torsion >= m g 0.01, the weight 2 mu f_n >= m g:
    # the soft cone couples them, |(f_t, m / torsion)| <= mu f_n, so f_n = m g / (2 mu) sqrt(1 + (0.01/0.005)^2)
    need = G / (2 * 0.5) * math.sqrt(1 + (0.01 / 0.005) ** 2)
    assert b.lo <= need <= b.hi
    assert check_holds(soft, 1.0, (0, 0, 0), (0, 1, 0), b.hi * (1 + 1e-12), b.forces)
    # a patch of radius a resists torsion as a soft finger of torsion 2 a / 3 (uniform pressure)
    patch = box_grasp(0.5, "patch", offset=(0.0, 0.01), torsion=0.005)
    b = least_grip(patch, 1.0, (0, 0, 0), (0, 1, 0))
    assert patch.contacts[0].param("radius") == pytest.approx(0.0075) and b.lo <= need <= b.hi


def test_tampered_certificates_are_refused():
    grasp = box_grasp(0.5)
    b = least_grip(grasp, 1.0, (0, 0, 0), (0, 0, -1))
    hi = b.hi * (1 + 1e-12)
    assert check_holds(grasp, 1.0, (0, 0, 0), (0, 0, -1), hi, b.forces)
    assert not check_holds(grasp, 1.0, (0, 0, 0), (0, 0, -1), b.lo, b.forces)       # budget below the forces
    assert not check_holds(grasp, 1.2, (0, 0, 0), (0, 0, -1), hi, b.forces)         # a heavier object
    assert not check_holds(grasp, 1.0, (0, 0, 0), (0, 0, -1), hi, tuple(0.5 * v for v in b.forces))
    assert not check_holds(grasp, 1.0, (0, 0, 0), (0, 0, -1), hi, b.forces[:-1])
    assert not check_holds(box_grasp(0.3), 1.0, (0, 0, 0), (0, 0, -1), hi, b.forces)  # less friction
    assert check_slips(grasp, 1.0, (0, 0, 0), (0, 0, -1), b.slip)
    assert not check_slips(grasp, 1.0, (0, 0, 0), (0, 0, -1), dataclasses.replace(b.slip, budget=b.hi))
    assert not check_slips(grasp, 1.0, (0, 0, 0), (0, 0, 1e-3 - 1), dataclasses.replace(b.slip))  # other gravity
    y = list(b.slip.y)
    y[2] = -y[2]
    assert not check_slips(grasp, 1.0, (0, 0, 0), (0, 0, -1), dataclasses.replace(b.slip, y=tuple(y)))
    assert not check_slips(grasp, 1.0, (0, 0, 0), (0, 0, -1),
                           dataclasses.replace(b.slip, lam=tuple(-v for v in b.slip.lam)))
    assert not check_slips(box_grasp(0.8), 1.0, (0, 0, 0), (0, 0, -1), b.slip)     # more friction


@pytest.mark.parametrize("mu", [0.3, 0.5])
def test_every_direction_brackets_the_worst_gravity(mu):
    grasp = box_grasp(mu, "soft", torsion=0.01)
    m = 0.4
    # the worst direction tilts from the faces towards the closing axis: max_a m g (cos a + sin a / (2 mu))
    worst = m * G * math.sqrt(1 + 1 / (4 * mu * mu))
    for level in (0, 1):
        e = every_direction(grasp, m, (0, 0, 0), level=level)
        assert e.lo <= worst <= e.hi
        assert e.hi / e.lo <= 1 / e.radius * (1 + 1e-4)
        assert check_every_direction(grasp, m, (0, 0, 0), e)
    bad = dataclasses.replace(e, hi=e.hi * 0.9)
    assert not check_every_direction(grasp, m, (0, 0, 0), bad)
    bad = dataclasses.replace(e, vertices=e.vertices[:-1])
    assert not check_every_direction(grasp, m, (0, 0, 0), bad)


def test_pads_on_a_made_up_box_hold_its_weight_iff_mu_F_at_least_half_its_weight():
    """From a pose to a verdict: the Franka hand across a box's faces, gravity along the faces."""
    box = trimesh.creation.box((0.05, 0.06, 0.06))
    panda = load_gripper("franka_panda")
    out = jaw_contacts(box, panda, np.eye(4)[None], np.array([0.07]))[0]
    props = mass_properties(box, mass=0.25)
    for mu in (0.3, 0.6):
        grasp = grasp_of(out, mu, "soft", props)
        need = 0.25 * G / (2 * mu)
        for budget in (need * 1.02, need * 0.98):
            b = least_grip(grasp, props.mass, props.com, (0, 0, -1))
            assert hold_verdict(b.lo, b.hi, budget) == ("holds" if budget > need else "slips")


def test_a_sphere_between_pads_resists_torsion_only_through_its_small_patch():
    sphere = trimesh.creation.icosphere(5, 0.03)
    box = trimesh.creation.box((0.06, 0.06, 0.06))
    panda = load_gripper("franka_panda")
    T = np.eye(4)
    grip = {}
    for name, mesh in (("sphere", sphere), ("box", box)):
        out = jaw_contacts(mesh, panda, T[None], np.array([0.075]))[0]
        props = mass_properties(mesh, mass=0.2)
        # put the centre of mass 1 cm off the grasp axis: gravity along y then twists about the axis
        props = dataclasses.replace(props, com=(0.0, 0.0, 0.01))
        grasp = grasp_of(out, 0.5, "soft", props)
        grip[name] = least_grip(grasp, props.mass, props.com, (0, -1, 0))
        torsion = grasp.contacts[0].torsion
        need = 0.2 * G / (2 * 0.5) * math.sqrt(1 + (0.01 / torsion) ** 2)
        assert grip[name].lo <= need * (1 + 1e-3) and need <= grip[name].hi * (1 + 1e-3)
    assert grip["sphere"].lo > 1.5 * grip["box"].hi  # the cap is smaller than the pad

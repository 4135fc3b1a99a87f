"""The pad's whole face, rim included, is its contact area (qualgrasp.certify.meshes.contacts):
features that only the outer half-cell rim of the pad meets are found, at the same travel as
the independent route (dense surface samples in the pad's prism)."""

import numpy as np
import pytest

trimesh = pytest.importorskip("trimesh")

from qualgrasp.certify.meshes.contacts import TOLERANCE, jaw_contacts, pad_grid
from qualgrasp.certify.meshes.gripper import load_gripper
from qualgrasp.experiments.mesh_study import independent_travel

PANDA = load_gripper("franka_panda")
W = 0.06


def bar(lo, hi) -> trimesh.Trimesh:
    """A box from corner ``lo`` to corner ``hi``."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    return trimesh.creation.box(hi - lo, trimesh.transformations.translation_matrix((lo + hi) / 2))


def outer_cell_edge() -> float:
    """``y`` of the outermost cell centres: the rim beyond it is what cell rays do not see."""
    return float(np.abs(pad_grid(PANDA)[0][:, 0]).max())


def agree_with_samples(mesh, out):
    points = trimesh.sample.sample_surface(mesh, 200_000, seed=3)[0]
    ta, tb = independent_travel(points, np.eye(4), W, PANDA)
    assert abs(out.patches[0].travel - ta) <= TOLERANCE and abs(out.patches[1].travel - tb) <= TOLERANCE


@pytest.mark.parametrize("z", [0.005, 0.03])  # the bar's corners inside the pad's prism, or its edges crossing it
def test_a_thin_bar_under_the_rim_only_is_touched(z):
    y0 = outer_cell_edge() + 0.0001            # between the last cell centre and the pad's edge
    assert y0 + 0.0002 < PANDA.pad_width / 2
    mesh = bar((0.015, y0, -z), (0.02, y0 + 0.0002, z))
    out = jaw_contacts(mesh, PANDA, np.eye(4)[None], np.array([W]))[0]
    assert out.ok, out.message
    a, b = out.patches
    assert a.travel == pytest.approx(W / 2 - 0.02, abs=1e-12) and b.travel == pytest.approx(W / 2 + 0.015, abs=1e-12)
    # a flat pad pressing the bar's corner or edge: the pad's normal, no area, the one-cell torsion floor
    assert a.normal.tolist() == [-1.0, 0.0, 0.0] and b.normal.tolist() == [1.0, 0.0, 0.0]
    assert a.area == 0 and a.torsion > 0 and len(a.points) == 1
    agree_with_samples(mesh, out)


def test_a_bump_under_the_rim_sets_the_travel_of_a_patch_seen_by_the_cells():
    """A block the cells see, and a 3 mm bump nearer the pad that only the rim meets: the travel is
    the bump's; the cells within the tolerance of it form the patch (here none but the bump)."""
    y0 = outer_cell_edge() + 0.0001
    block = bar((-0.02, -0.02, -0.02), (0.017, 0.02, 0.02))
    bump = bar((0.017, y0, -0.002), (0.02, y0 + 0.0002, 0.002))
    mesh = trimesh.util.concatenate([block, bump])
    out = jaw_contacts(mesh, PANDA, np.eye(4)[None], np.array([W]))[0]
    assert out.ok, out.message
    assert out.patches[0].travel == pytest.approx(W / 2 - 0.02, abs=1e-12)   # not the block's W/2 - 0.017
    assert out.patches[1].travel == pytest.approx(W / 2 - 0.02, abs=1e-12)   # pad B meets the block's face
    assert out.patches[1].area > 0
    agree_with_samples(mesh, out)


def test_a_pad_whose_cells_meet_the_object_is_unchanged():
    box = trimesh.creation.box((0.05, 0.06, 0.06))
    out = jaw_contacts(box, PANDA, np.eye(4)[None], np.array([0.07]))[0]
    a = out.patches[0]
    assert a.travel == pytest.approx(0.01) and a.area == pytest.approx(PANDA.pad_width * PANDA.pad_height)
    assert len(a.points) == 21 * 21


def test_a_thin_wall_through_the_pad_is_a_collision():
    """A 0.2 mm wall between the cells' rays and the approach test's rays, passing through pad A's
    face: no vertex in the finger's prism, no ray starting inside, yet the pad cuts into it."""
    mesh = bar((0.0, 0.0005, -0.005), (0.05, 0.0007, 0.005))
    out = jaw_contacts(mesh, PANDA, np.eye(4)[None], np.array([W]))[0]
    assert out.reason == "collision" and "pad A cuts into the object" in out.message


def test_sampled_poses_do_not_cut_into_a_curved_object():
    """On a capsule the sampler's 5 mm clearance does not always clear a pad's corner (a cell of
    pad B once started inside it): such approaches are not kept."""
    from qualgrasp.certify.meshes.sampling import sample_poses

    mesh = trimesh.creation.capsule(0.05, 0.02)
    poses = sample_poses(mesh, PANDA, 25, mu=0.5, seed=0)
    out = jaw_contacts(mesh, PANDA, np.array([p.T for p in poses]), np.array([p.width for p in poses]))
    assert len(poses) == 25 and all(o.ok for o in out)

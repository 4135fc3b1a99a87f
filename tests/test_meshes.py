"""Meshes, rays, grippers and contacts from poses (qualgrasp.certify.meshes), on meshes made
here with trimesh.creation, with answers known in closed form."""


import numpy as np
import pytest

trimesh = pytest.importorskip("trimesh")

from qualgrasp.certify.errors import CertifyError
from qualgrasp.certify.meshes.contacts import jaw_contacts, fingertip_contacts
from qualgrasp.certify.meshes.errors import GripperError, MeshError, PoseError
from qualgrasp.certify.meshes.gripper import (builtin_grippers, check_pose, from_qualgrasp, gripper_from_dict,
                                              load_gripper, to_qualgrasp)
from qualgrasp.certify.meshes.mesh import check_mesh, load_mesh, mass_properties, repair_mesh
from qualgrasp.certify.meshes.rays import RayCaster, embree_available
from qualgrasp.certify.meshes.sampling import sample_poses

PANDA = load_gripper("franka_panda")


def pose(x=(1, 0, 0), z=(0, 0, 1), origin=(0, 0, 0)):
    """A qualgrasp pose with closing axis x and approach axis z (orthonormalised)."""
    x = np.asarray(x, float) / np.linalg.norm(x)
    z = np.asarray(z, float) - np.dot(z, x) * x
    z /= np.linalg.norm(z)
    T = np.eye(4)
    T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = x, np.cross(z, x), z, origin
    return T


def l_bracket():
    """An L in the xy plane (arms 0.1 long, 0.02 thick) extruded 0.1 along z, centred on z = 0."""
    L = np.array([(-0.05, -0.01), (0.05, -0.01), (0.05, 0.09), (0.03, 0.09), (0.03, 0.01), (-0.05, 0.01)])
    V = np.vstack([np.column_stack([L, np.full(6, -0.05)]), np.column_stack([L, np.full(6, 0.05)])])
    cap = np.array([(0, 1, 4), (0, 4, 5), (1, 2, 3), (1, 3, 4)])
    sides = [f for i in range(6) for f in ((i, (i + 1) % 6, (i + 1) % 6 + 6), (i, (i + 1) % 6 + 6, i + 6))]
    return trimesh.Trimesh(V, np.vstack([cap + 6, cap[:, ::-1], sides]))


def close(mesh, T, w, **kw):
    return jaw_contacts(mesh, PANDA, np.asarray(T)[None], np.array([w]), **kw)[0]


# --- meshes --------------------------------------------------------------------------------

@pytest.mark.parametrize("suffix", [".obj", ".stl", ".ply", ".glb", ".off"])
def test_formats_read_to_the_same_solid(tmp_path, suffix):
    box = trimesh.creation.box((40, 60, 80))
    path = tmp_path / f"box{suffix}"
    box.export(path)
    m = load_mesh(path, units="mm")
    assert m.volume == pytest.approx(0.04 * 0.06 * 0.08, rel=1e-9)


def test_open_degenerate_flat_inverted_and_nonmanifold_meshes_are_refused_with_counts():
    box = trimesh.creation.box((0.1, 0.1, 0.1))
    with pytest.raises(MeshError, match=r"not closed: 4 edges belong to one face only"):
        check_mesh(trimesh.Trimesh(box.vertices, box.faces[:-2], process=False))
    degenerate = trimesh.Trimesh(np.vstack([box.vertices, box.vertices[:1]]),
                                 np.vstack([box.faces, [[0, 8, 1]]]), process=False)
    with pytest.raises(MeshError, match=r"1 of 13 faces are degenerate"):
        check_mesh(degenerate)
    flat = trimesh.Trimesh(box.vertices * [1, 1, 0], box.faces, process=False)
    with pytest.raises(MeshError, match="degenerate|zero volume"):
        check_mesh(flat)
    with pytest.raises(MeshError, match="wound inward"):
        check_mesh(trimesh.Trimesh(box.vertices, box.faces[:, ::-1], process=False))
    two = trimesh.util.concatenate([box, box])
    two.merge_vertices()
    with pytest.raises(MeshError, match="not manifold"):
        check_mesh(two)


def test_repair_reports_what_it_changed_and_the_result_checks():
    box = trimesh.creation.box((0.1, 0.1, 0.1))
    fixed, notes = repair_mesh(trimesh.Trimesh(box.vertices, box.faces[:, ::-1], process=False))
    check_mesh(fixed)
    assert notes == ("inverted the faces (they were wound inward)",)
    assert repair_mesh(box)[1] == ()


def test_wrong_units_are_refused_with_the_unit_that_fits(tmp_path):
    path = tmp_path / "mug.stl"
    trimesh.creation.cylinder(40, 100).export(path)  # millimetres
    with pytest.raises(MeshError, match=r"give units='mm' \(--units mm\)"):
        load_mesh(path)
    tiny = tmp_path / "tiny.stl"
    trimesh.creation.box((0.0004, 0.0004, 0.0004)).export(tiny)
    with pytest.raises(MeshError, match="less than 0.001 m"):
        load_mesh(tiny)
    with pytest.raises(MeshError, match="no such file"):
        load_mesh(tmp_path / "missing.obj")
    (tmp_path / "junk.obj").write_text("this is not a mesh\n")
    with pytest.raises(CertifyError):
        load_mesh(tmp_path / "junk.obj")


def test_mass_properties_of_a_box_and_a_cylinder_are_the_closed_forms():
    a, b, c, m = 0.1, 0.2, 0.3, 2.0
    p = mass_properties(trimesh.creation.box((a, b, c)), mass=m)
    expected = np.diag([m * (b * b + c * c), m * (a * a + c * c), m * (a * a + b * b)]) / 12
    assert np.allclose(p.inertia, expected, rtol=1e-9) and np.allclose(p.com, 0, atol=1e-12)
    cyl = trimesh.creation.cylinder(0.05, 0.2, sections=256)
    q = mass_properties(cyl, density=1000.0)
    assert q.mass == pytest.approx(1000 * np.pi * 0.05 ** 2 * 0.2, rel=1e-3)
    assert q.inertia[2][2] == pytest.approx(q.mass * 0.05 ** 2 / 2, rel=1e-3)
    with pytest.raises(MeshError, match="not both"):
        mass_properties(cyl, density=1.0, mass=1.0)
    with pytest.raises(MeshError, match="finite positive"):
        mass_properties(cyl, mass=-1.0)


# --- grippers and poses ----------------------------------------------------------------------

def test_builtin_grippers_carry_their_published_pad_dimensions():
    assert set(builtin_grippers()) >= {"franka_panda", "robotiq_2f85", "three_finger_point"}
    robotiq = load_gripper("robotiq_2f85")
    assert (robotiq.pad_width, robotiq.pad_height, robotiq.max_opening) == (0.022, 0.0375, 0.085)
    assert (PANDA.pad_width, PANDA.pad_height, PANDA.max_opening) == (0.0175, 0.0185, 0.08)
    assert load_gripper("three_finger_point").fingers == 3


def test_gripper_files_with_errors_name_the_key(tmp_path):
    with pytest.raises(GripperError, match=r"pad.width must be a number > 0"):
        gripper_from_dict({"name": "g", "kind": "parallel_jaw", "mu": 0.5, "pad": {"width": -1}})
    bad = tmp_path / "g.toml"
    bad.write_text("name = 'g'\nkind = 'parallel_jaw'\nmu = 0.5\n[pad]\nwidth = 0.02\nheight = 0.02\n"
                   "[finger]\nthickness = 0.01\n[opening]\nmin = 0.1\nmax = 0.05\n")
    with pytest.raises(GripperError, match=r"opening.min \(0.1\) must be below opening.max"):
        load_gripper(bad)
    with pytest.raises(GripperError, match="no gripper 'nope'"):
        load_gripper("nope")


def test_acronym_and_graspnet_conventions_put_the_pads_where_their_tools_draw_the_fingers():
    rng = np.random.default_rng(3)
    for _ in range(20):
        q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        q *= np.sign(np.linalg.det(q))
        T = np.eye(4)
        T[:3, :3], T[:3, 3] = q, rng.normal(size=3) * 0.1
        # ACRONYM: fingers along x of the flange frame, pad centre flange_to_pad along z
        Tq = to_qualgrasp(T, "acronym", PANDA)
        assert np.allclose(Tq[:3, 3], T[:3, 3] + PANDA.flange_to_pad * T[:3, 2])
        assert np.allclose(Tq[:3, 0], T[:3, 0]) and np.allclose(Tq[:3, 2], T[:3, 2])
        # GraspNet: approach x, closing y, fingertips at x = depth
        depth = 0.03
        Tg = to_qualgrasp(T, "graspnet", PANDA, depth)
        tip = Tg[:3, 3] + PANDA.pad_height / 2 * Tg[:3, 2]
        assert np.allclose(tip, T[:3, 3] + depth * T[:3, 0])
        assert np.allclose(Tg[:3, 0], T[:3, 1]) and np.allclose(Tg[:3, 2], T[:3, 0])
        for conv in ("qualgrasp", "acronym", "graspnet"):
            assert np.allclose(from_qualgrasp(to_qualgrasp(T, conv, PANDA, depth), conv, PANDA, depth), T)


def test_malformed_poses_are_refused():
    with pytest.raises(PoseError, match="reflection"):
        check_pose(np.diag([1.0, 1.0, -1.0, 1.0]))
    with pytest.raises(PoseError, match="last row"):
        check_pose([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 1, 1]])
    with pytest.raises(PoseError, match="4x4"):
        check_pose([[1, 0, 0], [0, 1, 0], [0, 0, 1]])


# --- contacts from poses --------------------------------------------------------------------

def test_box_across_its_faces_touches_the_face_centres_with_the_whole_pad():
    box = trimesh.creation.box((0.05, 0.06, 0.06))
    out = close(box, pose(origin=(0.004, 0, 0)), 0.07)
    A, B = out.patches
    assert np.allclose(A.centroid, (0.025, 0, 0), atol=1e-9) and np.allclose(B.centroid, (-0.025, 0, 0), atol=1e-9)
    assert np.allclose(A.normal, (-1, 0, 0)) and np.allclose(B.normal, (1, 0, 0))
    assert A.area == pytest.approx(PANDA.pad_width * PANDA.pad_height)
    # pads close on their own: A (at x = 0.004 + 0.035) travels 0.014, B (at 0.004 - 0.035) 0.006
    assert (A.travel, B.travel) == (pytest.approx(0.014), pytest.approx(0.006))
    # torsion: the mean distance over the pad rectangle (a fine quadrature of the same integral)
    y, z = np.meshgrid(np.linspace(-1, 1, 801) * PANDA.pad_width / 2, np.linspace(-1, 1, 801) * PANDA.pad_height / 2)
    assert A.torsion == pytest.approx(np.hypot(y, z).mean(), rel=0.01)


def test_sphere_patch_is_the_cap_within_the_tolerance_and_its_torsion_two_thirds_its_radius():
    R = 0.03
    sphere = trimesh.creation.icosphere(subdivisions=5, radius=R)
    for tol in (2e-4, 5e-4, 1e-3):
        A, B = close(sphere, pose(z=(0.3, 0.2, 1)), 0.07, tolerance=tol, resolution=61).patches
        a = np.sqrt(2 * R * tol - tol * tol)  # the cap of a sphere cut tol below its top
        cell = PANDA.pad_width / 61
        for p in (A, B):
            assert abs(p.radius - a) < 2 * cell + 3e-4  # faceting: the icosphere's facets are ~0.4 mm
            assert p.torsion == pytest.approx(2 * a / 3, abs=2 * cell + 3e-4)
            # the cap's points lie r^2 / (2 R) deep, tol / 2 on average over the pad's area
            assert np.linalg.norm(p.centroid) == pytest.approx(R - tol / 2, abs=1e-4)
    small = close(sphere, pose(), 0.07, tolerance=1e-5).patches[0]
    assert small.torsion < 0.2 * close(trimesh.creation.box((0.05, 0.06, 0.06)), pose(), 0.07).patches[0].torsion


def test_cylinder_across_its_axis_touches_a_strip_and_along_it_the_whole_pad():
    R, H, tol = 0.02, 0.05, 5e-4
    cyl = trimesh.creation.cylinder(R, H, sections=512)  # axis z
    # across the axis: closing x, approach -y; the pad's height (along z of the pose) lies along the axis
    A, _ = close(cyl, pose(x=(1, 0, 0), z=(0, 1, 0)), 0.06, tolerance=tol, resolution=61).patches
    strip = 2 * np.sqrt(2 * R * tol - tol * tol)
    assert A.area == pytest.approx(strip * PANDA.pad_width, rel=0.15)
    assert A.radius == pytest.approx(np.hypot(PANDA.pad_width / 2, strip / 2), rel=0.05)
    # along the axis: the flat end faces take the whole pad
    short = trimesh.creation.cylinder(R, 0.04, sections=512)
    C, D = close(short, pose(x=(0, 0, 1), z=(1, 0, 0)), 0.07).patches
    assert C.area == pytest.approx(PANDA.pad_width * PANDA.pad_height) and np.allclose(C.normal, (0, 0, -1))
    y, z = np.meshgrid(np.linspace(-1, 1, 801) * PANDA.pad_width / 2, np.linspace(-1, 1, 801) * strip / 2)
    assert A.torsion == pytest.approx(np.hypot(y, z).mean(), rel=0.05)  # the strip's mean distance
    assert C.torsion > 1.2 * A.torsion


def test_every_pose_is_a_row_errors_name_their_reason():
    box = trimesh.creation.box((0.05, 0.06, 0.06))
    poses = np.array([pose(), pose(origin=(0, 0.2, 0)), pose(origin=(0, 0, 0.04)), pose(), pose(), pose(z=(0, 0, -1))])
    widths = np.array([0.09, 0.07, 0.07, 0.03, -0.01, 0.07])
    out = jaw_contacts(box, PANDA, poses, widths, caster=RayCaster(box, "triangle"))
    assert len(out) == len(poses)
    assert [o.reason for o in out] == ["too_wide", "no_contact", "collision", "collision", "too_narrow", None]
    assert out[2].message == "the palm meets the object while approaching"
    assert out[3].message == "the finger A meets the object while approaching"


def test_thin_features_between_the_approach_rays_are_caught_by_the_vertex_test():
    # a thin slab (0.5 mm) crossing the palm between its ray grid lines
    slab = trimesh.creation.box((0.001, 0.0005, 0.02))
    slab.apply_translation((0.003, 0.0031, -0.06))
    body = trimesh.creation.box((0.05, 0.06, 0.03))
    mesh = trimesh.util.concatenate([body, slab])
    out = close(mesh, pose(), 0.07)
    assert out.reason == "collision" and "palm" in out.message


def test_torus_and_l_bracket():
    torus = trimesh.creation.torus(0.04, 0.012, major_sections=128, minor_sections=64)
    # across the tube, coming from outside the ring: the pads meet the tube's top and bottom
    A, B = close(torus, pose(x=(0, 0, 1), z=(-1, 0, 0), origin=(0.04, 0, 0)), 0.04).patches
    assert A.centroid[2] == pytest.approx(0.012, abs=3e-4) and B.centroid[2] == pytest.approx(-0.012, abs=3e-4)
    assert np.allclose(A.normal, (0, 0, -1), atol=0.02)
    # the same from inside the ring: the palm runs into the far side of the ring
    inside = close(torus, pose(x=(0, 0, 1), z=(1, 0, 0), origin=(0.04, 0, 0)), 0.04)
    assert inside.reason == "collision" and "palm" in inside.message
    # pads lowered into the hole: the fingers behind them meet the ring while approaching
    hole = close(torus, pose(x=(1, 0, 0), z=(0, 0, 1)), 0.05)
    assert hole.reason == "collision" and "finger" in hole.message
    # an L-bracket: a pose whose finger lands on the other arm collides
    bracket = l_bracket()
    check_mesh(bracket)
    ok = close(bracket, pose(x=(0, 1, 0), z=(0, 0, -1), origin=(-0.02, 0, 0.04)), 0.04)
    assert ok.ok
    hit = close(bracket, pose(x=(0, 1, 0), z=(-1, 0, 0), origin=(0.0, 0, 0)), 0.04)
    assert hit.reason == "collision"


@pytest.mark.skipif(not embree_available(), reason="embreex not installed")
def test_embree_and_numpy_rays_give_the_same_contacts():
    rng = np.random.default_rng(0)
    meshes = [trimesh.creation.box((0.05, 0.06, 0.04)), trimesh.creation.icosphere(4, 0.03),
              trimesh.creation.capsule(0.05, 0.02), trimesh.creation.torus(0.04, 0.012)]
    for mesh in meshes:
        poses = sample_poses(mesh, PANDA, 30, mu=0.5, seed=1, caster=RayCaster(mesh, "triangle"))
        T = np.array([p.T for p in poses])
        # shake the poses so that some collide or miss
        T[:, :3, 3] += rng.normal(scale=0.01, size=(len(T), 3))
        w = np.array([p.width for p in poses])
        a = jaw_contacts(mesh, PANDA, T, w, caster=RayCaster(mesh, "triangle"))
        b = jaw_contacts(mesh, PANDA, T, w, caster=RayCaster(mesh, "embree"))
        for x, y in zip(a, b):
            assert x.reason == y.reason
            for p, q in zip(x.patches, y.patches):
                assert np.allclose(p.centroid, q.centroid, atol=1e-5) and np.allclose(p.normal, q.normal, atol=1e-4)
                assert p.area == pytest.approx(q.area, rel=0.02)


def test_contacts_agree_with_sampled_surface_points_nearest_the_closed_pad():
    """An independent route: dense surface samples in the pad's prism; the first touch is the
    sample nearest the open pad along the closing axis."""
    tol = 5e-4
    for mesh in (trimesh.creation.icosphere(4, 0.03), trimesh.creation.capsule(0.05, 0.02),
                 trimesh.creation.box((0.05, 0.04, 0.03))):
        pts = trimesh.sample.sample_surface(mesh, 60_000, seed=2)[0]
        poses = sample_poses(mesh, PANDA, 20, mu=0.4, seed=5)
        out = jaw_contacts(mesh, PANDA, np.array([p.T for p in poses]), np.array([p.width for p in poses]),
                           tolerance=tol)
        for p, o in zip(poses, out):
            local = (pts - p.T[:3, 3]) @ p.T[:3, :3]
            inside = (np.abs(local[:, 1]) <= PANDA.pad_width / 2) & (np.abs(local[:, 2]) <= PANDA.pad_height / 2)
            travel = p.width / 2 - local[inside, 0]  # pad A's distance to each sample
            assert o.ok
            assert o.patches[0].travel == pytest.approx(travel.min(), abs=tol)


def test_point_hand_fingertips_close_towards_their_centre():
    hand = load_gripper("three_finger_point")
    box = trimesh.creation.box((0.06, 0.06, 0.06))
    tips = np.array([[[0.1, 0.0, 0.0], [-0.1, 0.05, 0.0], [-0.1, -0.05, 0.0]],
                     [[0.3, 0.0, 0.0], [-0.3, 0.05, 0.0], [-0.3, -0.05, 0.0]],
                     [[0.0, 0.0, 0.0], [-0.1, 0.0, 0.02], [-0.1, 0.0, -0.02]]])
    out = fingertip_contacts(box, hand, tips)
    assert out[0].ok and [o.reason for o in out[1:]] == ["no_contact", "collision"]
    assert np.allclose(out[0].patches[0].centroid, (0.03, 0, 0)) and np.allclose(out[0].patches[0].normal, (-1, 0, 0))


def test_sampled_poses_are_antipodal_and_give_contacts():
    mesh = trimesh.creation.capsule(0.05, 0.02)
    poses = sample_poses(mesh, PANDA, 25, mu=0.5, seed=0)
    assert len(poses) == 25
    for p in poses:
        x = p.T[:3, 0]
        assert np.allclose(x, (p.p1 - p.p2) / np.linalg.norm(p.p1 - p.p2))
        assert p.width <= PANDA.max_opening
    out = jaw_contacts(mesh, PANDA, np.array([p.T for p in poses]), np.array([p.width for p in poses]))
    assert all(o.ok for o in out)

"""Spatial physics (MuJoCo): the closed-form box threshold and the trial's verdicts at either side
of it, and the convex pieces of a mesh."""

import math

import numpy as np
import pytest
import trimesh

pytest.importorskip("mujoco", reason="the spatial validation needs mujoco (pip install 'qualgrasp[physics]')")

from qualgrasp.certify.meshes.task import G  # noqa: E402
from qualgrasp.experiments.physics.closed_forms import BOX_MASS, SPATIAL_PRECISION, box_grasp, spatial_cases  # noqa: E402
from qualgrasp.experiments.physics.spatial import (  # noqa: E402
    SpatialPhysics, convex_pieces, least_physical_grip, squeeze_forces, trial, world_xml)

#: The measured error of the box's least grip force (closed-forms table, both settings of
#: docs/spatial-validation.md: at most 0.3 %), with the bisection's own bracket on top.
TOLERANCE = 0.005 + (SPATIAL_PRECISION - 1)


@pytest.mark.parametrize("mu", [0.5, 1.0])
def test_box_threshold_is_m_g_over_2_mu(mu):
    obj, jaw = box_grasp(mu)
    exact = BOX_MASS * G / (2 * mu)
    measured = least_physical_grip(obj, jaw, exact / 3, exact * 3.7, precision=SPATIAL_PRECISION)
    assert abs(measured / exact - 1) <= TOLERANCE


def test_trial_holds_at_3_f_star_and_drops_at_0_3():
    obj, jaw = box_grasp(0.5)
    star = BOX_MASS * G / (2 * 0.5)
    strong = trial(obj, jaw, 3 * star)
    assert strong.held and strong.held_shake and not strong.dropped
    assert strong.slip < SpatialPhysics().slip and strong.contacts >= 2 and strong.settle < 1e-3  # centred: barely moved
    weak = trial(obj, jaw, 0.3 * star)
    assert not weak.held and weak.dropped and weak.slip > SpatialPhysics().reach / 2


def test_squeeze_presses_with_the_grip_force():
    obj, jaw = box_grasp(0.5)
    forces, depth = squeeze_forces(obj, jaw, 4.0)
    assert np.allclose(forces, 4.0, rtol=1e-3) and 0 < depth < 1e-3


def test_off_centre_grasp_of_a_long_bar_needs_more_than_the_centred_one():
    """A weight off the grasp line twists the bar about the grasp axis: the pads' patches must resist
    that torque, so the same bar gripped 40 mm from its centre needs a larger grip force."""
    from qualgrasp.certify.meshes.mesh import mass_properties
    from qualgrasp.experiments.physics.spatial import Jaw, SpatialObject

    bar = trimesh.creation.box((0.04, 0.16, 0.03))
    obj = SpatialObject(tuple(convex_pieces(bar)[0]), mass_properties(bar, mass=BOX_MASS))
    _, jaw = box_grasp(0.5)
    centred = Jaw(np.eye(4), 0.05, jaw.gripper, 0.5, (0.0, 0.0))
    T = np.eye(4)
    T[1, 3] = 0.04  # along the bar: the weight's moment is about the closing axis
    off = Jaw(T, 0.05, jaw.gripper, 0.5, (0.0, 0.0))
    f_centre = least_physical_grip(obj, centred, 0.5, 40.0, precision=1.05)
    f_off = least_physical_grip(obj, off, 0.5, 40.0, precision=1.05)
    assert f_centre == pytest.approx(BOX_MASS * G, rel=0.06)
    assert f_off > 1.5 * f_centre


def test_convex_pieces_of_a_non_convex_mesh_cover_it():
    pytest.importorskip("coacd", reason="the convex decomposition needs coacd")
    ring = trimesh.creation.annulus(0.02, 0.04, 0.02, sections=32)
    pieces, how = convex_pieces(ring)
    assert how == "coacd" and len(pieces) > 1
    points = trimesh.sample.sample_surface(ring, 200, seed=0)[0]
    hulls = [trimesh.convex.convex_hull(v) for v in pieces]
    gap = np.min([np.abs(trimesh.proximity.signed_distance(h, points)) for h in hulls], axis=0)
    assert gap.max() < 3e-3  # an approximate decomposition: every surface point near a piece
    assert not any(h.contains([[0.0, 0.0, 0.0]])[0] for h in hulls)  # the hole stays open (not the hull)


def test_pieces_far_from_the_pads_are_left_out():
    obj, jaw = box_grasp(0.5)
    far = jaw.T.copy()
    far[2, 3] = 1.0
    with pytest.raises(ValueError, match="no piece"):
        world_xml(obj, type(jaw)(far, jaw.width, jaw.gripper, jaw.mu, jaw.torsion), 1.0)


def test_spatial_cases_name_every_case():
    rows = spatial_cases(SpatialPhysics(dt=2e-3, iterations=20))
    assert [r.case for r in rows][2:5] == [f"box: least grip force, mu {m:g}" for m in (0.25, 0.5, 1.0)]
    assert all(abs(r.error) <= TOLERANCE for r in rows[2:5])


def _app():
    import typer

    from qualgrasp.experiments.physics.cli import register

    app = typer.Typer()

    @app.callback()
    def main():
        pass

    register(app)
    return app


@pytest.mark.parametrize("args, message", [
    (["validate", "--spatial", "--setting", "huge"], "--setting must be one of"),
    (["validate", "--spatial", "--out", "file"], "is not a folder"),
])
def test_spatial_refused_options_exit_2_with_one_line(args, message, tmp_path, monkeypatch):
    from typer.testing import CliRunner

    monkeypatch.chdir(tmp_path)
    (tmp_path / "file").write_text("x")
    result = CliRunner().invoke(_app(), args)
    assert result.exit_code == 2, result.output
    assert message in result.output and "Traceback" not in result.output


def test_spatial_without_mujoco_exits_2(monkeypatch, tmp_path):
    import importlib.util

    from typer.testing import CliRunner

    from qualgrasp.experiments.physics import cli

    real = importlib.util.find_spec
    monkeypatch.setattr(cli.importlib.util, "find_spec", lambda name, *a: None if name == "mujoco" else real(name, *a))
    result = CliRunner().invoke(_app(), ["validate", "--spatial", "--out", str(tmp_path / "out")])
    assert result.exit_code == 2 and "needs mujoco" in result.output, result.output


def test_weight_along_the_closing_axis_is_borne_by_the_coupled_pads():
    """The closing axis vertical: the coupled pads (the Franka hand's fingers) close with 2 F in all,
    and the lower one carries the weight while 2 F >= m g. Pads pressed by independent forces would
    slide down with the object at any grip force."""
    obj, jaw = box_grasp(0.5)
    T = np.eye(4)
    T[:3, :3] = trimesh.transformations.rotation_matrix(math.pi / 2, (0, 1, 0))[:3, :3]  # hand x along world -z
    vertical = type(jaw)(T, 0.08, jaw.gripper, 0.5, (0.0, 0.0))  # across the 70 mm faces
    weight = BOX_MASS * G
    held = trial(obj, vertical, 0.6 * weight)
    assert held.held and held.held_shake and held.slip < 2e-3
    assert trial(obj, vertical, 0.4 * weight).dropped

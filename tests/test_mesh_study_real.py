"""The real-mesh study's reader (qualgrasp.experiments.mesh_study.real_meshes) on a package made in
the test: a model whose first (visual) mesh is open gives its collision mesh, scaled as the model
scales it; copies are skipped; a model none of whose meshes closes is skipped with its first
mesh's reason; a MuJoCo include's paths resolve from the including model's folder, and an MJCF's
later meshes (other parts) never stand in for an open first one. The real packages are optional
installs, so none is used here."""

import numpy as np
import pytest

trimesh = pytest.importorskip("trimesh")

from qualgrasp.experiments import mesh_study


def urdf(visual: str, collision: str, scale: str = "0.1 0.1 0.1") -> str:
    """A one-link URDF naming ``visual`` then ``collision``, both scaled by ``scale``."""
    return (f'<robot name="r"><link name="l"><visual><geometry><mesh filename="{visual}" scale="{scale}"/>'
            f'</geometry></visual><collision><geometry><mesh filename="{collision}" scale="{scale}"/>'
            '</geometry></collision></link></robot>')


@pytest.fixture
def package(tmp_path, monkeypatch):
    """An importable package ``fakeobjects`` with three models, read by ``real_meshes`` alone."""
    root = tmp_path / "fakeobjects"
    root.mkdir()
    (root / "__init__.py").write_text("")
    box = trimesh.creation.box((0.5, 0.3, 0.2))
    box.export(root / "closed.stl")
    ball = trimesh.creation.icosphere(2, 0.2)
    cut = trimesh.Trimesh(ball.vertices, ball.faces[ball.triangles_center[:, 2] < 0.1])  # a hole no repair fills
    cut.export(root / "open.stl")
    (root / "cup.urdf").write_text(urdf("open.stl", "closed.stl"))
    (root / "copy.urdf").write_text(urdf("open.stl", "closed.stl", "0.2 0.2 0.2"))  # same faces, rescaled
    (root / "hollow.urdf").write_text(urdf("open.stl", "open.stl"))
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setattr(mesh_study, "REAL_SOURCES", (("fakeobjects", "*.urdf", "made in the test"),))
    return root


def test_an_open_visual_mesh_gives_the_closed_collision_mesh_scaled(package):
    meshes, skipped = mesh_study.real_meshes()
    assert list(meshes) == ["fakeobjects/fakeobjects/copy"]
    mesh, source = meshes["fakeobjects/fakeobjects/copy"]
    assert source == "made in the test"
    assert mesh.is_watertight
    np.testing.assert_allclose(sorted(mesh.extents), sorted(0.2 * np.array([0.5, 0.3, 0.2])))
    assert np.isclose(mesh.volume, 0.5 * 0.3 * 0.2 * 0.2 ** 3)


def test_copies_and_models_that_never_close_are_skipped_with_reasons(package):
    skipped = dict(mesh_study.real_meshes()[1])
    assert skipped["fakeobjects/fakeobjects/cup"] == "the same mesh as fakeobjects/fakeobjects/copy"
    assert skipped["fakeobjects/fakeobjects/hollow"] == "the same mesh as fakeobjects/fakeobjects/copy"


def test_a_model_none_of_whose_meshes_closes_keeps_its_first_reason(package):
    (package / "copy.urdf").unlink()
    (package / "cup.urdf").unlink()
    meshes, skipped = mesh_study.real_meshes()
    assert meshes == {}
    (name, why), = skipped
    assert name == "fakeobjects/fakeobjects/hollow"
    assert why.startswith("the mesh is not closed")


def test_named_meshes_lists_every_mesh_with_its_scale(package):
    named = mesh_study.named_meshes(package / "cup.urdf")
    assert [(p.name, s) for p, s in named] == [("open.stl", (0.1, 0.1, 0.1)), ("closed.stl", (0.1, 0.1, 0.1))]
    (package / "none.urdf").write_text('<robot name="r"><link name="l"/></robot>')
    with pytest.raises(ValueError, match="names no mesh"):
        mesh_study.named_meshes(package / "none.urdf")


def test_an_include_s_paths_resolve_from_the_including_folder_and_its_parts_are_not_objects(tmp_path, monkeypatch):
    """A MuJoCo include ``objs/cup/assets.xml`` names ``../objs/cup/cup.stl``, a path relative to
    the folder of a model that would include it (a sibling of ``objs/``): it is found there. An MJCF whose first
    mesh is open is skipped: its later meshes are other parts (here a closed piece), not the object."""
    root = tmp_path / "fakemjcf"
    (root / "objs" / "cup").mkdir(parents=True)
    (root / "objs" / "bad").mkdir()
    (root / "__init__.py").write_text("")
    trimesh.creation.box((0.04, 0.05, 0.06)).export(root / "objs" / "cup" / "cup.stl")
    ball = trimesh.creation.icosphere(2, 0.03)
    cut = trimesh.Trimesh(ball.vertices, ball.faces[ball.triangles_center[:, 2] < 0.01])
    cut.export(root / "objs" / "bad" / "bad.stl")
    trimesh.creation.box((0.01, 0.01, 0.01)).export(root / "objs" / "bad" / "piece.stl")
    (root / "objs" / "cup" / "assets.xml").write_text(
        '<mujocoinclude><asset><mesh name="cup" file="../objs/cup/cup.stl"/></asset></mujocoinclude>')
    (root / "objs" / "bad" / "assets.xml").write_text(
        '<mujocoinclude><asset><mesh name="bad" file="../objs/bad/bad.stl"/>'
        '<mesh name="piece" file="../objs/bad/piece.stl"/></asset></mujocoinclude>')
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setattr(mesh_study, "REAL_SOURCES", (("fakemjcf", "objs/*/assets.xml", "made in the test"),))
    meshes, skipped = mesh_study.real_meshes()
    assert list(meshes) == ["fakemjcf/cup/assets"]
    np.testing.assert_allclose(meshes["fakemjcf/cup/assets"][0].extents, [0.04, 0.05, 0.06])
    assert [name for name, _ in skipped] == ["fakemjcf/bad/assets"]
    assert skipped[0][1].startswith("the mesh is not closed")

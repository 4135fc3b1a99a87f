"""``qualgrasp bench --single``: one spatial grasp per call against Dex-Net's force_closure_qp,
loaded from a graspnetAPI sdist at benchmark time (:mod:`qualgrasp.experiments.dexnet`). No
timing is asserted: what is checked is the table's content, the loader and Dex-Net's inputs."""

import io
import tarfile

import numpy as np
import pytest
from typer.testing import CliRunner

from qualgrasp.certify.batch import random_grasps
from qualgrasp.certify.core.wrench import wrench
from qualgrasp.cli import app
from qualgrasp.experiments.bench import run_single_bench
from qualgrasp.certify.errors import OptionError
from qualgrasp.experiments.dexnet import QUALITY_FILE, dexnet_inputs, load_dexnet

runner = CliRunner()

#: A stand-in for Dex-Net's quality module: the import on top cannot run, so loading proves that
#: only the class is compiled; its force_closure_qp says whether the first wrench has torque.
FAKE_QUALITY = '''
import module_that_does_not_exist
import IPython

class PointGraspMetrics3D:
    @staticmethod
    def force_closure_qp(forces, torques, normals, soft_fingers=False, params=None):
        return int(np.abs(torques[:, 0] * params.torque_scaling).max() > 0)
'''


def _sdist(tmp_path, text=FAKE_QUALITY):
    path = tmp_path / "graspnetAPI-1.2.11.tar.gz"
    data = text.encode()
    with tarfile.open(path, "w:gz") as tar:
        info = tarfile.TarInfo("graspnetAPI-1.2.11/" + QUALITY_FILE)
        info.size = len(data)
        tar.addfile(info, io.BytesIO(data))
    return path


def test_dexnets_wrenches_are_the_grasps_on_eight_edges_of_each_exact_cone():
    for g in random_grasps(0, 20, dim=3, n_contacts=3, model="point"):
        forces, torques, normals, config = dexnet_inputs(g)
        N, P = g.normals, g.points
        assert np.array_equal(normals, N.T)
        mu = np.repeat([c.mu for c in g.contacts], 8)
        n = np.repeat(N, 8, axis=0)
        f = forces.T
        # unit normal force and a tangential part of norm mu: on the exact cone's boundary
        assert np.allclose(np.sum(f * n, axis=1), 1) and np.allclose(np.linalg.norm(f - n, axis=1), mu)
        ours = wrench(np.repeat(P, 8, axis=0), f, np.array(g.center), g.length)
        dex = np.vstack([forces, config.torque_scaling * torques]).T  # Dex-Net's grasp_matrix
        assert np.allclose(dex, ours, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("form", ["tar", "folder", "file"])
def test_the_loader_compiles_the_class_alone_from_each_form_of_the_sdist(tmp_path, form):
    pytest.importorskip("cvxopt")
    path = _sdist(tmp_path)
    if form != "tar":
        with tarfile.open(path) as tar:
            tar.extractall(tmp_path / "unpacked")
        path = tmp_path / "unpacked"
        if form == "file":
            path = next(path.rglob("quality.py"))
    dex = load_dexnet(path)
    g = random_grasps(1, 1, dim=3, n_contacts=2, model="point")[0]
    assert dex.force_closure_qp(*dexnet_inputs(g)) == 1


def test_the_loader_says_what_is_wrong(tmp_path):
    with pytest.raises(OptionError, match="does not exist"):
        load_dexnet(tmp_path / "nope.tar.gz")
    (tmp_path / "empty").mkdir()
    with pytest.raises(OptionError, match="no graspnetAPI/utils/dexnet/grasping/quality.py under"):
        load_dexnet(tmp_path / "empty")
    (tmp_path / "junk.tar.gz").write_bytes(b"not a tar file")
    with pytest.raises(OptionError, match="is not a graspnetAPI sdist"):
        load_dexnet(tmp_path / "junk.tar.gz")
    (tmp_path / "quality.py").write_bytes(b"\xff\xfe not text")
    with pytest.raises(OptionError, match="cannot read"):
        load_dexnet(tmp_path / "quality.py")
    pytest.importorskip("cvxopt")
    with pytest.raises(OptionError, match="defines no PointGraspMetrics3D"):
        load_dexnet(_sdist(tmp_path, "x = 1\n"))


def test_single_bench_times_both_routes_on_the_same_grasps(tmp_path):
    pytest.importorskip("cvxopt")
    rows = run_single_bench(n=30, seed=3, dexnet=load_dexnet(_sdist(tmp_path)))
    ours, dex = rows
    assert ours.grasps == dex.grasps == 30 and dex.speedup == 1.0
    assert ours.speedup == pytest.approx(dex.median_us / ours.median_us)
    assert ours.median_us <= ours.p95_us and dex.median_us <= dex.p95_us
    # the stand-in says closure for every grasp: the tally counts ours against it
    closure = int(ours.note.split()[0])
    assert dex.note == f"closure: {closure} both, 0 only exact cones, {30 - closure} only Dex-Net"


def test_single_bench_command_without_dexnet_skips_its_row_and_rejects_bad_options():
    result = runner.invoke(app, ["bench", "--single", "--n", "5"])
    assert result.exit_code == 0, result.output
    assert "qualgrasp force_closure" in result.output and "not run: pass --dexnet" in result.output
    for args, message in ((["--single", "--quality"], "does not go with --quality"),
                          (["--dexnet", "x.tar.gz"], "--dexnet goes with --single"),
                          (["--single", "--dexnet", "/nonexistent.tar.gz"], "does not exist"),
                          (["--single", "--n", "0"], "--n must be at least 1")):
        result = runner.invoke(app, ["bench", *args])
        assert result.exit_code == 2 and message in result.output, (args, result.output)

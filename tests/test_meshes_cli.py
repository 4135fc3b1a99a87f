"""qualgrasp contacts and qualgrasp sample-poses (qualgrasp.certify.meshes.cli), end to end:
their output is a grasp set that certify certifies; every pose is a row or an error row."""

import errno
import json

import numpy as np
import pyarrow.parquet as pq
import pytest
import typer
from typer.testing import CliRunner

trimesh = pytest.importorskip("trimesh")

from qualgrasp.certify.batch import certify_file
from qualgrasp.certify.files import read_results
from qualgrasp.certify.meshes import cli as mesh_cli
from qualgrasp.certify.meshes.cli import register

app = typer.Typer()
register(app)
runner = CliRunner()


@pytest.fixture
def box(tmp_path):
    path = tmp_path / "box.stl"
    trimesh.creation.box((50, 60, 60)).export(path)  # millimetres
    return path


def rows(path):
    return [json.loads(line) for line in path.read_text().splitlines() if line.strip()]


def test_sample_poses_then_contacts_gives_a_grasp_set_certify_certifies(tmp_path, box):
    poses = tmp_path / "poses.jsonl"
    res = runner.invoke(app, ["sample-poses", str(box), "--units", "mm", "-n", "12", "-o", str(poses)])
    assert res.exit_code == 0, res.output
    assert len(rows(poses)) == 12
    out = tmp_path / "contacts.jsonl"
    res = runner.invoke(app, ["contacts", str(box), str(poses), "--units", "mm", "--mass", "0.3", "-o", str(out)])
    assert res.exit_code == 0, res.output
    grasps = rows(out)
    assert [g["pose_id"] for g in grasps] == list(range(12))
    assert all(c["model"] == "soft" and c["torsion"] > 0 for g in grasps for c in g["contacts"])
    assert all(g["mass"] == pytest.approx(0.3) and len(g["patches"]) == 2 for g in grasps)
    results = tmp_path / "results.jsonl"
    summary = certify_file(out, results, quality=False, workers=1)
    assert summary.errors == 0 and summary.unverified == 0 and summary.rows == 12
    assert {r["input_pose_id"] if "input_pose_id" in r else r["pose_id"] for r in read_results(results)} == set(range(12))


def test_every_pose_is_a_grasp_or_an_error_row_with_its_reason(tmp_path, box):
    eye = np.eye(4).tolist()
    far = np.eye(4)
    far[1, 3] = 0.3
    palm = np.eye(4)
    palm[2, 3] = 0.04
    lines = [{"id": "ok", "pose": eye, "width": 0.07}, {"id": "wide", "pose": eye, "width": 0.2},
             {"id": "miss", "pose": far.tolist(), "width": 0.07}, {"id": "deep", "pose": palm.tolist(), "width": 0.07},
             {"id": "bad", "pose": [[1, 2], [3, 4]]}, {"id": "gn", "translation": [0, 0, 0],
                                                      "rotation_matrix": [[0, 1, 0], [0, 0, 1], [1, 0, 0]], "depth": 0.02}]
    poses = tmp_path / "poses.jsonl"
    poses.write_text("\n".join(json.dumps(x) for x in lines) + "\nnot json\n")
    out = tmp_path / "c.parquet"
    res = runner.invoke(app, ["contacts", str(box), str(poses), "--units", "mm", "-o", str(out)])
    assert res.exit_code == 1, res.output
    ok = pq.read_table(out).to_pylist()
    errors = rows(tmp_path / "c.errors.jsonl")
    assert [r["id"] for r in ok] == ["ok", "gn"]  # gn: GraspNet's fields, approaching from below
    assert {e["id"]: e["reason"] for e in errors} == {"wide": "too_wide", "miss": "no_contact", "deep": "collision",
                                                      "bad": "bad_pose", 7: "bad_pose"}
    assert len(ok) + len(errors) == len(lines) + 1
    assert "4x4" in next(e["error"] for e in errors if e["id"] == "bad")
    summary = certify_file(out, tmp_path / "r.parquet", quality=False, workers=1)
    assert summary.rows == 2 and summary.errors == 0


def test_graspnet_rows_are_read_in_their_convention(tmp_path, box):
    # approach x_gn = -z of the object, closing y_gn = x: from above, the grasp point 1 cm below the top
    R = np.column_stack([(0, 0, -1), (1, 0, 0), np.cross((0, 0, -1), (1, 0, 0))])
    poses = tmp_path / "gn.jsonl"
    poses.write_text(json.dumps({"translation": [0, 0, 0.02], "rotation_matrix": R.tolist(), "width": 0.07,
                                 "depth": 0.02}) + "\n")
    out = tmp_path / "c.jsonl"
    res = runner.invoke(app, ["contacts", str(box), str(poses), "--units", "mm", "--convention", "graspnet",
                              "-o", str(out)])
    assert res.exit_code == 0, res.output
    (g,) = rows(out)
    # fingertips at the grasp point + depth along the approach: 0.02 - 0.02 = 0, pad centre h/2 above
    assert g["contacts"][0]["p"][2] == pytest.approx(0.0185 / 2, abs=1e-3)
    assert sorted(round(c["p"][0], 6) for c in g["contacts"]) == [-0.025, 0.025]


def test_acronym_hdf5_files_are_read(tmp_path, box):
    h5py = pytest.importorskip("h5py")
    T = np.tile(np.eye(4), (3, 1, 1))
    T[:, 2, 3] = -0.10365  # the flange below the box's centre: the pad centres at the centre
    T[1, 0, 3] = 0.5        # far away
    T[2, :3, :3] = np.diag([1.0, 1.0, 2.0])  # not a rotation
    path = tmp_path / "grasps.h5"
    with h5py.File(path, "w") as f:
        f["grasps/transforms"] = T
        f["grasps/qualities/flex/object_in_gripper"] = np.array([1, 0, 1])
    out = tmp_path / "c.jsonl"
    res = runner.invoke(app, ["contacts", str(box), str(path), "--units", "mm", "-o", str(out)])
    assert res.exit_code == 1, res.output
    (g,) = rows(out)
    assert g["acronym_success"] == 1 and g["width"] == 0.08
    assert sorted(round(c["p"][0], 6) for c in g["contacts"]) == [-0.025, 0.025]
    errors = rows(tmp_path / "c.errors.jsonl")  # in pose order
    assert [e["reason"] for e in errors] == ["no_contact", "bad_pose"]
    assert errors[0]["line"] < errors[1]["line"]


def test_hold_adds_certified_verdicts(tmp_path, box):
    poses = tmp_path / "poses.jsonl"
    poses.write_text(json.dumps({"id": 0, "pose": np.eye(4).tolist(), "width": 0.07}) + "\n")
    for budget, status in ((5.0, "holds"), (4.8, "slips")):  # m g / (2 mu) = 0.5 * 9.80665 / 1 = 4.90 N
        out = tmp_path / f"c{budget}.jsonl"
        res = runner.invoke(app, ["contacts", str(box), str(poses), "--units", "mm", "--mass", "0.5",
                                  "--hold", str(budget), "--gravity", "0,0,-1", "-o", str(out)])
        assert res.exit_code == 0, res.output
        (g,) = rows(out)
        assert g["hold_status"] == status and g["hold_verified"] is True
        assert g["grip_lo"] <= 0.5 * 9.80665 <= g["grip_hi"]


def test_refused_inputs_exit_2_with_one_line(tmp_path, box):
    open_box = trimesh.creation.box((0.05, 0.05, 0.05))
    holed = tmp_path / "holed.stl"
    trimesh.Trimesh(open_box.vertices, open_box.faces[:-1]).export(holed)
    poses = tmp_path / "p.jsonl"
    poses.write_text(json.dumps({"pose": np.eye(4).tolist()}) + "\n")
    cases = [([str(holed), str(poses)], "not closed"), ([str(box), str(poses)], "units='mm'"),
             ([str(box), str(tmp_path / "none.jsonl"), "--units", "mm"], "none.jsonl"),
             ([str(box), str(poses), "--units", "mm", "--gripper", "nope"], "no gripper"),
             ([str(box), str(poses), "--units", "mm", "--tolerance", "-1"], "--tolerance"),
             ([str(box), str(poses), "--units", "mm", "--gravity", "down"], "--gravity")]
    for args, text in cases:
        res = runner.invoke(app, ["contacts", *args, "-o", str(tmp_path / "o.jsonl")])
        assert res.exit_code == 2, (args, res.output)
        assert text in res.output and "Traceback" not in res.output
    res = runner.invoke(app, ["contacts", str(box), str(poses), "--units", "mm", "-o", str(poses)])
    assert res.exit_code == 2 and "never overwritten" in res.output


def test_readme_example_runs_as_written_and_says_what_it_gives(tmp_path, monkeypatch):
    """README's one-minute example ("Grasp sets on meshes"), each step as written, in a fresh
    folder; its stated counts are those the commands give."""
    import re
    import shlex
    import subprocess
    import sys
    from pathlib import Path

    from qualgrasp.cli import app as qualgrasp_app

    text = (Path(__file__).resolve().parents[1] / "README.md").read_text()
    section = text[text.index("\n## Grasp sets on meshes\n"):]
    line = next(ln for ln in section.splitlines() if ln.startswith("python -c \"import trimesh"))
    monkeypatch.chdir(tmp_path)
    for step in line.split(" && "):
        argv = shlex.split(step)
        if argv[0] == "python":
            subprocess.run([sys.executable, *argv[1:]], check=True)
            continue
        assert argv[0] == "qualgrasp"
        res = runner.invoke(qualgrasp_app, argv[1:])
        assert res.exit_code == 0, (step, res.output)
    grasps = rows(tmp_path / "contacts.jsonl")
    status = [g["hold_status"] for g in grasps]
    assert all(g["hold_verified"] for g in grasps)
    said = re.search(r"for these 20 poses: (\d+) hold, (\d+) slip", section)
    assert said and (status.count("holds"), status.count("slips")) == (int(said[1]), int(said[2]))
    closure = re.search(r"\((\d+) in closure", section)
    results = list(read_results(tmp_path / "results.jsonl"))
    assert len(results) == 20 and sum(r["status"] == "closure" for r in results) == int(closure[1])


def test_a_failed_write_leaves_the_output_as_it_was(tmp_path, box, monkeypatch):
    """sample-poses and contacts write through a temporary renamed at the end, as every command:
    a write that fails midway (here a full disk) ends in one line, exit 2, and the file named as
    the output keeps what it held, with no partial or temporary file beside it."""
    poses = tmp_path / "poses.jsonl"
    assert runner.invoke(app, ["sample-poses", str(box), "--units", "mm", "-n", "6", "-o", str(poses)]).exit_code == 0
    out = tmp_path / "out.jsonl"
    out.write_text("kept\n")
    written = []

    class FullDisk:
        @staticmethod
        def dumps(row, **kwargs):
            written.append(row)
            if len(written) == 3:
                raise OSError(errno.ENOSPC, "No space left on device")
            return json.dumps(row, **kwargs)

    monkeypatch.setattr(mesh_cli, "json", FullDisk)
    for args in (["sample-poses", str(box), "--units", "mm", "-n", "6", "-o", str(out)],
                 ["contacts", str(box), str(poses), "--units", "mm", "-o", str(out)]):
        written.clear()
        res = runner.invoke(app, args)
        assert res.exit_code == 2, res.output
        assert "disk is full" in res.output and len(res.output.strip().splitlines()) == 1, res.output
        assert out.read_text() == "kept\n"
        assert sorted(p.name for p in tmp_path.iterdir()) == ["box.stl", "out.jsonl", "poses.jsonl"]

"""`qualgrasp certify POSES --mesh MESH`: contacts and certificates in one resumable run, the
same rows as `qualgrasp contacts` then `qualgrasp certify`, one results row per pose."""

from __future__ import annotations

import json

import pyarrow as pa
import pyarrow.parquet as pq
import pytest
import trimesh
from typer.testing import CliRunner

from qualgrasp.certify.batch.chunk import Options
from qualgrasp.certify.batch.engine import run
from qualgrasp.certify.errors import CertifyError
from qualgrasp.certify.meshes.gripper import load_gripper
from qualgrasp.certify.meshes.sampling import sample_poses
from qualgrasp.certify.meshes.source import PoseSource
from qualgrasp.cli import app

from helpers import interrupt_after

runner = CliRunner()
TIMINGS = ("time_ms",)


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    """A 50 x 60 x 70 mm box and 14 poses: 11 antipodal ones from the sampler, one too narrow to
    fit (it collides while approaching), one far away (no contact) and one unreadable."""
    folder = tmp_path_factory.mktemp("scene")
    box = trimesh.creation.box((50, 60, 70))
    box.export(folder / "box.stl")
    sampled = sample_poses(box.apply_scale(0.001), load_gripper("franka_panda"), 11, mu=0.5, seed=1)
    poses = [{"id": f"p{i}", "pose": p.T.tolist(), "width": p.width, "note": i} for i, p in enumerate(sampled)]
    poses.append({"id": "narrow", "pose": sampled[0].T.tolist(), "width": 0.001})
    far = sampled[0].T.copy()
    far[:3, 3] += 0.5
    poses.append({"id": "far", "pose": far.tolist(), "width": sampled[0].width})
    poses.append({"id": "bad", "pose": "x"})
    path = folder / "poses.jsonl"
    path.write_text("".join(json.dumps(p) + "\n" for p in poses))
    return folder


def _rows(path):
    if path.suffix == ".parquet":
        return pq.read_table(path).to_pylist()
    return [json.loads(line) for line in path.read_text().splitlines()]


def _comparable(row):
    return {k: v for k, v in row.items() if k not in TIMINGS and k != "line"}


def test_one_run_equals_contacts_then_certify(scene):
    mesh, poses = scene / "box.stl", scene / "poses.jsonl"
    res = runner.invoke(app, ["certify", str(poses), "--mesh", str(mesh), "--units", "mm", "--mass", "0.3",
                              "-o", str(scene / "one.jsonl"), "--workers", "1", "--chunk-size", "4"])
    assert res.exit_code == 1, res.output  # the three poses without contacts are error rows
    res = runner.invoke(app, ["contacts", str(mesh), str(poses), "--units", "mm", "--mass", "0.3",
                              "-o", str(scene / "c.jsonl")])
    assert res.exit_code == 1, res.output
    res = runner.invoke(app, ["certify", str(scene / "c.jsonl"), "-o", str(scene / "two.jsonl"), "--workers", "1"])
    assert res.exit_code == 0, res.output
    one, two = _rows(scene / "one.jsonl"), {r["id"]: r for r in _rows(scene / "two.jsonl")}
    assert [r["id"] for r in one] == [f"p{i}" for i in range(11)] + ["narrow", "far", "bad"]
    assert [r["line"] for r in one] == list(range(1, 15))  # the pose file's lines
    certified = [r for r in one if r["status"] != "error"]
    assert len(certified) == 11 and {r["status"] for r in certified} >= {"closure"}
    for r in certified:
        assert _comparable(r) == _comparable(two[r["id"]])
        assert r["input_line"] == r["line"] and r["note"] == int(r["id"][1:]) and r["pose_id"] == r["id"]
    errors = {r["id"]: r for r in one if r["status"] == "error"}
    assert {k: v["reason"] for k, v in errors.items()} == {"narrow": "collision", "far": "no_contact",
                                                          "bad": "bad_pose"}
    assert all(v["error"].startswith(f"line {v['line']}: ") for v in errors.values())


def test_parquet_results_keep_the_carried_fields(scene):
    out = scene / "one.parquet"
    res = runner.invoke(app, ["certify", str(scene / "poses.jsonl"), "--mesh", str(scene / "box.stl"),
                              "--units", "mm", "-o", str(out), "--workers", "2", "--chunk-size", "3", "-q"])
    assert res.exit_code == 1, res.output
    rows = _rows(out)
    assert len(rows) == 14 and [r["pose_id"] for r in rows[:2]] == ["p0", "p1"]
    assert rows[-1]["reason"] == "bad_pose" and rows[0]["reason"] is None
    assert len(rows[0]["patches"]) == 2 and rows[0]["patches"][0]["area"] > 0
    assert rows[-1]["patches"] is None  # a pose without contacts has no patches


def test_json_fields_of_changing_types_reach_parquet_as_json_text(tmp_path):
    two = [{"p": [1, 0], "n": [-1, 0], "mu": 0.5}, {"p": [-1, 0], "n": [1, 0], "mu": 0.5}]
    lines = [{"id": "a", "contacts": two, "note": "text", "tag": 1},
             {"id": "b", "contacts": two, "note": [1, 2], "tag": 2.5},
             {"id": "c", "contacts": two}]
    src = tmp_path / "g.jsonl"
    src.write_text("".join(json.dumps(x) + "\n" for x in lines))
    out = tmp_path / "r.parquet"
    res = runner.invoke(app, ["certify", str(src), "-o", str(out), "--chunk-size", "1", "--workers", "1", "-q"])
    assert res.exit_code == 0, res.output
    t = pq.read_table(out)
    assert t.column("note").to_pylist() == ['"text"', "[1, 2]", None]  # one column, JSON text
    assert t.schema.field("note").metadata == {b"qualgrasp": b"json"}
    assert t.column("tag").to_pylist() == [1.0, 2.5, None] and t.schema.field("tag").type == pa.float64()


def test_interrupted_run_resumes_and_refuses_another_mesh(scene, tmp_path):
    out = tmp_path / "r.jsonl"
    source = PoseSource.of(scene / "box.stl", units="mm")
    with pytest.raises(KeyboardInterrupt):
        run(scene / "poses.jsonl", out, options=Options(quality=False, source=source), workers=1, chunk_size=3,
            progress=interrupt_after(2))
    assert not out.exists()
    other = PoseSource.of(scene / "box.stl", units="mm", mu=0.2)
    with pytest.raises(CertifyError, match="other options"):
        run(scene / "poses.jsonl", out, options=Options(quality=False, source=other), workers=1, chunk_size=3,
            resume=True)
    summary = run(scene / "poses.jsonl", out, options=Options(quality=False, source=source), workers=1,
                  chunk_size=3, resume=True)
    assert summary.resumed_chunks == 2 and summary.resumed_rows == 6 and summary.rows == 14  # 2 kept chunks of 3
    ids = [r["id"] for r in _rows(out)]
    assert ids == [f"p{i}" for i in range(11)] + ["narrow", "far", "bad"]


def test_hold_in_one_run_equals_contacts_hold(scene):
    """certify --mesh --hold writes each grasp's weight-holding columns as contacts --hold does,
    next to its closure verdict."""
    mesh, poses = scene / "box.stl", scene / "poses.jsonl"
    hold = ["--hold", "30", "--gravity", "0,0,-1", "--units", "mm", "--mass", "0.3"]
    res = runner.invoke(app, ["certify", str(poses), "--mesh", str(mesh), *hold, "--no-quality",
                              "-o", str(scene / "hold.jsonl"), "--workers", "1"])
    assert res.exit_code == 1, res.output
    res = runner.invoke(app, ["contacts", str(mesh), str(poses), *hold, "-o", str(scene / "hold-c.jsonl")])
    assert res.exit_code == 1, res.output
    one, two = _rows(scene / "hold.jsonl"), {r["id"]: r for r in _rows(scene / "hold-c.jsonl")}
    keys = ("hold_status", "hold_budget", "grip_lo", "grip_hi", "hold_verified", "hold_note", "hold_certificate")
    certified = [r for r in one if r["status"] != "error"]
    assert len(certified) == 11 and {r["hold_status"] for r in certified} >= {"holds", "slips"}
    for r in certified:
        assert {k: r[k] for k in keys} == {k: two[r["id"]][k] for k in keys} and r["hold_verified"]


@pytest.mark.parametrize("args, message", [
    (["--gripper", "robotiq_2f85"], "--gripper needs --mesh"),
    (["--hold", "2"], "--hold needs --mesh"),
    (["--mesh", "MESH", "--gravity", "all"], "--gravity needs --hold"),
    (["--mesh", "MESH", "--hold", "0"], "--hold must be"),
    (["--mesh", "MESH", "--hold", "2", "--level", "7"], "--level must be between 0 and 4"),
    (["--mesh", "MESH", "--model", "elliptic"], "--model must be a model that describes a patch (point, soft, patch)"),
    (["--mesh", "missing.stl"], "missing.stl"),
    (["--mesh", "MESH", "--units", "mm", "-o", "MESH"], "never overwritten"),
])
def test_refused_before_any_work(scene, tmp_path, args, message):
    args = [a.replace("MESH", str(scene / "box.stl")) for a in args]
    if "-o" not in args:
        args += ["-o", str(tmp_path / "r.jsonl")]
    res = runner.invoke(app, ["certify", str(scene / "poses.jsonl"), *args], terminal_width=300)
    assert res.exit_code == 2 and message in res.output and "Traceback" not in res.output, res.output
    assert not (tmp_path / "r.jsonl").exists()


def test_hdf5_pose_files_are_named(scene, tmp_path):
    src = tmp_path / "grasps.h5"
    src.write_bytes(b"\x89HDF\r\n\x1a\n" + b"\0" * 64)
    res = runner.invoke(app, ["certify", str(src), "--mesh", str(scene / "box.stl"), "-o", str(tmp_path / "r.jsonl")],
                        terminal_width=300)
    assert res.exit_code == 2 and "qualgrasp contacts" in res.output, res.output

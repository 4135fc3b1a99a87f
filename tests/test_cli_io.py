"""Grasp-set files and the certify / verify commands, including bad lines."""

import json

import pytest
from typer.testing import CliRunner

from qualgrasp.certify.batch import certify_file, verify_file
from qualgrasp.certify.files import write_grasps
from qualgrasp.certify.batch import random_grasps, textbook_grasps
from qualgrasp.cli import app

runner = CliRunner()

BAD_LINES = {
    "malformed": ('{"id": "m", "contacts": [', "malformed JSON"),
    "nan": ('{"id": "nan", "contacts": [{"p": [NaN, 0], "n": [1, 0]}]}', "NaN or infinite"),
    "inf": ('{"id": "inf", "contacts": [{"p": [1e999, 0], "n": [1, 0]}]}', "NaN or infinite"),
    "zero-normal": ('{"id": "zn", "contacts": [{"p": [0, 0], "n": [0, 0]}]}', "normal n is zero"),
    "negative-mu": ('{"id": "mu", "contacts": [{"p": [0, 0], "n": [1, 0], "mu": -1}]}', "mu must be >= 0"),
    "nan-mu": ('{"id": "mun", "contacts": [{"p": [0, 0], "n": [1, 0], "mu": NaN}]}', "mu must be finite"),
    "mixed": ('{"id": "mix", "contacts": [{"p": [0, 0], "n": [1, 0]}, {"p": [0, 0, 1], "n": [1, 0, 0]}]}',
              "mix dimensions"),
    "empty": ('{"id": "none", "contacts": []}', "at least one contact"),
    "model": ('{"id": "um", "contacts": [{"p": [0, 0], "n": [1, 0], "model": "glue"}]}', "unknown contact model"),
    "soft-2d": ('{"id": "s2", "contacts": [{"p": [0, 0], "n": [1, 0], "model": "soft", "mu": 1, "torsion": 1}]}',
                "spatial only"),
}


@pytest.fixture
def grasp_file(tmp_path):
    path = tmp_path / "grasps.jsonl"
    write_grasps(path, textbook_grasps() + random_grasps(3, 20, dim=3, n_contacts=3))
    with path.open("a") as fh:
        for text, _ in BAD_LINES.values():
            fh.write(text + "\n")
    return path


def _rows(path):
    return [json.loads(line) for line in path.read_text().splitlines()]


def test_bad_lines_become_error_rows_and_the_run_goes_on(grasp_file, tmp_path):
    out = tmp_path / "results.jsonl"
    summary = certify_file(grasp_file, out, quality=False)
    rows = _rows(out)
    n_good = len(textbook_grasps()) + 20
    assert len(rows) == n_good + len(BAD_LINES) == summary.rows
    assert summary.errors == len(BAD_LINES)
    for row, (name, (_, message)) in zip(rows[n_good:], BAD_LINES.items()):
        assert row["status"] == "error" and message in row["error"], name
        assert f"line {row['line']}" in row["error"]
        assert row["verified"] is False
    assert rows[n_good]["id"] is None  # unreadable line: the line number identifies it
    assert rows[n_good + 1]["id"] == "nan"
    for row in rows[:n_good]:
        assert row["status"] in ("closure", "no_closure") and row["verified"]
        assert set(row) >= {"id", "dim", "status", "form_closure", "force_closure", "margin",
                            "certificate", "verified", "error", "center", "length"}


def test_cli_certify_exit_code_and_verify(grasp_file, tmp_path):
    out = tmp_path / "results.jsonl"
    result = runner.invoke(app, ["certify", str(grasp_file), "-o", str(out), "-q", "--no-quality"])
    assert result.exit_code == 1  # some rows are errors
    result = runner.invoke(app, ["verify", str(out), "--grasps", str(grasp_file)])
    assert result.exit_code == 0, result.output


def test_cli_clean_file_exits_zero(tmp_path):
    grasps, out = tmp_path / "g.jsonl", tmp_path / "r.jsonl"
    write_grasps(grasps, textbook_grasps())
    assert runner.invoke(app, ["certify", str(grasps), "-o", str(out), "-q"]).exit_code == 0
    by_id = {r["id"]: r for r in _rows(out)}
    assert by_id["antipodal-2d"]["force_closure"] is True
    assert by_id["antipodal-2d"]["form_closure"] is False
    assert by_id["cube-7"]["center"] == [0.0, 0.0, 0.0]
    for row in by_id.values():  # epsilon columns: equal bounds in the plane, 0 without closure
        assert 0 <= row["eps_l1_lo"] <= row["eps_l1_hi"] and 0 <= row["eps_linf_lo"] <= row["eps_linf_hi"]
        assert (row["eps_l1_hi"] > 0) == (row["status"] == "closure")
        if row["dim"] == 2:
            assert row["eps_l1_lo"] == row["eps_l1_hi"]


def test_verify_reports_tampered_rows(grasp_file, tmp_path):
    out = tmp_path / "results.jsonl"
    certify_file(grasp_file, out, quality=False)
    rows = _rows(out)
    tampered = {}
    for row in rows:
        cert = (row.get("certificate") or {}).get("force")
        if cert and cert["kind"] == "interior" and "a" not in tampered:
            cert["values"] = [-v for v in cert["values"]]
            tampered["a"] = row["id"]
        elif cert and cert["kind"] == "farkas" and not cert["null_space"] and "b" not in tampered:
            cert["y"] = [-v for v in cert["y"]]
            tampered["b"] = row["id"]
        elif row["status"] == "no_closure" and "c" not in tampered:
            row["status"], row["force_closure"] = "closure", True  # status without its evidence
            tampered["c"] = row["id"]
    out.write_text("".join(json.dumps(r) + "\n" for r in rows))
    summary = verify_file(out, grasp_file)
    assert {gid for gid, _ in summary.failures} == set(tampered.values())
    result = runner.invoke(app, ["verify", str(out), "--grasps", str(grasp_file)])
    assert result.exit_code == 1
    for gid in tampered.values():
        assert str(gid) in result.stdout


def test_missing_file_is_a_clear_error(tmp_path):
    result = runner.invoke(app, ["certify", str(tmp_path / "nope.jsonl"), "-o", str(tmp_path / "r")])
    assert result.exit_code == 2
    assert "cannot read" in result.output


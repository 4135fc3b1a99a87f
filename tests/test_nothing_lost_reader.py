"""Nothing lost (issue 23, part 2): one hardened reader for every line file and Parquet file.

Region sets (``certify-regions``, ``verify --regions``) are read by the reader ``certify`` uses:
a bad line is an error row naming the field, a whole-file problem one line and exit 2, FIFOs and
devices are refused. The format is decided on the content as a whole, so that a bad line among
good ones is one error row, not a refused file. Parquet column names are carried or refused by
name, never dropped. The corpus is made here at run time.
"""

import json
import os
import subprocess
import sys

import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from typer.testing import CliRunner

from qualgrasp.certify.files import write_grasps
from qualgrasp.certify.batch import random_grasps
from qualgrasp.cli import app

runner = CliRunner()
LIMIT = 60
REGION = {"id": "r1", "regions": [{"a": [1, -0.3], "b": [1, 0.3], "n": [-1, 0], "mu": 0.5},
                                  {"a": [-1, -0.3], "b": [-1, 0.3], "n": [1, 0], "mu": 0.5}]}
GOOD = json.dumps(REGION).encode()
BAD_LINES = {  # a bad region line, and what its error row must say
    "invalid-utf8": (GOOD.replace(b'"r1"', b'"r\xff1"'), "not valid UTF-8"),
    "deep": (b'{"id": "d", "regions": ' + b"[" * 100_000 + b"]" * 100_000 + b"}", "nested deeper"),
    "huge-int": (GOOD.replace(b"0.5}", b"1" + b"0" * 5000 + b"}", 1), "malformed JSON"),
    "lone-surrogate": (GOOD.replace(b'"r1"', b'"\\ud800"'), "lone surrogate"),
    "nul": (GOOD[:10] + b"\x00" + GOOD[10:], "malformed JSON"),
}


def invoke(*args):
    result = runner.invoke(app, [str(a) for a in args])
    assert result.exception is None or isinstance(result.exception, SystemExit), repr(result.exception)
    return result.exit_code, result.output


def cli(*args):
    try:
        proc = subprocess.run([sys.executable, "-m", "qualgrasp.cli", *map(str, args)], capture_output=True,
                              timeout=LIMIT)
    except subprocess.TimeoutExpired:
        pytest.fail(f"qualgrasp {' '.join(map(str, args))} blocked for more than {LIMIT} s")
    return proc.returncode, (proc.stderr + proc.stdout).decode(errors="replace")


def one_line(text: str) -> str:
    lines = [x for x in text.strip().splitlines() if x.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: ") and "Traceback" not in text, text
    return lines[0]


def rows(path):
    return [json.loads(line) for line in path.read_text().splitlines()]


# -- region sets ----------------------------------------------------------------------------------

@pytest.mark.parametrize("case", sorted(BAD_LINES))
def test_region_lines_are_read_like_grasp_lines(case, tmp_path):
    bad, message = BAD_LINES[case]
    src = tmp_path / "r.jsonl"
    src.write_bytes(GOOD + b"\n" + bad + b"\n" + GOOD.replace(b'"r1"', b'"r3"') + b"\n")
    out = tmp_path / "o.jsonl"
    code, text = invoke("certify-regions", src, "-o", out, "-q")
    assert code == 1, text  # an error row
    got = rows(out)
    assert [r["line"] for r in got] == [1, 2, 3]
    assert [r["status"] for r in got] == ["robust", "error", "robust"]
    assert got[1]["error"].startswith("line 2: ") and message in got[1]["error"], got[1]["error"]
    code, text = invoke("verify", out, "--regions", src)
    assert code == 0, text


@pytest.mark.parametrize("case", ["invalid-utf8", "deep", "huge-int"])
def test_verify_regions_reads_a_bad_results_line_as_a_failure(case, tmp_path):
    src = tmp_path / "r.jsonl"
    src.write_bytes(GOOD + b"\n" + GOOD.replace(b'"r1"', b'"r2"') + b"\n")
    out = tmp_path / "o.jsonl"
    assert invoke("certify-regions", src, "-o", out, "-q")[0] == 0
    lines = out.read_bytes().splitlines()
    lines[1] = BAD_LINES[case][0]
    out.write_bytes(b"\n".join(lines) + b"\n")
    code, text = invoke("verify", out, "--regions", src)
    assert code == 1 and "results line 2" in text, text


@pytest.mark.parametrize("command", ["certify-regions", "verify-regions", "certify", "verify"])
@pytest.mark.parametrize("kind", ["fifo", "dev-zero"])
def test_fifo_and_device_inputs_are_refused_without_blocking(command, kind, tmp_path):
    src = tmp_path / "in.jsonl"
    if kind == "fifo":
        os.mkfifo(src)
    else:
        src = "/dev/zero"
    good = tmp_path / "g.jsonl"
    good.write_bytes(GOOD + b"\n")
    args = {"certify-regions": ("certify-regions", src, "-o", tmp_path / "o.jsonl", "-q"),
            "verify-regions": ("verify", src, "--regions", good),
            "certify": ("certify", src, "-o", tmp_path / "o.jsonl", "-q", "--workers", "1"),
            "verify": ("verify", src, "--grasps", good, "--workers", "1")}[command]
    code, text = cli(*args)
    assert code == 2 and "not a regular file" in one_line(text)
    assert not (tmp_path / "o.jsonl").exists()


def test_a_parquet_file_is_not_a_region_set(tmp_path):
    src = tmp_path / "r.jsonl"
    pq.write_table(pa.table({"id": ["r1"]}), src)
    code, text = invoke("certify-regions", src, "-o", tmp_path / "o.jsonl", "-q")
    assert code == 2 and "JSON Lines" in one_line(text)


# -- the format decided on the content as a whole -------------------------------------------------

@pytest.fixture(scope="module")
def many(tmp_path_factory):
    """2,000 good grasp lines."""
    path = tmp_path_factory.mktemp("many") / "g.jsonl"
    write_grasps(path, random_grasps(21, 2000))
    return path.read_bytes().splitlines()


@pytest.mark.parametrize("where", [2, 1500])
def test_a_nul_byte_on_one_line_is_one_error_row(many, tmp_path, where):
    lines = list(many)
    lines[where - 1] = lines[where - 1][:20] + b"\x00" + lines[where - 1][20:]
    src = tmp_path / "g.jsonl"
    src.write_bytes(b"\n".join(lines) + b"\n")
    out = tmp_path / "o.jsonl"
    code, text = invoke("certify", src, "-o", out, "-q", "--no-quality", "--workers", "1")
    assert code == 1, text
    got = rows(out)
    assert len(got) == 2000
    errors = [r for r in got if r["status"] == "error"]
    assert [r["line"] for r in errors] == [where] and errors[0]["error"].startswith(f"line {where}: ")


def test_a_json_array_on_line_one_is_one_error_row(many, tmp_path):
    lines = list(many)
    lines[0] = b"[" + lines[0] + b"]"
    src = tmp_path / "g.jsonl"
    src.write_bytes(b"\n".join(lines) + b"\n")
    out = tmp_path / "o.jsonl"
    code, text = invoke("certify", src, "-o", out, "-q", "--no-quality", "--workers", "1")
    assert code == 1, text
    got = rows(out)
    assert len(got) == 2000 and got[0]["status"] == "error" and got[0]["error"].startswith("line 1: ")
    assert all(r["status"] != "error" for r in got[1:])


@pytest.mark.parametrize("data, reason", [
    (b"\x00\x01\x02" * 1000, "binary data"),
    (b'[{"id": "g1", "contacts": []}, {"id": "g2", "contacts": []}]\n', "a JSON array of grasps"),
    (b'[\n{"id": "g1", "contacts": []},\n{"id": "g2", "contacts": []}\n]\n', "spread over many lines"),
])
def test_whole_files_that_are_not_json_lines_are_still_refused(data, reason, tmp_path):
    src = tmp_path / "g.jsonl"
    src.write_bytes(data)
    code, text = invoke("certify", src, "-o", tmp_path / "o.jsonl", "-q", "--workers", "1")
    assert code == 2 and reason in one_line(text)


# -- Parquet names --------------------------------------------------------------------------------

def _grasp_table(n=3, **extra):
    contacts = [[{"p": [1.0, 0.0], "n": [-1.0, 0.0], "mu": 0.5}, {"p": [-1.0, 0.0], "n": [1.0, 0.0], "mu": 0.5}]] * n
    return pa.table({"id": [f"g{i}" for i in range(n)], "contacts": contacts, **extra})


@pytest.mark.parametrize("case, named", [
    ("input_status beside status", ("status", "input_status")),
    ("reserved marker", ("_qualgrasp_read_error",)),
    ("two contacts columns", ("contacts",)),
])
def test_parquet_columns_are_carried_or_refused_by_name(case, named, tmp_path):
    t = _grasp_table()
    if case == "input_status beside status":
        t = t.append_column("status", pa.array(["a", "b", "c"])).append_column("input_status", pa.array(["x", "y", "z"]))
    elif case == "reserved marker":
        t = t.append_column("_qualgrasp_read_error", pa.array(["mine", None, None]))
    else:
        t = t.append_column("contacts", t.column("contacts"))
    src = tmp_path / "g.parquet"
    pq.write_table(t, src)
    for out in (tmp_path / "o.parquet", tmp_path / "o.jsonl"):
        code, text = invoke("certify", src, "-o", out, "-q", "--workers", "1")
        line = one_line(text)
        assert code == 2 and all(name in line for name in named), line
        assert not out.exists()


def test_parquet_status_column_alone_is_carried(tmp_path):
    src = tmp_path / "g.parquet"
    pq.write_table(_grasp_table().append_column("status", pa.array(["a", "b", "c"])), src)
    out = tmp_path / "o.parquet"
    code, text = invoke("certify", src, "-o", out, "-q", "--workers", "1", "--no-quality")
    assert code == 0, text
    assert pq.read_table(out).column("input_status").to_pylist() == ["a", "b", "c"]


def test_in_memory_arrow_with_clashing_columns_is_refused(tmp_path):
    from qualgrasp.certify import GraspFileError, Options, certify_arrow

    t = _grasp_table().append_column("status", pa.array(["a"] * 3)).append_column("input_status", pa.array(["b"] * 3))
    with pytest.raises(GraspFileError, match="input_status"):
        certify_arrow(t, Options(quality=False))


def test_json_fields_with_clashing_carried_names_are_an_error_row(tmp_path):
    line = json.loads(GOOD)
    grasp = {"id": "g1", "contacts": [{"p": [1, 0], "n": [-1, 0], "mu": 0.5}, {"p": [-1, 0], "n": [1, 0], "mu": 0.5}]}
    src = tmp_path / "g.jsonl"
    src.write_text("\n".join(json.dumps(d) for d in (grasp, {**grasp, "id": "g2", "status": "a", "input_status": "b"},
                                                     {**grasp, "id": "g3", "status": "c"})) + "\n")
    out = tmp_path / "o.jsonl"
    code, text = invoke("certify", src, "-o", out, "-q", "--workers", "1", "--no-quality")
    assert code == 1, text
    got = rows(out)
    assert got[1]["status"] == "error" and "input_status" in got[1]["error"] and "status" in got[1]["error"]
    assert got[2]["status"] == "closure" and got[2]["input_status"] == "c"
    assert line["id"] == "r1"
    code, text = invoke("verify", out, "--grasps", src, "--workers", "1")
    assert code == 0, text

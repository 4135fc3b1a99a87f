"""``qualgrasp verify`` on part of a results file (issue 22, part 5).

Each results row is paired with its grasp by its ``line`` (and its ``id`` checked), so a subset of
the rows, or the rows in another order, verifies; grasps without a row are counted, not failed;
a row naming a line that is no grasp, or a line twice, fails; every failure names the row's own
id and line; a tampered certificate in a subset is still named. JSON Lines and Parquet, one
process and two, in order (streamed) and shuffled (bucketed), with chunks small enough that rows
cross chunk boundaries.
"""

import json
import random

import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from typer.testing import CliRunner

from qualgrasp.certify.batch import certify_file, verify_file
from qualgrasp.certify.files import write_grasps
from qualgrasp.certify.batch import random_grasps, textbook_grasps
from qualgrasp.cli import app

runner = CliRunner()
CHUNK = 16


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("subset")
    grasps = textbook_grasps() + random_grasps(31, 120) + random_grasps(32, 20, dim=3, n_contacts=3)
    out = {}
    for fmt in ("jsonl", "parquet"):
        g = d / f"g.{fmt}"
        write_grasps(g, grasps)
        if fmt == "jsonl":  # blank lines: lines and positions differ
            text = g.read_text().splitlines()
            g.write_text("\n".join(text[:10] + [""] + text[10:50] + ["", ""] + text[50:]) + "\n")
        r = d / f"r.{fmt}"
        certify_file(g, r, quality=True, eps_budget=20_000, chunk_size=CHUNK)
        out[fmt] = (g, r)
    return out


def read(path):
    if path.suffix == ".parquet":
        return pq.read_table(path)
    return [json.loads(line) for line in path.read_text().splitlines()]


def write(path, rows):
    if isinstance(rows, pa.Table):
        pq.write_table(rows, path)
    else:
        path.write_text("".join(json.dumps(r) + "\n" for r in rows))
    return path


def select(rows, idx):
    return rows.take(pa.array(idx, pa.int64())) if isinstance(rows, pa.Table) else [rows[i] for i in idx]


def statuses(rows):
    return rows.column("status").to_pylist() if isinstance(rows, pa.Table) else [r["status"] for r in rows]


def ids(rows):
    return rows.column("id").to_pylist() if isinstance(rows, pa.Table) else [r["id"] for r in rows]


def n_grasps(rows):
    return rows.num_rows if isinstance(rows, pa.Table) else len(rows)


@pytest.mark.parametrize("fmt", ["jsonl", "parquet"])
@pytest.mark.parametrize("order", ["kept", "shuffled", "reversed"])
@pytest.mark.parametrize("workers", [1, 2])
def test_a_subset_in_any_order_verifies(files, tmp_path, fmt, order, workers):
    g, r = files[fmt]
    rows = read(r)
    idx = [i for i, s in enumerate(statuses(rows)) if s == "closure"]
    assert 10 < len(idx) < n_grasps(rows)
    if order == "shuffled":
        random.Random(5).shuffle(idx)
    elif order == "reversed":
        idx = idx[::-1]
    subset = write(tmp_path / f"s.{fmt}", select(rows, idx))
    summary = verify_file(subset, g, workers=workers, chunk_size=CHUNK)
    assert summary.failures == []
    assert summary.rows == len(idx) and summary.missing == n_grasps(rows) - len(idx)


@pytest.mark.parametrize("fmt", ["jsonl", "parquet"])
def test_the_whole_file_verifies_with_nothing_missing(files, fmt):
    g, r = files[fmt]
    summary = verify_file(r, g, workers=1, chunk_size=CHUNK)
    assert summary.failures == [] and summary.missing == 0 and summary.rows == n_grasps(read(r))


@pytest.mark.parametrize("fmt", ["jsonl", "parquet"])
@pytest.mark.parametrize("order", ["kept", "shuffled"])
def test_a_tampered_certificate_in_a_subset_is_named(files, tmp_path, fmt, order):
    g, r = files[fmt]
    rows = read(r)
    idx = [i for i, s in enumerate(statuses(rows)) if s == "closure"][::2]
    if order == "shuffled":
        random.Random(7).shuffle(idx)
    sub = select(rows, idx)
    victim = 3
    if isinstance(sub, pa.Table):
        py = sub.to_pylist()
        py[victim]["margin"] *= 3
        sub = pa.Table.from_pylist(py, schema=sub.schema)
    else:
        sub[victim]["margin"] *= 3
    path = write(tmp_path / f"s.{fmt}", sub)
    failures = verify_file(path, g, workers=1, chunk_size=CHUNK).failures
    line = (sub.column("line")[victim].as_py() if isinstance(sub, pa.Table) else sub[victim]["line"])
    assert [gid for gid, _ in failures] == [ids(sub)[victim]]
    assert failures[0][1].startswith(f"line {line}: ") and "margin" in failures[0][1]


@pytest.mark.parametrize("order", ["kept", "shuffled"])
def test_unknown_and_repeated_lines_fail_naming_the_rows_own_id(files, tmp_path, order):
    g, r = files["jsonl"]
    rows = read(r)
    sub = [dict(x) for x in rows[5:40]]
    sub.append({**rows[20], "id": "again"})  # line of row 20, a second time
    sub.append({**rows[0], "id": "ghost", "line": 10**6})  # no such line
    sub.append({**rows[0], "id": "blank", "line": 11})  # a blank line of the grasp file
    sub.append({**rows[1], "id": "other"})  # its line's grasp has another id
    if order == "shuffled":
        random.Random(3).shuffle(sub)
    path = write(tmp_path / "s.jsonl", sub)
    failures = dict(verify_file(path, g, workers=1, chunk_size=CHUNK).failures)
    assert set(failures) == {"again", "ghost", "blank", "other"} if order == "kept" else set(failures) >= {
        "ghost", "blank", "other"}
    assert "not a grasp of the grasp file" in failures["ghost"] and "line 1000000" in failures["ghost"]
    assert "line 11" in failures["blank"]
    assert failures["other"].startswith(f"line {rows[1]['line']}: ") and "does not match" in failures["other"]
    repeated = [k for k, v in failures.items() if "appears twice" in v]
    assert len(repeated) == 1 and repeated[0] in ("again", rows[20]["id"])


def test_cli_subset_exits_0_and_says_how_many_grasps_have_no_row(files, tmp_path):
    g, r = files["parquet"]
    rows = read(r)
    sub = write(tmp_path / "s.parquet", rows.slice(40, 30))
    result = runner.invoke(app, ["verify", str(sub), "--grasps", str(g), "--workers", "1"])
    assert result.exit_code == 0, result.output
    assert f"{rows.num_rows - 30} of the {rows.num_rows} grasps have no results row" in result.output
    bad = rows.slice(40, 30).to_pylist()
    bad[4]["eps_l1_lo"] = (bad[4]["eps_l1_lo"] or 0) + 1
    path = write(tmp_path / "b.parquet", pa.Table.from_pylist(bad, schema=rows.schema))
    result = runner.invoke(app, ["verify", str(path), "--grasps", str(g), "--workers", "1"])
    assert result.exit_code == 1 and str(bad[4]["id"]) in result.output


def test_rows_that_state_no_usable_line_fail_each(files, tmp_path):
    g, r = files["jsonl"]
    rows = read(r)[:6]
    rows[1]["line"] = "3"
    rows[2]["line"] = None
    del rows[3]["line"]
    path = tmp_path / "s.jsonl"
    path.write_text("".join(json.dumps(x) + "\n" for x in rows) + "[1, 2]\n")
    failures = verify_file(path, g, workers=1).failures
    reasons = [reason for _, reason in failures]
    assert len(failures) == 4
    assert any('line "3" is not a line number' in x for x in reasons)
    assert any("line null is not a line number" in x for x in reasons)
    assert any("column line missing" in x for x in reasons)
    assert any(x.startswith("results line 7: not a JSON object") for x in reasons)

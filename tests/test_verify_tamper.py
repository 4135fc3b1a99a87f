"""``qualgrasp verify`` re-checks every number a results row states: tampering with any column,
in JSON Lines or Parquet, is rejected with a message naming the column, and nothing raises.

For every column and several kinds of tampering (changed, halved, doubled, negative, NaN, null,
deleted, wrong type, huge, nested) on a row in closure, a row not in closure and an error row,
the tampered file is re-checked. A tampering that changes a stated value beyond its stated
tolerance (or its type, or deletes it) must make that row fail with the column's name in the
message; the untampered file must pass, in JSON Lines also with CRLF line ends and odd
whitespace. The only claim verify cannot re-check is ``eps_limited`` (whether a time limit was
hit depends on the machine), so flipping it is accepted. Certificates and epsilon evidence are
evidence, not stated numbers: a changed one that still proves every stated number (a Farkas
direction moved a little still separates) is accepted; one that does not is rejected.
"""

import json
import math
import re
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from typer.testing import CliRunner

from qualgrasp.certify import Contact, Grasp, force_closure
from qualgrasp.certify.batch import certify_file, verify_file
from qualgrasp.certify.files import write_grasps
from qualgrasp.certify.files import NAMES, RESULT_SCHEMA
from qualgrasp.certify.batch import random_grasps
from qualgrasp.certify.files import rows_to_table, table_to_rows
from qualgrasp.cli import app

KINDS = ("changed", "halved", "doubled", "negative", "nan", "null", "deleted", "wrong_type",
         "huge", "nested")
DEEP = 100_000  # nesting depth of the line-level tampering (beyond json's recursion limit)


def _grasps():
    """The rows tampered with (:func:`_targets`) and a pad grasp: each tampered file is verified
    whole over a thousand times, so it holds no other row."""
    planar = random_grasps(8, 12, dim=2, n_contacts=3)
    pad = Grasp((Contact((1, 0), (-1, 0), "pad", mu=0.5, width=0.4),
                 Contact((-1, 0), (1, 0), "pad", mu=0.5, width=0.4)), id="pads")
    spatial = random_grasps(9, 4, dim=3, n_contacts=3, model="point", spread=0.3)
    status = [force_closure(g).status for g in planar]
    closure = next(g for g, s in zip(planar, status) if s == "closure")
    no_closure = next(g for g, s in zip(planar, status) if s == "no_closure")
    spatial = next(g for g in spatial if force_closure(g).status == "closure")
    return [closure, no_closure, pad, Grasp(spatial.contacts, id="s0")]


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    root = tmp_path_factory.mktemp("tamper")
    out = {}
    for fmt in ("jsonl", "parquet"):
        grasps = root / f"grasps.{fmt}"
        write_grasps(grasps, _grasps())
        if fmt == "jsonl":  # an invalid grasp: its row is an error row
            with grasps.open("a") as fh:
                fh.write('{"id": "bad", "contacts": [{"p": [0, 0], "n": [0, 0]}]}\n')
        results = root / f"results.{fmt}"
        certify_file(grasps, results, workers=1)
        out[fmt] = (grasps, results)
    return out


def _rows(path: Path) -> list:
    if path.suffix == ".parquet":
        return table_to_rows(pq.read_table(path))
    return [json.loads(line) for line in path.read_text().splitlines()]


def _targets(rows):
    """A planar row in closure, a planar row not in closure, a spatial row in closure and (in
    JSON Lines) the error row."""
    out = {"closure": next(i for i, r in enumerate(rows) if r["status"] == "closure" and r["dim"] == 2),
           "no_closure": next(i for i, r in enumerate(rows) if r["status"] == "no_closure"),
           "spatial": next(i for i, r in enumerate(rows) if r["status"] == "closure" and r["dim"] == 3)}
    err = [i for i, r in enumerate(rows) if r["status"] == "error"]
    if err:
        out["error"] = err[0]
    return out


def _nested(depth=40):
    v = [1.0]
    for _ in range(depth):
        v = [v]
    return v


def _tamper_value(value, kind):
    """The tampered value (``...`` for a deletion), or None when the kind does not apply."""
    number = isinstance(value, (int, float)) and not isinstance(value, bool)
    if kind == "changed":
        if isinstance(value, bool):
            return not value
        if number:
            return value + 1 if isinstance(value, int) else value * 1.5 + 0.125
        if isinstance(value, str):
            return value + "x"
        if isinstance(value, list):
            return [v * 1.5 + 0.125 if isinstance(v, float) else v for v in value][::-1] + [0.25]
        if isinstance(value, dict):
            return _changed_struct(value)
        return 0.5  # null -> a number
    if kind in ("halved", "doubled", "negative"):
        if not number:
            return None
        return {"halved": value / 2, "doubled": value * 2, "negative": -value}[kind]
    return {"nan": float("nan"), "null": None, "deleted": ..., "huge": 10**400,
            "nested": _nested(), "wrong_type": _wrong_type(value)}[kind]


def _wrong_type(value):
    if isinstance(value, str):
        return 12
    if isinstance(value, (list, dict)):
        return "text"
    if value is None:
        return {"a": 1}
    return str(value)


def _changed_struct(d):
    """A struct with one number inside changed (the first one found, depth first)."""
    d = json.loads(json.dumps(d))

    def walk(x):
        if isinstance(x, dict):
            for k, v in x.items():
                if isinstance(v, (int, float)) and not isinstance(v, bool):
                    x[k] = v * 1.5 + 0.125
                    return True
                if isinstance(v, (dict, list)) and walk(v):
                    return True
        if isinstance(x, list):
            for i, v in enumerate(x):
                if isinstance(v, float):
                    x[i] = v * 1.5 + 0.125
                    return True
                if isinstance(v, (dict, list)) and walk(v):
                    return True
        return False

    walk(d)
    return d


def _same(a, b) -> bool:
    """Equal values of equal kind (a tampering that changes nothing may be accepted)."""
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    if isinstance(a, bool) != isinstance(b, bool):
        return False
    return a == b and (type(a) is type(b) or (isinstance(a, (int, float)) and isinstance(b, (int, float))))


def _write_jsonl(path, rows):
    with path.open("w") as fh:
        for r in rows:
            fh.write(json.dumps(r) + "\n")


def _parquet_tampered(results, column, kind, index, value):
    """A tampered Parquet results table: value kinds keep the schema; the others replace or drop
    the whole column (Parquet columns have one type)."""
    table = pq.read_table(results)
    if kind == "deleted":
        return table.drop([column])
    if kind in ("wrong_type", "nested", "huge") or (kind == "changed" and value is not None and not _fits(column, value)):
        old = table.column(column).to_pylist()
        if kind == "wrong_type":
            new, type_ = [json.dumps(v) for v in old], pa.string()
        elif kind == "nested":
            new, type_ = [[[1.0, 2.0]] for _ in old], pa.list_(pa.list_(pa.float64()))
        else:  # huge: the largest values the column's type holds
            type_ = table.schema.field(column).type
            big = {pa.float64(): 1e308, pa.int64(): 2**63 - 1, pa.int32(): 2**31 - 1, pa.int8(): 127,
                   pa.string(): "x" * 100_000}
            if type_ not in big:
                return None
            new = list(old)
            new[index] = big[type_]
        i = table.schema.get_field_index(column)
        return table.set_column(i, pa.field(column, type_), pa.array(new, type=type_))
    rows = table_to_rows(table)
    rows[index][column] = value
    try:
        return rows_to_table(rows)
    except (pa.ArrowException, TypeError, ValueError, OverflowError):
        return None


def _fits(column, value) -> bool:
    try:
        pa.array([value], type=RESULT_SCHEMA.field(column).type)
        return True
    except (pa.ArrowException, TypeError, ValueError, OverflowError):
        return False


def run_matrix(files, tmp: Path, kinds=KINDS):
    """Every (format, target row, column, kind of ``kinds``): tampered file re-checked. Returns
    records ``(fmt, target, column, kind, expected_reject, rejected, named, reason)``."""
    records = []
    for fmt, (grasps, results) in files.items():
        rows = _rows(results)
        targets = _targets(rows)
        for target, index in targets.items():
            for column in NAMES:
                for kind in kinds:
                    old = rows[index].get(column)
                    value = _tamper_value(old, kind)
                    if value is None and kind not in ("null",):
                        continue
                    if kind == "null" and old is None:
                        continue
                    path = tmp / f"t.{fmt}"
                    if fmt == "jsonl":
                        tampered = json.loads(json.dumps(rows))
                        if kind == "deleted":
                            del tampered[index][column]
                        else:
                            tampered[index][column] = value
                        _write_jsonl(path, tampered)
                    else:
                        table = _parquet_tampered(results, column, kind, index, None if value is ... else value)
                        if table is None:
                            continue
                        pq.write_table(table, path)
                        back = table_to_rows(table) if column in table.column_names else None
                        value = ... if back is None else back[index].get(column)
                    summary = verify_file(path, grasps, workers=1)
                    # a failure names the row's own id: the tampered one when the id was tampered
                    own = [rows[index]["id"]] + ([None if value is ... else value] if column == "id" else [])
                    mine = [r for g, r in summary.failures if any(_same(g, x) or str(g) == str(x) for x in own)]
                    changed = value is ... or not _same(old, value)
                    evidence_moved = column in ("certificate", "eps_evidence") and kind == "changed"
                    expected = changed and column != "eps_limited" and not evidence_moved
                    named = any(column in re.sub(r"^line \d+: ", "", r) for r in mine)
                    records.append((fmt, target, column, kind, expected, bool(mine), named,
                                    mine[0] if mine else ""))
    return records


def test_untampered_files_pass_also_with_crlf_and_odd_whitespace(files, tmp_path):
    for fmt, (grasps, results) in files.items():
        summary = verify_file(results, grasps, workers=1)
        assert not summary.failures, summary.failures[:3]
    grasps, results = files["jsonl"]
    text = results.read_text().splitlines()
    odd = tmp_path / "odd.jsonl"
    odd.write_bytes("".join("  " + line.replace('": ', '":\t ') + " \r\n" for line in text).encode())
    assert not verify_file(odd, grasps, workers=1).failures


#: The kinds of the test command's matrix: a changed value, a missing one, a deleted column, a
#: wrong type and NaN on every column and target row (the slow set runs all of :data:`KINDS`).
FAST_KINDS = ("changed", "null", "deleted", "wrong_type", "nan")


@pytest.mark.parametrize("kinds, least", [
    (FAST_KINDS, 200),
    pytest.param(KINDS, 400, marks=pytest.mark.slow),
])
def test_every_tampering_of_a_stated_value_is_rejected_naming_the_column(files, tmp_path, kinds, least):
    records = run_matrix(files, tmp_path, kinds)
    assert len(records) > least
    missed = [r for r in records if r[4] and not r[5]]
    assert not missed, missed[:10]
    unnamed = [r for r in records if r[4] and not r[6]]
    assert not unnamed, unnamed[:10]
    # what is accepted: unchanged values and the time-limit flag only
    assert {r[2] for r in records if r[5] is False and r[4] is False} <= set(NAMES)
    assert all(r[2] == "eps_limited" or not r[4] for r in records if not r[5])


def _line_tampered(files, tmp_path, fmt_line):
    grasps, results = files["jsonl"]
    lines = results.read_bytes().splitlines(keepends=True)
    rows = [json.loads(x) for x in lines]
    i = next(k for k, r in enumerate(rows) if r["status"] == "closure")
    lines[i] = fmt_line(lines[i], rows[i])
    path = tmp_path / "lines.jsonl"
    path.write_bytes(b"".join(lines))
    return grasps, path, rows[i]["id"]


@pytest.mark.parametrize("name, make", [
    ("deep", lambda line, row: b'{"status": ' + b"[" * DEEP + b"]" * DEEP + b"}\n"),
    ("huge-int", lambda line, row: line.replace(b'"margin": ', b'"margin": 1' + b"0" * 5000 + b", \"x\": ")),
    ("huge-int-ok", lambda line, row: line.replace(b'"n_contacts": 3', b'"n_contacts": 1' + b"0" * 400)),
    ("invalid-utf8", lambda line, row: line.replace(b'"status"', b'"st\xff\xfeatus"')),
    ("lone-surrogate", lambda line, row: line.replace(json.dumps(row["id"]).encode(), b'"\\ud800"')),
    ("status-list", lambda line, row: line.replace(b'"status": "closure"', b'"status": ["closure"]')),
    ("status-dict", lambda line, row: line.replace(b'"form_status": "', b'"form_status": {"a": 1}, "x": "')),
    ("not-object", lambda line, row: b"[1, 2, 3]\n"),
    ("garbage", lambda line, row: b"\x01\x02garbage\n"),  # NUL bytes make the whole file binary: below
])
def test_malformed_lines_fail_their_row_without_a_traceback(files, tmp_path, name, make):
    grasps, path, gid = _line_tampered(files, tmp_path, make)
    summary = verify_file(path, grasps, workers=1)
    assert summary.failures
    result = CliRunner().invoke(app, ["verify", str(path), "--grasps", str(grasps)])
    assert result.exit_code == 1, result.output
    assert result.exception is None or isinstance(result.exception, SystemExit)


@pytest.mark.parametrize("column", ["margin", "certificate", "eps_l1_lo", "eps_evidence", "status"])
def test_parquet_columns_dropped_fail_every_row(files, tmp_path, column):
    grasps, results = files["parquet"]
    path = tmp_path / "dropped.parquet"
    pq.write_table(pq.read_table(results).drop([column]), path)
    summary = verify_file(path, grasps, workers=1)
    assert len(summary.failures) == pq.read_metadata(results).num_rows
    assert all(column in reason for _, reason in summary.failures)


def test_a_file_that_is_neither_json_lines_nor_parquet_is_a_one_line_error(files, tmp_path):
    grasps, _ = files["jsonl"]
    for name, data in (("r.jsonl", b"\x89PNG\r\n\x1a\n\x00\x00binary"), ("r.parquet", b"\x1f\x8b\x08\x00gzip data"),
                       ("nul.jsonl", b'{"id": 1}\n\x00\x01garbage\n')):
        path = tmp_path / name
        path.write_bytes(data)
        result = CliRunner().invoke(app, ["verify", str(path), "--grasps", str(grasps)])
        assert result.exit_code == 2, result.output
        assert len(result.output.strip().splitlines()) == 1


def test_rows_without_epsilon_among_rows_with_it_are_rejected(files, tmp_path):
    grasps, results = files["jsonl"]
    rows = _rows(results)
    i = next(k for k, r in enumerate(rows) if r["status"] == "closure")
    for key in ("eps_l1_lo", "eps_l1_hi", "eps_linf_lo", "eps_linf_hi", "eps_limited", "eps_evidence"):
        rows[i][key] = None
    path = tmp_path / "mixed.jsonl"
    _write_jsonl(path, rows)
    failures = verify_file(path, grasps, workers=1).failures
    assert [gid for gid, _ in failures] == [rows[i]["id"]]
    assert "epsilon" in failures[0][1]

"""Hostile input: every line or row answers with exactly one results row, bad ones as error rows
naming the line; good rows are the same as in a clean run; no input stops a run or raises.

The corpus under ``tests/data/hostile`` keeps the cases found by hand (one bad line each, and
whole files that are not grasp sets); hypothesis generates more: random JSON values, grasps with
mutated fields, Arrow layouts with nulls, ST0 formulas and traces.
"""

import json
import math
import pathlib

import cv2
import numpy as np
import pyarrow as pa
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from qualgrasp.certify import CertifyError, GraspError, Options, certify_arrow, certify_grasp, grasp_from_dict
from qualgrasp.certify.batch import certify_file, verify_file
from qualgrasp.certify.batch.chunk import certify_values
from qualgrasp.certify.files import grasp_columns
from qualgrasp.certify.files import table_to_rows
from qualgrasp.certify.core import MAX_CONTACTS
from qualgrasp.cli import app
from qualgrasp.qualitative.errors import FormulaError, TraceError
from qualgrasp.qualitative.reasoning.st0 import parse, read_trace

DATA = pathlib.Path(__file__).parent / "data" / "hostile"
GOOD = [b'{"id": "g1", "contacts": [{"p": [1, 0], "n": [-1, 0], "mu": 0.5}, {"p": [-1, 0], "n": [1, 0], "mu": 0.5}]}',
        b'{"id": "g3", "contacts": [{"p": [0, 1], "n": [0, -1], "mu": 0.3}, {"p": [0, -1], "n": [0, 1], "mu": 0.3}]}']
STATUSES = {"closure", "no_closure", "degenerate", "error"}
runner = CliRunner()


def _rows(path):
    return [json.loads(line) for line in path.read_text().splitlines()]


@pytest.fixture(scope="module")
def clean(tmp_path_factory):
    path = tmp_path_factory.mktemp("clean") / "g.jsonl"
    path.write_bytes(GOOD[0] + b"\n" + GOOD[1] + b"\n")
    out = path.with_name("r.jsonl")
    certify_file(path, out, quality=False, workers=1)
    return _rows(out)


@pytest.mark.parametrize("case", sorted(p.name for p in (DATA / "lines").glob("*.line")))
def test_corpus_lines_become_error_rows_and_the_run_goes_on(case, clean, tmp_path):
    bad = (DATA / "lines" / case).read_bytes()
    path = tmp_path / "g.jsonl"
    path.write_bytes(GOOD[0] + b"\n" + bad + b"\n" + GOOD[1] + b"\n")
    out = tmp_path / "r.jsonl"
    summary = certify_file(path, out, quality=False, workers=1)
    rows = _rows(out)
    assert summary.rows == len(rows) == 3
    assert [r["line"] for r in rows] == [1, 2, 3]
    assert rows[0] == clean[0] and {**rows[2], "line": 2} == clean[1]
    if rows[1]["status"] == "error":
        assert rows[1]["error"].startswith("line 2: ") and len(rows[1]["error"]) > 12, case
    else:  # a line that is a valid grasp after all (a huge normal, say): certified and verified
        assert rows[1]["verified"] is True
    assert not verify_file(out, path, workers=1).failures


@pytest.mark.parametrize("case, code", [("array.jsonl", 2), ("bom.jsonl", 0), ("cr.jsonl", 0), ("gz.jsonl", 2),
                                        ("parquet.jsonl", 0), ("png.jsonl", 2), ("pretty.jsonl", 2),
                                        ("random.jsonl", 2), ("utf16.jsonl", 2)])
def test_corpus_files_are_read_or_refused_in_one_line(case, code, tmp_path):
    out = tmp_path / "r.jsonl"
    result = runner.invoke(app, ["certify", str(DATA / "files" / case), "-o", str(out), "-q", "--workers", "1"])
    assert result.exception is None or isinstance(result.exception, SystemExit)
    assert result.exit_code == code, result.output
    if code == 2:
        assert result.output.startswith("error: ") and "neither JSON Lines nor Parquet" in result.output
        assert not out.exists()
    else:
        assert all(r["status"] != "error" for r in _rows(out))


def test_output_never_overwrites_the_input_and_options_are_checked(tmp_path):
    path = tmp_path / "g.jsonl"
    path.write_bytes(GOOD[0] + b"\n")
    before = path.read_bytes()
    for args in (["-o", str(path)], ["-o", str(tmp_path)], ["-o", str(tmp_path / "r.jsonl"), "--chunk-size", "0"],
                 ["-o", str(tmp_path / "r.jsonl"), "--method", "bogus"],
                 ["-o", str(tmp_path / "r.jsonl"), "--eps-gap", "nan"]):
        result = runner.invoke(app, ["certify", str(path), *args, "-q"])
        assert result.exit_code == 2 and result.output.startswith("error: "), (args, result.output)
    assert path.read_bytes() == before
    result = runner.invoke(app, ["certify", str(path), "-o", str(tmp_path / "r.jsonl"), "--dask", "bogus", "-q"])
    assert result.exit_code == 2 and "--dask" in result.output
    assert not list(tmp_path.glob("r.jsonl*"))


# --- generated lines ----------------------------------------------------------------------------

def _containers(children):
    return st.lists(children, max_size=4) | st.dictionaries(st.text(max_size=6), children, max_size=4)


json_values = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats(allow_nan=True, allow_infinity=True) | st.text(max_size=8),
    _containers, max_leaves=12)
numbers = st.floats(allow_nan=True, allow_infinity=True) | st.integers(-10**30, 10**30)
vectors = st.lists(numbers, min_size=0, max_size=4) | json_values
contacts = st.fixed_dictionaries({"p": vectors, "n": vectors}, optional={
    "model": st.sampled_from(["point", "frictionless", "soft", "pad", "glue", 3, None]),
    "mu": numbers | json_values, "torsion": numbers, "width": numbers, "colour": json_values})
grasps = st.fixed_dictionaries({"contacts": st.lists(contacts, max_size=4) | json_values}, optional={
    "id": st.text(max_size=6) | st.integers() | json_values, "center": vectors, "length": numbers | json_values,
    "extra": json_values})


def _line(value) -> bytes:
    try:
        return json.dumps(value).encode()
    except (ValueError, TypeError):
        return b"{"


def _one_row_each(values):
    """50 hostile values: one row per value, an error row exactly when the grasp reader refuses
    it, the certified row of certify_grasp when it accepts it, and rows that can be written as
    strict JSON."""
    lines = [_line(v) for v in values]
    parsed = [json.loads(line) if line != b"{" else CertifyError("malformed JSON") for line in lines]
    rows = certify_values(parsed, list(range(1, 51)), Options(quality=False))
    assert len(rows) == 50 and [r["line"] for r in rows] == list(range(1, 51))
    for value, row in zip(parsed, rows):
        assert row["status"] in STATUSES
        json.dumps(row, allow_nan=False)
        try:
            grasp = grasp_from_dict(value) if not isinstance(value, Exception) else None
        except GraspError:
            grasp = None
        if grasp is None:
            assert row["status"] == "error" and row["error"].startswith(f"line {row['line']}: ")
        elif row["status"] != "error":  # an extra field that cannot be written back is an error row
            expected = certify_grasp(grasp, quality=False).row(line=row["line"])
            assert {k: row[k] for k in expected} == expected


_LINES = st.lists(st.one_of(grasps, json_values), min_size=50, max_size=50)
_HEALTH = [HealthCheck.too_slow, HealthCheck.data_too_large]
#: 2,000 hostile values in the test command, 10,000 in the slow set.
test_generated_lines_give_one_row_each = settings(max_examples=40, suppress_health_check=_HEALTH, deadline=None)(
    given(_LINES)(_one_row_each))
test_generated_lines_give_one_row_each_many = pytest.mark.slow(
    settings(max_examples=200, suppress_health_check=_HEALTH, deadline=None)(given(_LINES)(_one_row_each)))


@settings(max_examples=8, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                                 HealthCheck.function_scoped_fixture], deadline=None)
@given(st.lists(st.one_of(grasps, json_values), min_size=20, max_size=20),
       st.sampled_from([b"\n", b"\r\n", b"\r"]))
def test_generated_files_through_the_command_line(tmp_path, values, end):
    """The same contract through ``qualgrasp certify`` and ``qualgrasp verify``: one row per line
    in order, exit 1 exactly when a row is an error, and the untampered results verify."""
    folder = tmp_path / f"run{len(list(tmp_path.iterdir()))}"
    folder.mkdir()
    path, out = folder / "g.jsonl", folder / "r.jsonl"
    path.write_bytes(end.join(_line(v) for v in values) + end)
    result = runner.invoke(app, ["certify", str(path), "-o", str(out), "-q", "--no-quality", "--workers", "1"])
    rows = _rows(out)
    assert [r["line"] for r in rows] == list(range(1, 21))
    errors = any(r["status"] == "error" or not r["verified"] for r in rows)
    assert result.exit_code == (1 if errors else 0), result.output
    assert result.exception is None or isinstance(result.exception, SystemExit)
    result = runner.invoke(app, ["verify", str(out), "--grasps", str(path), "--workers", "1"])
    assert result.exit_code == 0 and result.exception is None, result.output


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.data())
def test_generated_arrow_layouts_give_one_row_each(data):
    """Valid grasps in a random Arrow layout with random nulls: one row per row, error rows for
    the rows a null made invalid, the rest equal to the same grasps' per-grasp rows."""
    n = 20
    rng = np.random.default_rng(data.draw(st.integers(0, 2**32 - 1)))
    rows = []
    for i in range(n):
        m = int(rng.integers(1, 5))
        contacts = [{"p": list(map(float, rng.normal(size=2))), "n": list(map(float, rng.normal(size=2))),
                     "mu": float(rng.uniform(0, 1))} for _ in range(m)]
        rows.append({"id": f"r{i}", "contacts": contacts})
    table = pa.Table.from_pylist(rows)
    value_type = data.draw(st.sampled_from([pa.float64(), pa.float32(), pa.float16()]))
    vector = data.draw(st.sampled_from(["list", "large_list", "fixed"]))
    make = {"list": pa.list_, "large_list": pa.large_list, "fixed": lambda t: pa.list_(t, 2)}[vector]
    struct = pa.struct([("p", make(value_type)), ("n", make(value_type)), ("mu", value_type)])
    table = table.cast(pa.schema([("id", pa.string()), ("contacts", pa.list_(struct))]))
    nulls = data.draw(st.lists(st.integers(0, n - 1), max_size=5))
    contacts_col = table.column("contacts").to_pylist()
    for i in nulls:
        contacts_col[i] = None
    table = table.set_column(1, "contacts", pa.array(contacts_col, type=pa.list_(struct)))
    results = table_to_rows(certify_arrow(table, Options(quality=False)))
    assert len(results) == n
    values = table.to_pylist()
    for i, (value, row) in enumerate(zip(values, results)):
        if value["contacts"] is None:
            assert row["status"] == "error" and "contacts" in row["error"]
            continue
        contacts = [{k: v for k, v in c.items() if v is not None} for c in value["contacts"]]
        expected = certify_grasp(grasp_from_dict({"id": value["id"], "contacts": contacts}),
                                 quality=False).row(line=i + 1)
        assert row == expected


# --- formulas and traces --------------------------------------------------------------------------

tokens = st.sampled_from(["EC(A,B)", "DC(B,C)", "TPP(A,C)", "true", "false", "!", "(", ")", "&", "|", "->",
                          "U", "S", "G", "F", "X", "Y", "O", "H", "{EC,PO}(A,B)", ",", "A", "ec", "%", " "])


@settings(max_examples=300, deadline=None)
@given(st.lists(tokens, max_size=60), st.integers(0, 300))
def test_generated_formulas_parse_or_say_why(parts, depth):
    text = "(" * depth + " ".join(parts) + ")" * depth
    try:
        f = parse(text)
    except FormulaError as err:
        assert str(err)
        return
    trace = [{("A", "B"): "EC", ("B", "C"): "DC", ("A", "C"): "DC"}] * 3
    try:
        values = f.evaluate(trace)
    except TraceError:
        return
    assert values.shape == (3,)


@settings(max_examples=200, deadline=None)
@given(json_values)
def test_generated_traces_are_read_or_refused(tmp_path_factory, value):
    path = tmp_path_factory.mktemp("trace") / "t.json"
    path.write_text(json.dumps(value, allow_nan=True))
    try:
        frames = read_trace(path)
    except TraceError as err:
        assert str(err)
        return
    assert isinstance(frames, list)


def test_commands_refuse_bad_numbers_in_their_own_units(tmp_path):
    image = tmp_path / "disc.png"
    img = np.full((200, 200), 255, np.uint8)
    cv2.circle(img, (100, 100), 60, 0, -1)
    cv2.imwrite(str(image), img)
    for args, flag in [(["regions", str(image), "--finger-width", "inf"], "--finger-width"),
                       (["regions", str(image), "--finger-width", "1e-300"], "--finger-width"),
                       (["regions", str(image), "--margin", "inf"], "--margin"),
                       (["regions", str(image), "--plot", str(tmp_path / "p.xyz")], "--plot"),
                       (["regions", str(image), "--plot", str(tmp_path / "noext")], "--plot"),
                       (["synthesize", str(image), "--fingers", "2", "--mu", "1e16", "-o", str(tmp_path / "g.jsonl")], "--mu"),
                       (["synthesize", str(image), "--fingers", "2", "-o", str(image)], "-o"),
                       (["figures", "--out", str(image)], "--out"),
                       (["compare", "--builtins", "--trials", "-1"], "--trials"),
                       (["compare", "--silhouettes", "100000"], "--silhouettes"),
                       (["silhouettes", "--n", "-3"], "--n"),
                       (["st0", "true", "--trace", "/dev/zero"], "not a regular file")]:
        result = runner.invoke(app, args)
        assert result.exit_code == 2, (args, result.output)
        assert flag in result.output, (args, result.output)
        assert result.exception is None or isinstance(result.exception, SystemExit)


# --- sizes and scales -------------------------------------------------------------------------------

def test_a_row_over_the_contact_limit_costs_nothing_and_is_an_error_row():
    """A Parquet row beyond MAX_CONTACTS is an error row whose contacts are not even read; a row
    with many contacts is padded on its own, not across the chunk."""
    two = [{"p": [1.0, 0.0], "n": [-1.0, 0.0], "mu": 0.5}, {"p": [-1.0, 0.0], "n": [1.0, 0.0], "mu": 0.5}]
    rows = [{"id": f"g{i}", "contacts": two} for i in range(300)]
    rows[3] = {"id": "over", "contacts": two * (MAX_CONTACTS // 2 + 1)}
    rows[4] = {"id": "many", "contacts": two * 500}
    table = pa.Table.from_pylist(rows)
    cols = grasp_columns(table)
    assert len(cols.checked.contacts.p) == 299 * 2 + 998  # the row over the limit is not read
    P, N, _ = cols.contacts(np.arange(5, 300))
    assert P.shape == (295, 2, 3)
    results = table_to_rows(certify_arrow(table, Options(quality=False)))
    assert results[3]["status"] == "error" and "10002 contacts" in results[3]["error"]
    assert results[4]["status"] == "closure" and results[4]["n_contacts"] == 1000
    assert all(r["status"] == "closure" for i, r in enumerate(results) if i != 3)


@pytest.mark.parametrize("scale", [1e-170, 1e-100, 1e-13, 1e-5, 1.0, 1e11])
def test_tiny_and_huge_grasps_keep_their_verdict_or_say_why(scale):
    """Closure does not depend on the scale: within the usable lengths a grasp keeps its verdict
    and what is written reads back; contacts closer together than MIN_LENGTH (whose default
    length would underflow the tolerances) give an error row that says what to do."""
    contacts = [{"p": [scale, 0.0], "n": [-1.0, 0.0], "mu": 0.5}, {"p": [-scale, 0.0], "n": [1.0, 0.0], "mu": 0.5}]
    row = certify_values([{"contacts": contacts}], [1], Options(quality=False))[0]
    if scale < 1e-12:
        assert row["status"] == "error" and "give 'length' or rescale" in row["error"]
        return
    assert row["status"] == "closure" and math.isclose(row["length"], scale)
    again = grasp_from_dict({"contacts": contacts, "center": row["center"], "length": row["length"]})
    assert again.length == row["length"]
    given = certify_values([{"contacts": contacts, "length": 3 * scale}], [1], Options(quality=False))[0]
    assert given["status"] == "closure" and given["margin"] == row["margin"]

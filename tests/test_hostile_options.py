"""What a hostile run against the command line found (2026-11-28), each now refused in one line
with exit 2 before any work, or read as documented: a negative ``--seed``; a ``--workers`` count
that would start a pool of thousands of processes; ``--eps-time`` negative or NaN (once read as
"no time limit") or infinite (once refused with a rule that admitted it); ``sample --model patch``
(once a ``KeyError``); a normal shorter than the least length (once called "zero" with its length
beside it); ``verify`` counting rows it could not pair with a grasp, and error rows it
re-checks, wrongly; Parquet input misreporting values (a null as NaN) that JSON Lines reports as
given. A text file that is no JSON Lines at all is read line by line, as documented."""

import json

import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from typer.testing import CliRunner

from qualgrasp.certify import models
from qualgrasp.certify.batch.samples import RANGES, parameter_ranges, random_grasp_table
from qualgrasp.certify.cli.options import MAX_WORKERS
from qualgrasp.certify.core.arguments import number_in
from qualgrasp.certify.core.validation import MIN_NORMAL
from qualgrasp.certify.errors import ArgumentError
from qualgrasp.certify.files import grasp_columns, read_results
from qualgrasp.cli import app

runner = CliRunner()

GRASP = {"id": "g", "contacts": [{"p": [0, 1], "n": [0, -1], "mu": 0.5}, {"p": [0, -1], "n": [0, 1], "mu": 0.5}]}


@pytest.fixture
def grasps(tmp_path):
    path = tmp_path / "g.jsonl"
    path.write_text(json.dumps(GRASP) + "\n")
    return path


def _refused(args, *words):
    result = runner.invoke(app, [str(a) for a in args])
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output
    assert result.exception is None or isinstance(result.exception, SystemExit)
    line = result.output.strip()
    assert len(line.splitlines()) == 1 and line.startswith("error: "), line
    assert all(w in line for w in words), line
    return line


@pytest.mark.parametrize("value", ["-1", "-5"])
def test_sample_refuses_a_negative_seed(tmp_path, value):
    out = tmp_path / "s.jsonl"
    _refused(["sample", out, "--n", "3", "--seed", value], "--seed", value)
    assert not out.exists()


@pytest.mark.parametrize("command", ["certify", "verify"])
def test_a_worker_count_beyond_the_limit_is_refused_before_any_process_starts(grasps, tmp_path, command):
    workers = MAX_WORKERS + 1  # not more: were the check gone, this many processes would start
    args = (["certify", grasps, "-o", tmp_path / "r.jsonl", "-q"] if command == "certify"
            else ["verify", grasps, "--grasps", grasps])
    _refused(args + ["--workers", workers], "--workers", str(MAX_WORKERS), str(workers))
    assert not (tmp_path / "r.jsonl").exists() and not (tmp_path / "r.jsonl.parts").exists()


@pytest.mark.parametrize("value", ["-1", "nan", "inf", "-inf"])
def test_eps_time_must_be_a_finite_number_of_seconds(grasps, tmp_path, value):
    out = tmp_path / "r.jsonl"
    _refused(["certify", grasps, "-o", out, "-q", "--eps-time", value], "--eps-time", "0: no time limit")
    assert not out.exists()


def test_eps_time_zero_is_no_time_limit(grasps, tmp_path):
    out = tmp_path / "r.jsonl"
    result = runner.invoke(app, ["certify", str(grasps), "-o", str(out), "-q", "--eps-time", "0", "--workers", "1"])
    assert result.exit_code == 0, result.output
    row, = read_results(out)
    assert row["status"] == "closure" and row["eps_limited"] is False


def test_a_range_without_an_end_is_not_stated():
    with pytest.raises(ArgumentError) as err:
        number_in(float("inf"), "eps_time", 0, float("inf"), unit="seconds")
    assert str(err.value) == "eps_time must be a finite number >= 0 seconds, got inf"
    with pytest.raises(ArgumentError, match=r"^x must be a finite number, got nan$"):
        number_in(float("nan"), "x", float("-inf"), float("inf"))


@pytest.mark.parametrize("suffix", [".jsonl", ".parquet"])
def test_sample_draws_every_built_in_models_parameters(tmp_path, suffix):
    """``patch`` (a radius) was listed by ``sample --help`` and failed; every built-in model's
    parameters have a range, and the set certifies."""
    out = tmp_path / f"p{suffix}"
    result = runner.invoke(app, ["sample", str(out), "--n", "50", "--dim", "3", "--model", "patch"])
    assert result.exit_code == 0, result.output
    res = tmp_path / "r.jsonl"
    result = runner.invoke(app, ["certify", str(out), "-o", str(res), "-q", "--no-quality", "--workers", "1"])
    assert result.exit_code == 0, result.output
    rows = list(read_results(res))
    assert len(rows) == 50 and {r["status"] for r in rows} <= {"closure", "no_closure"}
    radius = random_grasp_table(0, 20, dim=3, model="patch").column("contacts").combine_chunks().flatten()
    values = radius.field("radius").to_numpy()
    assert ((values >= RANGES["radius"][0]) & (values <= RANGES["radius"][1])).all()
    for model in models.names():  # a built-in model added without a range fails here
        assert set(parameter_ranges(model)) == {par.name for par in models.get(model).params}


def test_a_model_parameter_without_a_range_is_named(tmp_path, monkeypatch):
    """A model whose parameter has no range (one registered outside the package, say) is refused
    by name, by the function and by the command before any file is written."""
    monkeypatch.delitem(RANGES, "radius")
    with pytest.raises(ValueError, match="no range to draw the parameter radius of model 'patch'"):
        parameter_ranges("patch")
    out = tmp_path / "p.jsonl"
    _refused(["sample", out, "--dim", "3", "--model", "patch"], "--model patch", "radius")
    assert not out.exists()


@pytest.mark.parametrize("length, refused", [(0.5 * MIN_NORMAL, True), (2 * MIN_NORMAL, False)])
def test_a_normal_shorter_than_the_least_length_is_refused_saying_so(tmp_path, length, refused):
    grasp = json.loads(json.dumps(GRASP))
    grasp["contacts"][0]["n"] = [0, -length]
    src, out = tmp_path / "g.jsonl", tmp_path / "r.jsonl"
    src.write_text(json.dumps(grasp) + "\n")
    runner.invoke(app, ["certify", str(src), "-o", str(out), "-q", "--no-quality", "--workers", "1"])
    row, = read_results(out)
    if refused:
        assert row["status"] == "error"
        assert f"normal n is zero or shorter than {MIN_NORMAL:g} (length {length:.3g})" in row["error"]
    else:
        assert row["status"] == "closure"


def test_a_text_file_of_few_json_objects_is_read_line_by_line(tmp_path):
    """A CSV file is neither binary data nor one JSON document: read as JSON Lines damaged
    throughout, one error row per line (exit 1), as the README says; the run goes on past them."""
    src, out = tmp_path / "table.csv", tmp_path / "r.jsonl"
    src.write_text("a,b,c\n1,2,3\n" + json.dumps(GRASP) + "\n")
    result = runner.invoke(app, ["certify", str(src), "-o", str(out), "-q", "--no-quality", "--workers", "1"])
    assert result.exit_code == 1, result.output
    rows = list(read_results(out))
    assert [r["status"] for r in rows] == ["error", "error", "closure"]
    assert all("malformed JSON" in r["error"] for r in rows[:2])


def _verify(results, grasps):
    result = runner.invoke(app, ["verify", str(results), "--grasps", str(grasps), "--workers", "1"])
    return result.exit_code, result.output.strip().splitlines()


def test_verify_states_which_rows_it_re_checked_against_their_grasps(tmp_path):
    """A results file with an unreadable row group: its rows fail naming the reader's error and
    are not counted as re-checked; error rows are re-checked (their error recomputed), not
    skipped; a grasp file given as results re-checks nothing."""
    src = tmp_path / "g.jsonl"
    lines = [json.dumps({**GRASP, "id": f"g{i}"}) for i in range(60)] + ['{"id": "bad", "contacts": []}']
    src.write_text("\n".join(lines) + "\n")
    results = tmp_path / "r.parquet"
    assert runner.invoke(app, ["certify", str(src), "-o", str(results), "-q", "--no-quality",
                               "--workers", "1"]).exit_code == 1  # the bad line: an error row
    code, out = _verify(results, src)
    assert code == 0 and out[-1] == "60 certified rows and 1 error rows re-checked against their grasps, 0 failed"
    table = pq.read_table(results)
    pq.write_table(table, tmp_path / "rg.parquet", row_group_size=20, compression="none")
    meta = pq.ParquetFile(tmp_path / "rg.parquet").metadata.row_group(1).column(table.schema.get_field_index("margin"))
    data = bytearray((tmp_path / "rg.parquet").read_bytes())
    start = meta.dictionary_page_offset or meta.data_page_offset
    data[start:start + 40] = bytes(b ^ 0x5A for b in data[start:start + 40])
    (tmp_path / "bad.parquet").write_bytes(bytes(data))
    code, out = _verify(tmp_path / "bad.parquet", src)
    assert code == 1
    assert sum("unreadable Parquet data (row group 1)" in line for line in out) == 20
    assert out[-1] == ("40 certified rows and 1 error rows re-checked against their grasps, 20 failed; 20 of the "
                       "failed rows were re-checked against no grasp (unreadable, stating no line of the grasp "
                       "file, or repeating another row's line); 20 of the 61 grasps have no results row (a subset: "
                       "not a failure)")
    code, out = _verify(src, src)
    assert code == 1 and out[-1].startswith("0 certified rows and 0 error rows re-checked against their grasps, "
                                            "61 failed; 61 of the failed rows")


def test_parquet_and_json_lines_state_the_same_errors_of_the_same_values(tmp_path):
    """A null inside a vector is not a number (it was reported as NaN from Parquet), and an
    infinite or null coordinate of ``center`` is shown as given (Parquet said ``got null``): the
    same grasps as JSON Lines and as Parquet give the same error rows, and each file's results
    verify against the other's grasps."""
    contact = lambda p, n: {"p": p, "n": n, "model": "point", "mu": 0.5}  # noqa: E731
    pair = [contact([0.0, 1.0], [0.0, -1.0]), contact([0.0, -1.0], [0.0, 1.0])]
    grasps = [{"id": "p-null", "contacts": [contact([None, 1.0], [0.0, -1.0]), pair[1]], "center": None},
              {"id": "n-null", "contacts": [contact([0.0, 1.0], [0.0, None]), pair[1]], "center": None},
              {"id": "c-inf", "contacts": pair, "center": [float("inf"), 0.0]},
              {"id": "c-null", "contacts": pair, "center": [None, 0.0]},
              {"id": "c-long", "contacts": pair, "center": [0.0, 0.0, 0.0, 1.0]},
              {"id": "fine", "contacts": pair, "center": [0.0, 0.5]}]
    paths = {"jsonl": tmp_path / "g.jsonl", "parquet": tmp_path / "g.parquet"}
    paths["jsonl"].write_text("".join(json.dumps(g) + "\n" for g in grasps))
    pq.write_table(pa.Table.from_pylist(grasps), paths["parquet"])
    rows = {}
    for fmt, path in paths.items():
        out = tmp_path / f"r-{fmt}.jsonl"
        runner.invoke(app, ["certify", str(path), "-o", str(out), "-q", "--no-quality", "--workers", "1"])
        rows[fmt] = list(read_results(out))
    assert [r["error"] for r in rows["parquet"]] == [r["error"] for r in rows["jsonl"]]
    errors = [r["error"] for r in rows["jsonl"]]
    assert "contacts[0].p: expected 2 (planar) or 3 (spatial) finite numbers, got [null, 1.0]" in errors[0]
    assert "contacts[0].n: expected 2 (planar) or 3 (spatial) finite numbers, got [0.0, null]" in errors[1]
    assert "got [Infinity, 0.0]" in errors[2] and "got [null, 0.0]" in errors[3]
    assert "center: expected 2 or 3 finite numbers, got [0.0, 0.0, 0.0, 1.0]" in errors[4]
    assert errors[5] is None and rows["parquet"][5]["status"] == "closure"
    for fmt, other in (("jsonl", "parquet"), ("parquet", "jsonl")):
        code, out = _verify(tmp_path / f"r-{fmt}.jsonl", paths[other])
        assert code == 0, out


def test_verify_regions_states_which_rows_it_re_checked_against_their_tuples(tmp_path):
    """Region results: an unreadable row and a row stating another line fail without a tuple to
    re-check against, and are not counted as re-checked."""
    region = {"id": "r1", "regions": [{"a": [1, -0.2], "b": [1, 0.2], "n": [-1, 0], "mu": 0.5},
                                      {"a": [-1, -0.2], "b": [-1, 0.2], "n": [1, 0], "mu": 0.5}]}
    src, out = tmp_path / "t.jsonl", tmp_path / "o.jsonl"
    src.write_text("".join(json.dumps({**region, "id": f"r{i}"}) + "\n" for i in range(4)))
    assert runner.invoke(app, ["certify-regions", str(src), "-o", str(out), "-q"]).exit_code == 0
    code, out_lines = _verify_regions(out, src)
    assert code == 0
    assert out_lines[-1] == "4 certified rows and 0 error rows re-checked against their region tuples, 0 failed"
    rows = out.read_text().splitlines()
    rows[1] = "not json"
    rows[2] = rows[2].replace('"line": 3', '"line": 9')
    out.write_text("\n".join(rows) + "\n")
    code, out_lines = _verify_regions(out, src)
    assert code == 1 and out_lines[-1] == (
        "2 certified rows and 0 error rows re-checked against their region tuples, 2 failed; 2 of the failed rows "
        "were re-checked against no region tuple (unreadable, or stating another line than its tuple's)")


def _verify_regions(results, regions):
    result = runner.invoke(app, ["verify", str(results), "--regions", str(regions)])
    return result.exit_code, result.output.strip().splitlines()


def test_arrow_null_lists_that_still_cover_values_are_read_as_null():
    """Arrow allows a null list whose offsets still cover values (in-memory producers make them;
    Parquet does not keep them): its values are not the next row's (they raised an IndexError,
    or a broadcast error for ``center``)."""
    good = [{"p": [0.0, 1.0], "n": [0.0, -1.0], "mu": 0.5}, {"p": [0.0, -1.0], "n": [0.0, 1.0], "mu": 0.5}]
    hidden = [{"p": [5.0, 1.0], "n": [0.0, -1.0], "mu": 0.5}] * 2
    flat = pa.array([good, hidden, good]).flatten()
    contacts = pa.ListArray.from_arrays(pa.array([0, 2, 4, 6], pa.int32()), flat, mask=pa.array([False, True, False]))
    center = pa.ListArray.from_arrays(pa.array([0, 2, 4, 6], pa.int32()), pa.array([9.0, 9.0, 0.0, 0.5, 0.0, 0.25]),
                                      mask=pa.array([True, False, False]))
    cols = grasp_columns(pa.table({"id": ["a", "b", "c"], "contacts": contacts, "center": center}))
    assert [cols.message(i) is None for i in range(3)] == [True, False, True]
    assert "contacts: missing" in cols.message(1)
    a, c = cols.grasps([0, 2])
    assert [x.p for x in a.contacts] == [x.p for x in c.contacts] == [(0.0, 1.0), (0.0, -1.0)]
    assert tuple(c.center) == (0.0, 0.25) and tuple(a.center) == (0.0, 0.0)  # a: no center given, the contacts'


def test_refused_integers_from_parquet_are_shown_as_given(tmp_path):
    """Integer coordinates beyond the bound are shown as the integers given, from Parquet's
    integer lists as from JSON Lines (they were shown as floats)."""
    far = 2_000_000_000_000
    grasps = [{"id": "p-far", "contacts": [{"p": [far, 1], "n": [0, -1]}, {"p": [0, -1], "n": [0, 1]}],
               "center": None},
              {"id": "c-far", "contacts": [{"p": [0, 1], "n": [0, -1]}, {"p": [0, -1], "n": [0, 1]}],
               "center": [far, 0]}]
    paths = {"jsonl": tmp_path / "g.jsonl", "parquet": tmp_path / "g.parquet"}
    paths["jsonl"].write_text("".join(json.dumps(g) + "\n" for g in grasps))
    table = pa.Table.from_pylist(grasps)
    assert pa.types.is_integer(table.schema.field("center").type.value_type)
    pq.write_table(table, paths["parquet"])
    errors = {}
    for fmt, path in paths.items():
        out = tmp_path / f"r-{fmt}.jsonl"
        runner.invoke(app, ["certify", str(path), "-o", str(out), "-q", "--no-quality", "--workers", "1"])
        errors[fmt] = [r["error"] for r in read_results(out)]
    assert errors["parquet"] == errors["jsonl"]
    assert f"got [{far}, 1]" in errors["jsonl"][0] and f"got [{far}, 0]" in errors["jsonl"][1]

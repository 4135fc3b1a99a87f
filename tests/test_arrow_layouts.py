"""Grasp sets in the layouts other tools write: the same grasps give the same results.

JSON Lines, Parquet with lists, large lists, fixed-size lists, float32 (the same float32 values
written as double in the reference), dictionary-encoded names, no optional fields, pandas and
polars data frames (Arrow PyCapsule interface): identical verdicts and certificates. Extra user
columns are carried through; a corrupt Parquet page makes error rows, not a failed run.
"""

import json

import numpy as np
import pandas as pd
import polars as pl
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from hypothesis import given, settings, strategies as st
from hypothesis.extra.numpy import arrays

from qualgrasp.certify import Options, certify_arrow
from qualgrasp.certify.batch import certify_file
from qualgrasp.certify.files import table_to_rows
from qualgrasp.certify.files.columns import row_labels, value_columns

N = 10_000


def _base() -> pa.Table:
    """Random planar grasps (3 point contacts or 4 frictionless) whose values are exactly
    representable in float32; center and length left to their defaults."""
    rng = np.random.default_rng(17)
    rows = []
    for i in range(N):
        m = 3 if i % 2 else 4
        u = rng.normal(size=(m, 2))
        u /= np.linalg.norm(u, axis=1, keepdims=True)
        p = (u * rng.uniform(0.7, 1.3, size=(m, 1))).astype(np.float32).astype(float)
        n = (-u + 0.7 * rng.normal(size=(m, 2))).astype(np.float32).astype(float)
        mu = rng.uniform(0.2, 1.0, size=m).astype(np.float32).astype(float)
        contacts = [{"p": list(p[j]), "n": list(n[j]), "model": "point" if m == 3 else "frictionless",
                     "mu": float(mu[j]) if m == 3 else None} for j in range(m)]
        rows.append({"id": f"g{i}", "contacts": contacts})
    return pa.Table.from_pylist(rows)


def _cast(table: pa.Table, *, vector, value=pa.float64(), contacts=pa.list_, names=pa.string(),
          fields=("p", "n", "model", "mu")) -> pa.Table:
    """The table with its vectors as ``vector(value)`` (a list constructor), contact lists as
    ``contacts``, the model names as ``names``, keeping only ``fields`` of each contact."""
    kinds = {"p": vector(value), "n": vector(value), "model": names, "mu": value}
    struct = pa.struct([(f, kinds[f]) for f in fields])
    target = pa.schema([("id", pa.string()), ("contacts", contacts(struct))])
    return table.select(["id", "contacts"]).cast(target)


def _rows(results: pa.Table) -> list[dict]:
    return table_to_rows(results.select([name for name in results.column_names if name != "note"]))


@pytest.fixture(scope="module")
def reference():
    base = _base()
    return base, _rows(certify_arrow(base, Options(quality=False)))


@pytest.mark.parametrize("layout", [
    "large_list", "fixed_size_list", "float32", "fixed_float32", "dictionary", "no_optional_fields",
    "int_widths", "pandas", "polars"])
def test_layouts_give_identical_results(reference, layout):
    base, ref = reference
    fixed2 = lambda t: pa.list_(t, 2)  # noqa: E731
    table = {
        "large_list": lambda: _cast(base, vector=pa.large_list, contacts=pa.large_list, names=pa.large_string()),
        "fixed_size_list": lambda: _cast(base, vector=fixed2),
        "float32": lambda: _cast(base, vector=pa.list_, value=pa.float32()),
        "fixed_float32": lambda: _cast(base, vector=fixed2, value=pa.float32()),
        "dictionary": lambda: _cast(base, vector=pa.list_, names=pa.dictionary(pa.int8(), pa.string())),
        "no_optional_fields": lambda: base.select(["contacts"]).cast(pa.schema([("contacts", pa.list_(
            pa.struct([("p", pa.list_(pa.float64())), ("n", pa.list_(pa.float64())), ("mu", pa.float64())])))])),
        "int_widths": lambda: base,  # replaced below
        "pandas": lambda: pd.DataFrame(base.to_pylist()),
        "polars": lambda: pl.DataFrame(base.to_pylist()),
    }[layout]()
    if layout == "int_widths":  # integer coordinates of any width read as numbers
        ints = pa.Table.from_pylist([{"id": "i", "contacts": [
            {"p": [1, 0], "n": [-1, 0], "mu": 0.5}, {"p": [-1, 0], "n": [1, 0], "mu": 0.5}]}])
        for t in (pa.int8(), pa.int16(), pa.int32(), pa.int64()):
            struct = pa.struct([("p", pa.list_(t)), ("n", pa.list_(t)), ("mu", pa.float64())])
            out = _rows(certify_arrow(ints.cast(pa.schema([("id", pa.string()), ("contacts", pa.list_(struct))])),
                                      Options(quality=False)))
            assert out[0]["status"] == "closure" and out[0]["margin"] == 0.25
        return
    got = _rows(certify_arrow(table, Options(quality=False)))
    assert len(got) == N
    for a, b in zip(got, ref):
        if layout == "no_optional_fields":  # no id column: ids are null
            a, b = dict(a, id=None), dict(b, id=None)
        assert a == b, (layout, a["line"])


def test_json_lines_and_parquet_files_give_identical_results(reference, tmp_path):
    base, ref = reference
    jsonl, parquet = tmp_path / "g.jsonl", tmp_path / "g.parquet"
    with jsonl.open("w") as fh:
        for row in base.to_pylist():
            row["contacts"] = [{k: v for k, v in c.items() if v is not None} for c in row["contacts"]]
            fh.write(json.dumps(row) + "\n")
    pq.write_table(_cast(base, vector=pa.large_list, value=pa.float32(), contacts=pa.large_list), parquet)
    for src in (jsonl, parquet):
        out = tmp_path / f"{src.stem}-{src.suffix[1:]}.jsonl"
        summary = certify_file(src, out, quality=False, workers=1, chunk_size=2500)
        assert summary.rows == N
        got = [json.loads(line) for line in out.read_text().splitlines()]
        for a, b in zip(got, ref):
            assert a == b, (src.suffix, a["line"])


def test_extra_columns_are_carried_and_extra_contact_fields_ignored(tmp_path):
    t = pa.table({
        "id": ["g1", "g2"],
        "contacts": [[{"p": [1.0, 0.0], "n": [-1.0, 0.0], "mu": 0.5, "colour": "red"},
                      {"p": [-1.0, 0.0], "n": [1.0, 0.0], "mu": 0.5, "colour": "blue"}],
                     [{"p": [0.0, 0.0], "n": [0.0, 0.0], "mu": 0.5, "colour": None}]],
        "note": ["first", "second"], "status": ["mine", "yours"]})
    r = certify_arrow(t, Options(quality=False))
    assert r.column("status").to_pylist() == ["closure", "error"]
    assert r.column("note").to_pylist() == ["first", "second"]
    assert r.column("input_status").to_pylist() == ["mine", "yours"]  # a results column's name
    assert "contacts[0].n: normal n is zero" in r.column("error")[1].as_py()
    path, out = tmp_path / "g.parquet", tmp_path / "r.parquet"
    pq.write_table(t, path)
    certify_file(path, out, quality=False, workers=1)
    written = pq.read_table(out)
    assert written.column("note").to_pylist() == ["first", "second"]


def test_a_corrupt_parquet_page_gives_error_rows_and_the_run_goes_on(tmp_path):
    base = _base().slice(0, 600)
    path = tmp_path / "g.parquet"
    pq.write_table(base, path, row_group_size=200, compression="snappy")
    clean = tmp_path / "clean.jsonl"
    certify_file(path, clean, quality=False, workers=1)
    meta = pq.ParquetFile(path).metadata
    column = meta.row_group(1).column(1)  # the contacts column's pages of the middle row group
    data = bytearray(path.read_bytes())
    start = column.data_page_offset + 40
    data[start:start + 200] = bytes(200)
    broken = tmp_path / "broken.parquet"
    broken.write_bytes(bytes(data))
    out = tmp_path / "out.jsonl"
    summary = certify_file(broken, out, quality=False, workers=1, chunk_size=64)
    rows = [json.loads(line) for line in out.read_text().splitlines()]
    good = [json.loads(line) for line in clean.read_text().splitlines()]
    assert summary.rows == len(rows) == 600 and [r["line"] for r in rows] == list(range(1, 601))
    errors = [r for r in rows if r["status"] == "error"]
    assert errors and all("unreadable Parquet data (row group 1)" in r["error"] for r in errors)
    assert all(200 <= r["line"] - 1 < 400 for r in errors)
    assert rows[:200] == good[:200] and rows[400:] == good[400:]


@given(st.integers(1, 6).flatmap(lambda m: arrays(np.int64, st.tuples(st.integers(0, 40), st.just(m)),
                                                  elements=st.sampled_from([0, 1, 2, 9, 17, 2**40, -3]))),
       st.sampled_from([np.int64, np.uint64, np.int32]))
@settings(max_examples=200, deadline=None)
def test_row_labels_are_numpys_unique_rows(key, dtype):
    """The group labels of the columnar path number rows as numpy's unique rows do, whichever of
    its three routes (all rows equal, packed into one integer, numpy's rows) a key takes, for signed
    and unsigned keys."""
    if dtype == np.uint64:  # rows that pack near 2**60, where a float64 loses their last digits
        key = np.uint64(2**20) - (np.abs(key) % 8).astype(np.uint64)
    elif dtype != np.int64:
        key = np.abs(key).astype(dtype)
    want = np.unique(key, axis=0, return_inverse=True)[1].ravel() if len(key) else np.zeros(0, dtype=np.int64)
    assert np.array_equal(row_labels(key), want)


def test_group_labels_of_mixed_patterns():
    """Rows of two dimensions, three contact counts and mixed models get one label per pattern."""
    rng = np.random.default_rng(5)
    rows = []
    for i in range(300):
        dim, m = int(rng.integers(2, 4)), int(rng.integers(2, 5))
        models = [str(rng.choice(["point", "frictionless"])) for _ in range(m)]
        contacts = [{"p": rng.normal(size=dim).tolist(), "n": rng.normal(size=dim).tolist(), "model": mod}
                    | ({"mu": 0.5} if mod == "point" else {}) for mod in models]
        rows.append({"id": i, "contacts": contacts})
    cols = value_columns(rows)
    label = cols.pattern()
    assert cols.ok.all()
    keys = [(r["contacts"][0]["p"].__len__(), tuple(c["model"] for c in r["contacts"])) for r in rows]
    for a in range(len(rows)):
        same = [b for b in range(len(rows)) if keys[b] == keys[a]]
        assert set(np.flatnonzero(label == label[a])) == set(same)

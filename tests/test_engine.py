"""Chunked, parallel, resumable certification: Parquet and JSON Lines, kill -9 and resume, dask."""

import json
import os
import subprocess
import sys

import pyarrow.parquet as pq
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from qualgrasp.certify import Grasp
from qualgrasp.certify.batch import certify_file, verify_file
from qualgrasp.certify.batch.engine import chunk_size_for
from qualgrasp.certify.files import read_results, write_grasps
from qualgrasp.certify.files.results import RESULT_WRITE_OPTIONS
from qualgrasp.certify.batch import random_grasps, textbook_grasps

from helpers import interrupt_after, signal_after

BAD = '{"id": "bad", "contacts": [{"p": [0, 0], "n": [0, 0]}]}\n'


@pytest.fixture(scope="module")
def grasp_files(tmp_path_factory):
    d = tmp_path_factory.mktemp("grasps")
    spatial = random_grasps(2, 60, dim=3, n_contacts=3, model="point", spread=0.3)
    grasps = (textbook_grasps() + random_grasps(1, 300, dim=2, n_contacts=3)
              + [Grasp(g.contacts, id=f"s{i}") for i, g in enumerate(spatial)])
    jsonl, parquet = d / "g.jsonl", d / "g.parquet"
    write_grasps(jsonl, grasps)
    with jsonl.open("a") as fh:
        fh.write(BAD)
    write_grasps(parquet, grasps)
    return jsonl, parquet, len(grasps)


def _rows(path):
    return list(read_results(path))


def _comparable(rows):
    return [{k: v for k, v in r.items() if k != "line"} for r in rows]


def test_parquet_and_jsonl_give_the_same_results(grasp_files, tmp_path):
    jsonl, parquet, n = grasp_files
    a, b = tmp_path / "a.jsonl", tmp_path / "b.parquet"
    sa = certify_file(jsonl, a, quality=False, chunk_size=64)
    sb = certify_file(parquet, b, quality=False, chunk_size=50, workers=2)
    assert sa.rows == n + 1 and sa.errors == 1 and sb.rows == n and sb.errors == 0
    ra, rb = _rows(a)[:n], _rows(b)
    assert pq.read_schema(b).names[:4] == ["id", "line", "dim", "status"]
    for x, y in zip(ra, rb):
        keys = ("id", "status", "form_status", "margin")
        assert [x[k] for k in keys] == [y[k] for k in keys]
        assert x["certificate"] == y["certificate"]
    assert not verify_file(b, parquet, workers=2).failures
    assert not verify_file(a, jsonl).failures
    assert 0 < sb.seconds and sb.chunks == -(-n // 50)
    if sys.platform.startswith("linux"):  # peak memory as getrusage reports it
        assert sb.peak_mb > 50 and sb.peak_worker_mb > 50


def _start(args, cwd):
    return subprocess.Popen([sys.executable, "-m", "qualgrasp.cli", *args], cwd=cwd,
                            start_new_session=True, stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE)


@pytest.mark.parametrize("fmt", ["jsonl", "parquet"])
def test_kill_9_and_resume_loses_and_duplicates_nothing(grasp_files, tmp_path, fmt):
    jsonl, parquet, n = grasp_files
    src = jsonl if fmt == "jsonl" else parquet
    total = n + (fmt == "jsonl")
    ref = tmp_path / f"ref.{fmt}"
    certify_file(src, ref, quality=False, chunk_size=16)
    out = tmp_path / f"out.{fmt}"
    parts = tmp_path / f"out.{fmt}.parts"
    args = ["certify", str(src), "-o", str(out), "--no-quality", "--chunk-size", "16", "-q",
            "--workers", "2"]
    kills = 0
    proc = _start(args, os.getcwd())
    for round_ in range(3):  # kill mid-run three times, resuming each time
        killed = signal_after(proc, lambda: len(list(parts.glob("part-*"))) if parts.exists() else 0,
                              2 + 4 * round_)
        proc.wait()
        kills += killed
        proc = _start(args + ["--resume"], os.getcwd())
    assert proc.wait(timeout=300) in (0, 1), proc.stderr.read().decode()
    assert kills == 3
    assert not parts.exists()
    rows = _rows(out)
    ids = [r["id"] for r in rows]
    assert len(rows) == total and len(set(map(str, ids))) == len(ids)
    assert _comparable(rows) == _comparable(_rows(ref))


@pytest.mark.parametrize("workers", [1, 2])
def test_parquet_output_is_written_in_the_schema_of_all_its_parts(tmp_path, workers):
    """Parquet parts are appended as they complete while they share the first part's schema; a
    carried field whose type changes between chunks (null, then text, then a list; or floats, then
    integers past 2**53 that the floats' type cannot hold exactly, then text or floats again) puts
    every part in the schema of them all (JSON text), and one that keeps its type keeps it. Either
    way every row is there, in input order, with its value: the table a run in one chunk writes."""
    grasps = random_grasps(5, 300, dim=2, n_contacts=3)
    notes = {"changing": ([None] * 100 + [f"s{i}" for i in range(100, 200)]
                          + [[i, i + 1] for i in range(200, 300)]),
             "steady": [f"s{i}" for i in range(300)],
             # the second part's integers pass the first part's float type but do not convert
             "unconvertible": [1.5] * 100 + [2**53 + i for i in range(100)] + ["t"] * 100,
             "unconvertible-numbers": [1.5] * 100 + [2**53 + i for i in range(100)] + [2.5] * 100}
    for kind, values in notes.items():
        src = tmp_path / f"{kind}.jsonl"
        write_grasps(src, grasps)
        lines = [dict(json.loads(x), note=v) for x, v in zip(src.read_text().splitlines(), values)]
        src.write_text("".join(json.dumps(x) + "\n" for x in lines))
        out = tmp_path / f"{kind}.parquet"
        certify_file(src, out, quality=False, chunk_size=100, workers=workers)
        table = pq.read_table(out)
        assert table.column("id").to_pylist() == [g.id for g in grasps]
        field = table.schema.field("note")
        if kind != "steady":
            assert field.metadata == {b"qualgrasp": b"json"}
            assert [None if v is None else json.loads(v) for v in table.column("note").to_pylist()] == values
        else:
            assert field.metadata is None and table.column("note").to_pylist() == values
        whole = tmp_path / f"{kind}-one-chunk.parquet"
        certify_file(src, whole, quality=False, chunk_size=300, workers=workers)
        assert table.equals(pq.read_table(whole), check_metadata=True)


def test_resume_refuses_other_options(grasp_files, tmp_path):
    jsonl, _, _ = grasp_files
    out = tmp_path / "o.jsonl"
    parts = tmp_path / "o.jsonl.parts"
    parts.mkdir()
    (parts / "manifest.json").write_text(json.dumps({"chunk_size": 3}))
    from qualgrasp.certify.errors import CertifyError

    with pytest.raises(CertifyError, match="cannot resume"):
        certify_file(jsonl, out, resume=True, quality=False)


def test_resume_without_a_chunk_size_keeps_the_interrupted_runs(grasp_files, tmp_path):
    """A run stopped mid-way (here by its progress callback) and resumed without a chunk size
    goes on with its own (the default would differ), and gives the uninterrupted run's rows."""
    _, parquet, n = grasp_files
    whole, out = tmp_path / "whole.parquet", tmp_path / "o.parquet"
    certify_file(parquet, whole, quality=False, chunk_size=50, workers=2)
    with pytest.raises(KeyboardInterrupt):
        certify_file(parquet, out, quality=False, chunk_size=50, progress=interrupt_after(3))
    summary = certify_file(parquet, out, quality=False, resume=True, workers=2)
    assert summary.resumed_chunks >= 3 and summary.chunks == -(-n // 50)
    assert pq.read_table(out).equals(pq.read_table(whole))


def test_the_default_chunk_size_gives_each_worker_chunks(grasp_files, tmp_path):
    """Without a chunk size a run cuts its input by :func:`chunk_size_for`: here every grasp in
    one chunk (fewer than 1024), the same rows as small chunks give."""
    _, parquet, n = grasp_files
    a, b = tmp_path / "a.parquet", tmp_path / "b.parquet"
    assert certify_file(parquet, a, quality=False, workers=2).chunks == 1 == -(-n // chunk_size_for(n, 2))
    certify_file(parquet, b, quality=False, chunk_size=64, workers=2)
    assert pq.read_table(a).equals(pq.read_table(b))
    assert [chunk_size_for(x, w) for x, w in ((10**6, 2), (80_000, 2), (80_000, 4), (0, 2))] == [16384, 10000, 5000,
                                                                                                16384]


def test_parquet_results_dictionary_encode_names_and_indices(tmp_path):
    """Every column the results writer names for a dictionary is a column of the file (pyarrow
    ignores a name that is not), and the evidence's index lists are written with one."""
    parquet, out = tmp_path / "g.parquet", tmp_path / "q.parquet"
    write_grasps(parquet, random_grasps(3, 200, dim=2, n_contacts=3))
    certify_file(parquet, out, quality=True, workers=1)
    meta = pq.ParquetFile(out).metadata
    encodings = {meta.row_group(0).column(i).path_in_schema: meta.row_group(0).column(i).encodings
                 for i in range(meta.num_columns)}
    named = RESULT_WRITE_OPTIONS["use_dictionary"]
    assert set(named) <= set(encodings)
    assert all("RLE_DICTIONARY" in encodings[f"eps_evidence.{norm}.{name}.list.element"]
               for norm in ("l1", "linf") for name in ("ref", "faces") if (norm, name) != ("l1", "ref"))
    assert "RLE_DICTIONARY" not in encodings["eps_l1_lo"]


def test_dask_local_cluster_matches_local_processes(grasp_files, tmp_path):
    pytest.importorskip("distributed")
    _, parquet, _ = grasp_files
    local, distributed = tmp_path / "local.parquet", tmp_path / "dask.parquet"
    certify_file(parquet, local, quality=True, eps_budget=20_000, chunk_size=40, workers=2)
    certify_file(parquet, distributed, quality=True, eps_budget=20_000, chunk_size=40, workers=2,
                 dask="local")
    assert pq.read_table(local).equals(pq.read_table(distributed))


@settings(max_examples=200, deadline=None)
@given(st.lists(st.tuples(st.sampled_from(["closure", "no_closure", "degenerate", "error"]),
                          st.sampled_from([True, False, None])), max_size=30))
def test_status_counts_of_lists_equal_those_of_arrow_columns(rows):
    """The engine counts a chunk's rows from lists (JSON Lines) or Arrow columns (Parquet)."""
    import pyarrow as pa

    from qualgrasp.certify.batch.chunk import status_counts

    statuses, verified = [s for s, _ in rows], [v for _, v in rows]
    arrow = status_counts(pa.array(statuses, pa.string()), pa.array(verified, pa.bool_()))
    assert status_counts(statuses, verified) == arrow
    assert status_counts(statuses) == (arrow[0], 0)

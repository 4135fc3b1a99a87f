"""The fast first answer on a cold compile cache: ``qualgrasp certify`` starts compiling quality's
kernels on other cores before it loads its own modules (:mod:`qualgrasp.certify.warmup`), the
processes compiling them import the kernels alone, and nothing about a file or an argument can make
that step fail a command."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from qualgrasp.certify import warmup
from qualgrasp.cli import AHEAD, COMMANDS

GRASP2 = {"id": "a", "contacts": [{"p": [1, 0], "n": [-1, 0]}, {"p": [-1, 0], "n": [1, 0]}]}
GRASP3 = {"id": "b", "contacts": [{"p": [1, 0, 0], "n": [-1, 0, 0]}, {"p": [-1, 0, 0], "n": [1, 0, 0]}]}


@pytest.fixture
def started(monkeypatch):
    """The dimensions :func:`warmup.compile_ahead` was asked for, instead of compiling."""
    calls = []
    monkeypatch.setattr(warmup, "compile_ahead", lambda dims: calls.append(sorted(dims)))
    return calls


def _file(tmp_path, name, data: bytes):
    path = tmp_path / name
    path.write_bytes(data)
    return str(path)


def test_the_first_grasp_gives_the_dimensions(tmp_path, started):
    planar = _file(tmp_path, "p.jsonl", b"\n  \n" + json.dumps(GRASP2).encode() + b"\n" + json.dumps(GRASP3).encode())
    spatial = _file(tmp_path, "s.jsonl", json.dumps(GRASP3).encode() + b"\n")
    assert warmup.first_grasp_dims(planar) == {2} and warmup.first_grasp_dims(spatial) == {3}
    # the input is found wherever it stands among the options
    warmup.compile_ahead_for_command([planar, "-o", str(tmp_path / "out.jsonl")])
    warmup.compile_ahead_for_command(["-o", str(tmp_path / "out.jsonl"), "--workers", "2", spatial])
    assert started == [[2], [3]]


@pytest.mark.parametrize("extra", [["--no-quality"], ["--quality", "--no-quality"], ["--help"], ["--mesh", "m.obj"],
                                   ["--mesh=m.obj"], ["--dask", "local"]])
def test_nothing_starts_where_the_run_needs_no_quality_kernels_here(tmp_path, started, extra):
    planar = _file(tmp_path, "p.jsonl", json.dumps(GRASP2).encode() + b"\n")
    warmup.compile_ahead_for_command([planar, "-o", "out.jsonl", *extra])
    assert started == []


def test_the_last_quality_toggle_counts_and_an_output_is_needed(tmp_path, started):
    planar = _file(tmp_path, "p.jsonl", json.dumps(GRASP2).encode() + b"\n")
    warmup.compile_ahead_for_command([planar])  # no output: the command refuses it, nothing starts
    warmup.compile_ahead_for_command([planar, "--", "-o"])  # after --, -o is no option
    assert started == []
    warmup.compile_ahead_for_command([planar, "--no-quality", "--output", "out.jsonl", "--quality"])
    warmup.compile_ahead_for_command([planar, "--output=out.jsonl"])
    assert started == [[2], [2]]


@pytest.mark.parametrize("data", [
    b"", b"\n\n", b"PAR1\x00\x01garbage", b"\xff\xfe\x00not utf-8\n", b"[1, 2, 3]\n", b'"text"\n',
    b'{"contacts": "none"}\n', b'{"contacts": [1, 2]}\n', b'{"contacts": [{"n": [1, 0]}]}\n',
    b'{"id": 1}\n', b"[" * 100_000 + b"]" * 100_000 + b"\n",
    b'{"contacts": [{"p": [' + b"1, " * 40_000 + b"1]}]}\n",  # a first line longer than the peek
])
def test_no_file_makes_the_step_fail(tmp_path, started, data):
    path = _file(tmp_path, "g.jsonl", data)
    assert warmup.first_grasp_dims(path) == set()
    warmup.compile_ahead_for_command([path, "-o", "out.jsonl"])
    warmup.compile_ahead_for_command([str(tmp_path), "no such file", "bad\x00path", "-", ""])
    assert started == []


def test_certify_has_its_step_and_names_it():
    module, function = AHEAD["certify"]
    assert set(AHEAD) <= set(COMMANDS) and callable(getattr(warmup, function)) and module == warmup.__name__


def test_the_compiling_processes_import_the_kernels_alone():
    code = ("import sys, json\nimport qualgrasp.certify._kernels.sets, qualgrasp.certify.warmup\n"
            "print(json.dumps(sorted(m for m in sys.modules if m.startswith(('qualgrasp', 'scipy.s', 'pyarrow', "
            "'clarabel', 'cvxpy', 'matplotlib')))))")
    loaded = json.loads(subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                                       check=True).stdout.splitlines()[-1])
    assert not [m for m in loaded if not m.startswith("qualgrasp")]  # no scipy.sparse or .spatial, no solver
    assert {m.rpartition(".")[0] for m in loaded if m.count(".") > 2} <= {"qualgrasp.certify._kernels",
                                                                          "qualgrasp.certify.core"}
    assert "qualgrasp.certify.core.cones" in loaded and "qualgrasp.certify.core.grasp" not in loaded

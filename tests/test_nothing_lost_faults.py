"""Nothing lost (issue 23, part 3): a fault mid-run ends cleanly and ``--resume`` finishes.

Each fault is real: a full disk is a small tmpfs (root only), a read-only folder the same tmpfs
remounted read-only, a file-size limit ``RLIMIT_FSIZE`` in the child process (Python ignores
SIGXFSZ, so the write fails with EFBIG), a truncated or corrupted checkpoint part a part cut or
changed on disk. Each run ends with exit 2 and one line saying what failed, keeps every finished
part, and ``--resume`` once the cause is gone gives every id exactly once, with the rows of an
uninterrupted run. SIGINT then ``--resume`` is kept tested too.
"""

import json
import os
import resource
import signal
import subprocess
import sys
import uuid
from pathlib import Path

import pyarrow.parquet as pq
import pytest

from qualgrasp.certify.batch import certify_file
from qualgrasp.certify.batch.engine import certify_chunk as _certify_chunk
from qualgrasp.certify.files import read_results, write_grasps
from qualgrasp.certify.batch import random_grasps

from helpers import signal_after

N, CHUNK = 600, 50
LIMIT = 120  # seconds: longer is a hang
ARGS = ("--no-quality", "-q", "--workers", "1", "--chunk-size", str(CHUNK))


def can_mount() -> str | None:
    """None when this process can mount a tmpfs, else why not."""
    if not hasattr(os, "geteuid") or os.geteuid() != 0:
        return "mounting a tmpfs needs root"
    probe = Path(f"/tmp/qualgrasp-probe-{uuid.uuid4().hex}")
    probe.mkdir()
    try:
        if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(probe)],
                          capture_output=True).returncode:
            return "mount -t tmpfs is not permitted here"
        subprocess.run(["umount", str(probe)], check=True)
        return None
    except FileNotFoundError:
        return "no mount command"
    finally:
        probe.rmdir()


MOUNT = can_mount()
needs_mount = pytest.mark.skipif(MOUNT is not None, reason=str(MOUNT))


@pytest.fixture(scope="module")
def grasps(tmp_path_factory):
    """A grasp set and its uninterrupted results, JSON Lines and Parquet."""
    d = tmp_path_factory.mktemp("faults")
    path = d / "g.jsonl"
    write_grasps(path, random_grasps(11, N))
    refs = {}
    for fmt in ("jsonl", "parquet"):
        refs[fmt] = d / f"ref.{fmt}"
        certify_file(path, refs[fmt], quality=False, chunk_size=CHUNK)
    return path, refs


@pytest.fixture
def disk(tmp_path):
    """A mount point; the test mounts a tmpfs on it (unmounted at the end)."""
    point = tmp_path / "disk"
    point.mkdir()
    yield point
    subprocess.run(["umount", str(point)], capture_output=True)


def mount(point: Path, options: str) -> None:
    subprocess.run(["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(point)], check=True)


def remount(point: Path, options: str) -> None:
    subprocess.run(["mount", "-o", f"remount,{options}", str(point)], check=True)


def cli(*args, limit_bytes=None):
    def child():
        if limit_bytes is not None:
            resource.setrlimit(resource.RLIMIT_FSIZE, (limit_bytes, limit_bytes))

    try:
        proc = subprocess.run([sys.executable, "-m", "qualgrasp.cli", *map(str, args)], capture_output=True,
                              timeout=LIMIT, preexec_fn=child)
    except subprocess.TimeoutExpired:
        pytest.fail(f"qualgrasp {' '.join(map(str, args))} ran for more than {LIMIT} s")
    return proc.returncode, (proc.stderr + proc.stdout).decode(errors="replace")


def one_line(text: str) -> str:
    lines = [x for x in text.strip().splitlines() if x.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: ") and "Traceback" not in text, text
    return lines[0]


def comparable(path: Path) -> list:
    return [{k: v for k, v in r.items()} for r in read_results(path)]


def finished_parts(parts: Path) -> list[str]:
    return sorted(p.name for p in parts.glob("part-*.sum"))


def assert_whole(out: Path, ref: Path) -> None:
    rows = comparable(out)
    ids = [r["id"] for r in rows]
    assert len(rows) == N and len(set(ids)) == N
    assert rows == comparable(ref)
    assert not Path(str(out) + ".parts").exists()
    assert not list(out.parent.glob(".qualgrasp-*"))


@needs_mount
@pytest.mark.parametrize("fmt", ["jsonl", "parquet"])
@pytest.mark.parametrize("stage", ["parts", "assembly"])
def test_full_disk_ends_cleanly_and_resume_finishes(grasps, disk, fmt, stage):
    src, refs = grasps
    size = refs[fmt].stat().st_size
    # parts: the disk fills while chunks are written; assembly: the parts fit, parts + output not
    room = size // 3 if stage == "parts" else int(size * 1.6) if fmt == "jsonl" else int(size * 2.2)
    mount(disk, f"size={max(room, 16384) // 4096 * 4096}")
    out = disk / f"R.{fmt}"
    code, text = cli("certify", src, "-o", out, *ARGS)
    line = one_line(text)
    assert code == 2 and "disk is full" in line and "--resume" in line, line
    kept = finished_parts(disk / f"R.{fmt}.parts")
    assert kept and not out.exists()
    remount(disk, "size=64m")
    code, text = cli("certify", src, "-o", out, *ARGS, "--resume")
    assert code == 0, text
    assert_whole(out, refs[fmt])


@needs_mount
def test_read_only_folder_refused_in_one_line_then_resume_finishes(grasps, disk):
    src, refs = grasps
    mount(disk, f"size={refs['jsonl'].stat().st_size // 3 // 4096 * 4096}")
    out = disk / "R.jsonl"
    assert cli("certify", src, "-o", out, *ARGS)[0] == 2  # a full disk first: parts left
    parts = disk / "R.jsonl.parts"
    before = {p.name: p.read_bytes() for p in parts.iterdir()}
    remount(disk, "ro")
    code, text = cli("certify", src, "-o", out, *ARGS, "--resume")
    assert code == 2 and "read-only" in one_line(text)
    assert {p.name: p.read_bytes() for p in parts.iterdir()} == before
    remount(disk, "rw,size=64m")
    code, text = cli("certify", src, "-o", out, *ARGS, "--resume")
    assert code == 0, text
    assert_whole(out, refs["jsonl"])


@pytest.mark.parametrize("fmt", ["jsonl", "parquet"])
def test_file_size_limit_ends_cleanly_and_resume_finishes(grasps, tmp_path, fmt):
    src, refs = grasps
    out = tmp_path / f"R.{fmt}"
    size = refs[fmt].stat().st_size
    code, text = cli("certify", src, "-o", out, *ARGS, limit_bytes=size // 2)  # parts fit, the output not
    line = one_line(text)
    assert code == 2 and "file-size limit" in line and "--resume" in line, line
    assert len(finished_parts(tmp_path / f"R.{fmt}.parts")) >= 4 and not out.exists()
    code, text = cli("certify", src, "-o", out, *ARGS, "--resume")
    assert code == 0, text
    assert_whole(out, refs[fmt])


@pytest.mark.parametrize("fmt", ["jsonl", "parquet"])
@pytest.mark.parametrize("damage", ["truncated", "flipped", "sum-truncated"])
def test_a_damaged_part_is_computed_again_on_resume(grasps, tmp_path, fmt, damage):
    src, refs = grasps
    out = tmp_path / f"R.{fmt}"
    assert cli("certify", src, "-o", out, *ARGS, limit_bytes=refs[fmt].stat().st_size // 2)[0] == 2
    parts = tmp_path / f"R.{fmt}.parts"
    kept = len(finished_parts(parts))
    part = sorted(p for p in parts.glob("part-*") if not p.name.endswith(".sum"))[3]
    data = part.read_bytes()
    if damage == "truncated":  # a crash or a disk error cut it short
        part.write_bytes(data[: len(data) // 2])
    elif damage == "flipped":  # same size, one byte changed
        part.write_bytes(data[:100] + bytes([data[100] ^ 0x20]) + data[101:])
    else:
        summed = Path(str(part) + ".sum")
        summed.write_bytes(summed.read_bytes()[:5])
    summary = certify_file(src, out, quality=False, chunk_size=CHUNK, resume=True)
    assert summary.resumed_chunks == kept - 1 and summary.rows == N
    assert_whole(out, refs[fmt])


def test_sigint_then_resume_loses_and_duplicates_nothing(grasps, tmp_path):
    src, refs = grasps
    out = tmp_path / "R.jsonl"
    parts = tmp_path / "R.jsonl.parts"
    proc = subprocess.Popen([sys.executable, "-m", "qualgrasp.cli", "certify", str(src), "-o", str(out), *ARGS],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, start_new_session=True)
    assert signal_after(proc, lambda: len(finished_parts(parts)) if parts.exists() else 0, 2, signal.SIGINT)
    assert proc.wait(timeout=LIMIT) != 0  # interrupted mid-run
    code, text = cli("certify", src, "-o", out, *ARGS, "--resume")
    assert code == 0, text
    assert_whole(out, refs["jsonl"])


def test_parquet_results_of_a_resumed_run_match(grasps, tmp_path):
    """The assembled Parquet output of a resumed run is the uninterrupted run's, column for column."""
    src, refs = grasps
    out = tmp_path / "R.parquet"
    assert cli("certify", src, "-o", out, *ARGS, limit_bytes=refs["parquet"].stat().st_size // 2)[0] == 2
    certify_file(src, out, quality=False, chunk_size=CHUNK, resume=True)
    assert pq.read_table(out).equals(pq.read_table(refs["parquet"]))
    assert json.loads(json.dumps(pq.read_metadata(out).num_rows)) == N


def _dies_on_the_third_chunk(chunk, options, part):
    if chunk.index == 2:
        os._exit(1)  # as the system's out-of-memory killer leaves it: no Python error, no part
    return _certify_chunk(chunk, options, part)


def test_a_worker_killed_mid_run_ends_in_one_error_then_resume_finishes(grasps, tmp_path, monkeypatch):
    from qualgrasp.certify.batch import engine
    from qualgrasp.certify.errors import CertifyError

    path, refs = grasps
    out = tmp_path / "r.jsonl"
    monkeypatch.setattr(engine, "certify_chunk", _dies_on_the_third_chunk)
    with pytest.raises(CertifyError, match="a worker process ended abruptly") as err:
        certify_file(path, out, quality=False, chunk_size=CHUNK, workers=2)
    assert "Traceback" not in str(err.value) and not out.exists()
    monkeypatch.undo()
    certify_file(path, out, quality=False, chunk_size=CHUNK, workers=2, resume=True)
    assert_whole(out, refs["jsonl"])

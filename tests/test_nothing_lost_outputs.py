"""Nothing lost (issue 23, part 1): no command that writes ever replaces or deletes an input or a
file or folder it did not make, refuses outputs that are not regular files, and refuses a second
run on the same output.

The corpus is made here at run time: for every command that writes, the collisions tried are the
input, the old temporary name, the checkpoint folder, a symbolic link, a hard link, a FIFO, a
device and a concurrent run. Each case checks the exit code, the one-line message and that every
file of the folder that the command did not write is byte for byte as before. Commands that could
block (a FIFO) run in a subprocess with a time limit.
"""

import hashlib
import json
import os
import stat
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from typer.testing import CliRunner

from qualgrasp.certify.cli.options import OptionError, output_file, output_folder
from qualgrasp.certify.files import write_grasps
from qualgrasp.certify.batch import random_grasps, textbook_grasps
from qualgrasp.cli import app

runner = CliRunner()
LIMIT = 60  # seconds: a command that blocks longer has hung
REGION = {"id": "r1", "regions": [{"a": [1, -0.3], "b": [1, 0.3], "n": [-1, 0], "mu": 0.5},
                                  {"a": [-1, -0.3], "b": [-1, 0.3], "n": [1, 0], "mu": 0.5}]}


def snapshot(folder: Path) -> dict:
    """Every entry below ``folder``: its kind and, for files, a hash of its bytes."""
    out = {}
    for p in sorted(folder.rglob("*")):
        st = os.lstat(p)
        if stat.S_ISREG(st.st_mode):
            out[str(p.relative_to(folder))] = ("file", hashlib.sha256(p.read_bytes()).hexdigest())
        elif stat.S_ISLNK(st.st_mode):
            out[str(p.relative_to(folder))] = ("link", os.readlink(p))
        else:
            out[str(p.relative_to(folder))] = (stat.S_IFMT(st.st_mode), None)
    return out


def assert_kept(before: dict, after: dict, written: tuple = ()) -> None:
    """Every entry of ``before`` is in ``after`` unchanged, except the outputs ``written``."""
    lost = {k: v for k, v in before.items() if k not in written and after.get(k) != v}
    assert not lost, f"changed or lost: {lost}"
    litter = [k for k in after if k not in before and k not in written]
    assert not litter, f"left behind: {litter}"


def cli(*args, timeout=LIMIT):
    """Run ``qualgrasp ARGS`` in a subprocess: (exit code, stderr); a hang fails the test."""
    try:
        proc = subprocess.run([sys.executable, "-m", "qualgrasp.cli", *map(str, args)], capture_output=True,
                              timeout=timeout)
    except subprocess.TimeoutExpired:
        pytest.fail(f"qualgrasp {' '.join(map(str, args))} blocked for more than {timeout} s")
    return proc.returncode, proc.stderr.decode(errors="replace") + proc.stdout.decode(errors="replace")


def invoke(*args):
    result = runner.invoke(app, [str(a) for a in args])
    assert result.exception is None or isinstance(result.exception, SystemExit), result.exception
    return result.exit_code, result.output


def one_error_line(output: str) -> str:
    lines = [line for line in output.strip().splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: ") and "Traceback" not in output, output
    return lines[0]


@pytest.fixture
def folder(tmp_path):
    """A folder with a grasp set ``g.jsonl`` (40 grasps) and a region set ``r.jsonl``."""
    write_grasps(tmp_path / "g.jsonl", textbook_grasps() + random_grasps(4, 40 - len(textbook_grasps())))
    (tmp_path / "r.jsonl").write_text(json.dumps(REGION) + "\n")
    return tmp_path


def ids(path: Path) -> list:
    return [json.loads(line)["id"] for line in path.read_text().splitlines()]


CERTIFY = ("certify", "--no-quality", "-q", "--workers", "1", "--chunk-size", "8")


# -- certify ------------------------------------------------------------------------------------

def test_certify_input_named_like_the_temporary_is_kept(folder):
    src = folder / "R.jsonl.tmp"
    os.replace(folder / "g.jsonl", src)
    before = snapshot(folder)
    code, out = invoke(*CERTIFY, src, "-o", folder / "R.jsonl")
    assert code == 0, out
    assert_kept(before, snapshot(folder), written=("R.jsonl",))
    assert len(ids(folder / "R.jsonl")) == 40 == len(set(map(str, ids(folder / "R.jsonl"))))


@pytest.mark.parametrize("resume", [False, True])
def test_certify_never_touches_a_users_folder_named_like_the_parts(folder, resume):
    parts = folder / "R.jsonl.parts"
    parts.mkdir()
    (parts / "mine.txt").write_text("my own notes")
    before = snapshot(folder)
    code, out = invoke(*CERTIFY, folder / "g.jsonl", "-o", folder / "R.jsonl", *(["--resume"] if resume else []))
    assert code == 2
    assert "R.jsonl.parts" in one_error_line(out) and "did not make" in out
    assert_kept(before, snapshot(folder))


def test_certify_input_named_like_the_parts_is_refused(folder):
    src = folder / "R.jsonl.parts"
    os.replace(folder / "g.jsonl", src)
    before = snapshot(folder)
    code, out = invoke(*CERTIFY, src, "-o", folder / "R.jsonl")
    assert code == 2 and "R.jsonl.parts" in one_error_line(out)
    assert_kept(before, snapshot(folder))


def test_certify_refuses_a_parts_folder_of_its_own_holding_a_strangers_file(folder):
    """A run stopped by a fault leaves its parts; a file someone put there is never deleted."""
    out = folder / "R.jsonl"
    code, text = cli(*CERTIFY[:-2], "--chunk-size", "40", folder / "g.jsonl", "-o", out)
    assert code == 0, text
    parts = folder / "R.jsonl.parts"
    parts.mkdir()
    manifest = {"made_by": "qualgrasp certify", "output": str(out.resolve())}
    (parts / "manifest.json").write_text(json.dumps(manifest))
    (parts / "keep-me.txt").write_text("a stranger's file")
    before = snapshot(folder)
    code, text = invoke(*CERTIFY, folder / "g.jsonl", "-o", out)
    assert code == 2 and "keep-me.txt" in one_error_line(text)
    assert_kept(before, snapshot(folder))


def test_certify_refuses_a_fifo_output(folder):
    fifo = folder / "R.jsonl"
    os.mkfifo(fifo)
    before = snapshot(folder)
    code, out = cli(*CERTIFY, folder / "g.jsonl", "-o", fifo)
    assert code == 2 and "FIFO" in one_error_line(out)
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)
    assert_kept(before, snapshot(folder))


def test_certify_refuses_a_link_to_a_device(folder):
    link = folder / "R.jsonl"
    link.symlink_to("/dev/null")
    before = snapshot(folder)
    code, out = invoke(*CERTIFY, folder / "g.jsonl", "-o", link)
    assert code == 2 and "device" in one_error_line(out)
    assert os.readlink(link) == "/dev/null"
    assert_kept(before, snapshot(folder))


@pytest.mark.skipif(not hasattr(os, "geteuid") or os.geteuid() != 0, reason="making a device node needs root")
def test_certify_refuses_a_device_output(folder):
    dev = folder / "null"
    os.mknod(dev, 0o666 | stat.S_IFCHR, os.makedev(1, 3))
    before = snapshot(folder)
    code, out = invoke(*CERTIFY, folder / "g.jsonl", "-o", dev)
    assert code == 2 and "device" in one_error_line(out)
    assert stat.S_ISCHR(os.lstat(dev).st_mode)
    assert_kept(before, snapshot(folder))


@pytest.mark.parametrize("link", ["symbolic", "hard"])
def test_certify_output_linked_to_the_input_is_refused(folder, link):
    out = folder / "R.jsonl"
    (out.symlink_to if link == "symbolic" else out.hardlink_to)(folder / "g.jsonl")
    before = snapshot(folder)
    code, text = invoke(*CERTIFY, folder / "g.jsonl", "-o", out)
    assert code == 2 and "is the input" in one_error_line(text)
    assert_kept(before, snapshot(folder))


def lock_output(path, flag):
    """A run in progress on ``path`` (the lock it holds)."""
    from qualgrasp.certify.files import lock_output

    return lock_output(path, flag)


def test_certify_refuses_a_second_run_on_the_same_output(folder):
    out = folder / "R.jsonl"
    with lock_output(out, "-o"):  # a run in progress
        before = snapshot(folder)
        code, text = invoke(*CERTIFY, folder / "g.jsonl", "-o", out)
        assert code == 2 and "another run is writing" in one_error_line(text)
        assert_kept(before, snapshot(folder))
    code, text = invoke(*CERTIFY, folder / "g.jsonl", "-o", out)  # the lock is gone with its run
    assert code == 0, text
    assert not list(folder.glob(".qualgrasp-*"))


def test_two_concurrent_runs_end_and_the_output_is_whole(folder):
    """Whatever the timing: both end, at least one writes the whole output, none is left
    half-written, and nothing else is left behind."""
    out = folder / "R.jsonl"
    args = [sys.executable, "-m", "qualgrasp.cli", *CERTIFY, str(folder / "g.jsonl"), "-o", str(out)]
    procs = [subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT) for _ in range(2)]
    codes = []
    for p in procs:
        try:
            codes.append(p.wait(timeout=3 * LIMIT))
        except subprocess.TimeoutExpired:
            for q in procs:
                q.kill()
            pytest.fail("two concurrent runs stalled")
    texts = [p.stdout.read().decode() for p in procs]
    assert 0 in codes and set(codes) <= {0, 2}, texts
    for code, text in zip(codes, texts):
        if code == 2:
            assert "another run is writing" in one_error_line(text)
    assert len(ids(out)) == 40
    assert sorted(p.name for p in folder.iterdir()) == ["R.jsonl", "g.jsonl", "r.jsonl"]


@pytest.mark.parametrize("length, what", [(244, "NAME.parts"), (250, "it has 256 bytes")])
def test_certify_name_too_long_for_its_parts_is_refused_before_any_work(folder, length, what):
    out = folder / ("x" * length + ".jsonl")
    before = snapshot(folder)
    code, text = invoke(*CERTIFY, folder / "g.jsonl", "-o", out)
    line = one_error_line(text)
    assert code == 2 and "too long" in line and what in line, line
    assert_kept(before, snapshot(folder))


# -- certify-regions ------------------------------------------------------------------------------

def test_certify_regions_input_named_like_the_temporary_is_kept(folder):
    src = folder / "RR.jsonl.tmp"
    os.replace(folder / "r.jsonl", src)
    before = snapshot(folder)
    code, out = invoke("certify-regions", src, "-o", folder / "RR.jsonl", "-q")
    assert code == 0, out
    assert_kept(before, snapshot(folder), written=("RR.jsonl",))
    assert ids(folder / "RR.jsonl") == ["r1"]


def test_certify_regions_refuses_a_fifo_output(folder):
    fifo = folder / "RR.jsonl"
    os.mkfifo(fifo)
    before = snapshot(folder)
    code, out = cli("certify-regions", folder / "r.jsonl", "-o", fifo, "-q")
    assert code == 2 and "FIFO" in one_error_line(out)
    assert_kept(before, snapshot(folder))


@pytest.mark.parametrize("link", ["symbolic", "hard"])
def test_certify_regions_output_linked_to_the_input_is_refused(folder, link):
    out = folder / "RR.jsonl"
    (out.symlink_to if link == "symbolic" else out.hardlink_to)(folder / "r.jsonl")
    before = snapshot(folder)
    code, text = invoke("certify-regions", folder / "r.jsonl", "-o", out, "-q")
    assert code == 2 and "is the input" in one_error_line(text)
    assert_kept(before, snapshot(folder))


def test_certify_regions_refuses_a_second_run(folder):
    out = folder / "RR.jsonl"
    with lock_output(out, "-o"):
        before = snapshot(folder)
        code, text = invoke("certify-regions", folder / "r.jsonl", "-o", out, "-q")
        assert code == 2 and "another run is writing" in one_error_line(text)
        assert_kept(before, snapshot(folder))


@pytest.mark.parametrize("budget", ["0", "-1"])
def test_certify_regions_refuses_a_budget_below_one(folder, budget):
    before = snapshot(folder)
    code, text = invoke("certify-regions", folder / "r.jsonl", "-o", folder / "RR.jsonl", "--budget", budget, "-q")
    assert code == 2 and "--budget" in one_error_line(text)
    assert_kept(before, snapshot(folder))


# -- sample, and the writers behind synthesize -o -----------------------------------------------

def test_sample_refuses_a_fifo_without_blocking(folder):
    fifo = folder / "s.jsonl"
    os.mkfifo(fifo)
    before = snapshot(folder)
    code, out = cli("sample", fifo, "--n", "5")
    assert code == 2 and "FIFO" in one_error_line(out)
    assert_kept(before, snapshot(folder))


def test_sample_refuses_a_second_run(folder):
    out = folder / "s.parquet"
    with lock_output(out, "OUT"):
        code, text = invoke("sample", out, "--n", "5")
    assert code == 2 and "another run is writing" in one_error_line(text)
    assert not out.exists()


def test_write_grasps_refuses_a_fifo_and_an_input(folder):
    """``synthesize -o`` writes with write_grasps: a FIFO is refused at once, never opened."""
    fifo = folder / "out.jsonl"
    os.mkfifo(fifo)
    code = textwrap.dedent(f"""
        from qualgrasp.certify.errors import OptionError
        from qualgrasp.certify.files.writers import write_grasps
        from qualgrasp.certify.batch.samples import textbook_grasps
        try:
            write_grasps({str(fifo)!r}, textbook_grasps())
        except OptionError as err:
            print(err)
        """)
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, timeout=LIMIT)
    assert "FIFO" in proc.stdout.decode(), proc.stderr.decode()
    with pytest.raises(OptionError, match="is the input"):
        write_grasps(folder / "g.jsonl", textbook_grasps(), reads=[folder / "g.jsonl"])


# -- the mechanism other commands call (independent-regions, synthesize --plot, figures --out) ----

def test_atomic_output_refuses_an_input_image_through_any_link(folder):
    from qualgrasp.certify.files import atomic_output

    image = folder / "obj.png"
    image.write_bytes(b"\x89PNG not really")
    (folder / "hard.png").hardlink_to(image)
    (folder / "soft.png").symlink_to(image)
    before = snapshot(folder)
    for out in (image, folder / "hard.png", folder / "soft.png"):
        with pytest.raises(OptionError, match="is the input"):
            with atomic_output(out, "-o", reads=[image, folder / "g.jsonl"]):
                pytest.fail("the block must not run")
    assert_kept(before, snapshot(folder))


def test_a_failed_write_keeps_the_old_output_whole(folder):
    from qualgrasp.certify.files import write_lines

    out = folder / "o.jsonl"
    write_lines(out, [{"id": 1}, {"id": 2}])

    def rows():
        yield {"id": 3}
        raise RuntimeError("the computation failed")

    before = snapshot(folder)
    with pytest.raises(RuntimeError):
        write_lines(out, rows())
    assert_kept(before, snapshot(folder))
    assert ids(out) == [1, 2]


def test_output_folder_refuses_an_input_folder_and_output_file_a_fifo(folder):
    from qualgrasp.certify.cli.options import input_file

    with pytest.raises(OptionError, match="input"):
        output_folder(folder, "--out", reads=[folder / "g.jsonl"])
    os.mkfifo(folder / "fig.png")
    with pytest.raises(OptionError, match="FIFO"):
        output_file(folder / "fig.png", "--plot", suffixes=(".png",))
    with pytest.raises(OptionError, match="not a regular file"):
        input_file(folder / "fig.png", "TRACE")


def test_verify_writes_nothing(folder):
    out = folder / "R.jsonl"
    assert invoke(*CERTIFY, folder / "g.jsonl", "-o", out)[0] == 0
    before = snapshot(folder)
    code, text = invoke("verify", out, "--grasps", folder / "g.jsonl", "--workers", "1")
    assert code == 0, text
    assert_kept(before, snapshot(folder))


def test_a_write_error_is_one_line_and_an_oserror_keeping_the_old_output(folder):
    """Callers that catch OSError (synthesize -o, --plot) and callers that catch CertifyError
    both see a failed write; the old output stays whole and no temporary is left."""
    import errno

    from qualgrasp.certify.errors import CertifyError
    from qualgrasp.certify.files import write_lines

    out = folder / "o.jsonl"
    write_lines(out, [{"id": 1}])

    def rows():
        yield {"id": 2}
        raise OSError(errno.ENOSPC, "No space left on device")

    before = snapshot(folder)
    with pytest.raises(OSError) as caught:
        write_lines(out, rows())
    assert isinstance(caught.value, CertifyError) and caught.value.errno == errno.ENOSPC
    assert str(caught.value) == f"-o: cannot write {out}: the disk is full"
    assert caught.value.strerror == "the disk is full"
    assert_kept(before, snapshot(folder))

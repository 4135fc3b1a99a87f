"""The installation: compiled kernels are cached in the user's cache directory, never inside the
package (files there would outlive ``pip uninstall``), and the version has one source."""

import os
import subprocess
import sys
import tomllib
from importlib.metadata import version
from pathlib import Path

from typer.testing import CliRunner

import qualgrasp
from qualgrasp.cli import app

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = Path(qualgrasp.__file__).resolve().parent

# A kernel compiled in a fresh interpreter (numba writes the cache when it compiles), then
# numba's own setting printed: qualgrasp must leave it as the user had it.
_COMPILE = """
import numba
from qualgrasp.certify._kernels.linalg import cross_unit
import numpy as np
cross_unit(np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]))
print(repr(numba.config.CACHE_DIR))
"""


def _compile(tmp_path, **env):
    """Compile a kernel in a fresh interpreter with ``env`` (HOME and XDG_CACHE_HOME in
    ``tmp_path`` unless given, NUMBA_CACHE_DIR unset unless given); its stdout and the cache
    files written inside the package meanwhile."""
    base = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CACHE_DIR", "XDG_CACHE_HOME")}
    base["HOME"] = str(tmp_path / "home")
    base.update(env)
    before = set((PACKAGE / "certify").rglob("*.nb[ic]"))
    out = subprocess.run([sys.executable, "-c", _COMPILE], env=base, capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-3000:]
    return out.stdout.strip(), set((PACKAGE / "certify").rglob("*.nb[ic]")) - before


def test_kernels_are_cached_in_xdg_cache_home(tmp_path):
    printed, in_package = _compile(tmp_path, XDG_CACHE_HOME=str(tmp_path / "xdg"))
    assert list((tmp_path / "xdg" / "qualgrasp" / "numba").rglob("linalg.cross_unit-*.nbi"))
    assert not in_package
    assert printed == "''"  # numba's setting for the user's own code is left as it was


def test_kernels_are_cached_in_home_cache_without_xdg(tmp_path):
    _, in_package = _compile(tmp_path)
    assert list((tmp_path / "home" / ".cache" / "qualgrasp" / "numba").rglob("linalg.cross_unit-*.nbi"))
    assert not in_package


def test_numba_cache_dir_is_honoured(tmp_path):
    printed, in_package = _compile(tmp_path, NUMBA_CACHE_DIR=str(tmp_path / "mine"))
    assert list((tmp_path / "mine").rglob("linalg.cross_unit-*.nbi"))
    assert not list(tmp_path.joinpath("home").rglob("*.nbi")) and not in_package
    assert printed == repr(str(tmp_path / "mine"))


def test_no_writable_cache_dir_means_no_cache_and_kernels_still_run(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    printed, in_package = _compile(tmp_path, XDG_CACHE_HOME=str(blocker))  # XDG_CACHE_HOME/qualgrasp: not creatable
    assert not in_package and not list(tmp_path.rglob("*.nbi"))


def test_version_has_one_source():
    expected = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"]
    assert qualgrasp.__version__ == version("qualgrasp") == expected


def test_version_option():
    result = CliRunner().invoke(app, ["--version"])
    assert result.exit_code == 0 and result.output == f"qualgrasp {qualgrasp.__version__}\n"


def test_the_cache_folder_changes_with_any_kernel_source(tmp_path):
    # numba checks only a cached kernel's own file: a callee changed in another module (a new
    # release, an edit) must not be loaded from a cache compiled with the old callee
    from qualgrasp.certify._kernels.jit import KERNEL_SOURCES, source_fingerprint

    names = {p.name for p in KERNEL_SOURCES}
    assert {"cones.py", "planar.py", "linalg.py", "order.py"} <= names and KERNEL_SOURCES[-1].parent.name == "core"
    copies = []
    for path in KERNEL_SOURCES:
        copies.append(tmp_path / path.parent.name / path.name)
        copies[-1].parent.mkdir(exist_ok=True)
        copies[-1].write_bytes(path.read_bytes())
    before = source_fingerprint(tuple(copies))
    assert before == source_fingerprint(KERNEL_SOURCES)
    callee = next(c for c in copies if c.name == "cones.py" and c.parent.name == "_kernels")
    callee.write_text(callee.read_text() + "\n# an edit\n")
    assert source_fingerprint(tuple(copies)) != before


def test_await_compiled_waits_for_the_process_compiling_the_set(tmp_path, monkeypatch):
    """While a kernel set's lock is held (here by another open file of this process, as by the
    process compiling it), await_compiled does not return; when nobody holds it, at once."""
    import fcntl
    import threading

    from qualgrasp.certify._kernels.jit import await_compiled, cache_dir

    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    await_compiled("demo")  # no lock file: nobody compiles it
    fd = os.open(Path(cache_dir()) / "demo.lock", os.O_RDWR | os.O_CREAT)
    fcntl.flock(fd, fcntl.LOCK_EX)
    released = threading.Event()

    def release():
        released.set()
        os.close(fd)

    threading.Timer(0.2, release).start()
    await_compiled("demo")
    assert released.is_set()
    await_compiled("demo")  # released: at once


def test_a_cold_cache_gets_a_kernel_set_compiled_by_another_process_once(tmp_path, monkeypatch):
    from qualgrasp.certify._kernels import sets
    from qualgrasp.certify._kernels.jit import await_compiled, cache_dir, compile_elsewhere

    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))  # the smallest set: the mechanism is the same
    folder = Path(cache_dir())
    assert compile_elsewhere(sets.__name__, "quality-hulls")  # as warmup.compile_ahead starts it
    await_compiled("quality-hulls")
    assert (folder / "quality-hulls.compiled").exists()
    for fn, _ in sets.KERNEL_SETS["quality-hulls"]:  # each kernel's cache index, written there
        assert any(folder.rglob(f"*.{fn.__name__}-*.nbi")), fn.__name__
    assert not compile_elsewhere(sets.__name__, "quality-hulls")  # marked: not again


def test_a_lock_file_that_cannot_be_opened_leaves_the_compiling_to_the_run(tmp_path, monkeypatch):
    from qualgrasp.certify._kernels.jit import await_compiled, cache_dir, compile_elsewhere

    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    (Path(cache_dir()) / "quality-hulls.lock").mkdir()  # not a file: os.open fails
    assert not compile_elsewhere("qualgrasp.certify._kernels.sets", "quality-hulls")
    await_compiled("quality-hulls", timeout=0.5)  # nobody holds a lock: at once, no error


def test_a_file_system_without_locks_makes_nobody_wait(tmp_path, monkeypatch):
    import errno
    import time

    from qualgrasp.certify._kernels import jit

    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    (Path(jit.cache_dir()) / "quality-hulls.lock").touch()

    def no_locks(fd, operation):
        raise OSError(errno.ENOLCK, "No locks available")

    def waited(seconds):
        raise AssertionError("waited for a lock nobody can hold")

    monkeypatch.setattr(jit.fcntl, "flock", no_locks)
    monkeypatch.setattr(time, "sleep", waited)
    assert not jit.compile_elsewhere("qualgrasp.certify._kernels.sets", "quality-hulls")
    jit.await_compiled("quality-hulls")  # returns at once: the run compiles the set itself


# Compile (or load) one kernel, then print how many kernels numba compiled and where the package is.
_COUNT = """
from numba.core import event
import numpy as np
import qualgrasp
from qualgrasp.certify._kernels.linalg import cross_unit
with event.install_recorder("numba:compile") as rec:
    cross_unit(np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]))
print(len(rec.buffer) // 2, qualgrasp.__file__)  # a start and an end event per compiled function
"""


def test_a_copy_of_the_package_elsewhere_loads_the_kernels_it_compiled(tmp_path):
    """The installed package and an editable checkout (or two virtual environments) hold the same
    kernel sources at other paths: the second one loads what the first compiled."""
    import shutil

    copy = tmp_path / "site" / "qualgrasp"
    copy.mkdir(parents=True)
    shutil.copy(PACKAGE / "__init__.py", copy)
    shutil.copytree(PACKAGE / "certify", copy / "certify", ignore=shutil.ignore_patterns("__pycache__"))
    env = {k: v for k, v in os.environ.items() if k != "XDG_CACHE_HOME"}
    env["NUMBA_CACHE_DIR"] = str(tmp_path / "cache")
    runs = []
    for path in ("", str(tmp_path / "site"), ""):
        out = subprocess.run([sys.executable, "-c", _COUNT], env=dict(env, PYTHONPATH=path), capture_output=True,
                             text=True, timeout=600, cwd=tmp_path)
        assert out.returncode == 0, out.stderr[-3000:]
        runs.append(out.stdout.split())
    assert Path(runs[1][1]).parent == copy and Path(runs[0][1]).parent == PACKAGE  # two copies of the package
    compiled = [int(n) for n, _ in runs]
    assert compiled[0] > 0 and compiled[1:] == [0, 0]

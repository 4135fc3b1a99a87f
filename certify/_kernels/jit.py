"""How the kernels are compiled: :func:`kernel`, numba's ``njit`` with its on-disk cache in the
user's cache directory (:func:`cache_dir`), never inside the installed package; and
:func:`precompile`, which compiles kernels for given argument types ahead of a computation whose
time is measured.

numba caches a compiled function beside its source file (in ``__pycache__``) whenever that folder
is writable. For an installed package that folder is in site-packages, where the cache files are
in no installation record: ``pip uninstall`` leaves them, and the folder ``qualgrasp/`` they keep
is then a namespace package that shadows a later editable install of the project.

numba picks a function's cache folder once, when the function is decorated, from
``numba.config.CACHE_DIR``; :func:`kernel` sets that value for the decoration only and restores
it, so numba behaves as before for the user's other code. numba's own locator puts each source
folder's cache in a subfolder named by that folder's path, so a copy of the same kernels elsewhere
(the installed package and an editable checkout, two virtual environments) would compile them
again. :func:`kernel` therefore also names its own locator class for the decoration
(``numba.config.CACHE_LOCATOR_CLASSES``, :class:`KernelLocator`), which keeps the kernels in the
cache folder by package name, stamped by their source file's contents.

numba's cache checks only the source file of the function it caches, not those of the functions
it calls, which are compiled into it: a kernel cached before a change to a kernel it calls (in
another module, or in a new release) would be loaded with the old callee. The cache folder is
therefore named by :func:`source_fingerprint`, a digest of every kernel module and of the
constants they import, so that a changed kernel source starts a fresh cache.

A *kernel set* (a module's ``KERNEL_SETS[name]``, pairs for :func:`precompile`) can be compiled
into the cache by another process while this one works on something else: on a cold cache the
first ``qualgrasp certify`` with quality compiles closure's kernels and quality's two sets in
processes of their own, on the other cores (:func:`compile_elsewhere`, :func:`await_compiled`,
:mod:`qualgrasp.certify.warmup`). The cache folder then holds ``NAME.compiled`` once the set is in
it, and ``NAME.lock``, locked (``flock``) by the process compiling it. Where ``fcntl`` is missing
(Windows), or the cache's file system has no locks or a lock file cannot be opened, every process
compiles what it needs.
"""

from __future__ import annotations

import errno
import functools
import hashlib
import importlib
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Callable, Iterable, Sequence

import numpy as np
from numba import config, njit, types
from numba.core.caching import UserProvidedCacheLocator

try:
    import fcntl
except ImportError:  # Windows: no flock, no compiling elsewhere
    fcntl = None

__all__ = ["cache_dir", "source_fingerprint", "KERNEL_SOURCES", "kernel", "kernel_array", "precompile", "compiled_here",
           "compile_elsewhere", "await_compiled", "compile_set", "mark_compiled", "WAIT_SECONDS",
           "F1", "F2", "F3", "I1", "I2", "B1", "INT", "FLOAT", "BOOL"]

#: Argument types as the callers pass them: C-contiguous float64 arrays of 1 to 3 dimensions,
#: int64 arrays of 1 and 2 and boolean arrays of 1, and Python's int, float and bool.
F1, F2, F3 = types.float64[::1], types.float64[:, ::1], types.float64[:, :, ::1]
I1, I2 = types.int64[::1], types.int64[:, ::1]
B1 = types.boolean[::1]
INT, FLOAT, BOOL = types.int64, types.float64, types.boolean


def kernel_array(a, dtype=np.float64) -> np.ndarray:
    """``a`` as the kernels take an array: C-contiguous, of ``dtype``, and writable. numba compiles
    a kernel anew for each array layout and for read-only arrays (Arrow's, ``numpy.broadcast_to``'s),
    so a caller passing them would compile a large kernel a second time for the same work.

    Examples
    --------
    >>> a = np.broadcast_to(np.ones(3), (2, 3))
    >>> b = kernel_array(a)
    >>> b.flags.writeable and b.flags.c_contiguous and not np.shares_memory(a, b)
    True
    >>> c = np.zeros(4)
    >>> kernel_array(c) is c
    True
    """
    a = np.ascontiguousarray(a, dtype=dtype)
    return a if a.flags.writeable else a.copy()


def _writable(path: str) -> bool:
    try:
        os.makedirs(path, exist_ok=True)
        tempfile.TemporaryFile(dir=path).close()
    except (OSError, ValueError):  # ValueError: a path numba could not use either (NUL byte)
        return False
    return True


_HERE = Path(__file__).resolve().parent
#: The files whose text the compiled kernels depend on: the kernel modules, and the cone codes
#: they take from :mod:`qualgrasp.certify.core.cones`.
KERNEL_SOURCES = tuple(sorted(_HERE.glob("*.py"))) + (_HERE.parent / "core" / "cones.py",)


def source_fingerprint(paths: Sequence[Path] = KERNEL_SOURCES) -> str:
    """The first 16 hexadecimal digits of the SHA-256 of ``paths``' names and contents, in order.

    Examples
    --------
    >>> len(source_fingerprint())
    16
    """
    digest = hashlib.sha256()
    for path in paths:
        digest.update(Path(path).name.encode() + b"\0" + Path(path).read_bytes() + b"\0")
    return digest.hexdigest()[:16]


@functools.lru_cache(maxsize=None)
def _installed_fingerprint() -> str:  # read once per process: every kernel's decoration asks
    return source_fingerprint()


def cache_dir(environ=os.environ) -> str | None:
    """The folder holding the compiled kernels' cache.

    The folder :func:`source_fingerprint` names (module docstring) under ``NUMBA_CACHE_DIR`` when
    set (numba's own setting, honoured as numba does), else under ``$XDG_CACHE_HOME/qualgrasp/numba``
    (an absolute ``XDG_CACHE_HOME`` only, as the XDG base directory specification says), else under
    ``~/.cache/qualgrasp/numba``; None when that folder cannot be created or written (the kernels
    are then compiled in every process).

    Parameters
    ----------
    environ : mapping
        The environment variables to read.

    Returns
    -------
    str or None

    Examples
    --------
    >>> cache_dir({"NUMBA_CACHE_DIR": "/dev/null/cache"}) is None   # not a folder: no cache
    True
    """
    path = environ.get("NUMBA_CACHE_DIR", "")
    if not path:
        base = environ.get("XDG_CACHE_HOME", "")
        if not os.path.isabs(base):
            base = os.path.join(os.path.expanduser("~"), ".cache")
        path = os.path.join(base, "qualgrasp", "numba")
    path = os.path.join(path, _installed_fingerprint())
    return path if _writable(path) else None


class KernelLocator(UserProvidedCacheLocator):
    """numba's cache locator for the kernels: a subfolder of ``numba.config.CACHE_DIR`` (one per
    :func:`source_fingerprint`) named by the kernel's package (``qualgrasp.certify._kernels``),
    whatever the path of the source files, and the SHA-256 of the source file as its stamp (numba
    before 0.68 stamps its modification time and size)."""

    def __init__(self, py_func, py_file):
        super().__init__(py_func, py_file)
        self._cache_path = os.path.join(config.CACHE_DIR, py_func.__module__.rpartition(".")[0])

    def get_source_stamp(self):
        return source_fingerprint((self._py_file,))


_LOCATOR = f"{__name__}.KernelLocator"


def kernel(fn: Callable | None = None, *, inline: bool = False) -> Callable:
    """``numba.njit`` with the on-disk cache in :func:`cache_dir` (module docstring); without
    a writable cache folder, ``njit`` without a cache. No kernel is passed as a first-class
    function, so none gets the C function wrapper numba otherwise builds for each (about 5 % of
    a cold compile).

    ``@kernel(inline=True)``: a small kernel called per item inside other kernels' loops, which
    numba then compiles into each caller (``inline="always"``) instead of calling it through its
    calling convention: the same operations, without a call's status checks between them (a
    third less time for the face checks of :func:`~.surface.face_bounds`)."""
    if fn is None:
        return functools.partial(kernel, inline=inline)
    options = {"no_cfunc_wrapper": True, **({"inline": "always"} if inline else {})}
    path = cache_dir()
    if path is None:
        return njit(**options)(fn)
    saved = config.CACHE_DIR, config.CACHE_LOCATOR_CLASSES
    config.CACHE_DIR, config.CACHE_LOCATOR_CLASSES = path, _LOCATOR
    try:
        return njit(cache=True, **options)(fn)
    finally:
        config.CACHE_DIR, config.CACHE_LOCATOR_CLASSES = saved


def precompile(signatures: Iterable[tuple[Callable, tuple]]) -> None:
    """Compile, or load from the on-disk cache, each kernel of ``signatures`` (pairs of a kernel
    and a tuple of argument types) for those types, unless this process has done so already (a
    dictionary look-up per kernel then). Nothing to do when numba's JIT is disabled.

    Examples
    --------
    >>> from qualgrasp.certify._kernels.linalg import gamma
    >>> precompile([(gamma, (INT,))])
    >>> (INT,) in gamma.overloads
    True
    """
    for fn, args in signatures:
        if not _has(fn, args):
            fn.compile(args)


def _has(fn: Callable, args: tuple) -> bool:
    """Whether ``fn`` is compiled (or loaded) in this process for ``args``; True without JIT."""
    overloads = getattr(fn, "overloads", None)
    return overloads is None or args in overloads


def compiled_here(signatures: Iterable[tuple[Callable, tuple]]) -> bool:
    """Whether this process has compiled (or loaded) every kernel of ``signatures`` for its
    types, or runs without numba's JIT: then :func:`precompile` has nothing to do."""
    return all(_has(fn, args) for fn, args in signatures)


#: Longest wait (s) for another process compiling a kernel set (:func:`await_compiled`): past it
#: the waiting process compiles the set itself.
WAIT_SECONDS = 300.0
#: The ``flock`` errors meaning that another process holds the lock (any other: a file system
#: without locks, where nobody waits).
_BUSY = (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES)


def _set_files(name: str) -> tuple[str, str] | None:
    """``NAME.lock`` and ``NAME.compiled`` in the cache folder; None without a cache, ``fcntl``
    or numba's JIT."""
    path = cache_dir() if fcntl is not None and not config.DISABLE_JIT else None
    return None if path is None else (os.path.join(path, name + ".lock"), os.path.join(path, name + ".compiled"))


def compile_elsewhere(module: str, name: str) -> bool:
    """Start a process compiling the kernel set ``KERNEL_SETS[name]`` of ``module`` into the
    on-disk cache (:func:`compile_set`), unless the cache holds it (``NAME.compiled``), another
    process is compiling it, or there is no cache or no ``fcntl``. Returns whether it started.

    The new process inherits the lock on ``NAME.lock`` taken here, so :func:`await_compiled`
    waits for it from the moment this returns; the lock ends with that process, however it ends.
    """
    files = _set_files(name)
    if files is None or os.path.exists(files[1]):
        return False
    try:  # a lock file this user cannot open (another user's, a folder): compile where needed
        fd = os.open(files[0], os.O_RDWR | os.O_CREAT, 0o644)
    except OSError:
        return False
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:  # another process compiles it, or the file system has no locks
        os.close(fd)
        return False
    code = f"from qualgrasp.certify._kernels.jit import compile_set; compile_set({module!r}, {name!r})"
    try:
        subprocess.Popen([sys.executable, "-c", code], pass_fds=(fd,), stdin=subprocess.DEVNULL,
                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    except OSError:
        return False
    finally:
        os.close(fd)  # the lock stays with the new process
    return True


def await_compiled(name: str, timeout: float = WAIT_SECONDS) -> None:
    """Wait while another process compiles the kernel set ``name`` (holds ``NAME.lock``), at
    most ``timeout`` seconds; at once when none does."""
    files = _set_files(name)
    if files is None:
        return
    try:
        fd = os.open(files[0], os.O_RDONLY)
    except OSError:  # no lock file: nobody compiles it
        return
    try:
        end = time.monotonic() + timeout
        while True:
            try:
                fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
                return
            except OSError as err:
                if err.errno not in _BUSY or time.monotonic() > end:  # not held (no locks here), or too long
                    return
                time.sleep(0.02)
    finally:
        os.close(fd)


def mark_compiled(name: str) -> None:
    """Record that the cache holds the kernel set ``name`` (``NAME.compiled``), so that no
    process compiles it elsewhere again."""
    files = _set_files(name)
    if files is not None and not os.path.exists(files[1]):
        try:
            Path(files[1]).touch()
        except OSError:  # a cache that cannot take it: the set is compiled where needed
            pass


def compile_set(module: str, name: str) -> None:
    """Compile (or load) the kernel set ``KERNEL_SETS[name]`` of ``module`` and mark it
    compiled: what the process :func:`compile_elsewhere` starts runs."""
    precompile(importlib.import_module(module).KERNEL_SETS[name])
    mark_compiled(name)

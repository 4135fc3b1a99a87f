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
it, so numba behaves as before for the user's other code.

numba's cache checks only the source file of the function it caches, not those of the functions
it calls, which are compiled into it: a kernel cached before a change to a kernel it calls (in
another module, or in a new release) would be loaded with the old callee. The cache folder is
therefore named by :func:`source_fingerprint`, a digest of every kernel module and of the
constants they import, so that a changed kernel source starts a fresh cache.
"""

from __future__ import annotations

import functools
import hashlib
import os
import tempfile
from pathlib import Path
from typing import Callable, Iterable, Sequence

from numba import config, njit, types

__all__ = ["cache_dir", "source_fingerprint", "KERNEL_SOURCES", "kernel",
           "precompile", "F1", "F2", "F3", "I1", "I2", "INT", "FLOAT", "BOOL"]

#: Argument types as the callers pass them: C-contiguous float64 arrays of 1 to 3 dimensions and
#: int64 arrays of 1 and 2, and Python's int, float and bool.
F1, F2, F3 = types.float64[::1], types.float64[:, ::1], types.float64[:, :, ::1]
I1, I2 = types.int64[::1], types.int64[:, ::1]
INT, FLOAT, BOOL = types.int64, types.float64, types.boolean


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


def kernel(fn: Callable) -> Callable:
    """``numba.njit`` with the on-disk cache in :func:`cache_dir` (module docstring); without
    a writable cache folder, ``njit`` without a cache."""
    path = cache_dir()
    if path is None:
        return njit(fn)
    saved = config.CACHE_DIR
    config.CACHE_DIR = path
    try:
        return njit(cache=True)(fn)
    finally:
        config.CACHE_DIR = saved


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
        overloads = getattr(fn, "overloads", None)
        if overloads is not None and args not in overloads:
            fn.compile(args)

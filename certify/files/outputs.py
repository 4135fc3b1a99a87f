"""Writing outputs without losing anything: what a command may write, and how.

Every command that writes goes through these rules (:func:`check_output`, :func:`lock_output`,
:func:`atomic_output`, :func:`write_lines`):

* The output is never an input of the run, nor a companion of it (the checkpoint folder), compared
  by inode, so through symbolic and hard links.
* An existing output must be a regular file (a FIFO, a device, a socket or a folder is refused,
  never opened: writing into a FIFO blocks, ``/dev/null`` would be replaced).
* The output is written under a fresh temporary name in its folder (created exclusively, so it
  can be no existing file) and renamed over the output only when complete; a failed write
  removes the temporary and leaves the old output as it was.
* One run at a time writes an output: a second one is refused with a message (a lock file
  ``.qualgrasp-<hash>.lock`` next to the output, held with ``flock`` and removed by its owner).
* Names are checked against the folder's limit before any work, companions included.
* Write errors (full disk, read-only folder, file-size limit) become one-line messages.

Errors are :class:`qualgrasp.certify.errors.OptionError` with a message naming the flag.
"""

from __future__ import annotations

import errno
import fcntl
import hashlib
import json
import os
import secrets
import stat
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Iterable, Iterator

from ..errors import OptionError, WriteError

__all__ = ["same_file", "inside", "check_output", "check_name_length", "OutputLock", "lock_output",
           "temporary_name", "atomic_output", "write_lines", "write_error", "file_kind", "writable_folder"]

#: Start of the lock files' names (the rest is a hash of the output's name, so never too long).
LOCK_PREFIX = ".qualgrasp-"
_LOCK_MARK = b"qualgrasp lock\n"


def same_file(a: str | Path, b: str | Path) -> bool:
    """True when ``a`` and ``b`` both exist and are the same file (same device and inode, after
    following symbolic links: hard links and symbolic links to one file are the same file).

    Examples
    --------
    >>> import os, pathlib, tempfile
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (d / "a").write_text("x"); os.link(d / "a", d / "b")
    >>> same_file(d / "a", d / "b"), same_file(d / "a", d / "missing")
    (True, False)
    """
    try:
        return os.path.samefile(a, b)
    except (OSError, ValueError):
        return False


def inside(path: str | Path, folder: str | Path) -> bool:
    """True when ``path`` lies in ``folder`` or below it (by inode, each parent of ``path`` in
    turn), or is it."""
    try:
        target = os.stat(folder)
    except (OSError, ValueError):
        return False
    p = Path(os.path.abspath(path))
    for candidate in (p, *p.parents):
        try:
            st = os.stat(candidate)
        except OSError:
            continue
        if (st.st_dev, st.st_ino) == (target.st_dev, target.st_ino):
            return True
    return False


def file_kind(mode: int) -> str:
    """What a file of ``st_mode`` ``mode`` is, in words (``"a FIFO"``, ``"a device"``, ...)."""
    if stat.S_ISDIR(mode):
        return "a folder"
    if stat.S_ISFIFO(mode):
        return "a FIFO (named pipe)"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device"
    if stat.S_ISSOCK(mode):
        return "a socket"
    return "not a regular file"


def _folder(path: Path) -> Path:
    return path.parent if str(path.parent) else Path(".")


def check_name_length(path: str | Path, flag: str, *, companions: Iterable[str | Path] = ()) -> None:
    """Refuse an output whose name, or a companion's (a checkpoint folder, say), is longer than its
    folder allows.

    Raises
    ------
    OptionError
        Naming the flag, the name's length and the limit.
    """
    out = Path(path)
    for p in (out, *map(Path, companions)):
        folder = _folder(p)
        try:
            limit = os.pathconf(folder if folder.exists() else ".", "PC_NAME_MAX")
        except (OSError, ValueError):
            limit = 255
        size = len(os.fsencode(p.name))
        if size > limit:
            tail = p.name[len(out.name):] if p != out and p.name.startswith(out.name) else ""
            what = f"its companion NAME{tail} would have" if p != out else "it has"
            raise OptionError(f"{flag}: the output's name is too long: {what} {size} bytes, at most "
                              f"{limit} in {folder}; choose a shorter name")


def writable_folder(folder: str | Path, flag: str) -> None:
    """Create ``folder`` if needed and check that files can be made in it (else :class:`OptionError`)."""
    folder = Path(folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except FileExistsError:
        raise OptionError(f"{flag}: {folder} exists and is not a folder") from None
    except OSError as err:
        raise OptionError(f"{flag}: cannot create the folder {folder} ({err.strerror or err})") from None
    if not os.access(folder, os.W_OK | os.X_OK):
        raise OptionError(f"{flag}: cannot write into {folder}"
                          + (" (read-only file system)" if _read_only(folder) else ""))


def _read_only(folder: Path) -> bool:
    try:
        return bool(os.statvfs(folder).f_flag & os.ST_RDONLY)
    except (OSError, AttributeError):
        return False


def check_output(path: str | Path, flag: str, *, reads: Iterable[str | Path] = (),
                 companions: Iterable[str | Path] = ()) -> Path:
    """Check an output file before any work, and create its folder; return it as a Path.

    Refused: a folder; an existing file that is not a regular file (FIFO, device, socket; symbolic
    links followed); an input of the run (``reads``, by inode); a companion (``companions``, such
    as a checkpoint folder) that is an input or holds one; a name longer than the folder allows;
    a folder that cannot be created or written.

    Raises
    ------
    OptionError
        With a one-line message naming ``flag``.

    Examples
    --------
    >>> import os, pathlib, tempfile
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> os.mkfifo(d / "pipe")
    >>> check_output(d / "pipe", "-o")
    Traceback (most recent call last):
    ...
    qualgrasp.certify.errors.OptionError: -o: ... is a FIFO (named pipe), not a regular file: give a file name
    """
    path = Path(path)
    reads = [Path(r) for r in reads]
    try:
        st = os.stat(path)
    except FileNotFoundError:
        st = None
    except OSError as err:
        if err.errno == errno.ENAMETOOLONG:
            check_name_length(path, flag)
        raise OptionError(f"{flag}: cannot use {path} ({err.strerror or err})") from None
    if st is not None and stat.S_ISDIR(st.st_mode):
        raise OptionError(f"{flag}: {path} is a folder; give a file name")
    if st is not None and not stat.S_ISREG(st.st_mode):
        raise OptionError(f"{flag}: {path} is {file_kind(st.st_mode)}, not a regular file: give a file name")
    for other in reads:
        if same_file(path, other):
            raise OptionError(f"{flag}: {path} is the input {other}; the input is never overwritten: "
                              "choose another name")
    for companion in map(Path, companions):
        for other in reads:
            if same_file(companion, other) or inside(other, companion):
                raise OptionError(f"{flag}: the output's companion {companion} is (or holds) an input of "
                                  f"this run ({other}): choose another output name")
    check_name_length(path, flag, companions=companions)
    writable_folder(_folder(path), flag)
    return path


class OutputLock:
    """An exclusive lock on an output, held by this process until :meth:`release`.

    The lock is a small file next to the output (``.qualgrasp-<hash>.lock``, a fixed-length name)
    locked with ``flock``; a second run asking for the same output is refused at once. The file
    is created by the first run and removed by the run holding the lock; a file of that name that
    qualgrasp did not write is never used nor removed.
    """

    def __init__(self, path: Path, lock: Path, fd: int) -> None:
        self.path, self.lock, self.fd = path, lock, fd

    def release(self) -> None:
        """Remove the lock file and release the lock (safe to call twice)."""
        if self.fd < 0:
            return
        try:
            self.lock.unlink()
        except OSError:  # a read-only folder, say: the file stays, the lock goes with the descriptor
            pass
        os.close(self.fd)
        self.fd = -1

    def __enter__(self) -> "OutputLock":
        return self

    def __exit__(self, *exc) -> None:
        self.release()


def _lock_path(path: Path) -> Path:
    digest = hashlib.blake2b(os.fsencode(path.name), digest_size=10).hexdigest()
    return _folder(path) / f"{LOCK_PREFIX}{digest}.lock"


def lock_output(path: str | Path, flag: str) -> OutputLock:
    """Lock ``path`` for writing (its folder must exist): an :class:`OutputLock`, or an error.

    Raises
    ------
    OptionError
        Another run holds the lock, or the lock file cannot be made.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> out = pathlib.Path(tempfile.mkdtemp()) / "r.jsonl"
    >>> with lock_output(out, "-o"):
    ...     lock_output(out, "-o")
    Traceback (most recent call last):
    ...
    qualgrasp.certify.errors.OptionError: -o: another run is writing ...r.jsonl (its lock ... is held); wait for it to end
    """
    path = Path(path)
    lock = _lock_path(path)
    for _ in range(100):  # the lock file may be removed by its owner between open and flock
        created = False
        try:
            fd = os.open(lock, os.O_RDWR | os.O_CREAT | os.O_EXCL, 0o644)
            created = True
        except FileExistsError:
            try:
                fd = os.open(lock, os.O_RDWR | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0))
            except FileNotFoundError:
                continue
            except OSError as err:
                raise OptionError(f"{flag}: cannot use the lock file {lock} ({err.strerror or err})") from None
        except OSError as err:
            raise OptionError(f"{flag}: cannot create the lock file {lock} in {_folder(path)} "
                              f"({err.strerror or err})") from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            os.close(fd)
            raise OptionError(f"{flag}: another run is writing {path} (its lock {lock} is held); wait for "
                              "it to end") from None
        try:
            same = os.fstat(fd).st_ino == os.stat(lock).st_ino
        except FileNotFoundError:
            same = False
        if not same:  # unlinked by its previous owner after we opened it: try again
            os.close(fd)
            continue
        if not created:
            head = os.pread(fd, len(_LOCK_MARK), 0) if stat.S_ISREG(os.fstat(fd).st_mode) else b"?"
            if head != _LOCK_MARK and head:
                os.close(fd)
                raise OptionError(f"{flag}: {lock} exists and was not written by qualgrasp; move it away")
        try:  # who holds the lock, for a person looking; a full disk leaves it empty, still a lock
            os.ftruncate(fd, 0)
            os.pwrite(fd, _LOCK_MARK + f"pid {os.getpid()}\noutput {os.path.abspath(path)}\n".encode(
                errors="replace"), 0)
        except OSError:
            pass
        return OutputLock(path, lock, fd)
    raise OptionError(f"{flag}: cannot lock {path}: its lock file keeps changing")


def temporary_name(path: str | Path) -> Path:
    """A fresh name for the temporary of ``path``, in its folder, keeping its suffix (writers
    that choose a format by suffix still work); short, whatever the length of ``path``'s name."""
    path = Path(path)
    suffix = path.suffix if len(path.suffix) <= 16 else ""
    return _folder(path) / f"{LOCK_PREFIX}{secrets.token_hex(6)}.tmp{suffix}"


def write_error(target: str | Path, err: OSError) -> str:
    """A one-line message for a failed write to ``target`` (full disk, read-only file system, file
    size limit, ...)."""
    hints = {errno.ENOSPC: "the disk is full", errno.EDQUOT: "the disk quota is exceeded",
             errno.EFBIG: "the file is larger than the file-size limit (ulimit -f)",
             errno.EROFS: "the file system is read-only", errno.ENAMETOOLONG: "the name is too long"}
    code = getattr(err, "errno", None)
    reason = hints.get(code) or getattr(err, "strerror", None) or (str(err).splitlines() or [type(err).__name__])[0]
    return f"cannot write {target}: {reason}"


@contextmanager
def atomic_output(path: str | Path, flag: str = "-o", *, reads: Iterable[str | Path] = ()) -> Iterator[Path]:
    """Write ``path`` safely: check it (:func:`check_output`), lock it (:func:`lock_output`) and
    give a fresh temporary path to write; renamed over ``path`` when the block ends normally,
    removed otherwise. An ``OSError`` in the block (full disk, file-size limit, ...) becomes a
    :class:`qualgrasp.certify.errors.WriteError` naming ``flag`` (an :class:`OptionError` and an
    ``OSError``).

    Examples
    --------
    >>> import pathlib, tempfile
    >>> out = pathlib.Path(tempfile.mkdtemp()) / "figure.png"
    >>> with atomic_output(out, "--plot") as tmp:
    ...     _ = tmp.write_bytes(b"...")
    >>> out.read_bytes(), sorted(p.name for p in out.parent.iterdir())
    (b'...', ['figure.png'])
    """
    path = check_output(path, flag, reads=reads)
    with lock_output(path, flag):
        tmp = temporary_name(path)
        try:
            try:
                os.close(os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644))
                yield tmp
                check_output(path, flag, reads=reads)  # nothing put in its place meanwhile
                os.replace(tmp, path)
            except OSError as err:
                reason = write_error(path, err)
                raise WriteError(f"{flag}: {reason}", getattr(err, "errno", None),
                                 reason.split(": ", 1)[-1]) from None
        finally:
            try:
                tmp.unlink()
            except OSError:
                pass


def write_lines(path: str | Path, rows: Iterable[Any], flag: str = "-o", *,
                reads: Iterable[str | Path] = ()) -> int:
    """Write ``rows`` (JSON values) as JSON Lines to ``path`` through :func:`atomic_output`;
    return how many were written.

    Raises
    ------
    OptionError
        The output is refused, locked by another run, or cannot be written.
    ValueError
        A row holds NaN or infinity (not JSON).

    Examples
    --------
    >>> import pathlib, tempfile
    >>> out = pathlib.Path(tempfile.mkdtemp()) / "rows.jsonl"
    >>> write_lines(out, [{"id": "a"}, {"id": "b"}])
    2
    >>> out.read_text()
    '{"id": "a"}\\n{"id": "b"}\\n'
    """
    count = 0
    with atomic_output(path, flag, reads=reads) as tmp:
        with tmp.open("w", encoding="utf-8") as fh:
            for row in rows:
                fh.write(json.dumps(row, allow_nan=False) + "\n")
                count += 1
    return count

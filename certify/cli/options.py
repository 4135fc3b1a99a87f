"""Checks every command makes before it works (output paths and numeric options), and how a
command refuses: one line, exit code 2.

Commands are thin layers over public functions; these checks run first, so that a bad path or
number is refused at once with a one-line message in the command line's own terms (the flag and
its unit), never after minutes of work and never as a traceback. Each raises
:class:`OptionError` (a ``ValueError``).

Rules
-----
* An output file is not a folder, not an existing FIFO, device or socket, not a file the run
  reads (by inode, through symbolic and hard links: the input is never overwritten), has a suffix
  the writer knows when the format comes from the suffix (a figure without ``.png`` is refused,
  not silently renamed), a name its folder allows, and lives in a folder that exists or can be
  created and can be written; the folder is created. How it is then written (a temporary name, a
  lock, a rename) is :mod:`qualgrasp.certify.files.outputs`.
* An output folder is a folder or does not exist yet (it is created); an existing file there is
  refused, and so is an input folder of the run.
* An input file is a regular file (a FIFO or ``/dev/zero`` is refused, never read), within its
  size limit.
* Numbers are finite and inside their documented range.

Every half's command line (:mod:`qualgrasp.certify.cli`, :mod:`qualgrasp.certify.meshes.cli`,
:mod:`qualgrasp.qualitative.cli`, :mod:`qualgrasp.experiments.cli`) uses these checks; a command
that refuses prints :func:`fail`'s one line.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path
from typing import Iterable, NoReturn

import typer
from rich.console import Console
from rich.markup import escape

from ..core import arguments
from ..errors import OptionError
from ..files.outputs import check_name_length, check_output, file_kind, inside, same_file, writable_folder

__all__ = ["OptionError", "FIGURE_SUFFIXES", "FOLDER_MARKER", "MAX_WORKERS", "output_file", "output_folder",
           "input_file", "number_in", "count_in", "optional_number_in", "printable", "fail"]

#: The most worker processes a command's ``--workers`` may ask for: a local pool starts them all
#: at once, so a mistyped count would fill the machine with processes before any work.
MAX_WORKERS = 256
#: Suffixes a figure may be saved with (matplotlib's writers).
FIGURE_SUFFIXES = (".png", ".pdf", ".svg", ".jpg", ".jpeg", ".tif", ".tiff", ".eps", ".ps", ".webp")


def output_file(path: str | Path, flag: str, *, suffixes: Iterable[str] | None = None,
                reads: Iterable[str | Path] = ()) -> Path:
    """Check (and prepare the folder of) an output file; return it as a :class:`~pathlib.Path`.

    The rules of :func:`qualgrasp.certify.files.outputs.check_output`: not a folder, not an existing
    FIFO, device or socket, not an input (by inode: symbolic and hard links are seen through), a
    name the folder allows, a folder that can be created and written. Write the file itself with
    :func:`qualgrasp.certify.files.outputs.atomic_output` (temporary name, lock, rename).

    Parameters
    ----------
    path : str or pathlib.Path
        The output.
    flag : str
        The option's name for messages (``--plot``).
    suffixes : iterable of str, optional
        Allowed suffixes (lower case, with the dot); None: any.
    reads : iterable of paths
        Files the run reads; the output may be none of them.

    Raises
    ------
    OptionError
        With a message naming ``flag``.

    Examples
    --------
    >>> from qualgrasp.certify.cli.options import output_file
    >>> output_file("figure", "--plot", suffixes=(".png", ".pdf"))
    Traceback (most recent call last):
    ...
    qualgrasp.certify.errors.OptionError: --plot: figure has no suffix: give one of .png, .pdf
    """
    path = Path(path)
    if path.is_dir():
        raise OptionError(f"{flag}: {path} is a folder; give a file name")
    if suffixes is not None:
        allowed = tuple(suffixes)
        if not path.suffix:
            raise OptionError(f"{flag}: {path} has no suffix: give one of {', '.join(allowed)}")
        if path.suffix.lower() not in allowed:
            raise OptionError(f"{flag}: cannot write {path.suffix} files; give one of {', '.join(allowed)}")
    return check_output(path, flag, reads=reads)


#: The file that marks a folder as written by qualgrasp (:func:`output_folder`): a later run may
#: replace the files in it.
FOLDER_MARKER = ".qualgrasp-output"


def output_folder(path: str | Path, flag: str, *, reads: Iterable[str | Path] = ()) -> Path:
    """Check (and create) an output folder, mark it as qualgrasp's (:data:`FOLDER_MARKER`);
    return it.

    Refused: an existing path that is not a folder (a file, a FIFO, a device; symbolic links
    followed), a folder that is one of ``reads`` (an input folder or file of the run), holds one
    of them, or cannot be created or written, and an existing folder holding anything without the
    marker (a run writes its files by name, and would replace a user's file of the same name).
    Write each file in it with :func:`qualgrasp.certify.files.outputs.atomic_output`.

    Raises
    ------
    OptionError
        Naming ``flag`` and the problem.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from qualgrasp.certify.cli.options import output_folder
    >>> out = output_folder(pathlib.Path(tempfile.mkdtemp()) / "figures", "--out")
    >>> out.is_dir()
    True
    """
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise OptionError(f"{flag}: {path} exists and is not a folder")
    for other in reads:
        if same_file(path, other) or inside(other, path):
            raise OptionError(f"{flag}: {path} is (or holds) an input of this run ({other}); give another folder")
    check_name_length(path, flag)
    if path.is_dir() and not (path / FOLDER_MARKER).exists() and any(path.iterdir()):
        raise OptionError(f"{flag}: {path} already holds files qualgrasp did not write (no {FOLDER_MARKER} "
                          "in it); give a new or empty folder")
    writable_folder(path, flag)
    try:
        (path / FOLDER_MARKER).touch()
    except OSError as err:
        raise OptionError(f"{flag}: cannot write into {path} ({err.strerror or err})") from None
    return path


def input_file(path: str | Path, flag: str, *, max_bytes: int | None = None) -> Path:
    """Check an input file before reading it: it exists, is a regular file (a FIFO or a device
    such as ``/dev/zero`` would block or never end), can be opened, and holds at most
    ``max_bytes`` bytes when given; return it.

    Raises
    ------
    OptionError
        Naming ``flag`` and the problem.

    Examples
    --------
    >>> from qualgrasp.certify.cli.options import input_file
    >>> input_file("/dev/zero", "TRACE")
    Traceback (most recent call last):
    ...
    qualgrasp.certify.errors.OptionError: TRACE: /dev/zero is a device, not a regular file
    """
    path = Path(path)
    try:
        st = os.stat(path)
    except FileNotFoundError:
        raise OptionError(f"{flag}: {path}: no such file") from None
    except OSError as err:
        raise OptionError(f"{flag}: cannot read {path} ({err.strerror or err})") from None
    if not stat.S_ISREG(st.st_mode):
        raise OptionError(f"{flag}: {path} is {file_kind(st.st_mode)}, not a regular file")
    if max_bytes is not None and st.st_size > max_bytes:
        raise OptionError(f"{flag}: {path} has {st.st_size:,} bytes, more than the limit of {max_bytes:,}")
    if not os.access(path, os.R_OK):
        raise OptionError(f"{flag}: cannot read {path} (permission denied)")
    return path


def number_in(value: float, flag: str, low: float, high: float, *, unit: str = "",
              low_open: bool = False, high_open: bool = False) -> float:
    """``value`` if it is finite and within ``[low, high]`` (open ends as asked).

    Raises
    ------
    OptionError
        Saying the flag, the range and the unit.

    Examples
    --------
    >>> from qualgrasp.certify.cli.options import number_in
    >>> number_in(0.5, "--mu", 0, 1e6, low_open=True)
    0.5
    """
    return arguments.number_in(value, flag, low, high, unit=unit, low_open=low_open, high_open=high_open,
                               error=OptionError)


def count_in(value: int, flag: str, low: int, high: int | None = None, *, what: str = "") -> int:
    """``value`` if ``low <= value <= high`` (no upper bound when ``high`` is None).

    Raises
    ------
    OptionError
        Saying the flag and the range.
    """
    return arguments.count_in(value, flag, low, high, what=what, error=OptionError)


def optional_number_in(value: float | None, flag: str, low: float, high: float, *, unit: str = "",
                       low_open: bool = False, high_open: bool = False) -> float | None:
    """None for an option not given, else :func:`number_in`'s check (``--tol`` with a default
    computed later, say).

    Examples
    --------
    >>> from qualgrasp.certify.cli.options import optional_number_in
    >>> optional_number_in(None, "--tol", 0, 1, low_open=True) is None
    True
    >>> optional_number_in(0.0, "--tol", 0, 1, low_open=True, unit="pixels")
    Traceback (most recent call last):
    ...
    qualgrasp.certify.errors.OptionError: --tol must be a finite number > 0 and <= 1 pixels, got 0
    """
    if value is None:
        return None
    return number_in(value, flag, low, high, unit=unit, low_open=low_open, high_open=high_open)


def printable(text: str) -> str:
    """``text`` with lone surrogates (from invalid UTF-8 or JSON escapes) escaped, on one line.

    Examples
    --------
    >>> printable("two\\nlines \\udcff")
    'two\\\\nlines \\\\udcff'
    """
    return text.encode("utf-8", "backslashreplace").decode("utf-8").replace("\n", "\\n")


def fail(message: str, console: Console | None = None) -> NoReturn:
    """Print a one-line error (``error: message``, no markup interpreted in it, made
    :func:`printable`) on ``console`` (default: standard error) and exit with code 2.

    Raises
    ------
    typer.Exit
        With code 2.
    """
    console = Console(stderr=True) if console is None else console
    console.print("[red]error:[/red]", escape(printable(message)), soft_wrap=True)
    raise typer.Exit(2)

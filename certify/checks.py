"""Checks every command makes before it works: output paths and numeric options.

Commands are thin layers over public functions; these checks run first, so that a bad path or
number is refused at once with a one-line message in the command line's own terms (the flag and
its unit), never after minutes of work and never as a traceback. Each raises
:class:`OptionError` (a ``ValueError``).

Rules
-----
* An output file is not a folder, not a file the run reads (the input is never overwritten), has
  a suffix the writer knows when the format comes from the suffix (a figure without ``.png`` is
  refused, not silently renamed), and lives in a folder that exists or can be created and can be
  written; the folder is created.
* An output folder is a folder or does not exist yet (it is created); an existing file there is
  refused.
* Numbers are finite and inside their documented range.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Iterable

from .errors import CertifyError

__all__ = ["OptionError", "FIGURE_SUFFIXES", "output_file", "output_folder", "number_in", "count_in"]

#: Suffixes a figure may be saved with (matplotlib's writers).
FIGURE_SUFFIXES = (".png", ".pdf", ".svg", ".jpg", ".jpeg", ".tif", ".tiff", ".eps", ".ps", ".webp")


class OptionError(CertifyError, ValueError):
    """A command-line option or path is unusable (the message names the flag)."""


def _writable_folder(folder: Path, flag: str) -> None:
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except FileExistsError:
        raise OptionError(f"{flag}: {folder} exists and is not a folder") from None
    except OSError as err:
        raise OptionError(f"{flag}: cannot create the folder {folder} ({err.strerror or err})") from None
    if not os.access(folder, os.W_OK | os.X_OK):
        raise OptionError(f"{flag}: cannot write into {folder}")


def output_file(path: str | Path, flag: str, *, suffixes: Iterable[str] | None = None,
                reads: Iterable[str | Path] = ()) -> Path:
    """Check (and prepare the folder of) an output file; return it as a :class:`~pathlib.Path`.

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
    >>> from qualgrasp.certify.checks import output_file
    >>> output_file("figure", "--plot", suffixes=(".png", ".pdf"))
    Traceback (most recent call last):
    ...
    qualgrasp.certify.checks.OptionError: --plot: figure has no suffix: give one of .png, .pdf
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
    for other in reads:
        other = Path(other)
        if path.exists() and other.exists() and os.path.samefile(path, other):
            raise OptionError(f"{flag}: {path} is an input of this run; the input is never overwritten")
    if path.exists() and not path.is_file():
        raise OptionError(f"{flag}: {path} is not a regular file")
    _writable_folder(path.parent, flag)
    return path


def output_folder(path: str | Path, flag: str) -> Path:
    """Check (and create) an output folder; return it.

    Raises
    ------
    OptionError
        ``path`` exists and is not a folder, or cannot be created or written.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from qualgrasp.certify.checks import output_folder
    >>> out = output_folder(pathlib.Path(tempfile.mkdtemp()) / "figures", "--out")
    >>> out.is_dir()
    True
    """
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise OptionError(f"{flag}: {path} exists and is not a folder")
    _writable_folder(path, flag)
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
    >>> from qualgrasp.certify.checks import number_in
    >>> number_in(0.5, "--mu", 0, 1e6, low_open=True)
    0.5
    """
    ok = math.isfinite(value) and (value > low if low_open else value >= low) and (
        value < high if high_open else value <= high)
    if not ok:
        lo = f"{'>' if low_open else '>='} {low:g}"
        hi = f"{'<' if high_open else '<='} {high:g}"
        unit = f" {unit}" if unit else ""
        raise OptionError(f"{flag} must be a finite number {lo} and {hi}{unit}, got {value:g}")
    return value


def count_in(value: int, flag: str, low: int, high: int | None = None, *, what: str = "") -> int:
    """``value`` if ``low <= value <= high`` (no upper bound when ``high`` is None).

    Raises
    ------
    OptionError
        Saying the flag and the range.
    """
    if value < low or (high is not None and value > high):
        span = f"at least {low}" if high is None else f"between {low} and {high}"
        raise OptionError(f"{flag} must be {span}{' ' + what if what else ''}, got {value}")
    return value

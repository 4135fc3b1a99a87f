"""Compiling quality's kernels ahead, on other cores, while a run does other work.

On a cold compile cache, the first ``qualgrasp certify`` with quality would wait for the kernels of
its epsilons. :func:`compile_ahead` has other processes compile the kernel sets the epsilons of
each dimension need (:data:`qualgrasp.certify._kernels.sets.EPSILON_SETS`) into the cache
meanwhile, one process per set (:func:`qualgrasp.certify._kernels.jit.compile_elsewhere`), and
:func:`compile_ahead_for_command` starts them from the command's arguments, before the command
loads the modules it runs (about a second on one core, which the compiling processes use).

Both do nothing on a warm cache, and the results are the same either way: a run waits for a set
another process is compiling, then loads it from the cache (:func:`qualgrasp.certify._kernels.jit.await_compiled`),
and a time limit never counts the wait. This module imports the kernels alone (numpy and numba),
not the rest of the package.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Iterable, Sequence

from ._kernels import sets as kernel_sets
from ._kernels.jit import compile_elsewhere, compiled_here

__all__ = ["compile_ahead", "compile_ahead_for_command", "first_grasp_dims", "PEEK_BYTES"]

#: Most bytes :func:`first_grasp_dims` reads of a file.
PEEK_BYTES = 1 << 16
#: Options with which :func:`compile_ahead_for_command` starts nothing: help, poses on a mesh
#: (their grasps are made later), workers elsewhere (dask).
_NOTHING_AHEAD = ("--help", "--mesh", "--dask")


def compile_ahead(dims: Iterable) -> None:
    """Have other processes compile quality's kernels for grasps of ``dims`` (2, 3) into the
    compile cache when it lacks them, one per kernel set, while this one certifies closure: on a
    cold cache the cores compile at once. A no-op on a warm cache, and the results are the same
    either way.

    Examples
    --------
    >>> compile_ahead([2])   # the cache holds them: nothing to do
    """
    for dim in sorted({int(d) for d in dims} & {2, 3}):
        for name in kernel_sets.EPSILON_SETS[dim]:
            if not compiled_here(kernel_sets.KERNEL_SETS[name]):
                compile_elsewhere(kernel_sets.__name__, name)


def first_grasp_dims(path: str | Path) -> set[int]:
    """The dimensions (2, 3) of the contacts of the first grasp of a JSON Lines grasp file; empty
    when the file cannot be read or its first non-blank line (within :data:`PEEK_BYTES`) is not a
    grasp with contacts (``{"contacts": [{"p": [x, y], ...}, ...], ...}``). Reads nothing else.

    Examples
    --------
    >>> import tempfile, os
    >>> with tempfile.NamedTemporaryFile("w", suffix=".jsonl", delete=False) as fh:
    ...     _ = fh.write('\\n{"contacts": [{"p": [1, 0], "n": [-1, 0]}, {"p": [-1, 0], "n": [1, 0]}]}\\n')
    >>> first_grasp_dims(fh.name)
    {2}
    >>> os.remove(fh.name)
    """
    try:
        with open(path, "rb") as fh:
            head = fh.read(PEEK_BYTES)
    except (OSError, ValueError):
        return set()
    lines = head.splitlines()
    if len(head) == PEEK_BYTES and not head.endswith(b"\n"):
        lines = lines[:-1]  # a line cut by the peek
    for line in lines:
        if not line.strip():
            continue
        try:
            return {len(c["p"]) for c in json.loads(line)["contacts"]} & {2, 3}
        except (ValueError, TypeError, KeyError, IndexError, RecursionError):
            return set()
    return set()


def compile_ahead_for_command(args: Sequence[str]) -> None:
    """:func:`compile_ahead` for the grasps of a ``qualgrasp certify`` with arguments ``args``
    (those after the command's name): the dimensions of the first grasp of the first argument
    naming a JSON Lines grasp file (:func:`first_grasp_dims`). Nothing without an output
    (``-o``), when the last of ``--quality`` and ``--no-quality`` is ``--no-quality``, with
    ``--help``, ``--mesh`` or ``--dask``, or when no argument names such a file (a Parquet input:
    its run compiles them when it needs them, as ever). The command parses and checks its
    arguments afterwards, as ever: one it then refuses for a bad value leaves the kernels
    compiled in the cache, for the next run.

    Examples
    --------
    >>> compile_ahead_for_command(["no-such-file.jsonl", "-o", "out.jsonl"])   # nothing to do
    """
    options = [a.split("=")[0] for a in (args[:args.index("--")] if "--" in args else args)]
    toggles = [a for a in options if a in ("--quality", "--no-quality")]
    if (any(a in _NOTHING_AHEAD for a in options) or (toggles and toggles[-1] == "--no-quality")
            or not {"-o", "--output"} & set(options)):
        return
    for a in args:
        try:
            is_file = not a.startswith("-") and Path(a).is_file()
        except (OSError, ValueError):
            continue
        dims = first_grasp_dims(a) if is_file else set()
        if dims:
            compile_ahead(dims)
            return

"""Checks of the public functions' arguments, by the rule of :mod:`qualgrasp.certify.errors`.

An argument of a plainly wrong Python type raises ``TypeError`` (:func:`require`); a value of
the right type outside the function's domain (NaN, out of range, an unknown name) raises
:class:`~qualgrasp.certify.errors.ArgumentError` naming the argument (:func:`choice`,
:func:`number_in`, :func:`count_in`). The command lines' option checks
(:mod:`qualgrasp.certify.cli.options`) are these, with :class:`~qualgrasp.certify.errors.OptionError`
and the flag's name.
"""

from __future__ import annotations

import math
from numbers import Integral, Real
from typing import Any, Iterable, TypeVar

from ..errors import ArgumentError

__all__ = ["require", "choice", "number_in", "count_in"]

T = TypeVar("T")


def require(value: T, kind: type | tuple[type, ...], name: str) -> T:
    """``value`` if it is an instance of ``kind``, else ``TypeError`` naming ``name``.

    Examples
    --------
    >>> require(3, str, "grasp")
    Traceback (most recent call last):
    ...
    TypeError: grasp must be a str, got int
    """
    if not isinstance(value, kind):
        kinds = kind if isinstance(kind, tuple) else (kind,)
        raise TypeError(f"{name} must be a {' or '.join(k.__name__ for k in kinds)}, got {type(value).__name__}")
    return value


def choice(value: Any, name: str, choices: Iterable[str], error: type[Exception] = ArgumentError) -> str:
    """``value`` if it is one of ``choices``, else ``error`` (default :class:`ArgumentError`).

    Examples
    --------
    >>> choice("L3", "norm", ("L1", "Linf"))
    Traceback (most recent call last):
    ...
    qualgrasp.certify.errors.ArgumentError: norm must be one of 'L1', 'Linf', got 'L3'
    """
    choices = tuple(choices)
    if not isinstance(value, str) or value not in choices:
        raise error(f"{name} must be one of {', '.join(map(repr, choices))}, got {value!r}")
    return value


def number_in(value: float, name: str, low: float, high: float, *, unit: str = "", low_open: bool = False,
              high_open: bool = False, error: type[Exception] = ArgumentError) -> float:
    """``value`` if it is a finite real number within ``[low, high]`` (open ends as asked), else
    ``error`` saying the name, the range and the unit (``TypeError`` for a value that is not a
    real number).

    Examples
    --------
    >>> number_in(float("nan"), "rel_gap", 0, 1, high_open=True)
    Traceback (most recent call last):
    ...
    qualgrasp.certify.errors.ArgumentError: rel_gap must be a finite number >= 0 and < 1, got nan

    An infinite end is no bound, and the message does not state it:

    >>> number_in(float("inf"), "eps_time", 0, math.inf, unit="seconds")
    Traceback (most recent call last):
    ...
    qualgrasp.certify.errors.ArgumentError: eps_time must be a finite number >= 0 seconds, got inf
    """
    if isinstance(value, bool) or not isinstance(value, Real):
        raise TypeError(f"{name} must be a number, got {type(value).__name__}")
    ok = math.isfinite(value) and (value > low if low_open else value >= low) and (
        value < high if high_open else value <= high)
    if not ok:
        bounds = [f"{'>' if low_open else '>='} {low:g}"] if math.isfinite(low) else []
        bounds += [f"{'<' if high_open else '<='} {high:g}"] if math.isfinite(high) else []  # no "<= inf"
        words = [" and ".join(bounds)] if bounds else []
        words += ([unit] if bounds else [f"of {unit}"]) if unit else []
        raise error(" ".join([f"{name} must be a finite number", *words]) + f", got {value:g}")
    return value


def count_in(value: int, name: str, low: int, high: int | None = None, *, what: str = "",
             error: type[Exception] = ArgumentError) -> int:
    """``value`` if it is an integer with ``low <= value <= high`` (no upper bound when ``high``
    is None), else ``error`` saying the name and the range (``TypeError`` for a value that is not
    an integer).

    Examples
    --------
    >>> count_in(0, "budget", 1, what="direction")
    Traceback (most recent call last):
    ...
    qualgrasp.certify.errors.ArgumentError: budget must be at least 1 direction, got 0
    """
    if isinstance(value, bool) or not isinstance(value, Integral):
        raise TypeError(f"{name} must be an integer, got {type(value).__name__}")
    if value < low or (high is not None and value > high):
        span = f"at least {low}" if high is None else f"between {low} and {high}"
        raise error(f"{name} must be {span}{' ' + what if what else ''}, got {value}")
    return value

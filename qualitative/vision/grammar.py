"""The grammar of qualitative outlines (Galton & Meathrel 1999): the alphabet of seven curvature
types, the canonical rotation of a cyclic string, and well-formedness.

Alphabet (the project's ASCII rendering of the seven curvature types), in canonical order:

======  ===========================================  ==========
symbol  curvature type                               kind
======  ===========================================  ==========
``/``   straight line segment                        line-like
``)``   convex curve segment                         line-like
``(``   concave curve segment                        line-like
``>``   outward-pointing angle (convex corner)       point-like
``<``   inward-pointing angle (concave corner)       point-like
``}``   outward-pointing cusp                        point-like
``{``   inward-pointing cusp                         point-like
======  ===========================================  ==========

Rules
-----
* **Canonical rotation.** Any rotation of the cyclic string describes the same outline; the
  canonical string is the lexicographically least rotation under the symbol order ``/)(><}{``
  (straight first). A square is ``/>/>/>/>``, a disc ``)``.
* **Well-formedness** (paper section 4.1, project notes section 4): (1) the string contains ``)`` or
  at least three convex points (``>`` or ``}``); (2) no two cyclically consecutive identical symbols
  (a single symbol, such as a disc's ``)``, has no neighbour and is allowed); (3) no two cyclically
  consecutive point-like symbols; (4) every cusp (``}`` or ``{``) is adjacent on at least one side to
  a curve (``)`` or ``(``) -- the notes' reading of a garbled sentence of the paper; geometry
  says more (an outward cusp's sides meet tangentially with the object between them, so one of
  them must be concave; likewise an inward cusp needs a convex side), but only the notes' rule is
  enforced; (5) the total turning is 2 pi: for a string, some choice of turning angles in the
  ranges of its symbols (``/`` 0, ``)`` positive, ``(`` negative, ``>`` in (0, pi), ``<`` in
  (-pi, 0), ``}`` pi, ``{`` -pi) must add up to 2 pi; for an extracted outline the measured
  turnings must add up to 2 pi and each must have its symbol's sign (:func:`check_turnings`).

These rules are about strings; :mod:`~qualgrasp.qualitative.vision.outline` extracts the strings
from contours.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..errors import OutlineError

__all__ = ["SYMBOLS", "NAMES", "LINE_LIKE", "POINT_LIKE", "CURVES", "CONVEX_POINTS", "LINE_SET", "POINT_SET",
           "CURVE_SET", "canonical", "least_rotation", "turning_range", "validate", "check_turnings",
           "is_well_formed"]

SYMBOLS = "/)(><}{"
NAMES = {
    "/": "straight line",
    ")": "convex curve",
    "(": "concave curve",
    ">": "outward angle",
    "<": "inward angle",
    "}": "outward cusp",
    "{": "inward cusp",
}
LINE_LIKE = "/)("
POINT_LIKE = "><}{"
CURVES = ")("
CONVEX_POINTS = ">}"
#: The same as sets, for membership tests of one symbol (``"" in POINT_LIKE`` is True: "" is a
#: substring of every str).
LINE_SET, POINT_SET, CURVE_SET = frozenset(LINE_LIKE), frozenset(POINT_LIKE), frozenset(CURVES)
_RANK = {s: i for i, s in enumerate(SYMBOLS)}
_TURNING_TOLERANCE = 1e-6


# --------------------------------------------------------------------------------------------------
# Strings: canonical form and well-formedness


def _check_alphabet(string: str) -> None:
    if not isinstance(string, str) or not string:
        raise OutlineError(f"an outline string must be a non-empty str, got {string!r}")
    bad = sorted(set(string) - set(SYMBOLS))
    if bad:
        raise OutlineError(f"unknown symbol(s) {''.join(bad)!r} in {string!r}; the alphabet is {SYMBOLS!r}")


def least_rotation(string: str) -> int:
    """Index where the lexicographically least rotation (in symbol order) starts; first if tied."""
    ranks = [_RANK[s] for s in string]
    n = len(ranks)
    return min(range(n), key=lambda i: ranks[i:] + ranks[:i])


def canonical(string: str) -> str:
    """The canonical rotation of a cyclic outline string.

    Parameters
    ----------
    string : str
        Symbols from :data:`SYMBOLS`, read along the positively oriented contour.

    Returns
    -------
    str
        The lexicographically least rotation under the symbol order ``/)(><}{``.

    Raises
    ------
    OutlineError
        Empty string or unknown symbol.
    """
    _check_alphabet(string)
    i = least_rotation(string)
    return string[i:] + string[:i]


def turning_range(string: str) -> tuple[float, bool, float, bool]:
    """Infimum and supremum of the total turning (radians) a string allows, with whether each is
    attained: ``(lo, lo_attained, hi, hi_attained)``.

    Examples
    --------
    >>> turning_range("/>/>/>/>")[2] / math.pi   # four angles, each less than pi
    4.0
    """
    lo, lo_closed, hi, hi_closed = 0.0, True, 0.0, True
    for s in string:
        if s == "/":
            continue
        if s == "}" or s == "{":
            v = math.pi if s == "}" else -math.pi
            lo, hi = lo + v, hi + v
        elif s == ")":
            lo_closed, hi = False, math.inf
        elif s == "(":
            hi_closed, lo = False, -math.inf
        elif s == ">":
            lo_closed, hi_closed, hi = False, False, hi + math.pi
        elif s == "<":
            lo_closed, hi_closed, lo = False, False, lo - math.pi
    return lo, lo_closed, hi, hi_closed


def _check_rules(string: str) -> None:
    n = len(string)
    convex_points = sum(string.count(s) for s in CONVEX_POINTS)
    if ")" not in string and convex_points < 3:
        raise OutlineError(
            f"rule 1 (bounded): {string!r} has no convex curve ')' and only {convex_points} convex "
            "point(s) ('>' or '}'); at least three are needed")
    if n > 1:
        for i in range(n):
            a, b = string[i], string[(i + 1) % n]
            if a == b:
                raise OutlineError(
                    f"rule 2 (no repeated symbol): {string!r} has {a!r} twice in a row at positions "
                    f"{i} and {(i + 1) % n} (cyclically)")
            if a in POINT_SET and b in POINT_SET:
                raise OutlineError(
                    f"rule 3 (no consecutive points): {string!r} has point-like {a!r}{b!r} at positions "
                    f"{i} and {(i + 1) % n} (cyclically)")
    for i, s in enumerate(string):
        if s in "}{" and string[i - 1] not in CURVE_SET and string[(i + 1) % n] not in CURVE_SET:
            raise OutlineError(
                f"rule 4 (cusp next to a curve): the cusp {s!r} at position {i} of {string!r} has no "
                "curve ')' or '(' on either side")


def _check_string_turning(string: str) -> None:
    lo, lo_closed, hi, hi_closed = turning_range(string)
    target = 2 * math.pi
    above = target > lo or (lo_closed and math.isclose(target, lo))
    below = target < hi or (hi_closed and math.isclose(target, hi))
    if not (above and below):
        raise OutlineError(
            f"turning (total 2 pi): the symbols of {string!r} allow a total turning between "
            f"{lo / math.pi:g} pi and {hi / math.pi:g} pi, which excludes 2 pi")


def check_turnings(symbols: str, turnings) -> None:
    """Measured turnings (radians) of the elements ``symbols``: 2 pi in total, each of its symbol's sign."""
    total = sum(turnings)
    if abs(total - 2 * math.pi) > _TURNING_TOLERANCE:
        raise OutlineError(f"turning (total 2 pi): the segments turn by {total / math.pi:.6g} pi in total")
    for symbol, turning in zip(symbols, turnings):
        sign = {"/": 0, ")": 1, "(": -1, ">": 1, "<": -1, "}": 1, "{": -1}[symbol]
        if sign and np.sign(turning) != sign:
            raise OutlineError(
                f"turning (sign): segment {symbol!r} ({NAMES[symbol]}) turns by "
                f"{math.degrees(turning):.3g} degrees, of the wrong sign")


def validate(outline: Any) -> None:
    """Check that an outline string (or an extracted :class:`~qualgrasp.qualitative.vision.outline.Outline`)
    is well formed.

    Parameters
    ----------
    outline : str or qualgrasp.qualitative.vision.outline.Outline
        A cyclic string over :data:`SYMBOLS`, or an extracted outline (its string and its measured
        segment turnings are checked).

    Raises
    ------
    OutlineError
        Naming the first rule broken: ``rule 1 (bounded)``, ``rule 2 (no repeated symbol)``,
        ``rule 3 (no consecutive points)``, ``rule 4 (cusp next to a curve)``,
        ``turning (total 2 pi)`` or ``turning (sign)``; or an unknown symbol.
    """
    string = outline if isinstance(outline, str) else outline.raw_string
    _check_alphabet(string)
    _check_rules(string)
    if isinstance(outline, str):
        _check_string_turning(string)
    else:
        check_turnings(string, [seg.turning for seg in outline.segments])


def is_well_formed(outline: Any) -> bool:
    """True when :func:`validate` accepts the outline."""
    try:
        validate(outline)
    except OutlineError:
        return False
    return True


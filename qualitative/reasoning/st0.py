"""ST0: temporal logic over RCC-8 atoms, evaluated on finite traces.

A *trace* is a sequence of frames, one per instant (instants 0, 1, ..., n - 1). A frame maps an
ordered pair of region names ``(x, y)`` (a tuple) to the name of the RCC-8 base relation that
holds between x and y at that instant (see :mod:`qualgrasp.qualitative.reasoning.rcc8`). A pair missing from a frame
is read as the converse of the reversed pair; a pair missing both ways is an error. A region is
always ``EQ`` to itself.

Syntax
------
================================  ==================================================
``REL(X,Y)``                      atom: base relation REL holds between regions X and Y
``{REL1,REL2,...}(X,Y)``          atom: one of the relations holds (disjunction)
``true``, ``false``               constants
``!p``                            not
``p & q``, ``p | q``              and, or
``p -> q``                        implies
``X p``, ``F p``, ``G p``         next (strong), sometime, always (now or later)
``p U q``                         until
``Y p``, ``O p``, ``H p``         previous (strong), once, historically (now or earlier)
``p S q``                         since
``( p )``                         grouping
================================  ==================================================

Relation names are exactly ``DC EC PO EQ TPP TPPi NTPP NTPPi``. Region names are words of
letters, digits and underscores; inside an atom's parentheses every word is a region name, so
regions may be called ``X``, ``F``, ``O``... (``EC(F1,O)``, ``G(EC(F2,O) -> O(EC(F1,O)))``).
Operators are only read in operator position. A word made of unary operator letters, optionally
ending in a relation name or constant, is read letter by letter: ``GF p`` is ``G F p``,
``XEC(A,B)`` is ``X EC(A,B)``.

Precedence, tightest first: the unary operators ``! X F G Y O H``; then ``U`` and ``S``
(right-associative: ``p U q U r`` is ``p U (q U r)``, ``p U q S r`` is ``p U (q S r)``); then
``&``; then ``|``; then ``->`` (right-associative). So ``G p -> q`` is ``(G p) -> q`` and
``!p U q`` is ``(!p) U q``.

Semantics (finite traces of length n; theory notes, section 9)
---------------------------------------------------------------
- ``(X p)[i] = p[i+1]`` for ``i < n - 1``; false at the last instant (strong next).
- ``(Y p)[i] = p[i-1]`` for ``i > 0``; false at instant 0 (strong previous).
- ``(p U q)[i] = q[i] or (p[i] and (p U q)[i+1])``, false past the end: some ``j >= i`` has
  ``q[j]`` and ``p`` holds on ``[i, j)``.
- ``(p S q)[i] = q[i] or (p[i] and (p S q)[i-1])``, false before the start: some ``j <= i`` has
  ``q[j]`` and ``p`` holds on ``(j, i]``.
- ``F p = true U p``, ``G p = !F!p``, ``O p = true S p``, ``H p = !O!p``.

Every operator is evaluated on the whole trace at once in O(n) with numpy (prefix and suffix
scans), so a formula costs O(n * size). The tests check it against a deliberately naive
per-instant evaluator of the same semantics (``tests/st0_reference.py``).
"""

from __future__ import annotations

import json
import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from itertools import repeat
from pathlib import Path

import numpy as np

from ..errors import FormulaError, TraceError
from .rcc8 import RELATIONS, path_consistency

#: Longest formula accepted, in characters.
MAX_FORMULA = 10_000
#: Most operators nested inside each other in a formula (:meth:`Formula.depth`: ``!``, the
#: temporal operators, ``&``, ``|``, ``->``, ``U`` and ``S`` each count where one encloses the
#: next; siblings such as ``p & q & r`` do not add up), and most brackets nested inside each
#: other: parsing, evaluation and printing recurse once per level.
MAX_DEPTH = 100
#: Largest trace file read, in bytes.
MAX_TRACE_BYTES = 64 << 20
#: Most work of the consistency checks of one trace: each different arrangement of its frames
#: (frames equal up to the regions' names share one check) costs 1 + its regions squared.
MAX_ARRANGEMENT_WORK = 500_000
#: Most work of one evaluation: frames times (10 per region pair the formula reads, which is
#: looked up in both directions in every frame, + 1 per operator, atom or constant, which is a
#: vectorised pass over the frames).
MAX_EVALUATION_WORK = 400_000_000

__all__ = [
    "Formula", "Const", "Atom", "Not", "And", "Or", "Implies",
    "Next", "Sometime", "Always", "Until", "Previous", "Once", "Historically", "Since",
    "parse", "read_trace", "write_trace", "evaluate_file",
    "MAX_FORMULA", "MAX_DEPTH", "MAX_TRACE_BYTES", "MAX_ARRANGEMENT_WORK", "MAX_EVALUATION_WORK",
]

Frame = Mapping[tuple[str, str], str]

_CODE = {name: i for i, name in enumerate(RELATIONS)}
_LOOKUP = {**_CODE, None: -1}  # a missing pair reads as None
_CONVERSE_CODE = np.array([_CODE[{"TPP": "TPPi", "TPPi": "TPP", "NTPP": "NTPPi",
                                  "NTPPi": "NTPP"}.get(r, r)] for r in RELATIONS], dtype=np.int8)

# precedence levels, loosest first
_IMPLIES, _OR, _AND, _BINARY, _UNARY, _ATOM = range(6)


# -------------------------------------------------------------------------------- formulas

class Formula:
    """Base class of ST0 formulas: immutable trees, compared by value, printable as ST0 text.

    ``str(formula)`` is ST0 text that :func:`parse` reads back to an equal formula.
    """

    _prec = _ATOM

    def evaluate(self, trace: Sequence[Frame]) -> np.ndarray:
        """Truth value at every instant of the trace.

        Parameters
        ----------
        trace : sequence of frames
            Each frame maps ``(x, y)`` to a base relation name.

        Returns
        -------
        numpy.ndarray of bool, shape (n,)
            Empty for an empty trace.

        Raises
        ------
        TraceError
            A frame is not a mapping, a relation name is unknown, a pair used by the formula is
            missing in both directions, or the two directions of a pair disagree.
        """
        n = _trace_length(trace)
        pairs = sorted(self.pairs())
        work = n * (10 * len(pairs) + self.size())
        if work > MAX_EVALUATION_WORK:
            raise TraceError(f"evaluating {self.size()} operators and atoms on {len(pairs)} region pairs "
                             f"over {n:,} frames is {work:,} units of work, more than the limit of "
                             f"{MAX_EVALUATION_WORK:,} (frames times (10 per pair + 1 per operator or "
                             "atom)); evaluate a shorter trace or a smaller formula")
        columns = {pair: _relation_codes(trace, n, pair) for pair in pairs}
        return self._eval(columns, n)

    def holds(self, trace: Sequence[Frame]) -> bool:
        """Truth value at instant 0 (the trace must not be empty)."""
        values = self.evaluate(trace)
        if values.size == 0:
            raise TraceError("the trace is empty: there is no instant 0 to evaluate at")
        return bool(values[0])

    def pairs(self) -> frozenset[tuple[str, str]]:
        """The ordered region pairs that the formula's atoms mention."""
        self._check_depth()
        pairs, stack = set(), [self]
        while stack:
            f = stack.pop()
            if isinstance(f, Atom):
                pairs |= f.pairs()
            stack.extend(f._children())
        return frozenset(pairs)

    def depth(self) -> int:
        """Operators nested inside each other: 0 for an atom or a constant, 1 for ``!p``, ``p &
        q`` or ``X p`` of atoms, and so on (computed without recursion, whatever the depth)."""
        return max(d for _, d in self._nodes())

    def size(self) -> int:
        """Number of operators, atoms and constants in the formula."""
        return sum(1 for _ in self._nodes())

    def _nodes(self):
        """Every node of the tree with its depth, without recursion."""
        stack = [(self, 0)]
        while stack:
            f, d = stack.pop()
            yield f, d
            stack.extend((c, d + 1) for c in f._children())

    def _check_depth(self) -> None:
        # evaluation and printing recurse once per level
        if self.depth() > MAX_DEPTH:
            raise FormulaError(_too_deep())

    def _children(self) -> tuple[Formula, ...]:
        return ()

    def _eval(self, columns: dict, n: int) -> np.ndarray:
        raise NotImplementedError

    def _wrap(self, child: Formula, level: int) -> str:
        return f"({child})" if child._prec < level else str(child)


@dataclass(frozen=True)
class Const(Formula):
    """``true`` or ``false``."""

    value: bool

    def _eval(self, columns, n):
        return np.full(n, bool(self.value))

    def __str__(self):
        return "true" if self.value else "false"


@dataclass(frozen=True)
class Atom(Formula):
    """``{R1,...}(x, y)``: one of the base relations ``relations`` holds between x and y."""

    relations: frozenset[str]
    x: str
    y: str

    def __post_init__(self):
        rels = self.relations
        rels = frozenset((rels,)) if isinstance(rels, str) else frozenset(rels)
        bad = sorted(r for r in rels if r not in _CODE)
        if bad or not rels:
            raise FormulaError(f"atom over ({self.x}, {self.y}): "
                               + (f"unknown relation {bad[0]!r}" if bad else "empty set of relations")
                               + f"; the base relations are {', '.join(RELATIONS)}")
        object.__setattr__(self, "relations", rels)

    def pairs(self):
        return frozenset() if self.x == self.y else frozenset({(self.x, self.y)})

    def _eval(self, columns, n):
        if self.x == self.y:  # a region is EQ to itself
            return np.full(n, "EQ" in self.relations)
        table = np.array([r in self.relations for r in RELATIONS])
        return table[columns[(self.x, self.y)]]

    def __str__(self):
        names = [r for r in RELATIONS if r in self.relations]
        rel = names[0] if len(names) == 1 else "{" + ",".join(names) + "}"
        return f"{rel}({self.x},{self.y})"


@dataclass(frozen=True)
class _Unary(Formula):
    arg: Formula
    _symbol = "?"
    _prec = _UNARY

    def _children(self):
        return (self.arg,)

    def _eval(self, columns, n):
        return self._apply(self.arg._eval(columns, n))

    def __str__(self):
        inner = self._wrap(self.arg, _UNARY)
        if self._symbol == "!" or inner.startswith("("):
            return f"{self._symbol}{inner}"
        return f"{self._symbol} {inner}"


class Not(_Unary):
    """``!p``."""

    _symbol = "!"

    def _apply(self, p):
        return ~p


class Next(_Unary):
    """``X p``: p at the next instant; false at the last instant."""

    _symbol = "X"

    def _apply(self, p):
        out = np.zeros_like(p)
        out[:-1] = p[1:]
        return out


class Previous(_Unary):
    """``Y p``: p at the previous instant; false at instant 0."""

    _symbol = "Y"

    def _apply(self, p):
        out = np.zeros_like(p)
        out[1:] = p[:-1]
        return out


class Sometime(_Unary):
    """``F p``: p now or at some later instant."""

    _symbol = "F"

    def _apply(self, p):
        return np.logical_or.accumulate(p[::-1])[::-1]


class Always(_Unary):
    """``G p``: p now and at every later instant."""

    _symbol = "G"

    def _apply(self, p):
        return np.logical_and.accumulate(p[::-1])[::-1]


class Once(_Unary):
    """``O p``: p now or at some earlier instant."""

    _symbol = "O"

    def _apply(self, p):
        return np.logical_or.accumulate(p)


class Historically(_Unary):
    """``H p``: p now and at every earlier instant."""

    _symbol = "H"

    def _apply(self, p):
        return np.logical_and.accumulate(p)


@dataclass(frozen=True)
class _Nary(Formula):
    args: tuple[Formula, ...]
    _symbol = "?"

    def __post_init__(self):
        object.__setattr__(self, "args", tuple(self.args))
        if len(self.args) < 2:
            raise FormulaError(f"{type(self).__name__} needs at least two operands")

    def _children(self):
        return self.args

    def __str__(self):
        return f" {self._symbol} ".join(self._wrap(a, self._prec + 1) for a in self.args)


class And(_Nary):
    """``p & q & ...``."""

    _symbol = "&"
    _prec = _AND

    def _eval(self, columns, n):
        return np.logical_and.reduce([a._eval(columns, n) for a in self.args])


class Or(_Nary):
    """``p | q | ...``."""

    _symbol = "|"
    _prec = _OR

    def _eval(self, columns, n):
        return np.logical_or.reduce([a._eval(columns, n) for a in self.args])


@dataclass(frozen=True)
class _Binary(Formula):
    left: Formula
    right: Formula
    _symbol = "?"
    _prec = _BINARY

    def _children(self):
        return (self.left, self.right)

    def _eval(self, columns, n):
        return self._apply(self.left._eval(columns, n), self.right._eval(columns, n))

    def __str__(self):  # right-associative: the left operand binds tighter
        left, right = self._wrap(self.left, self._prec + 1), self._wrap(self.right, self._prec)
        return f"{left} {self._symbol} {right}"


class Implies(_Binary):
    """``p -> q``."""

    _symbol = "->"
    _prec = _IMPLIES

    def _apply(self, p, q):
        return ~p | q


def _next_index(cond: np.ndarray) -> np.ndarray:
    """For each i, the smallest j >= i with cond[j], or n when there is none."""
    n = cond.size
    idx = np.where(cond, np.arange(n), n)
    return np.minimum.accumulate(idx[::-1])[::-1]


def _last_index(cond: np.ndarray) -> np.ndarray:
    """For each i, the largest j <= i with cond[j], or -1 when there is none."""
    idx = np.where(cond, np.arange(cond.size), -1)
    return np.maximum.accumulate(idx)


class Until(_Binary):
    """``p U q``: q at some j >= i, and p at every instant of [i, j)."""

    _symbol = "U"

    def _apply(self, p, q):
        # the first q from i on must come no later than the first failure of p
        first_q = _next_index(q)
        return (first_q < q.size) & (first_q <= _next_index(~p))


class Since(_Binary):
    """``p S q``: q at some j <= i, and p at every instant of (j, i]."""

    _symbol = "S"

    def _apply(self, p, q):
        last_q = _last_index(q)
        return (last_q >= 0) & (last_q >= _last_index(~p))


_UNARY_OPS = {"!": Not, "X": Next, "F": Sometime, "G": Always,
              "Y": Previous, "O": Once, "H": Historically}
_BINARY_OPS = {"U": Until, "S": Since}


# ---------------------------------------------------------------------------------- traces

def _trace_length(trace) -> int:
    if isinstance(trace, (str, bytes, Mapping)) or not isinstance(trace, Sequence):
        raise TraceError(f"a trace must be a sequence (list) of frames, not {type(trace).__name__}")
    return len(trace)


def _column(trace, n: int, pair: tuple[str, str]) -> np.ndarray:
    """Codes of ``pair`` per frame: index into RELATIONS, -1 missing, -2 unknown name."""
    try:
        names = [frame.get(pair) for frame in trace]
        return np.fromiter(map(_LOOKUP.get, names, repeat(-2)), dtype=np.int8, count=n)
    except (AttributeError, TypeError):
        for t, frame in enumerate(trace):  # find the culprit for the message
            if not isinstance(frame, Mapping):
                raise TraceError(f"frame {t} is a {type(frame).__name__}, expected a mapping "
                                 f"(x, y) -> relation name") from None
            value = frame.get(pair)
            if not isinstance(value, str | None):
                raise TraceError(f"frame {t}, pair {pair}: relation must be a name, "
                                 f"not {value!r}") from None
        raise


def _relation_codes(trace, n: int, pair: tuple[str, str]) -> np.ndarray:
    """The relation of ``pair`` at every instant, read from either direction and checked."""
    x, y = pair
    forward = _column(trace, n, (x, y))
    backward = _column(trace, n, (y, x))
    for codes, key in ((forward, (x, y)), (backward, (y, x))):
        bad = np.flatnonzero(codes == -2)
        if bad.size:
            t = int(bad[0])
            raise TraceError(f"frame {t}, pair {key}: unknown relation {trace[t][key]!r}; "
                             f"the base relations are {', '.join(RELATIONS)}")
    missing = (forward < 0) & (backward < 0)
    if missing.any():
        t = int(np.flatnonzero(missing)[0])
        raise TraceError(f"frame {t} gives no relation for the pair {pair} (nor for {(y, x)})")
    converse = _CONVERSE_CODE[np.maximum(backward, 0)]
    clash = (forward >= 0) & (backward >= 0) & (forward != converse)
    if clash.any():
        t = int(np.flatnonzero(clash)[0])
        raise TraceError(f"frame {t}: {pair} is {trace[t][(x, y)]} but {(y, x)} is "
                         f"{trace[t][(y, x)]}, which is not its converse")
    return np.where(forward >= 0, forward, converse)


def read_trace(path: str | Path) -> list[dict[tuple[str, str], str]]:
    """Read a recorded trace: a JSON list of frames, each an object ``{"X,Y": "REL", ...}``.

    Keys are two region names joined by a comma (spaces around the names are ignored); values
    are base relation names.

    Returns
    -------
    list of dict
        Frames mapping ``(x, y)`` tuples to relation names, ready for :meth:`Formula.evaluate`.

    Raises
    ------
    TraceError
        Unreadable file, malformed JSON, or a frame, key or relation that does not fit the
        format (the message gives the frame index).
    """
    path = Path(path)
    try:
        if not path.is_file():
            raise TraceError(f"cannot read trace file {path}: " + (
                "no such file" if not path.exists() else "not a regular file (a folder, device or pipe)"))
        if path.stat().st_size > MAX_TRACE_BYTES:
            raise TraceError(f"trace file {path} is larger than {MAX_TRACE_BYTES >> 20} MiB")
        data = json.loads(path.read_text(encoding="utf-8"))
    except TraceError:
        raise
    except OSError as err:
        raise TraceError(f"cannot read trace file {path}: {err.strerror or err}") from None
    except (json.JSONDecodeError, UnicodeDecodeError) as err:
        raise TraceError(f"trace file {path} is not valid JSON: {err}") from None
    except RecursionError:
        raise TraceError(f"trace file {path} is nested deeper than the JSON parser allows") from None
    except ValueError as err:  # e.g. an integer of more than 4,300 digits
        raise TraceError(f"trace file {path} is not valid JSON: {err}") from None
    if not isinstance(data, list):
        raise TraceError(f"trace file {path}: expected a JSON list of frames, "
                         f"found {type(data).__name__}")
    frames = []
    consistent = _Consistency(path)
    read: dict[tuple, dict] = {}  # a recorded trace repeats its frames: read each text once
    for t, obj in enumerate(data):
        if not isinstance(obj, dict):
            raise TraceError(f"trace file {path}, frame {t}: expected an object mapping "
                             f'"X,Y" to a relation name, found {type(obj).__name__}')
        items = tuple(obj.items())
        try:
            frame = read.get(items)
        except TypeError:  # an unhashable value (a list, ...): _frame names it
            frame = None
        if frame is None:
            frame = _frame(path, t, items)
            if not consistent(frame):
                raise TraceError(f"trace file {path}, frame {t}: the relations contradict RCC-8's "
                                 "composition table (no arrangement of regions has them all)")
            read[items] = frame
        frames.append(dict(frame))
    return frames


def _frame(path: Path, t: int, items: tuple) -> dict[tuple[str, str], str]:
    """Frame ``t`` read from its JSON object's items (:func:`read_trace`)."""
    frame = {}
    for key, rel in items:
        names = tuple(part.strip() for part in key.split(","))
        if len(names) != 2 or not all(names):
            raise TraceError(f'trace file {path}, frame {t}: key {key!r} is not two region '
                             f'names joined by a comma, e.g. "F1,O"')
        if not isinstance(rel, str) or rel not in _CODE:
            shown = repr(rel) if isinstance(rel, (str, int, float, bool)) and len(repr(rel)) < 60 else \
                f"(a {type(rel).__name__})"
            raise TraceError(f"trace file {path}, frame {t}, pair {key!r}: unknown relation "
                             f"{shown}; the base relations are {', '.join(RELATIONS)}")
        if frame.get(names, rel) != rel:
            raise TraceError(f"trace file {path}, frame {t}: pair {names} is given twice")
        frame[names] = rel
    return frame


class _Consistency:
    """Whether frames are consistent under RCC-8's composition table, checked once per
    arrangement: frames that differ only in their regions' names share the verdict. The work
    of the checks (:data:`MAX_ARRANGEMENT_WORK`) is bounded before it is done."""

    def __init__(self, path: Path):
        self.path = path
        self.known: dict[tuple, bool] = {}
        self.work = 0

    def __call__(self, frame: dict[tuple[str, str], str]) -> bool:
        index: dict[str, int] = {}
        key = tuple((index.setdefault(x, len(index)), index.setdefault(y, len(index)), rel)
                    for (x, y), rel in frame.items())
        verdict = self.known.get(key)
        if verdict is None:
            self.work += 1 + len(index) ** 2  # path consistency revises O(regions^2) pairs
            if self.work > MAX_ARRANGEMENT_WORK:
                raise TraceError(
                    f"trace file {self.path}: its frames hold {len(self.known) + 1} or more different "
                    f"arrangements, whose consistency checks exceed the limit of "
                    f"{MAX_ARRANGEMENT_WORK:,} units (1 + regions squared per arrangement); "
                    "split the trace or record fewer regions per frame")
            verdict = self.known[key] = path_consistency(frame) is not None
        return verdict


def write_trace(trace: Sequence[Frame], path: str | Path) -> None:
    """Write a trace in the format of :func:`read_trace` (one frame per line)."""
    lines = []
    for t, frame in enumerate(trace):
        obj = {}
        for (x, y), rel in frame.items():
            if "," in x or "," in y:
                raise TraceError(f"frame {t}: region names with a comma cannot be written "
                                 f"({x!r}, {y!r})")
            if rel not in _CODE:
                raise TraceError(f"frame {t}, pair {(x, y)}: unknown relation {rel!r}")
            obj[f"{x},{y}"] = rel
        lines.append(json.dumps(obj))
    Path(path).write_text("[\n" + ",\n".join(lines) + "\n]\n")


def evaluate_file(formula: str | Formula, path: str | Path) -> np.ndarray:
    """Evaluate a formula (text or parsed) on a recorded trace file (:func:`read_trace`).

    Returns
    -------
    numpy.ndarray of bool
        The truth value at every instant.

    Raises
    ------
    FormulaError
        The formula text does not parse (or exceeds :data:`MAX_FORMULA` characters or
        :data:`MAX_DEPTH` nested operators).
    TraceError
        The file is missing, not a regular file, larger than :data:`MAX_TRACE_BYTES`,
        malformed, empty, inconsistent with RCC-8's composition table in some frame, or lacks a
        pair that the formula needs.
    """
    if isinstance(formula, str):
        formula = parse(formula)
    trace = read_trace(path)
    if not trace:
        raise TraceError(f"trace file {path} is empty: it holds no frame to evaluate the formula on")
    return formula.evaluate(trace)


# ---------------------------------------------------------------------------------- parser

_TOKEN = re.compile(r"\s*(?:(?P<arrow>->)|(?P<punct>[!&|(){},])|(?P<word>[A-Za-z0-9_]+)|(?P<bad>\S))")
_CONSTANTS = {"true": True, "false": False}
_RELATION_LIST = ", ".join(RELATIONS)


@dataclass(frozen=True)
class _Token:
    text: str
    column: int  # 1-based
    kind: str    # "op", "word" or "end"


def _tokenize(text: str) -> list[_Token]:
    tokens = []
    pos = 0
    while True:
        m = _TOKEN.match(text, pos)
        if m is None:  # only trailing whitespace is left
            break
        kind = m.lastgroup
        col = m.start(kind) + 1
        if kind == "bad":
            raise _error(text, col, "an operator, a relation name, a region name or a parenthesis",
                         repr(m.group(kind)))
        tokens.append(_Token(m.group(kind), col, "word" if kind == "word" else "op"))
        pos = m.end()
    tokens.append(_Token("", len(text) + 1, "end"))
    return tokens


def _error(text: str, column: int, expected: str, found: str) -> FormulaError:
    err = FormulaError(f"column {column}: expected {expected}, found {found}\n"
                       f"  {text}\n  {' ' * (column - 1)}^")
    err.column, err.expected, err.found = column, expected, found
    return err


def _describe(tok: _Token) -> str:
    return "the end of the formula" if tok.kind == "end" else repr(tok.text)


def _split_unary(word: str) -> tuple[list[str], str] | None:
    """``"GF"`` -> (["G", "F"], ""); ``"XEC"`` -> (["X"], "EC"); None when it does not split."""
    i = 0
    while i < len(word) and word[i] in _UNARY_OPS and word[i:] not in _CODE:
        i += 1
    rest = word[i:]
    if i and (rest == "" or rest in _CODE or rest in _CONSTANTS):
        return list(word[:i]), rest
    return None


class _Parser:
    def __init__(self, text: str):
        if len(text) > MAX_FORMULA:
            raise FormulaError(f"the formula has {len(text)} characters, more than the limit of {MAX_FORMULA}")
        self.text = text
        self.tokens = _tokenize(text)
        self.pos = 0
        self.depth = 0
        self.brackets = 0

    def nested(self, parse: Callable[[], Formula], levels: int = 1, bracket: bool = False) -> Formula:
        """``parse()`` inside ``levels`` more operators (or one more bracket).

        Counts what encloses the current position, so siblings (``p & q & ...``) do not add up.
        The operators counted here all become ancestors in the formula's tree, so their count
        never exceeds the tree's depth, which :func:`parse` checks exactly once the tree is
        built; brackets have their own count (redundant ones add no depth to the tree, but
        nest the parser's recursion).
        """
        if bracket:
            self.brackets += 1
        else:
            self.depth += levels
        try:
            if self.brackets > MAX_DEPTH:
                raise FormulaError(f"the formula nests more than {MAX_DEPTH} brackets inside each other")
            if self.depth > MAX_DEPTH:
                raise FormulaError(_too_deep())
            return parse()
        finally:
            if bracket:
                self.brackets -= 1
            else:
                self.depth -= levels

    def peek(self) -> _Token:
        return self.tokens[self.pos]

    def take(self) -> _Token:
        tok = self.tokens[self.pos]
        self.pos += 1
        return tok

    def fail(self, expected: str, tok: _Token | None = None) -> FormulaError:
        tok = tok or self.peek()
        return _error(self.text, tok.column, expected, _describe(tok))

    def expect(self, symbol: str, expected: str) -> _Token:
        if self.peek().text != symbol or self.peek().kind == "word":
            raise self.fail(expected)
        return self.take()

    def formula(self) -> Formula:
        f = self.implication()
        if self.peek().kind != "end":
            raise self.fail("an operator (&, |, ->, U, S) or the end of the formula")
        return f

    def implication(self) -> Formula:
        left = self.disjunction()
        if self.peek().text == "->":
            self.take()
            return Implies(left, self.nested(self.implication))
        return left

    def disjunction(self) -> Formula:
        args = [self.conjunction()]
        while self.peek().text == "|":
            self.take()
            args.append(self.conjunction())
        return args[0] if len(args) == 1 else Or(tuple(args))

    def conjunction(self) -> Formula:
        args = [self.binary()]
        while self.peek().text == "&":
            self.take()
            args.append(self.binary())
        return args[0] if len(args) == 1 else And(tuple(args))

    def binary(self) -> Formula:
        left = self.unary()
        tok = self.peek()
        if tok.kind == "word" and tok.text in _BINARY_OPS:
            self.take()
            return _BINARY_OPS[tok.text](left, self.nested(self.binary))
        return left

    def unary(self, word: str | None = None, tok: _Token | None = None) -> Formula:
        """A unary formula; ``word`` is the rest of a split word (``"EC"`` of ``"XEC"``)."""
        if word is None:
            tok = self.peek()
            if tok.kind == "op" and tok.text == "!":
                self.take()
                return Not(self.nested(self.unary))
            if tok.kind == "op" and tok.text == "(":
                self.take()
                f = self.nested(self.implication, bracket=True)
                self.expect(")", "')' closing the '(' at column " + str(tok.column))
                return f
            if tok.kind == "op" and tok.text == "{":
                return self.atom()
            if tok.kind != "word":
                raise self.fail("a formula (an atom such as EC(A,B), true, false, '!', '(' "
                                "or a temporal operator)")
            word = tok.text
            self.take()
        if word in _CONSTANTS:
            return Const(_CONSTANTS[word])
        if word in _CODE:
            return self.atom(word)
        if word in _UNARY_OPS:
            return _UNARY_OPS[word](self.nested(self.unary))
        split = _split_unary(word)
        if split is not None:
            ops, rest = split
            inner = self.nested(lambda: self.unary(rest) if rest else self.unary(), len(ops))
            for op in reversed(ops):
                inner = _UNARY_OPS[op](inner)
            return inner
        hint = next((r for r in RELATIONS if r.lower() == word.lower()), None)
        if hint:
            raise self.fail(f"a relation name ({_RELATION_LIST}; did you mean {hint}?)", tok)
        if word in _BINARY_OPS:
            raise self.fail("a formula before the binary operator " + word, tok)
        raise self.fail(f"a formula: a relation name ({_RELATION_LIST}), true, false, or one of "
                        f"the operators ! X F G Y O H", tok)

    def relation_name(self) -> str:
        tok = self.peek()
        if tok.kind != "word" or tok.text not in _CODE:
            hint = next((r for r in RELATIONS
                         if tok.kind == "word" and r.lower() == tok.text.lower()), None)
            raise self.fail(f"a relation name ({_RELATION_LIST}"
                            + (f"; did you mean {hint}?)" if hint else ")"))
        return self.take().text

    def region_name(self) -> str:
        tok = self.peek()
        if tok.kind != "word":
            raise self.fail("a region name")
        return self.take().text

    def atom(self, relation: str | None = None) -> Atom:
        if relation is None:  # a set: { REL (, REL)* }
            self.expect("{", "'{'")
            names = [self.relation_name()]
            while self.peek().text == ",":
                self.take()
                names.append(self.relation_name())
            self.expect("}", "',' or '}' in the set of relations")
        else:
            names = [relation]
        self.expect("(", "'(' after the relation, as in EC(A,B)")
        x = self.region_name()
        self.expect(",", "',' between the two region names")
        y = self.region_name()
        self.expect(")", "')' after the second region name")
        return Atom(frozenset(names), x, y)


def parse(text: str) -> Formula:
    """Parse ST0 text (syntax and precedence in the module docstring) into a formula.

    Raises
    ------
    FormulaError
        With the 1-based ``column`` of the problem and what was ``expected`` there (also as
        attributes of the exception), e.g. ``column 4: expected a region name, found ')'``.

    Examples
    --------
    >>> str(parse("G(EC(F2,O) -> O EC(F1,O))"))
    'G(EC(F2,O) -> O EC(F1,O))'
    """
    if not isinstance(text, str):
        raise FormulaError(f"a formula must be text, not {type(text).__name__}")
    formula = _Parser(text).formula()
    if formula.depth() > MAX_DEPTH:
        raise FormulaError(_too_deep())
    return formula


def _too_deep() -> str:
    return (f"the formula nests more than {MAX_DEPTH} operators inside each other ('!', temporal "
            "operators, &, |, ->, U or S, each inside the next)")

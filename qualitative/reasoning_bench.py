"""Timing of the qualitative reasoning routes: ST0 evaluation and RCC-8 path consistency.

Rows (one run, wall-clock seconds, best of ``repeats``):

- ST0 on a random ``n_frames`` trace of three regions: a formula using every operator, and each
  operator on its own, both end to end (reading the relations out of the frames, then the
  dynamic programme) and for the operator alone on relations already read;
- the naive per-instant evaluator (:func:`qualgrasp.qualitative.st0.evaluate_reference`) against the fast
  route on a shorter trace, for the ratio;
- RCC-8 on ``n_regions`` random discs and boxes: reading the network off the geometry, path
  consistency of that network, and path consistency and a consistent scenario after loosening
  it (half the pairs unconstrained, the rest given as the true relation plus two others).

Speed is reported, never asserted.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from shapely.geometry import Point, box

from .rcc8 import RELATIONS, consistent_scenario, path_consistency, relations_among
from .st0 import _relation_codes, evaluate_reference, parse

__all__ = ["ReasoningRow", "ALL_OPERATORS", "OPERATORS", "random_trace", "random_regions",
           "run_reasoning_bench", "print_reasoning_bench"]

#: A formula using every ST0 operator and both kinds of atom.
ALL_OPERATORS = ("G(EC(A,B) -> F PO(B,C)) | (X DC(A,B) U !{TPP,NTPP}(A,C)) & "
                 "(Y O EC(A,B) S H !EQ(B,C)) | true & !false")

#: One formula per operator (name -> ST0 text).
OPERATORS = {
    "atom": "EC(A,B)", "set atom": "{DC,EC,PO}(A,B)", "!": "!EC(A,B)",
    "&": "EC(A,B) & PO(B,C)", "|": "EC(A,B) | PO(B,C)", "->": "EC(A,B) -> PO(B,C)",
    "X": "X EC(A,B)", "F": "F EC(A,B)", "G": "G EC(A,B)", "U": "EC(A,B) U PO(B,C)",
    "Y": "Y EC(A,B)", "O": "O EC(A,B)", "H": "H EC(A,B)", "S": "EC(A,B) S PO(B,C)",
}


@dataclass(frozen=True)
class ReasoningRow:
    """One timing: what was run, on how much, the best wall-clock time (s), and a remark."""

    task: str
    size: str
    seconds: float
    note: str = ""


def _best(fn, repeats: int) -> float:
    best = np.inf
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - start)
    return float(best)


def random_trace(n: int, seed: int = 0) -> list[dict[tuple[str, str], str]]:
    """``n`` frames over regions A, B, C with independent uniformly random relations."""
    rng = np.random.default_rng(seed)
    codes = rng.integers(0, 8, size=(n, 3))
    pairs = (("A", "B"), ("B", "C"), ("A", "C"))
    return [{pair: RELATIONS[c] for pair, c in zip(pairs, row)} for row in codes.tolist()]


def random_regions(n: int, seed: int = 0) -> dict[str, object]:
    """``n`` discs and boxes of sizes 5 to 300 in a 600 x 600 canvas (nesting and overlaps)."""
    rng = np.random.default_rng(seed)
    out = {}
    for i in range(n):
        x, y = rng.uniform(0, 600, 2)
        size = float(np.exp(rng.uniform(np.log(5), np.log(300))))
        if i % 2:
            out[f"R{i}"] = Point(x, y).buffer(size)
        else:
            out[f"R{i}"] = box(x, y, x + size, y + size * rng.uniform(0.5, 2))
    return out


def _loosen(scenario: dict, seed: int) -> dict:
    rng = np.random.default_rng(seed)
    out = {}
    for (x, y), r in scenario.items():
        if x < y and rng.random() < 0.5:
            others = [s for s in RELATIONS if s != r]
            out[(x, y)] = {r, *rng.choice(others, size=2, replace=False).tolist()}
    return out


def run_reasoning_bench(n_frames: int = 100_000, n_regions: int = 50, reference_frames: int = 2_000,
                        seed: int = 0, repeats: int = 3) -> list[ReasoningRow]:
    """Time ST0 evaluation and RCC-8 reasoning; see the module docstring for the rows."""
    rows = []
    trace = random_trace(n_frames, seed)
    size = f"{n_frames:,} frames"
    formula = parse(ALL_OPERATORS)
    rows.append(ReasoningRow("ST0, every operator, end to end", size,
                             _best(lambda: formula.evaluate(trace), repeats)))
    # the operators alone: relations read out of the frames once, then the dynamic programme
    columns = {pair: _relation_codes(trace, n_frames, pair)
               for pair in (("A", "B"), ("B", "C"), ("A", "C"))}
    rows.append(ReasoningRow("ST0, every operator, relations already read", size,
                             _best(lambda: formula._eval(columns, n_frames), repeats)))
    for name, text in OPERATORS.items():
        f = parse(text)
        end_to_end = _best(lambda: f.evaluate(trace), repeats)
        alone = _best(lambda: f._eval(columns, n_frames), repeats)
        rows.append(ReasoningRow(f"ST0 {name}: {text}", size, end_to_end,
                                 f"{1e3 * alone:.3f} ms on relations already read"))

    short = trace[:reference_frames]
    t_ref = _best(lambda: evaluate_reference(formula, short), 1)
    t_fast = _best(lambda: formula.evaluate(short), repeats)
    rows.append(ReasoningRow("ST0 every operator, naive per-instant reference",
                             f"{reference_frames:,} frames", t_ref,
                             f"{t_ref / t_fast:.0f} x the fast route"))
    rows.append(ReasoningRow("ST0 every operator, fast route", f"{reference_frames:,} frames", t_fast))

    regions = random_regions(n_regions, seed)
    rsize = f"{n_regions} regions"
    scenario = relations_among(regions)
    rows.append(ReasoningRow("RCC-8 network read off the geometry", rsize,
                             _best(lambda: relations_among(regions), 1),
                             f"{n_regions * (n_regions - 1) // 2} pairs"))
    rows.append(ReasoningRow("path consistency, network of base relations", rsize,
                             _best(lambda: path_consistency(scenario), repeats)))
    loose = _loosen(scenario, seed)
    refined = path_consistency(loose)
    left = sum(len(v) > 1 for (x, y), v in refined.items() if x < y)
    rows.append(ReasoningRow("path consistency, loosened network", rsize,
                             _best(lambda: path_consistency(loose), repeats),
                             f"{left} pairs still undecided after it"))
    rows.append(ReasoningRow("consistent scenario (backtracking), loosened network", rsize,
                             _best(lambda: consistent_scenario(loose), repeats)))
    return rows


def print_reasoning_bench(rows: list[ReasoningRow]) -> None:
    """Print the benchmark table with rich."""
    from rich.console import Console
    from rich.table import Table

    table = Table(title="qualitative reasoning: time per call")
    for col, justify in (("task", "left"), ("size", "right"), ("ms", "right"), ("note", "left")):
        table.add_column(col, justify=justify)
    for row in rows:
        table.add_row(row.task, row.size, f"{1e3 * row.seconds:.2f}", row.note)
    Console().print(table)

"""The reference route for the tests of ST0 (:mod:`qualgrasp.qualitative.reasoning.st0`): a
deliberately naive per-instant evaluator written directly from the semantics in st0's module
docstring, sharing nothing with the fast numpy route but the formula tree. Moved verbatim from
st0 (issue 26: test helpers out of production modules)."""

from collections.abc import Sequence

import numpy as np

from qualgrasp.qualitative.errors import TraceError
from qualgrasp.qualitative.reasoning.st0 import (Always, And, Atom, Const, Formula, Frame, Historically, Implies, Next,
                                                 Not, Once, Or, Previous, Since, Sometime, Until)


def evaluate_reference(formula: Formula, trace: Sequence[Frame]) -> np.ndarray:
    """Per-instant evaluation written directly from the semantics (quadratic; for tests).

    Shares nothing with the fast route but the formula tree: atoms look the relation up in each
    frame, and each temporal operator scans the trace from every instant.
    """
    n = len(trace)

    def rel(t, x, y):
        frame = trace[t]
        if x == y:
            return "EQ"
        if (x, y) in frame:
            return frame[(x, y)]
        if (y, x) in frame:
            back = frame[(y, x)]
            return {"TPP": "TPPi", "TPPi": "TPP", "NTPP": "NTPPi", "NTPPi": "NTPP"}.get(back, back)
        raise TraceError(f"frame {t} gives no relation for the pair {(x, y)}")

    def values(f):
        if isinstance(f, Const):
            return [bool(f.value)] * n
        if isinstance(f, Atom):
            return [rel(t, f.x, f.y) in f.relations for t in range(n)]
        if isinstance(f, (And, Or)):
            vs = [values(a) for a in f.args]
            combine = all if isinstance(f, And) else any
            return [combine(v[t] for v in vs) for t in range(n)]
        if isinstance(f, Implies):
            p, q = values(f.left), values(f.right)
            return [(not p[t]) or q[t] for t in range(n)]
        if isinstance(f, Not):
            return [not v for v in values(f.arg)]
        if isinstance(f, (Until, Since)):
            p, q = values(f.left), values(f.right)
            step = 1 if isinstance(f, Until) else -1
            out = []
            for i in range(n):
                j, result = i, False
                while 0 <= j < n:  # walk away from i until q holds or p fails
                    if q[j]:
                        result = True
                        break
                    if not p[j]:
                        break
                    j += step
                out.append(result)
            return out
        p = values(f.arg)
        if isinstance(f, Next):
            return [i + 1 < n and p[i + 1] for i in range(n)]
        if isinstance(f, Previous):
            return [i >= 1 and p[i - 1] for i in range(n)]
        if isinstance(f, Sometime):
            return [any(p[j] for j in range(i, n)) for i in range(n)]
        if isinstance(f, Always):
            return [all(p[j] for j in range(i, n)) for i in range(n)]
        if isinstance(f, Once):
            return [any(p[j] for j in range(0, i + 1)) for i in range(n)]
        if isinstance(f, Historically):
            return [all(p[j] for j in range(0, i + 1)) for i in range(n)]
        raise TypeError(f"not an ST0 formula: {f!r}")

    return np.array(values(formula), dtype=bool).reshape(n)

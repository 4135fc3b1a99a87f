"""Orders, compiled (numba): a stable argsort shared by the kernels.

numba compiles its own ``np.argsort`` (an introsort) anew for every array type, about a second
each on a first run; this bottom-up merge sort compiles in a fraction of that and is stable (ties
keep their index order), so the kernels' results do not depend on the sorting algorithm's way with
ties.
"""

from __future__ import annotations

import numpy as np

from .jit import kernel

__all__ = ["stable_argsort"]


@kernel
def stable_argsort(keys):
    """Indices that sort the 1-D array ``keys`` ascending, ties in index order (as
    ``np.argsort(keys, kind="stable")``)."""
    n = keys.shape[0]
    order = np.arange(n)
    work = np.empty(n, dtype=np.int64)
    width = 1
    while width < n:
        for lo in range(0, n, 2 * width):
            mid, hi = min(lo + width, n), min(lo + 2 * width, n)
            i, j, k = lo, mid, lo
            while i < mid and j < hi:
                if keys[order[j]] < keys[order[i]]:
                    work[k] = order[j]
                    j += 1
                else:
                    work[k] = order[i]
                    i += 1
                k += 1
            while i < mid:
                work[k] = order[i]
                i += 1
                k += 1
            while j < hi:
                work[k] = order[j]
                j += 1
                k += 1
        order, work = work, order
        width *= 2
    return order

"""Orders, compiled (numba): a stable argsort shared by the kernels.

numba compiles its own ``np.argsort`` (an introsort) anew for every array type, about a second
each on a first run; this bottom-up merge sort compiles in a fraction of that and is stable (ties
keep their index order), so the kernels' results do not depend on the sorting algorithm's way with
ties. :func:`radix_argsort` gives the same order for large arrays of non-negative integer keys
in linear time, and :func:`stable_smallest` its first few indices without sorting the rest.
"""

from __future__ import annotations

import numpy as np

from .jit import kernel

__all__ = ["stable_argsort", "stable_smallest", "radix_argsort"]


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


@kernel
def stable_smallest(keys, c):
    """The first ``min(c, n)`` indices of :func:`stable_argsort` of the 1-D array ``keys`` (n,)
    without NaN, in ``O(n c)``: each key is inserted after the kept ones it does not precede, so
    ties keep their index order."""
    out = np.empty(max(0, min(c, keys.shape[0])), dtype=np.int64)
    kept = 0
    for f in range(keys.shape[0] if out.shape[0] else 0):
        x = keys[f]
        if kept == out.shape[0]:
            if not x < keys[out[kept - 1]]:
                continue
            kept -= 1  # the last kept key makes room
        j = kept
        while j > 0 and x < keys[out[j - 1]]:
            out[j] = out[j - 1]
            j -= 1
        out[j] = f
        kept += 1
    return out


#: Bits of the key sorted per pass of :func:`radix_argsort`.
_DIGIT = 11


@kernel
def radix_argsort(keys):
    """:func:`stable_argsort` of non-negative int64 ``keys``, by a least-significant-digit radix
    sort (stable passes of :data:`_DIGIT` bits, as many as the largest key needs): the same
    indices, in linear time, for the ridge keys of large surfaces."""
    n = keys.shape[0]
    order = np.arange(n)
    if n < 64:
        return stable_argsort(keys)
    work = np.empty(n, dtype=np.int64)
    top = 0
    for i in range(n):
        top = max(top, keys[i])
    buckets = 1 << _DIGIT
    count = np.empty(buckets + 1, dtype=np.int64)
    shift = 0
    while shift < 63 and (top >> shift) > 0:
        for b in range(buckets + 1):
            count[b] = 0
        for i in range(n):
            count[((keys[order[i]] >> shift) & (buckets - 1)) + 1] += 1
        for b in range(buckets):
            count[b + 1] += count[b]
        for i in range(n):
            b = (keys[order[i]] >> shift) & (buckets - 1)
            work[count[b]] = order[i]
            count[b] += 1
        order, work = work, order
        shift += _DIGIT
    return order

"""Compiled kernels (numba) of :mod:`qualgrasp.certify`, by concept: small linear algebra and
rigorous bounds (:mod:`.linalg`), the polyhedral LP by basis enumeration (:mod:`.lp`), cone
tests (:mod:`.cones`), the dual barrier method for exact cones (:mod:`.barrier`), rigorous
floating-point re-checks of certificates (:mod:`.recheck`), planar grasps in one pass
(:mod:`.planar`), the exact planar epsilon (:mod:`.epsilon`), the float checks of epsilon
evidence (:mod:`.surface`), the planar epsilon evidence of many grasps at once
(:mod:`.evidence`) and the 3-D hulls it states (:mod:`.hull`). Every kernel is compiled by
:func:`.jit.kernel`, which caches it in the user's cache directory, never in the package.

Kernels take plain float arrays and return plain arrays; the decisions (closure, Farkas,
degenerate, fallback) are made by their callers, so that there is one rule for every route.
This subpackage is private to :mod:`qualgrasp.certify`.
"""

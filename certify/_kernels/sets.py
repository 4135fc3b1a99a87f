"""The kernel sets of the Ferrari-Canny epsilons (:mod:`qualgrasp.certify.quality.bounds`):
pairs of a kernel and the argument types the epsilons call it with, which
:func:`~qualgrasp.certify._kernels.jit.precompile` compiles before a time limit's clock runs.

On a cold compile cache, the sets a run needs are compiled in processes of their own
(:func:`~qualgrasp.certify._kernels.jit.compile_elsewhere`), which import this module: it imports the
kernels alone (numpy and numba), not the rest of the package, so that those processes start
compiling at once.
"""

from __future__ import annotations

from .conic import support_points
from .epsilon import hull_minima, linf_sweep, planar_edges, planar_epsilon_one, support_rows
from .evidence import minkowski_sums, support_choices, support_refine, support_refine_rows, vertex_sums
from .hull import face_planes, hull_faces, hull_grow, hulls_faces, live_facets, used_vertices, weakest_plane
from .jit import B1, BOOL, F1, F2, F3, FLOAT, I1, I2, INT
from .planar import planar_generators
from .surface import cycle_code, face_bounds, face_bounds_laplace, orient_cycle

__all__ = ["KERNEL_SETS", "EPSILON_SETS"]

#: Kernels in more than one set, with the one argument list each is called with: a surface's
#: closure, and the orientation of qhull's faces where the compiled hulls decline.
_CYCLE = (cycle_code, (I2, INT))
_ORIENT = (orient_cycle, (I2, INT, INT, BOOL))
#: The kernels checking planar surfaces, with the argument types the epsilons call them with:
#: compiled before the time limit's clock runs (``_after_compiling`` of :mod:`qualgrasp.certify.quality.bounds`).
_CHECK_KERNELS = ((face_bounds, (F2, F2, I2, I2, F1)), _CYCLE)
#: The kernels the epsilon of spatial grasps calls: the support points, the checks of 6-D faces
#: and the 6-D hulls.
_SURFACE_KERNELS = (
    (support_points, (F2, F2, F2, F2, I1, I1, BOOL, B1, I1, I2, I1, F2, F2, F1, F1, F1, F1)),
    (face_bounds_laplace, (F2, F2, I2, I2, F1)), _CYCLE,
    (hull_grow, (F2, I2, F2, F1, B1, INT, F1, INT)), (weakest_plane, (F2, F1, B1, INT)), (live_facets, (I2, B1, INT)),
    _ORIENT)
#: The same for planar grasps, in five sets: these, ...
_PLANAR_KERNELS = _CHECK_KERNELS + (
    (planar_generators, (F2, F2, F1, F1, F1, FLOAT, I1, F1, F1, F2, F2)),
    (planar_epsilon_one, (F2, I1, INT, BOOL)),
    (minkowski_sums, (F3, F3, I1, INT)),  # the vertices of sums and support evidence
)
#: ... the 3-D hulls (each of the two compiled in a process of its own on a cold cache, while
#: this one compiles closure's: :func:`~qualgrasp.certify.warmup.compile_ahead`), ...
_HULL_KERNELS = (
    (hull_faces, (F2,)),
)
#: ... those of the columnar route alone (many surfaces at once; compiled where that route first
#: runs, never by :func:`~qualgrasp.certify.warmup.compile_ahead`, which serves the per-grasp route), ...
_COLUMN_KERNELS = (
    (hulls_faces, (F2, I1)),  # every planar surface's faces
    (used_vertices, (I2, I1, I1)),
)
#: ... and those of grasps with more than
#: :data:`~qualgrasp.certify.quality.bounds.L1_ENUMERATION_MAX` generators or
#: :data:`~qualgrasp.certify.quality.bounds.SUMS_MAX` sums (the L1 hull minimum, the L-infinity
#: sweep, ``support`` evidence), compiled where a grasp first needs them. They hold the
#: orientation of qhull's faces where the compiled hull declines (rare: points near a plane),
#: which smaller grasps compile on first use: only these grasps run under a time limit (the
#: sweep, ``support`` rows), which must never count a compilation.
_LARGE_KERNELS = (
    (support_rows, (F2, I1, INT, F2, BOOL)),
    (hull_minima, (F3, I1, INT, I2, I1, INT)),
    (planar_edges, (F2, I1)),
    (linf_sweep, (F2, I1, INT, F2, INT, INT, F1, F2)),
    (support_choices, (F2, I1, INT, F2)),
    (vertex_sums, (F2, F2, I2)),
    (face_planes, (F2, I2)),
    (support_refine, (F2, F2, I1, INT, F1, FLOAT, INT, INT, F2, I2, INT, INT)),
    _ORIENT,
)
#: ... and the columnar route's for those grasps: the ``support`` refinement of many rows at once.
_LARGE_COLUMN_KERNELS = (
    (support_refine_rows, (F3, F3, I1, INT, F2, F1, INT, INT, INT, INT)),
)
#: Those kernel sets by name (:func:`~qualgrasp.certify.warmup.compile_ahead`; :mod:`qualgrasp.certify._kernels.jit`).
KERNEL_SETS = {"quality-planar": _PLANAR_KERNELS, "quality-hulls": _HULL_KERNELS,
               "quality-planar-columns": _COLUMN_KERNELS, "quality-planar-large": _LARGE_KERNELS,
               "quality-planar-large-columns": _LARGE_COLUMN_KERNELS, "quality-spatial": _SURFACE_KERNELS}
#: The sets the epsilons of each dimension need.
EPSILON_SETS = {2: ("quality-planar", "quality-hulls"), 3: ("quality-spatial",)}

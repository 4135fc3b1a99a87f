"""Certification at scale: whole grasp-set files, chunks, the columnar fast path.

* :mod:`.jobs`: :func:`certify_file` and :func:`verify_file`, whole files in, results out;
* :mod:`.engine`: the parallel, resumable run over a file's chunks (local processes or dask);
* :mod:`.chunk`: what happens to one chunk (certify every grasp, or re-check every row), and
  :func:`certify_arrow` for Arrow data in memory;
* :mod:`.fastpath`: the columnar route (compiled kernels for whole groups of grasps at once),
  row for row equal to :func:`qualgrasp.certify.certify_grasp` (its results tables are built by
  the private ``_arrow``; the private ``_recheck`` re-checks results tables columnar);
* :mod:`.samples`: random and textbook grasp sets, for trying the toolkit and for benchmarks.
"""

from .chunk import STATUSES, Options, certify_arrow
from .engine import RunSummary, run
from .fastpath import PlanarScreen, certify_table, planar_screen
from .jobs import Summary, certify_file, verify_file
from .samples import random_grasp, random_grasp_table, random_grasps, textbook_grasps, write_random_grasp_file

__all__ = [
    "certify_file", "verify_file", "Summary", "RunSummary", "run",
    "Options", "certify_arrow", "STATUSES", "certify_table", "PlanarScreen", "planar_screen",
    "random_grasp", "random_grasps", "random_grasp_table", "textbook_grasps", "write_random_grasp_file",
]

"""Grasp quality: the Ferrari-Canny epsilon of the L1 and L-infinity grasp wrench spaces, with
rigorous bounds and the evidence that proves them.

* :mod:`.bounds`: computing the bounds ``lo <= epsilon <= hi`` of a grasp in closure (exact in
  the plane; an inner and an outer approximation refined together in space), each with its
  evidence;
* :mod:`.evidence`: the evidence (a direction for ``hi``, an inscribed surface for ``lo``) and
  its re-check without a solver, in exact arithmetic;
* :mod:`.gws`: the grasp wrench space both build on (generators, support points, hulls), so that
  a vertex the evidence names is the vertex that was computed;
* :mod:`.steinitz`: Steinitz-style bounds and the efficiency of contacts on a polygon's boundary.

>>> from qualgrasp.certify import Contact, Grasp
>>> from qualgrasp.certify.quality import epsilon
>>> g = Grasp((Contact((1, 0), (-1, 0), "point", 0.5), Contact((-1, 0), (1, 0), "point", 0.5)))
>>> e = epsilon(g, "L1")
>>> e.exact, round(e.lo, 6)
(True, 0.333333)
"""

from .bounds import NORMS, Epsilon, epsilon, epsilons, planar_epsilon
from .evidence import Evidence, verify_epsilon
from .steinitz import Efficiency, boundary_contacts, boundary_epsilon, edge_samples, efficiency, steinitz_bound

__all__ = [
    "NORMS", "Epsilon", "epsilon", "epsilons", "planar_epsilon",
    "Evidence", "verify_epsilon",
    "Efficiency", "efficiency", "steinitz_bound", "boundary_contacts", "boundary_epsilon", "edge_samples",
]

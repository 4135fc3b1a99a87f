"""qualgrasp.certify: convex certification of closure grasps with re-checkable certificates.

Form closure and positive spanning are linear programmes; force closure is a linear programme in
the plane (friction cones have exactly two edges) and a second-order-cone programme in space
(exact Lorentz cones, no linearisation). Every verdict carries a certificate that
:func:`verify` re-checks with exact rational arithmetic, without any solver, and every
Ferrari-Canny epsilon bound its evidence (:mod:`qualgrasp.certify.quality.evidence`); a results row is
re-checked column by column (:func:`qualgrasp.certify.report.verify_row`).

The subpackages, one concept each (each ``__init__`` lists its public names):

* :mod:`~qualgrasp.certify.core`: grasps, wrenches, cones, the closure programmes and their
  certificates; :mod:`~qualgrasp.certify.models` the contact models, :mod:`~qualgrasp.certify.solvers`
  the solver routes;
* :mod:`~qualgrasp.certify.quality`: the epsilon bounds and the evidence that proves them;
* :mod:`~qualgrasp.certify.report`: one grasp end to end (closure, quality, the results row);
* :mod:`~qualgrasp.certify.regions`: region certificates and independent regions;
* :mod:`~qualgrasp.certify.files`: reading and writing grasp sets and results, safely;
* :mod:`~qualgrasp.certify.batch`: whole files, in parallel chunks, by the columnar fast path;
* :mod:`~qualgrasp.certify.meshes`: grasps of a gripper on a mesh;
* :mod:`~qualgrasp.certify.cli`: the commands, and the option checks every half's commands use;
* :mod:`~qualgrasp.certify.errors`: the exceptions (one root, :class:`QualgraspError`).

>>> from qualgrasp.certify import Contact, Grasp, force_closure
>>> g = Grasp((Contact((1, 0), (-1, 0), "point", 0.5), Contact((-1, 0), (1, 0), "point", 0.5)))
>>> force_closure(g).status
'closure'
"""

from ._lazy import lazy_names
from .errors import (ArgumentError, CertificateError, CertifyError, GraspError, GraspFileError, OptionError,
                     QualgraspError, SolverError, WriteError)

# The other names load from their modules on first use: a process that needs one module of this
# package (one compiling kernels) does not import them all.
__getattr__, __dir__ = lazy_names(__name__, {
    ".batch": ("Options", "certify_arrow"),
    ".core": ("Certificate", "Check", "Contact", "Grasp", "Tolerances", "Verdict", "force_closure", "form_closure",
              "grasp_from_dict", "grasp_to_dict", "positive_span", "verify", "verify_span"),
    ".report": ("Report", "certify_grasp"),
})
del lazy_names  # not a name of this package

__all__ = [
    "Contact", "Grasp", "grasp_from_dict", "grasp_to_dict",
    "Verdict", "force_closure", "form_closure", "positive_span",
    "Certificate", "Check", "Tolerances", "verify", "verify_span",
    "Report", "certify_grasp", "Options", "certify_arrow",
    "QualgraspError", "CertifyError", "ArgumentError", "GraspError", "GraspFileError", "CertificateError",
    "SolverError", "OptionError", "WriteError",
]

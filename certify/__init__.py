"""qualgrasp.certify: convex certification of closure grasps with re-checkable certificates.

Form closure and positive spanning are linear programmes; force closure is a linear programme in
the plane (friction cones have exactly two edges) and a second-order-cone programme in space
(exact Lorentz cones, no linearisation). Every verdict carries a certificate that
:func:`verify` re-checks with exact rational arithmetic, without any solver, and every
Ferrari-Canny epsilon bound its evidence (:mod:`qualgrasp.certify.quality.evidence`); a results row is
re-checked column by column (:func:`qualgrasp.certify.report.verify_row`).

>>> from qualgrasp.certify import Contact, Grasp, force_closure
>>> g = Grasp((Contact((1, 0), (-1, 0), "point", 0.5), Contact((-1, 0), (1, 0), "point", 0.5)))
>>> force_closure(g).status
'closure'
"""

from .core.certificates import Certificate, Check, Tolerances, verify, verify_span
from .core.closure import Verdict, force_closure, form_closure, positive_span
from .errors import CertificateError, CertifyError, GraspError, GraspFileError, SolverError
from .core.grasp import Contact, Grasp, grasp_from_dict, grasp_to_dict
from .report import Report, certify_grasp
from .batch.chunk import Options, certify_arrow

__all__ = [
    "Contact", "Grasp", "grasp_from_dict", "grasp_to_dict",
    "Verdict", "force_closure", "form_closure", "positive_span",
    "Certificate", "Check", "Tolerances", "verify", "verify_span",
    "Report", "certify_grasp", "Options", "certify_arrow",
    "CertifyError", "GraspError", "GraspFileError", "CertificateError", "SolverError",
]

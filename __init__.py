"""qualgrasp: qualitative grasp synthesis from images and convex certification of closure grasps.

The package has three halves, each importable on its own:

* :mod:`qualgrasp.certify`: grasps, closure verdicts with re-checkable certificates, quality;
* :mod:`qualgrasp.qualitative`: vision, qualitative outlines, feasible regions, RCC-8, ST0 and the
  synthesis procedures;
* :mod:`qualgrasp.experiments`: the paper's figures, the comparison study, the demo.

The names below are the main API, re-exported from the halves, and every exception the package
raises on purpose (all derive from :class:`QualgraspError`; :mod:`qualgrasp.certify.errors` states
the rule); ``__version__`` is the installed distribution's version (its one source is
``pyproject.toml``).

Examples
--------
>>> import qualgrasp as qg
>>> g = qg.Grasp((qg.Contact((1, 0), (-1, 0), "point", 0.5),
...               qg.Contact((-1, 0), (1, 0), "point", 0.5)))
>>> v = qg.force_closure(g)
>>> v.status, bool(qg.verify(g, v.certificate, status=v.status, margin=v.margin))
('closure', True)
"""

from importlib.metadata import version

# Absolute imports: this file is also the repository root's __init__.py, which pytest imports
# under the folder's name when it collects tests/; absolute imports load the installed package
# whatever that folder is called.
from qualgrasp.certify import (Certificate, Check, Contact, Grasp, Report, Verdict, certify_grasp,
                               force_closure, form_closure, grasp_from_dict, grasp_to_dict, positive_span,
                               verify)
from qualgrasp.certify.errors import (ArgumentError, CertificateError, CertifyError, GraspError, GraspFileError,
                                      OptionError, QualgraspError, SolverError, WriteError)
from qualgrasp.certify.meshes.errors import GripperError, MeshError, PoseError, PoseFileError
from qualgrasp.certify.quality import Epsilon, epsilon
from qualgrasp.qualitative.errors import (ContourError, FormulaError, ImageError, NetworkError, OutlineError,
                                          QualitativeError, RegionError, SegmentationError, SynthesisError,
                                          TraceError, ZoneError)
from qualgrasp.qualitative.synthesis import Synthesis, synthesize

__version__ = version("qualgrasp")

__all__ = [
    "Contact", "Grasp", "grasp_from_dict", "grasp_to_dict",
    "Verdict", "force_closure", "form_closure", "positive_span",
    "Certificate", "Check", "verify",
    "Report", "certify_grasp",
    "Epsilon", "epsilon",
    "Synthesis", "synthesize",
    "QualgraspError",
    "CertifyError", "ArgumentError", "GraspError", "GraspFileError", "CertificateError", "SolverError",
    "OptionError", "WriteError", "MeshError", "GripperError", "PoseError", "PoseFileError",
    "QualitativeError", "ImageError", "SegmentationError", "ContourError", "OutlineError", "FormulaError",
    "TraceError", "NetworkError", "RegionError", "ZoneError", "SynthesisError",
]

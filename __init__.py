"""qualgrasp: qualitative grasp synthesis from images and convex certification of closure grasps.

The package has three halves, each importable on its own:

* :mod:`qualgrasp.certify`: grasps, closure verdicts with re-checkable certificates, quality;
* :mod:`qualgrasp.qualitative`: vision, qualitative outlines, feasible regions, RCC-8, ST0 and the
  synthesis procedures;
* :mod:`qualgrasp.experiments`: the paper's figures, the comparison study, the demo.

The names below are the main API, re-exported from the halves, and every exception the package
raises on purpose (all derive from :class:`QualgraspError`; :mod:`qualgrasp.certify.errors` states
the rule); ``__version__`` is the installed distribution's version (its one source is
``pyproject.toml``). Names load from their half on first use.

Examples
--------
>>> import qualgrasp as qg
>>> g = qg.Grasp((qg.Contact((1, 0), (-1, 0), "point", 0.5),
...               qg.Contact((-1, 0), (1, 0), "point", 0.5)))
>>> v = qg.force_closure(g)
>>> v.status, bool(qg.verify(g, v.certificate, status=v.status, margin=v.margin))
('closure', True)
"""

from __future__ import annotations

import importlib
from importlib.metadata import version
from typing import TYPE_CHECKING

# Absolute module names: this file is also the repository root's __init__.py, which pytest imports
# under the folder's name when it collects tests/; absolute imports load the installed package
# whatever that folder is called.
_CERTIFY = "qualgrasp.certify"
_ERRORS = "qualgrasp.certify.errors"
_MESH_ERRORS = "qualgrasp.certify.meshes.errors"
_QUALITY = "qualgrasp.certify.quality"
_QUALITATIVE_ERRORS = "qualgrasp.qualitative.errors"
_SYNTHESIS = "qualgrasp.qualitative.synthesis"

# Each name is imported from its half on first use (PEP 562), so that ``import qualgrasp`` (and the
# ``qualgrasp`` command's help) loads none of the numerical libraries until a name needs them.
_HOMES: dict[str, str] = {
    **dict.fromkeys(("Certificate", "Check", "Contact", "Grasp", "Report", "Verdict", "certify_grasp",
                     "force_closure", "form_closure", "grasp_from_dict", "grasp_to_dict", "positive_span",
                     "verify"), _CERTIFY),
    **dict.fromkeys(("ArgumentError", "CertificateError", "CertifyError", "GraspError", "GraspFileError",
                     "OptionError", "QualgraspError", "SolverError", "WriteError"), _ERRORS),
    **dict.fromkeys(("GripperError", "MeshError", "PoseError", "PoseFileError"), _MESH_ERRORS),
    **dict.fromkeys(("Epsilon", "epsilon"), _QUALITY),
    **dict.fromkeys(("ContourError", "FormulaError", "ImageError", "NetworkError", "OutlineError",
                     "QualitativeError", "RegionError", "SegmentationError", "SynthesisError", "TraceError",
                     "ZoneError"), _QUALITATIVE_ERRORS),
    **dict.fromkeys(("Synthesis", "synthesize"), _SYNTHESIS),
}
_HALVES = ("certify", "qualitative", "experiments")

if TYPE_CHECKING:  # what the names are, for type checkers and editors
    from qualgrasp.certify import (Certificate, Check, Contact, Grasp, Report, Verdict, certify_grasp,
                                   force_closure, form_closure, grasp_from_dict, grasp_to_dict,
                                   positive_span, verify)
    from qualgrasp.certify.errors import (ArgumentError, CertificateError, CertifyError, GraspError,
                                          GraspFileError, OptionError, QualgraspError, SolverError, WriteError)
    from qualgrasp.certify.meshes.errors import GripperError, MeshError, PoseError, PoseFileError
    from qualgrasp.certify.quality import Epsilon, epsilon
    from qualgrasp.qualitative.errors import (ContourError, FormulaError, ImageError, NetworkError,
                                              OutlineError, QualitativeError, RegionError, SegmentationError,
                                              SynthesisError, TraceError, ZoneError)
    from qualgrasp.qualitative.synthesis import Synthesis, synthesize

    __version__: str


def __getattr__(name: str):
    if name == "__version__":
        value = version("qualgrasp")
    elif name in _HOMES:
        value = getattr(importlib.import_module(_HOMES[name]), name)
    elif name in _HALVES:
        value = importlib.import_module(f"qualgrasp.{name}")
    else:
        raise AttributeError(f"module 'qualgrasp' has no attribute {name!r}")
    globals()[name] = value  # later uses find it without this function
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__) | {"__version__", *_HALVES})


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

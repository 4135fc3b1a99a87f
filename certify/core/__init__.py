"""The core of certification: grasps, wrenches, contact cones, the closure programmes and their
certificates.

* :mod:`.grasp`: the grasp model (contacts with inward normals and contact models, a torque
  centre and length) and its JSON form; :mod:`.validation` its one set of rules and messages;
* :mod:`.wrench`: wrenches, friction-cone edges and contact frames; :mod:`.cones` the contact
  cones (rays and exact Lorentz cones);
* :mod:`.problem`: the closure programme every solver route shares; :mod:`.closure` the
  verdicts (form closure, force closure, positive spanning), each with a certificate;
* :mod:`.certificates`: the certificates and their verification without a solver, in exact
  rational arithmetic (:mod:`.exact`).

>>> from qualgrasp.certify.core import Contact, Grasp, force_closure
>>> force_closure(Grasp((Contact((1, 0), (-1, 0), "point", 0.5),
...                      Contact((-1, 0), (1, 0), "point", 0.5)))).status
'closure'
"""

from .._lazy import lazy_names

# The names load from their modules on first use (:mod:`qualgrasp.certify._lazy`): the kernels
# import the cone codes of :mod:`.cones` alone.
__getattr__, __dir__ = lazy_names(__name__, {
    ".certificates": ("Certificate", "Check", "Tolerances", "verify", "verify_span"),
    ".closure": ("Verdict", "force_closure", "form_closure", "positive_span"),
    ".grasp": ("Contact", "Grasp", "grasp_from_dict", "grasp_to_dict"),
    ".validation": ("MAX_CONTACTS",),
    ".wrench": ("contact_frame", "cross", "torque"),
})
del lazy_names  # not a name of this package

__all__ = [
    "Contact", "Grasp", "grasp_from_dict", "grasp_to_dict", "MAX_CONTACTS",
    "Verdict", "force_closure", "form_closure", "positive_span",
    "Certificate", "Check", "Tolerances", "verify", "verify_span",
    "contact_frame", "cross", "torque",
]

"""Synthesis procedures as objects, registered by name (see
:mod:`qualgrasp.qualitative.synthesis.procedures.base`).

Built in, in order: ``forcegrasp2``, ``forcegrasp3``, ``formgrasp``, ``pairgrasp3`` (three
fingers beyond the paper's condition: an opposed pair and a third finger). A new procedure is one
module here declaring its search and registering a :class:`Procedure`, plus its import below.

Examples
--------
>>> from qualgrasp.qualitative.synthesis import procedures
>>> procedures.names()
('forcegrasp2', 'forcegrasp3', 'formgrasp', 'pairgrasp3')
>>> procedures.for_fingers(4).title
'FormGrasp'
"""

from .base import Procedure, SearchInput, for_fingers, get, names, procedures, register
from . import forcegrasp2, forcegrasp3, formgrasp, pairgrasp3  # noqa: E402,F401  (registration, in order)

__all__ = ["Procedure", "SearchInput", "register", "get", "procedures", "names", "for_fingers"]

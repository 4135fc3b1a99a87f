"""The synthesis-procedure interface and its registry.

A synthesis procedure turns candidate contacts on an object's feasible grasp regions into grasps.
Each is a :class:`Procedure` registered by name with :func:`register`; synthesis
(:func:`qualgrasp.qualitative.synthesis.pipeline.synthesize`), the command line, the study's routes, plot
labels and colours and the demo are generated from the registry, never from finger counts.

A new procedure is one module in this package declaring its search and registering it, plus its
import in :mod:`qualgrasp.qualitative.synthesis.procedures`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Sequence

import numpy as np

from ....certify import models as registry
from ..candidates import Candidates

__all__ = ["SearchInput", "Procedure", "register", "get", "procedures", "names", "for_fingers"]


@dataclass(frozen=True, eq=False)
class SearchInput:
    """What a search is given (pixels of the input image, x = column, y = row).

    Attributes
    ----------
    candidates : Candidates
        Candidate contacts on the feasible regions.
    contour : numpy.ndarray
        ``(n, 2)`` closed contour of the object.
    center, length
        The object's area centroid and radius (the torque frame of the grasps).
    size : float
        The object's size (diameter of its minimum enclosing circle).
    theta_min : float or None
        Friction cone half-angle, radians (None for frictionless procedures).
    error : float
        Position error (pixels) frictionless grasps must survive.
    margin : float
        Smallest angular margin of friction grasps, fraction of ``theta_min``.
    """

    candidates: Candidates
    contour: np.ndarray
    center: np.ndarray
    length: float
    size: float
    theta_min: float | None
    error: float
    margin: float


@dataclass(frozen=True, eq=False)
class Procedure:
    """A registered synthesis procedure.

    Attributes
    ----------
    name : str
        Registry name (``formgrasp``, ``forcegrasp2``, ``forcegrasp3``).
    title : str
        The paper's name of the procedure (``FormGrasp``, ``ForceGrasp``), recorded in each
        grasp's ``procedure`` field.
    fingers : int
        Number of contacts of its grasps.
    model : str
        Contact model of its fingers (a name of :mod:`qualgrasp.certify.models`); procedures
        with friction take ``mu`` (or ``theta_min``).
    tag : str
        Short tag in grasp ids (``<image>-<tag>-0007``).
    search : callable
        ``search(SearchInput) -> list`` of found grasps (objects with ``points``, ``normals``,
        ``regions``).
    score : callable
        ``score(found) -> float``, higher is better (the procedure's own margin).
    meta : callable
        ``meta(found) -> dict`` of extra fields recorded on each grasp.
    description : str
        One line for help texts.
    failure : str
        What it means that the search found nothing, for messages (the condition no candidate
        tuple met).
    diagnose : callable, optional
        ``diagnose(SearchInput) -> str``: the best near-miss of a search that found nothing, in
        the condition's own terms (e.g. the best angle against ``theta_min``), for messages.
    """

    name: str
    title: str
    fingers: int
    model: str
    tag: str
    search: Callable[[SearchInput], Sequence[Any]]
    score: Callable[[Any], float]
    meta: Callable[[Any], dict]
    description: str = ""
    failure: str = "no candidate tuple met its condition"
    diagnose: Callable[[SearchInput], str] | None = None

    @property
    def friction(self) -> bool:
        """True when the procedure's contacts have friction (it takes ``mu``)."""
        return not registry.get(self.model).is_frictionless

    def label(self, mu: float | None = None) -> str:
        """Label for plots: ``'2 fingers, mu = 0.5 (ForceGrasp)'``."""
        if not self.friction:
            return f"{self.fingers} frictionless ({self.title})"
        return f"{self.fingers} fingers, mu = {mu:g} ({self.title})" if mu is not None else \
            f"{self.fingers} fingers ({self.title})"


_REGISTRY: dict[str, Procedure] = {}


def register(procedure: Procedure) -> Procedure:
    """Register ``procedure`` under its name (in order: the first registered for a finger count
    is the one ``--fingers`` selects)."""
    if procedure.name in _REGISTRY:
        raise ValueError(f"procedure {procedure.name!r} is registered already")
    _REGISTRY[procedure.name] = procedure
    return procedure


def get(name: str) -> Procedure:
    """The registered procedure of that name (KeyError if there is none)."""
    return _REGISTRY[name]


def procedures() -> tuple[Procedure, ...]:
    """The registered procedures, in registration order."""
    return tuple(_REGISTRY.values())


def names() -> tuple[str, ...]:
    """Names of the registered procedures."""
    return tuple(_REGISTRY)


def for_fingers(fingers: int) -> Procedure:
    """The first registered procedure with ``fingers`` contacts (KeyError if there is none)."""
    for p in _REGISTRY.values():
        if p.fingers == fingers:
            return p
    raise KeyError(fingers)

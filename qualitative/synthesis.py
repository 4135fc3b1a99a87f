"""Grasp synthesis from an image: outline, feasible regions, a synthesis procedure, certification.

:func:`synthesize` is the public function behind ``qualgrasp synthesize``. The procedure is a
registered object (:mod:`qualgrasp.qualitative.procedures`), chosen by name or by finger count:

* ``formgrasp`` (4 fingers): FormGrasp (:mod:`qualgrasp.qualitative.formgrasp`), frictionless
  contacts;
* ``forcegrasp2`` and ``forcegrasp3`` (2 and 3 fingers): ForceGrasp
  (:mod:`qualgrasp.qualitative.forcegrasp`), ``point`` contacts with Coulomb friction ``mu``
  (from ``mu``, or ``mu = tan(theta_min)``).

Every grasp found is converted to a :class:`qualgrasp.certify.Grasp` -- contacts in pixels of the input image
(x = column, y = row) with inward unit normals, ``center`` = the object's area centroid and
``length`` = its radius (largest distance from the centroid to the contour), so that epsilons are
comparable across procedures -- with the id ``<name>-<tag>-0007`` (the procedure's tag: ``form``,
``force2``, ``force3``) and the extra fields ``procedure`` (``FormGrasp`` or ``ForceGrasp``),
``fingers``, ``regions`` (indices into the feasible regions list) and the procedure's own fields
(``zone_depth`` for FormGrasp, ``cone_margin`` in radians for ForceGrasp). Each is then certified by :func:`qualgrasp.certify.certify_grasp`;
a synthesised grasp that does not certify is a bug of the synthesis, and is reported, not dropped.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..certify import Contact, Grasp, Report, certify_grasp
from . import procedures as registry
from .candidates import INSET, PER_REGION, STEP, Candidates, candidates, object_frame
from .errors import SynthesisError
from .forcegrasp import MARGIN, friction
from .formgrasp import ERROR
from .outline import Outline, outline_image
from .procedures import Procedure, SearchInput
from .regions import ALPHA, FINGER_WIDTH, MARGIN as REGION_MARGIN, Region, feasible_regions
from .vision import ImageSource

__all__ = ["MU", "Synthesis", "synthesize", "to_grasp", "choose"]

MU = 0.5
"""Default friction coefficient of procedures with friction."""


@dataclass(frozen=True, eq=False)
class Synthesis:
    """Grasps synthesised from one image, with their certification.

    Attributes
    ----------
    name : str
        Image name used in grasp ids (the file's stem, or the name given).
    fingers : int
        Number of contacts of the procedure's grasps.
    procedure : Procedure
        The registered procedure (:mod:`qualgrasp.qualitative.procedures`).
    mu, theta_min : float or None
        Friction coefficient and cone half-angle (radians) of procedures with friction; None for
        frictionless ones.
    outline : Outline
        The object's qualitative outline.
    regions : tuple of Region
        Feasible grasp regions.
    candidates : Candidates
        Candidate contacts sampled on the regions.
    center : numpy.ndarray
        Object's area centroid (x, y), pixels.
    length : float
        Object's radius about ``center``, pixels.
    found : tuple
        The procedure's results (:class:`~qualgrasp.qualitative.formgrasp.FormGrasp` or
        :class:`~qualgrasp.qualitative.forcegrasp.ForceGrasp`), parallel to ``grasps``.
    grasps : tuple of certify.Grasp
        The grasps in certify's format.
    reports : tuple of certify.Report
        Their certification (empty when certification was not asked for).
    seconds : float
        Synthesis time, image to grasps (vision included, certification excluded), seconds.
    certify_seconds : float
        Certification time, seconds.
    """

    name: str
    fingers: int
    procedure: Procedure
    mu: float | None
    theta_min: float | None
    outline: Outline
    regions: tuple[Region, ...]
    candidates: Candidates
    center: np.ndarray
    length: float
    found: tuple[Any, ...]
    grasps: tuple[Grasp, ...]
    reports: tuple[Report, ...]
    seconds: float
    certify_seconds: float

    @property
    def certified(self) -> tuple[bool, ...]:
        """Per grasp: force closure certified (status ``closure`` and both certificates verified)."""
        return tuple(r.certified for r in self.reports)

    @property
    def certified_fraction(self) -> float | None:
        """Fraction of grasps certified (None when there is no grasp or no certification)."""
        if not self.reports:
            return None
        return sum(self.certified) / len(self.reports)

    def summary(self) -> dict[str, Any]:
        """Counts, certified fraction, medians of margin and L1 epsilon (certified grasps), times."""
        ok = [r for r, c in zip(self.reports, self.certified) if c]
        eps = [r.epsilons["L1"].hi for r in ok if r.epsilons]
        return {
            "name": self.name,
            "procedure": self.procedure.name,
            "fingers": self.fingers,
            "mu": self.mu,
            "grasps": len(self.grasps),
            "certified": len(ok),
            "certified_fraction": self.certified_fraction,
            "median_margin": float(np.median([r.force.margin for r in ok])) if ok else None,
            "median_eps_l1": float(np.median(eps)) if eps else None,
            "seconds": self.seconds,
            "certify_seconds": self.certify_seconds,
        }


def to_grasp(found: Any, gid: str, center: np.ndarray, length: float, mu: float | None,
             procedure: Procedure) -> Grasp:
    """A grasp ``procedure`` found, in certify's format (see the module notes for the fields)."""
    model = procedure.model
    contacts = tuple(Contact(tuple(p), tuple(n), model, mu if procedure.friction else None)
                     for p, n in zip(found.points, found.normals))
    meta = {"procedure": procedure.title, "fingers": len(contacts), "regions": list(found.regions),
            **procedure.meta(found)}
    return Grasp(contacts, center=tuple(float(v) for v in center), length=float(length), id=gid, meta=meta)


def choose(fingers: int | None = None, procedure: str | None = None) -> Procedure:
    """The procedure named ``procedure``, else the first registered with ``fingers`` contacts
    (default 2).

    Raises
    ------
    SynthesisError
        Unknown name, no procedure with that many fingers, or a name and a finger count that
        disagree.
    """
    if procedure is not None:
        try:
            proc = registry.get(procedure)
        except KeyError:
            raise SynthesisError(f"unknown procedure {procedure!r}; use one of "
                                 f"{', '.join(registry.names())}") from None
        if fingers is not None and fingers != proc.fingers:
            raise SynthesisError(f"procedure {procedure!r} places {proc.fingers} fingers, not {fingers}")
        return proc
    fingers = 2 if fingers is None else fingers
    try:
        return registry.for_fingers(fingers)
    except KeyError:
        counts = sorted({p.fingers for p in registry.procedures()})
        raise SynthesisError(f"fingers must be one of {', '.join(map(str, counts))} ("
                             + "; ".join(f"{p.fingers}: {p.name}" for p in registry.procedures())
                             + f"), got {fingers}") from None


def _name(image: ImageSource, name: str | None) -> str:
    if name is not None:
        return name
    if isinstance(image, (str, Path)):
        return Path(image).stem
    return "image"


def synthesize(image: ImageSource, fingers: int | None = None, mu: float | None = None,
               theta_min: float | None = None, alpha: float = ALPHA, *, procedure: str | None = None,
               name: str | None = None, certify: bool = True, quality: bool = True,
               threshold: float | None = None, largest: bool = False, finger_width: float = FINGER_WIDTH,
               region_margin: float = REGION_MARGIN, step: float = STEP, inset: float = INSET,
               per_region: int = PER_REGION, error: float = ERROR, margin: float = MARGIN) -> Synthesis:
    """Synthesise and certify grasps of the object in an image.

    Parameters
    ----------
    image : str, pathlib.Path or numpy.ndarray
        Image file or array (see :func:`qualgrasp.qualitative.vision.read_image`).
    fingers : int, optional
        Finger count: the first registered procedure with that many fingers (2: ForceGrasp,
        3: ForceGrasp, 4: FormGrasp); default 2 when ``procedure`` is not given either.
    mu : float, optional
        Friction coefficient of procedures with friction (default 0.5 when ``theta_min`` is not
        given either).
    theta_min : float, optional
        Friction cone half-angle, **radians** (``mu = tan(theta_min)``); instead of ``mu``.
    alpha : float
        Curvature threshold of feasible regions, fraction of the object's size
        (:func:`qualgrasp.qualitative.regions.feasible_regions`).
    procedure : str, optional
        A registered procedure by name (:mod:`qualgrasp.qualitative.procedures`):
        ``forcegrasp2``, ``forcegrasp3``, ``formgrasp``.
    name : str, optional
        Name used in grasp ids (default: the file's stem, or ``image`` for an array).
    certify : bool
        Certify every grasp (:func:`qualgrasp.certify.certify_grasp`).
    quality : bool
        With ``certify``, compute the epsilon quality too.
    threshold, largest
        Segmentation (:func:`qualgrasp.qualitative.outline.outline_image`).
    finger_width, region_margin
        Feasible regions (:func:`qualgrasp.qualitative.regions.feasible_regions`), fractions of the size.
    step, inset, per_region
        Candidate contacts (:func:`qualgrasp.qualitative.candidates.candidates`).
    error : float
        FormGrasp: position error (pixels) the grasps must survive.
    margin : float
        ForceGrasp: smallest angular margin, fraction of ``theta_min``.

    Returns
    -------
    Synthesis

    Raises
    ------
    SynthesisError
        Bad parameters (unknown procedure or finger count, friction given to a frictionless
        procedure, both ``mu`` and ``theta_min``).
    ImageError, SegmentationError, ContourError
        Unusable image (see :func:`qualgrasp.qualitative.outline.outline_image`).

    Examples
    --------
    >>> from qualgrasp.qualitative.objects import render
    >>> from qualgrasp.qualitative.synthesis import synthesize
    >>> s = synthesize(render("polygon"), procedure="formgrasp", quality=False)
    >>> s.procedure.title, s.fingers, len(s.grasps) > 0, all(s.certified)
    ('FormGrasp', 4, True, True)
    """
    proc = choose(fingers, procedure)
    if not proc.friction:
        if mu is not None or theta_min is not None:
            raise SynthesisError(f"{proc.title} ({proc.fingers} fingers) uses frictionless contacts: "
                                 "give no mu or theta_min")
    else:
        if mu is None and theta_min is None:
            mu = MU
        mu, theta_min = friction(mu, theta_min)
    if not (math.isfinite(alpha) and alpha >= 0):
        raise SynthesisError(f"alpha must be finite and >= 0, got {alpha}")
    start = time.perf_counter()
    outline = outline_image(image, threshold=threshold, largest=largest)
    regions = tuple(feasible_regions(outline, alpha, finger_width, region_margin))
    cands = candidates(outline, regions, step, inset, per_region)
    center, length = object_frame(outline.contour)
    found = proc.search(SearchInput(cands, outline.contour, center, length, outline.size, theta_min,
                                    error, margin))
    stem = _name(image, name)
    grasps = tuple(to_grasp(g, f"{stem}-{proc.tag}-{k:04d}", center, length, mu, proc)
                   for k, g in enumerate(found))
    seconds = time.perf_counter() - start
    start = time.perf_counter()
    reports = tuple(certify_grasp(g, quality=quality) for g in grasps) if certify else ()
    return Synthesis(stem, proc.fingers, proc, mu, theta_min, outline, regions, cands,
                     center, length, tuple(found), grasps, reports, seconds, time.perf_counter() - start)

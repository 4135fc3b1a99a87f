"""Grasp synthesis from an image: outline, feasible regions, FormGrasp or ForceGrasp, certification.

:func:`synthesize` is the public function behind ``qualgrasp synthesize``:

* ``fingers=4``: FormGrasp (:mod:`qualgrasp.qualitative.formgrasp`), frictionless contacts;
* ``fingers=2`` or ``3``: ForceGrasp (:mod:`qualgrasp.qualitative.forcegrasp`), ``point`` contacts with
  Coulomb friction ``mu`` (from ``mu``, or ``mu = tan(theta_min)``).

Every grasp found is converted to a :class:`qualgrasp.certify.Grasp` -- contacts in pixels of the input image
(x = column, y = row) with inward unit normals, ``center`` = the object's area centroid and
``length`` = its radius (largest distance from the centroid to the contour), so that epsilons are
comparable across procedures -- with the id ``<name>-form-0007``, ``<name>-force2-0003`` or
``<name>-force3-0001`` and the extra fields ``procedure``, ``fingers``, ``regions`` (indices into
the feasible regions list) and the procedure's own margin (``zone_depth`` for FormGrasp,
``cone_margin`` in radians for ForceGrasp). Each is then certified by :func:`qualgrasp.certify.certify_grasp`;
a synthesised grasp that does not certify is a bug of the synthesis, and is reported, not dropped.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Union

import numpy as np

from qualgrasp.certify import Contact, Grasp, Report, certify_grasp

from .candidates import INSET, PER_REGION, STEP, Candidates, candidates, object_frame
from .errors import SynthesisError
from .forcegrasp import MARGIN, ForceGrasp, friction, pair_grasps, triplet_grasps
from .formgrasp import ERROR, FormGrasp, form_grasps
from .outline import Outline, outline_image
from .regions import ALPHA, FINGER_WIDTH, MARGIN as REGION_MARGIN, Region, feasible_regions
from .vision import ImageSource

__all__ = ["MU", "PROCEDURES", "Synthesis", "synthesize", "to_grasp"]

MU = 0.5
PROCEDURES = {2: "ForceGrasp", 3: "ForceGrasp", 4: "FormGrasp"}
_TAG = {2: "force2", 3: "force3", 4: "form"}


@dataclass(frozen=True, eq=False)
class Synthesis:
    """Grasps synthesised from one image, with their certification.

    Attributes
    ----------
    name : str
        Image name used in grasp ids (the file's stem, or the name given).
    fingers : int
        2 or 3 (ForceGrasp) or 4 (FormGrasp).
    procedure : str
        ``FormGrasp`` or ``ForceGrasp``.
    mu, theta_min : float or None
        Friction coefficient and cone half-angle (radians) of ForceGrasp; None for FormGrasp.
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
    found : tuple of FormGrasp or ForceGrasp
        The qualitative results, parallel to ``grasps``.
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
    procedure: str
    mu: float | None
    theta_min: float | None
    outline: Outline
    regions: tuple[Region, ...]
    candidates: Candidates
    center: np.ndarray
    length: float
    found: tuple[Union[FormGrasp, ForceGrasp], ...]
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
            "procedure": self.procedure,
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


def to_grasp(found: Union[FormGrasp, ForceGrasp], gid: str, center: np.ndarray, length: float,
             mu: float | None) -> Grasp:
    """A synthesised grasp in certify's format (see the module notes for the fields)."""
    if isinstance(found, FormGrasp):
        contacts = tuple(Contact(tuple(p), tuple(n)) for p, n in zip(found.points, found.normals))
        meta = {"procedure": "FormGrasp", "fingers": len(contacts), "regions": list(found.regions),
                "zone_depth": found.depth}
    else:
        contacts = tuple(Contact(tuple(p), tuple(n), "point", mu) for p, n in zip(found.points, found.normals))
        meta = {"procedure": "ForceGrasp", "fingers": len(contacts), "regions": list(found.regions),
                "cone_margin": found.margin}
        if found.point is not None:
            meta["meeting_point"] = [float(v) for v in found.point]
    return Grasp(contacts, center=tuple(float(v) for v in center), length=float(length), id=gid, meta=meta)


def _name(image: ImageSource, name: str | None) -> str:
    if name is not None:
        return name
    if isinstance(image, (str, Path)):
        return Path(image).stem
    return "image"


def synthesize(image: ImageSource, fingers: int = 2, mu: float | None = None, theta_min: float | None = None,
               alpha: float = ALPHA, *, name: str | None = None, certify: bool = True, quality: bool = True,
               threshold: float | None = None, largest: bool = False, finger_width: float = FINGER_WIDTH,
               region_margin: float = REGION_MARGIN, step: float = STEP, inset: float = INSET,
               per_region: int = PER_REGION, error: float = ERROR, margin: float = MARGIN) -> Synthesis:
    """Synthesise and certify grasps of the object in an image.

    Parameters
    ----------
    image : str, pathlib.Path or numpy.ndarray
        Image file or array (see :func:`qualgrasp.qualitative.vision.read_image`).
    fingers : {2, 3, 4}
        2 or 3: ForceGrasp with friction; 4: FormGrasp, frictionless.
    mu : float, optional
        Friction coefficient of ForceGrasp (default 0.5 when ``theta_min`` is not given either).
    theta_min : float, optional
        Friction cone half-angle, **radians** (``mu = tan(theta_min)``); instead of ``mu``.
    alpha : float
        Curvature threshold of feasible regions, fraction of the object's size
        (:func:`qualgrasp.qualitative.regions.feasible_regions`).
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
        Bad parameters (finger count, friction given for FormGrasp, both ``mu`` and ``theta_min``).
    ImageError, SegmentationError, ContourError
        Unusable image (see :func:`qualgrasp.qualitative.outline.outline_image`).
    """
    if fingers not in PROCEDURES:
        raise SynthesisError(f"fingers must be 2 or 3 (ForceGrasp) or 4 (FormGrasp), got {fingers}")
    if fingers == 4:
        if mu is not None or theta_min is not None:
            raise SynthesisError("FormGrasp (4 fingers) uses frictionless contacts: give no mu or theta_min")
    elif mu is None and theta_min is None:
        mu = MU
    if fingers != 4:
        mu, theta_min = friction(mu, theta_min)
    if not (math.isfinite(alpha) and alpha >= 0):
        raise SynthesisError(f"alpha must be finite and >= 0, got {alpha}")
    start = time.perf_counter()
    outline = outline_image(image, threshold=threshold, largest=largest)
    regions = tuple(feasible_regions(outline, alpha, finger_width, region_margin))
    cands = candidates(outline, regions, step, inset, per_region)
    center, length = object_frame(outline.contour)
    if fingers == 4:
        found = form_grasps(cands, outline.contour, center, length, outline.size, error=error)
    elif fingers == 2:
        found = pair_grasps(cands, theta_min, outline.size, margin=margin)
    else:
        found = triplet_grasps(cands, outline.contour, theta_min, outline.size, margin=margin)
    stem = _name(image, name)
    grasps = tuple(to_grasp(g, f"{stem}-{_TAG[fingers]}-{k:04d}", center, length, mu)
                   for k, g in enumerate(found))
    seconds = time.perf_counter() - start
    start = time.perf_counter()
    reports = tuple(certify_grasp(g, quality=quality) for g in grasps) if certify else ()
    return Synthesis(stem, fingers, PROCEDURES[fingers], mu, theta_min, outline, regions, cands,
                     center, length, tuple(found), grasps, reports, seconds, time.perf_counter() - start)

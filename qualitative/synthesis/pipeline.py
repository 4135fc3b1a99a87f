"""Grasp synthesis from an image: outline, feasible regions, a synthesis procedure, certification.

:func:`synthesize` is the public function behind ``qualgrasp synthesize``. The procedure is a
registered object (:mod:`qualgrasp.qualitative.synthesis.procedures`), chosen by name or by finger count:

* ``formgrasp`` (4 fingers): FormGrasp (:mod:`qualgrasp.qualitative.synthesis.formgrasp`), frictionless
  contacts;
* ``forcegrasp2`` and ``forcegrasp3`` (2 and 3 fingers): ForceGrasp
  (:mod:`qualgrasp.qualitative.synthesis.forcegrasp`), ``point`` contacts with Coulomb friction ``mu``
  (from ``mu``, or ``mu = tan(theta_min)``).

Every grasp found is converted to a :class:`qualgrasp.certify.Grasp` -- contacts in pixels of the input image
(x = column, y = row) with inward unit normals, ``center`` = the object's area centroid and
``length`` = its radius (largest distance from the centroid to the contour), so that epsilons are
comparable across procedures -- with the id ``<name>-<tag>-0007`` (the procedure's tag: ``form``,
``force2``, ``force3``) and the extra fields ``procedure`` (``FormGrasp`` or ``ForceGrasp``),
``fingers``, ``regions`` (indices into the feasible regions list) and the procedure's own fields
(``zone_depth`` for FormGrasp, ``cone_margin`` in radians for ForceGrasp), ``resolution``, and
the ``scale`` and ``alpha`` of the regions it was found on (below). Each is then certified by :func:`qualgrasp.certify.certify_grasp`;
a synthesised grasp that does not certify is a bug of the synthesis, and is reported, not dropped.

The finger's scale
------------------
A finger cannot feel a bump smaller than its pad, so feasible regions and the procedures work on
the outline at the **finger's scale** (:func:`qualgrasp.qualitative.vision.scales.finger_scale` of the
pad width ``finger_width``, a fraction of the object's size; never finer than the default scale
0.004), while contacts stay on the one contour the image gives (the same samples at every scale)
and curved regions carry the normals of the outline at the default (fine) scale, so that the
procedure's reasoning and the certification see the same contacts and normals; a straight region
keeps the normal of its fitted line, its points those of the contour. When the procedure finds nothing there, the next coarser
scales of the outline's hierarchy (:func:`qualgrasp.qualitative.vision.scales.outline_scales`) are
tried, at most :data:`FALLBACK_SCALES` of them, and last the default scale (details finer than
the finger; the scale reported says so) (:func:`search_scales`). ``scale`` fixes one scale (no
fallback). :attr:`Synthesis.scale` is the scale the grasps come from, and
:attr:`Synthesis.reason` says why nothing was found.

**Curvature threshold.** Curves are feasible first where their bounding circle under the pad is
wider than :data:`qualgrasp.qualitative.synthesis.regions.ALPHA` of the object's size (flat ones, as the
paper prefers). When no scale gives a grasp, the same scales are tried again with the threshold
relaxed to the finger's own width: a curve is then feasible wherever the pad fits on it (its
circle at least as wide as the pad), such as the rounded tip of a wing or of a cell's protrusion,
which an elongated object may need for a third finger (:func:`search_attempts`). Each grasp
records its ``scale`` and ``alpha``, and :attr:`Synthesis.alpha` is the threshold the grasps come
from; ``alpha`` given fixes it.

**Contacts whose normal the image pins down.** Every attempt is first searched with the
candidates whose normal spread is at most :data:`SPREAD` (10 degrees: the contour's own normal
stays that close within ``error`` pixels of arc either side;
:mod:`qualgrasp.qualitative.synthesis.candidates`), and only when no attempt gives a grasp again with every
candidate. On a lumpy outline (a cell's membrane, bumps of a pixel) a contact placed a pixel or
two off meets a normal tens of degrees away, and a frictionless finger's force turns with it.
:attr:`Synthesis.smooth` says which pass the grasps come from; ``normal_spread=None`` searches
every candidate at once.

Certified tolerance
-------------------
With ``tolerance`` (the default), every certified grasp also gets its **independent contact
regions** (:func:`qualgrasp.qualitative.synthesis.independent.independent_grasp`): a stretch of the outline
around every contact, within the contact's feasible region, over which each finger may land
anywhere and the grasp is still certified in force closure. The grasp's fields (so they reach the
grasp file) state what is certified: ``extents`` (per finger ``[before, after]``, pixels of arc
from the contact to the ends of its certified stretch), ``slide`` (the smallest extent, pixels:
every finger may slide at least that far either way) and ``slide_fraction`` (of the object's
size); and the search's ``delta`` and ``delta_fraction``, the half-width of every stretch
**before** it is clipped at the finger's feasible region (a finger near the end of its region
reaches less far on that side: ``delta`` is not how far it may slide).
:attr:`Synthesis.tolerances` holds the regions with their certificates. A grasp not certified, or
with a contact no stretch can be placed around (on a corner), has these fields None; a certified
grasp for which no sliding is certified has ``slide`` and ``delta`` 0.

Image resolution
----------------
A grasp certified on the contour the image gives may still rest on details the image cannot
resolve (a FormGrasp grasp on a large disc closes only through the pixel contour's facets, which a
disc does not have). :func:`resolution` bounds how far each generator wrench of the grasp can move
under the image's own uncertainty: contact points known to a pixel (:data:`POSITION`), normals to
``NORMAL / l`` radians where ``l`` is the length they are estimated over (the fitted line of a
straight element, four smoothing standard deviations on a curve) and :data:`NORMAL` half a pixel
of the contour's error across it. A contact force ``f`` rotated by
``dtheta`` and moved by ``e`` changes its wrench by at most ``|f| sqrt(dtheta^2 + ((e + r dtheta) /
L)^2)`` (``r`` the lever, ``L`` the length dividing torques), and a grasp whose L1 epsilon exceeds
the largest such change keeps a ball of wrenches after any such change (the hull of the moved
generators is within that distance of the hull): it is **resolved**. A grasp whose certified
epsilon is below it is reported as not resolved by the image, not as a good grasp.

Edge evidence
-------------
A segmentation can follow a shadow's soft boundary or a textured background instead of the
object's edge; a grasp certified on such a contour grasps the shadow. Each grasp records in its
field ``edge_strength`` the image's edge evidence at each contact
(:func:`qualgrasp.qualitative.vision.edges.edge_evidence`: the gradient across the contour at the
contact relative to the contrast and sharpness of the object's edges elsewhere); a contact below
:data:`qualgrasp.qualitative.vision.edges.WEAK_EDGE` is on a **weak edge** (:func:`on_weak_edge`).

One rule for every route. :func:`unresolved_reasons` gives the reasons a certified grasp is not
counted as found, from its own fields and its certified epsilon, whoever planned it:
``below_resolution`` (:func:`below_resolution`, the grasp's field ``resolution``) and
``weak_edge`` (:func:`on_weak_edge`, its field ``edge_strength``), both set by synthesis and by
the study's baseline (:mod:`qualgrasp.experiments.baseline`) alike. Each reason is a
:class:`NotCounted` of :data:`NOT_COUNTED` (a name, the label printed, a predicate), so a
further reason is one more entry; :func:`counted` is a certified grasp with no reason.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Iterator, Sequence

import numpy as np

from ...certify import Contact, Grasp, Report, certify_grasp
from ...certify.errors import GraspError
from ...certify.quality import epsilon
from ...certify.regions import IndependentRegions
from . import procedures as registry
from .candidates import ERROR, INSET, PER_REGION, STEP, Candidates, candidates, object_frame
from ..errors import SynthesisError
from .forcegrasp import MARGIN, friction
from .independent import independent_grasp
from ..vision.outline import DEFAULT_SCALE, SCALE_MAX, SCALE_MIN, Outline, outline_contour
from ..vision.scales import outline_contour_scales, planning_scale
from .procedures import Procedure, SearchInput
from .regions import ALPHA, FINGER_WIDTH, MARGIN as REGION_MARGIN, Region, feasible_regions, on_fine_outline
from ..vision.edges import WEAK_EDGE, edge_evidence, weak_edge
from ..vision.contour import ImageSource, extract_contour

__all__ = ["MU", "POSITION", "NORMAL", "SPREAD", "FALLBACK_SCALES", "FALLBACK_STEP", "NOT_COUNTED", "NotCounted",
           "Synthesis", "synthesize", "to_grasp", "choose", "resolution", "normal_span", "below_resolution",
           "on_weak_edge", "set_edge_strength", "unresolved_reasons", "counted", "search_scales", "search_alphas", "search_attempts"]

MU = 0.5
"""Default friction coefficient of procedures with friction."""

POSITION = 1.0
"""Uncertainty of a contact point found in an image, pixels (the image's resolution)."""

NORMAL = 0.5
"""Error of the contour across the length a normal is estimated over, pixels: a normal estimated
over ``l`` pixels is known to ``NORMAL / l`` radians."""

SPREAD = math.radians(10)
"""Largest normal spread of a contact in synthesis's first pass, radians (module notes): about
three times that of a clean edge or curve in an image (the built-in objects' candidates: at most
3 degrees)."""

FALLBACK_SCALES = 4
"""Coarser scales of the outline's hierarchy tried, one after the other, when a procedure finds
nothing at the finger's scale (up to :data:`qualgrasp.qualitative.vision.outline.SCALE_MAX`)."""

FALLBACK_STEP = 1.4
"""Smallest ratio between consecutive scales tried: the starts of the hierarchy's intervals are
taken only when at least this much coarser than the previous scale tried."""


def below_resolution(grasp: Grasp, eps_l1: float) -> bool:
    """Whether a grasp's certified L1 epsilon ``eps_l1`` is not above its field ``resolution``,
    the largest wrench change the image's uncertainty can cause (:func:`resolution`; module
    notes). False when the grasp records no ``resolution`` (not planned on an image).

    Examples
    --------
    >>> from qualgrasp.certify import Contact, Grasp
    >>> g = Grasp((Contact((1, 0), (-1, 0)), Contact((-1, 0), (1, 0))), meta={"resolution": 0.02})
    >>> below_resolution(g, 0.01), below_resolution(g, 0.05)
    (True, False)
    """
    limit = grasp.meta.get("resolution")
    return limit is not None and not eps_l1 > limit


@dataclass(frozen=True)
class NotCounted:
    """A reason a certified grasp is not counted as found (module notes).

    Attributes
    ----------
    name : str
        Key in summaries and the study's table columns (``below_resolution``).
    label : str
        What ``qualgrasp synthesize`` prints after ``verified,``.
    applies : callable
        ``applies(grasp, eps_l1) -> bool``, from the grasp's fields and its certified L1 epsilon.
    note : str
        What it means for the user, printed after the summary when some grasp has the reason.
    """

    name: str
    label: str
    applies: Any
    note: str = ""


def on_weak_edge(grasp: Grasp, eps_l1: float) -> bool:
    """Whether a contact of the grasp lies where the image shows no clear edge of the object (its
    field ``edge_strength`` has a value below :data:`qualgrasp.qualitative.vision.edges.WEAK_EDGE`;
    module notes): a shadow's or a texture's boundary. False without the field. ``eps_l1`` is
    not used (the signature of :class:`NotCounted`).

    Examples
    --------
    >>> from qualgrasp.certify import Contact, Grasp
    >>> g = Grasp((Contact((1, 0), (-1, 0)), Contact((-1, 0), (1, 0))), meta={"edge_strength": [0.9, 0.1]})
    >>> on_weak_edge(g, 1.0)
    True
    """
    return weak_edge(grasp.meta.get("edge_strength"))


NOT_COUNTED: tuple[NotCounted, ...] = (
    NotCounted("below_resolution", "BELOW IMAGE RESOLUTION", below_resolution,
               "are below the image's resolution: their certified epsilon is smaller than the wrench "
               "change that a pixel of error in the contacts and their normals can cause, so the closure "
               "may be an artefact of the pixels; do not rely on them"),
    NotCounted("weak_edge", "ON A WEAK EDGE (shadow or texture?)", on_weak_edge,
               f"have a contact where the image shows no clear edge of the object (field edge_strength "
               f"below {WEAK_EDGE:g}): the contour there may follow a shadow or a textured background, not the "
               "object; look at --plot, try --segmentation multiotsu (a shadow), adaptive (uneven "
               "lighting) or grabcut (a textured background), or give the object's mask with --mask"),
)
"""Every reason a certified grasp is not counted as found, in the order reported."""


def unresolved_reasons(grasp: Grasp, eps_l1: float) -> tuple[str, ...]:
    """Names of the reasons of :data:`NOT_COUNTED` that apply to a certified grasp of certified L1
    epsilon ``eps_l1`` (module notes), for any route that planned it.

    Examples
    --------
    >>> from qualgrasp.certify import Contact, Grasp
    >>> g = Grasp((Contact((1, 0), (-1, 0)), Contact((-1, 0), (1, 0))), meta={"resolution": 0.02})
    >>> unresolved_reasons(g, 0.01), unresolved_reasons(g, 0.05)
    (('below_resolution',), ())
    """
    return tuple(r.name for r in NOT_COUNTED if r.applies(grasp, eps_l1))


def counted(grasp: Grasp, certified: bool, eps_l1: float) -> bool:
    """Whether a grasp counts as found: ``certified`` and no reason of :func:`unresolved_reasons`.

    Examples
    --------
    >>> from qualgrasp.certify import Contact, Grasp
    >>> g = Grasp((Contact((1, 0), (-1, 0)), Contact((-1, 0), (1, 0))), meta={"resolution": 0.02})
    >>> counted(g, True, 0.05), counted(g, True, 0.01), counted(g, False, 0.05)
    (True, False, False)
    """
    return bool(certified) and not unresolved_reasons(grasp, eps_l1)


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
        The registered procedure (:mod:`qualgrasp.qualitative.synthesis.procedures`).
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
        The procedure's results (:class:`~qualgrasp.qualitative.synthesis.formgrasp.FormGrasp` or
        :class:`~qualgrasp.qualitative.synthesis.forcegrasp.ForceGrasp`), parallel to ``grasps``.
    grasps : tuple of certify.Grasp
        The grasps in certify's format.
    reports : tuple of certify.Report
        Their certification (empty when certification was not asked for).
    seconds : float
        Synthesis time, image to grasps (vision included, certification excluded), seconds.
    certify_seconds : float
        Certification time, seconds.
    tolerances : tuple of IndependentRegions or None
        Per grasp, its certified independent contact regions (module notes), None when not
        computed (``tolerance=False``, no certification, or the grasp not certified); empty when
        not asked for.
    scale : float
        The outline's scale the regions and grasps come from (fraction of the perimeter; module
        notes); ``outline`` is the outline at that scale.
    scales_tried : tuple of float
        Every scale tried, in order (the last is ``scale``; a scale comes again with the next
        curvature threshold, and in the second pass with every candidate).
    reason : str or None
        Why no grasp was found (None when some were): no feasible region at any scale tried, or
        feasible regions on which the procedure found no grasp, with the procedure's best
        near-miss in numbers.
    alpha : float
        The curvature threshold of the feasible regions the grasps come from (fraction of the
        object's size; module notes).
    alphas_tried : tuple of float
        The curvature threshold of every attempt, parallel to ``scales_tried``.
    smooth : bool
        Whether the grasps' contacts all have a normal spread within ``normal_spread`` (module
        notes); False when only contacts of any spread gave grasps, or ``normal_spread`` was None.
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
    tolerances: tuple[IndependentRegions | None, ...] = ()
    scale: float = DEFAULT_SCALE
    scales_tried: tuple[float, ...] = ()
    reason: str | None = None
    alpha: float = ALPHA
    alphas_tried: tuple[float, ...] = ()
    smooth: bool = True

    @property
    def deltas(self) -> tuple[float | None, ...]:
        """Per grasp, the search's half-width ``delta`` before clipping, as a fraction of the
        object's size (None when not computed; module notes: not how far a finger may slide,
        :attr:`slides` is)."""
        return tuple(g.meta.get("delta_fraction") for g in self.grasps)

    @property
    def slides(self) -> tuple[float | None, ...]:
        """Per grasp, the certified slide as a fraction of the object's size: how far every
        finger may slide along the outline either way with closure certified (None when not
        computed; 0 when no sliding is certified)."""
        return tuple(g.meta.get("slide_fraction") for g in self.grasps)

    @property
    def resolved(self) -> tuple[bool, ...]:
        """Per grasp: counted as found (:func:`counted`: certified, and no reason of
        :data:`NOT_COUNTED` applies, such as a certified L1 epsilon not above the wrench change
        the image's uncertainty can cause; module notes)."""
        return tuple(counted(g, c, r.eps_l1) for c, r, g in zip(self.certified, self.reports, self.grasps))

    @property
    def not_counted(self) -> tuple[tuple[str, ...], ...]:
        """Per grasp, the reasons it is not counted although certified (:func:`unresolved_reasons`;
        empty for a grasp not certified)."""
        return tuple(unresolved_reasons(g, r.eps_l1) if c else () for c, r, g in
                     zip(self.certified, self.reports, self.grasps))

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
        """Counts (``resolved``: counted as found; one count per reason of :data:`NOT_COUNTED`,
        by its name), certified fraction, medians of margin and L1 epsilon (certified grasps), median
        certified slide (``median_slide_fraction``) and median ``delta`` before clipping
        (``median_delta_fraction``; both None without tolerances), times."""
        ok = [r for r, c in zip(self.reports, self.certified) if c]
        eps = [r.epsilons["L1"].hi for r in ok if r.epsilons]
        deltas = [d for d in self.deltas if d is not None]
        slides = [d for d in self.slides if d is not None]
        return {
            "name": self.name,
            "procedure": self.procedure.title,
            "procedure_name": self.procedure.name,
            "fingers": self.fingers,
            "mu": self.mu,
            "grasps": len(self.grasps),
            "certified": len(ok),
            "resolved": sum(self.resolved),
            **{r.name: sum(r.name in why for why in self.not_counted) for r in NOT_COUNTED},
            "certified_fraction": self.certified_fraction,
            "median_margin": float(np.median([r.force.margin for r in ok])) if ok else None,
            "median_eps_l1": float(np.median(eps)) if eps else None,
            "median_delta_fraction": float(np.median(deltas)) if deltas else None,
            "median_slide_fraction": float(np.median(slides)) if slides else None,
            "scale": self.scale,
            "alpha": self.alpha,
            "smooth": self.smooth,
            "reason": self.reason,
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


def _certified(grasp: Grasp, quality: bool) -> Report:
    """The grasp's report, with at least its L1 epsilon (needed to tell resolved grasps)."""
    report = certify_grasp(grasp, quality=quality)
    if quality:
        return report
    return replace(report, epsilons={"L1": epsilon(grasp, "L1", verdict=report.force)})


def resolution(grasp: Grasp, spans) -> float:
    """Largest change of any generator wrench of a planar ``grasp`` under the image's
    uncertainty (module notes): every contact point within :data:`POSITION` pixels, every normal
    within ``NORMAL / span`` radians, ``spans`` the length (pixels) each contact's normal is
    estimated over. Unit-free, like the wrenches (torques divided by the grasp's ``length``).

    Examples
    --------
    >>> from qualgrasp.certify import Contact, Grasp
    >>> g = Grasp((Contact((100, 0), (-1, 0)), Contact((-100, 0), (1, 0))), center=(0, 0), length=100)
    >>> round(resolution(g, [50, 50]), 4)  # 0.01 rad on a lever of 100 px, and a pixel
    0.0224
    """
    out = 0.0
    c = np.asarray(grasp.center)
    for contact, span in zip(grasp.contacts, spans):
        turn = NORMAL / span
        lever = float(np.linalg.norm(np.asarray(contact.p) - c))
        force = math.sqrt(1 + contact.mu ** 2)  # the longest generator: a friction-cone edge
        out = max(out, force * math.hypot(turn, (POSITION + lever * turn) / grasp.length))
    return out


def normal_span(outline: Outline) -> float:
    """Length (pixels) over which an outline's smoothed normals are estimated: four smoothing
    standard deviations (module notes, image resolution).

    Examples
    --------
    >>> import numpy as np
    >>> from qualgrasp.qualitative.vision.outline import outline_contour
    >>> square = np.array([[0, 0], [100, 0], [100, 100], [0, 100]], float)
    >>> round(normal_span(outline_contour(square)), 3)  # 4 x 0.004 x 400 px
    6.4
    """
    return 4 * outline.scale * outline.perimeter


def _spans(outline: Outline, regions, found, fine: Outline) -> list[float]:
    """Length over which each contact's normal is estimated (pixels): the fitted line of a
    straight edge (its element, or its region when the edge runs on into its corners' windows,
    :mod:`qualgrasp.qualitative.synthesis.regions`), four smoothing standard deviations of the fine outline on a curve (the
    normals curved regions carry; :func:`qualgrasp.qualitative.synthesis.regions.on_fine_outline`)."""
    out = []
    for r in found.regions:
        seg = outline.segments[regions[r].segment]
        # a straight region's normal is its edge's line, fitted over at least the region
        out.append(max(float(np.linalg.norm(seg.endpoints[1] - seg.endpoints[0])), regions[r].length)
                   if seg.symbol == "/" else normal_span(fine))
    return out


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


def set_edge_strength(grasps: Sequence[Grasp], image: ImageSource, contour, normals) -> None:
    """Record in each grasp's field ``edge_strength`` the image's edge evidence at its contacts
    (:func:`qualgrasp.qualitative.vision.edges.edge_evidence` against the object's ``contour`` and its
    inward ``normals``, pixels; module notes), for every route that plans on an image."""
    if not grasps:
        return
    P = np.array([c.p[:2] for g in grasps for c in g.contacts], dtype=float)
    N = np.array([c.n[:2] for g in grasps for c in g.contacts], dtype=float)
    strengths = edge_evidence(image, contour, normals, P, N)
    k = 0
    for g in grasps:
        g.meta["edge_strength"] = [round(float(v), 4) for v in strengths[k:k + len(g.contacts)]]
        k += len(g.contacts)


def _name(image: ImageSource, name: str | None) -> str:
    if name is not None:
        return name
    if isinstance(image, (str, Path)):
        return Path(image).stem
    return "image"


def synthesize(image: ImageSource, fingers: int | None = None, mu: float | None = None,
               theta_min: float | None = None, alpha: float | None = None, *, procedure: str | None = None,
               name: str | None = None, certify: bool = True, quality: bool = True,
               threshold: float | None = None, largest: bool = False, method: str = "otsu",
               mask: ImageSource | None = None, rect: tuple[int, int, int, int] | None = None,
               finger_width: float = FINGER_WIDTH,
               region_margin: float = REGION_MARGIN, step: float = STEP, inset: float = INSET,
               per_region: int = PER_REGION, error: float = ERROR, margin: float = MARGIN,
               tolerance: bool = True, scale: float | None = None, explain: bool = True,
               normal_spread: float | None = SPREAD) -> Synthesis:
    """Synthesise and certify grasps of the object in an image.

    Parameters
    ----------
    image : str, pathlib.Path or numpy.ndarray
        Image file or array (see :func:`qualgrasp.qualitative.vision.contour.read_image`).
    fingers : int, optional
        Finger count: the first registered procedure with that many fingers (2: ForceGrasp,
        3: ForceGrasp, 4: FormGrasp); default 2 when ``procedure`` is not given either.
    mu : float, optional
        Friction coefficient of procedures with friction (default 0.5 when ``theta_min`` is not
        given either).
    theta_min : float, optional
        Friction cone half-angle, **radians** (``mu = tan(theta_min)``); instead of ``mu``.
    alpha : float, optional
        Curvature threshold of feasible regions, fraction of the object's size
        (:func:`qualgrasp.qualitative.synthesis.regions.feasible_regions`); default
        :data:`~qualgrasp.qualitative.synthesis.regions.ALPHA`, relaxed to ``finger_width`` when nothing is
        found (module notes). Given, it is the only one tried.
    procedure : str, optional
        A registered procedure by name (:mod:`qualgrasp.qualitative.synthesis.procedures`):
        ``forcegrasp2``, ``forcegrasp3``, ``formgrasp``.
    name : str, optional
        Name used in grasp ids (default: the file's stem, or ``image`` for an array).
    certify : bool
        Certify every grasp (:func:`qualgrasp.certify.certify_grasp`).
    quality : bool
        With ``certify``, compute both epsilons (L1 and L-infinity); otherwise only the L1
        epsilon, which tells resolved grasps (module notes).
    threshold, largest, method, mask, rect
        Segmentation (:func:`qualgrasp.qualitative.vision.contour.extract_contour`): a grey level, the
        largest of several objects, the method (``"otsu"``, ``"multiotsu"``, ``"adaptive"``,
        ``"grabcut"``), a user's mask of the object, GrabCut's rectangle ``(x, y, w, h)``. The
        contour is extracted once; every scale's outline is computed from it.
    finger_width, region_margin
        Feasible regions (:func:`qualgrasp.qualitative.synthesis.regions.feasible_regions`), fractions of the size.
    step, inset, per_region
        Candidate contacts (:func:`qualgrasp.qualitative.synthesis.candidates.candidates`).
    error : float
        Position error (pixels) the grasps must survive: FormGrasp's zone depth, and the window
        of the candidates' normal spread.
    margin : float
        ForceGrasp: smallest angular margin, fraction of ``theta_min``.
    tolerance : bool
        With ``certify``, give every certified grasp its certified slide and extents
        (independent contact regions, module notes; about 0.05 to 0.5 s per grasp).
    scale : float, optional
        The outline's scale (fraction of the perimeter, in ``[0.001, 0.032]``) for regions and
        procedures; default the finger's scale with coarser fallbacks (module notes).
    normal_spread : float or None
        Largest normal spread of a contact (radians; module notes) in the first pass over the
        attempts; None: one pass with every candidate.
    explain : bool
        When nothing is found, give the procedure's best near-miss in numbers in
        :attr:`Synthesis.reason` (another pass over the candidates of the largest search; the
        reason without numbers otherwise).

    Returns
    -------
    Synthesis

    Raises
    ------
    SynthesisError
        Bad parameters (unknown procedure or finger count, friction given to a frictionless
        procedure, both ``mu`` and ``theta_min``).
    ImageError, SegmentationError, ContourError
        Unusable image (see :func:`qualgrasp.qualitative.vision.outline.outline_image`).

    Examples
    --------
    >>> from qualgrasp.qualitative.objects import render
    >>> from qualgrasp.qualitative.synthesis.pipeline import synthesize
    >>> s = synthesize(render("polygon"), procedure="formgrasp", quality=False, tolerance=False)
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
    if alpha is not None and not (math.isfinite(alpha) and alpha >= 0):
        raise SynthesisError(f"alpha must be finite and >= 0, got {alpha}")
    if normal_spread is not None and not 0 <= normal_spread <= math.pi:
        raise SynthesisError(f"normal_spread must be in [0, pi] radians or None, got {normal_spread}")
    if scale is not None and not (math.isfinite(scale) and SCALE_MIN <= scale <= SCALE_MAX):
        raise SynthesisError(f"scale must be in [{SCALE_MIN:g}, {SCALE_MAX:g}] (fraction of the perimeter), "
                             f"got {scale}")
    start = time.perf_counter()
    contour = extract_contour(image, threshold=threshold, largest=largest, method=method, mask=mask, rect=rect)
    fine = outline_contour(contour)
    center, length = object_frame(fine.contour)
    tried: list[tuple[float, float, bool]] = []
    most, richest, found = 0, None, []
    attempts: list[tuple] = []  # (scale, alpha, outline, regions, every candidate, the first pass's), for the second
    for rough in (False, True):
        if rough and (found or normal_spread is None):
            break
        source = iter(attempts) if rough else _attempt_regions(contour, fine, finger_width, scale, alpha,
                                                                region_margin)
        for item in source:
            if rough:
                s, a, outline, regions, cands, first = item
                if len(first) == len(cands):
                    continue  # every contact is smooth: the first pass searched these already
            else:
                s, a, outline, regions = item
                every = candidates(outline, regions, step, inset, per_region, error)
                cands = every if normal_spread is None else every.smooth(normal_spread)
                attempts.append((s, a, outline, regions, every, cands))
            tried.append((s, a, rough))
            most = max(most, len(regions))
            search = SearchInput(cands, outline.contour, center, length, outline.size, theta_min, error, margin)
            if richest is None or len(cands) > len(richest[0].candidates):
                richest = (search, s, a)
            found = proc.search(search)
            if found:
                break
    smooth = normal_spread is not None and not (found and tried[-1][2])
    reason = None if found else _reason(proc, tried, most, richest if explain else None)
    stem = _name(image, name)
    grasps = []
    for k, g in enumerate(found):
        grasp = to_grasp(g, f"{stem}-{proc.tag}-{k:04d}", center, length, mu, proc)
        grasp.meta["resolution"] = resolution(grasp, _spans(outline, regions, g, fine))
        grasp.meta["scale"] = outline.scale
        grasp.meta["alpha"] = a
        grasps.append(grasp)
    grasps = tuple(grasps)
    set_edge_strength(grasps, image, fine.contour, fine.normals())
    seconds = time.perf_counter() - start
    start = time.perf_counter()
    reports = tuple(_certified(g, quality) for g in grasps) if certify else ()
    tolerances = tuple(_tolerance(fine, regions, g, r) for g, r in zip(grasps, reports)) if tolerance else ()
    return Synthesis(stem, proc.fingers, proc, mu, theta_min, outline, regions, cands,
                     center, length, tuple(found), grasps, reports, seconds, time.perf_counter() - start,
                     tolerances, outline.scale, tuple(t[0] for t in tried), reason, a, tuple(t[1] for t in tried),
                     smooth)


def search_scales(contour: np.ndarray, fine: Outline, finger_width: float, scale: float | None = None):
    """The outline scales synthesis tries, in order (module notes): ``scale`` alone when given;
    else the finger's scale (never finer than the default), then up to :data:`FALLBACK_SCALES`
    coarser scales of the hierarchy of the object's ``contour`` (as extracted from the image,
    :func:`qualgrasp.qualitative.vision.contour.extract_contour`; ``fine`` is its outline at the default
    scale), each the start of an interval with another string and at least :data:`FALLBACK_STEP`
    times the previous scale, and last the default (fine) scale. A generator: the hierarchy is
    computed only when the first scale is not enough."""
    if scale is not None:
        yield scale
        return
    first = planning_scale(fine, finger_width)
    yield first
    last, count = first, 0
    for iv in outline_contour_scales(contour):
        # real outlines change string at many nearby fine scales: step by a factor at least
        if iv.lo >= last * FALLBACK_STEP and count < FALLBACK_SCALES:
            yield iv.lo
            last, count = iv.lo, count + 1
    if first > fine.scale:
        yield fine.scale  # last resort: details finer than the finger, flagged by the scale reported


def search_alphas(alpha: float | None, finger_width: float) -> tuple[float, ...]:
    """The curvature thresholds synthesis tries, in order (module notes): ``alpha`` alone when
    given; else :data:`qualgrasp.qualitative.synthesis.regions.ALPHA`, then the finger's own width (a curve
    is feasible where its bounding circle under the pad is at least as wide as the pad) when that
    is lower.

    Examples
    --------
    >>> search_alphas(None, 0.08)
    (0.5, 0.08)
    >>> search_alphas(0.3, 0.08)
    (0.3,)
    """
    if alpha is not None:
        return (alpha,)
    return (ALPHA, finger_width) if finger_width < ALPHA else (ALPHA,)


def search_attempts(contour: np.ndarray, fine: Outline, finger_width: float, scale: float | None = None,
                    alpha: float | None = None) -> Iterator[tuple[float, float]]:
    """The ``(scale, alpha)`` pairs synthesis tries, in order (module notes): every scale of
    :func:`search_scales` at the first curvature threshold of :func:`search_alphas`, then the same
    scales at the next threshold. A generator: the hierarchy is computed only when the first scale
    is not enough, and once."""
    scales: list[float] = []
    for k, a in enumerate(search_alphas(alpha, finger_width)):
        if k == 0:
            for s in search_scales(contour, fine, finger_width, scale):
                scales.append(s)
                yield s, a
        else:
            yield from ((s, a) for s in scales)


def _attempt_regions(contour: np.ndarray, fine: Outline, finger_width: float, scale: float | None,
                     alpha: float | None, margin: float):
    """Per attempt of :func:`search_attempts`: ``(scale, alpha, outline, regions)``, each scale's
    outline computed once; an attempt whose regions are those of an earlier one at the same scale
    (no curve between the two thresholds) is skipped."""
    outlines = {fine.scale: fine}
    seen = set()
    for s, a in search_attempts(contour, fine, finger_width, scale, alpha):
        if s not in outlines:
            outlines[s] = outline_contour(contour, scale=s)
        regions = on_fine_outline(feasible_regions(outlines[s], a, finger_width, margin), fine, outlines[s])
        key = (s, tuple((r.start, r.stop) for r in regions))
        if key not in seen:
            seen.add(key)
            yield s, a, outlines[s], regions


def _tried(tried: list[tuple[float, float, bool]]) -> str:
    """``'0.0066, 0.004 at alpha 0.5; 0.0066 at alpha 0.08; 0.0066 at alpha 0.5 with contacts of any
    normal spread'``: the attempts by threshold and pass."""
    parts = []
    for a, rough in dict.fromkeys((t[1], t[2]) for t in tried):
        parts.append(", ".join(f"{s:.4g}" for s, b, r in tried if (b, r) == (a, rough)) + f" at alpha {a:g}"
                     + (" with contacts of any normal spread" if rough else ""))
    return "; ".join(parts)


def _reason(proc: Procedure, tried: list[tuple[float, float, bool]], regions: int,
            richest: tuple[SearchInput, float, float] | None) -> str:
    """Why ``proc`` found nothing at the ``(scale, alpha, rough)`` attempts ``tried`` (``regions``: the
    most feasible regions at any of them; ``richest``: the attempt with the most candidates, with
    its scale and alpha, for the procedure's own diagnosis; None to skip it)."""
    at = _tried(tried)
    if not regions:
        return f"no feasible region at the scales tried ({at})"
    why = proc.failure
    if proc.diagnose is not None and richest is not None and len(richest[0].candidates):
        search, s, a = richest
        why += f" ({proc.diagnose(search)}; at scale {s:.4g} and alpha {a:g})"
    return f"{proc.title} found no grasp on up to {regions} feasible region(s) at the scales tried ({at}): {why}"


def _tolerance(outline: Outline, regions: tuple[Region, ...], grasp: Grasp,
               report: Report) -> IndependentRegions | None:
    """The certified independent regions of a certified grasp (None otherwise), recorded in the
    grasp's fields ``slide`` (pixels), ``slide_fraction``, ``extents`` and ``delta`` (pixels),
    ``delta_fraction`` (module notes)."""
    for key in ("delta", "delta_fraction", "slide", "slide_fraction", "extents"):
        grasp.meta[key] = None
    if not report.certified:
        return None
    try:
        found = independent_grasp(outline, grasp, regions=list(regions))
    except GraspError:  # a contact the regions cannot place (on a corner): no certified tolerance
        return None
    # undecided: in closure, but no sliding certified, so the certified slide is 0
    grasp.meta.update(delta=float(found.delta), delta_fraction=float(found.delta_fraction),
                      slide=float(found.slide), slide_fraction=float(found.slide_fraction),
                      extents=[[float(v) for v in e] for e in found.extents])
    return found

"""Independent contact regions of grasps on an object seen by a camera.

For each grasp (certify's format, contacts on the object's outline, e.g. from ``qualgrasp
synthesize``), how far may every finger slide along the outline, and the grasp stay in force
closure whichever point of its stretch each finger touches? The certified stretches are stated
by their **extents** (per finger, the arc length from the contact to each end of its certified
region) and the **certified slide** (the smallest extent: every finger may slide at least that
far either way). :func:`independent_grasp` answers with
:func:`qualgrasp.certify.regions.independent_regions` on the outline's boundary
(:func:`outline_boundary`) and limits from the feasible regions; :func:`independent_file` runs it
on a grasp set, one results row per grasp line.

Readings (pixels of the input image, x = column, y = row):

* **Boundary.** The outline's contour, with every straight element (``/``) projected onto its
  total-least-squares line and given that line's inward normal (as feasible regions are), and
  every other sample taken from the contour smoothed at the outline's scale, with its normal
  (so points and normals describe one curve; the raw contour differs from it by pixel noise).
* **Limits.** A finger must stay in the feasible region it lies on (a region's points are where
  the centre of a finger pad may go), or, off every region, on its outline element; a contact on a
  corner or a cusp is an error. A grasp from ``qualgrasp synthesize`` records the outline scale
  and curvature threshold its regions were found at (fields ``scale`` and ``alpha``): its limits
  are those regions (:func:`planned_regions`).
* **Contacts.** Each is placed at the nearest boundary point (within 1 % of the object's size);
  the grasp itself, as given, decides ``not_robust``.

Results rows: ``id``, ``line``, ``status`` (``robust``, ``not_robust``, ``undecided``, ``error``),
``slide`` (pixels: the certified slide), ``slide_fraction`` (of the object's size, the diameter of
its minimum enclosing circle), ``extents`` (per finger ``[before, after]``, pixels of arc along the
outline, ``before`` towards the contour's start), ``delta`` (pixels: the bisection's half-width
of every stretch before it is clipped at the finger's feasible region, so that a finger near the
end of its region reaches less far on that side; ``slide`` says how far every finger may go),
``delta_fraction`` (``delta`` over the size), ``deltas`` (per finger, before clipping),
``regions`` (the certified tuple, in the region-set format of :mod:`qualgrasp.certify.regions`),
``certificate`` (of those regions; for ``not_robust`` the grasp's Farkas certificate),
``evaluations``, ``seconds`` and ``error``.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

from ...certify.errors import CertifyError, GraspError
from ...certify.core import Grasp, grasp_from_dict
from ...certify.files import atomic_output, check_output
from ...certify.regions.boundary import SEARCH_BUDGET, IndependentRegions, bisection_tol, independent_regions
from ...certify.regions import tuple_to_dict
from ...certify.files import json_lines
from ...certify.core.validation import id_problem, number, show
from ..errors import QualitativeError
from ..vision.outline import DEFAULT_SCALE, SCALE_MAX, SCALE_MIN, Outline, outline_contour
from ..vision.scales import planning_scale
from .regions import ALPHA, ALPHA_MAX, FINGER_WIDTH, MARGIN, Region, feasible_regions, planning_regions
from ..vision.contour import ImageSource, extract_contour

__all__ = ["ON_OUTLINE", "outline_boundary", "contact_limits", "planned_regions", "independent_grasp",
           "independent_file", "IndependentSummary"]

#: Largest distance of a contact from the outline, fraction of the object's size.
ON_OUTLINE = 0.01


def outline_boundary(outline: Outline) -> tuple[np.ndarray, np.ndarray]:
    """Boundary points and inward normals of an outline (module docstring).

    Parameters
    ----------
    outline : Outline

    Returns
    -------
    points, normals : numpy.ndarray
        ``(n, 2)`` each, one per contour sample, positively oriented.

    Examples
    --------
    >>> import numpy as np
    >>> from qualgrasp.qualitative.vision.outline import outline_contour
    >>> square = np.array([[0, 0], [100, 0], [100, 100], [0, 100]], float)
    >>> P, N = outline_boundary(outline_contour(square))
    >>> P.shape, bool(np.allclose(np.hypot(*N.T), 1))
    ((1024, 2), True)
    """
    n = len(outline.contour)
    points = np.array(outline.smoothed, dtype=float)
    normals = np.array(outline.normals(), dtype=float)
    for seg in outline.segments:
        if seg.symbol != "/":
            continue
        a, b = seg.endpoints
        if not np.linalg.norm(b - a) > 0:  # a degenerate fitted line: keep the smoothed samples
            continue
        t = (b - a) / np.linalg.norm(b - a)
        idx = np.arange(seg.start, seg.stop) % n
        points[idx] = a + np.outer((outline.contour[idx] - a) @ t, t)
        normals[idx] = [-t[1], t[0]]
    return points, normals


def _arc_limits(cum: np.ndarray, start: int, stop: int, n: int, j: int) -> tuple[float, float]:
    """Arc lengths of samples ``start`` and ``stop - 1`` (indices past ``n`` wrap), unwrapped; a
    stretch of the whole closed outline (a disc's) has no ends, so that of a contact at sample
    ``j`` reaches half the perimeter either way (not to a seam at ``start``)."""
    per = cum[-1]
    if stop - start >= n:
        return float(cum[j] - per / 2), float(cum[j] + per / 2)
    last = stop - 1
    return float(cum[start % n] + (start // n) * per), float(cum[last % n] + (last // n) * per)


def contact_limits(outline: Outline, regions: list[Region], points: np.ndarray, p) -> tuple[float, float]:
    """Arc-length limits (along the polygon ``points``) of a contact at ``p``: the feasible region
    it lies on, else the graspable element; raises GraspError on a corner or a cusp."""
    n = len(points)
    D = np.roll(points, -1, axis=0) - points
    cum = np.concatenate([[0.0], np.cumsum(np.hypot(D[:, 0], D[:, 1]))])
    dist = np.hypot(*(points - np.asarray(p, float)).T)
    j = int(np.argmin(dist))
    if dist[j] > ON_OUTLINE * outline.size + 2 * outline.spacing:
        raise GraspError(f"the contact at {[round(float(v), 2) for v in p]} is {dist[j]:.3g} px from the outline "
                         f"(more than {ON_OUTLINE:g} of the object's size {outline.size:.3g} px)")
    for r in regions:
        if any((j - r.start) % n == q for q in range(r.stop - r.start)):
            return _arc_limits(cum, r.start, r.stop, n, j)
    for seg in outline.segments:
        if (j - seg.start) % n < seg.stop - seg.start:
            if seg.is_point:
                article = "an" if seg.name[0] in "aeiou" else "a"
                raise GraspError(f"the contact at {[round(float(v), 2) for v in p]} lies on {article} {seg.name}: "
                                 "no finger goes there")
            return _arc_limits(cum, seg.start, seg.stop, n, j)
    raise GraspError(f"the contact at {list(p)} is on no outline element")  # pragma: no cover


def planned_regions(image: ImageSource, grasp: Grasp, *, alpha: float | None = None,
                    finger_width: float = FINGER_WIDTH, margin: float = MARGIN, threshold: float | None = None,
                    largest: bool = False, outline: Outline | None = None, contour: np.ndarray | None = None,
                    cache: dict | None = None, scale: float | None = None) -> list[Region]:
    """The feasible regions a grasp was planned on: those of the image's outline at the scale
    ``scale`` when given, else the grasp's field ``scale``, else the finger's
    (:func:`qualgrasp.qualitative.vision.scales.planning_scale` of ``finger_width``, the default of every
    qualitative command), with the curvature threshold ``alpha`` when given, else the grasp's field
    ``alpha``, else :data:`~qualgrasp.qualitative.synthesis.regions.ALPHA` (as
    :func:`qualgrasp.qualitative.synthesis.pipeline.synthesize` records them), found by
    :func:`qualgrasp.qualitative.synthesis.regions.planning_regions` as synthesis finds them.

    Parameters
    ----------
    image : str, pathlib.Path or numpy.ndarray
        The object's image.
    grasp : Grasp
        A grasp on that object.
    alpha, finger_width, margin
        Feasible regions' parameters (:func:`~qualgrasp.qualitative.synthesis.regions.feasible_regions`).
    threshold, largest
        As for :func:`~qualgrasp.qualitative.vision.outline.outline_image`.
    outline : Outline, optional
        The image's outline at the default scale (the fine one regions take their normals from).
    contour : numpy.ndarray, optional
        The object's contour as extracted from the image
        (:func:`qualgrasp.qualitative.vision.contour.extract_contour`): outlines are computed from it, and
        the image is not segmented again.
    cache : dict, optional
        Regions already found, by ``(scale, alpha)``, and the outline of each scale, by ``scale``
        (filled in); for one image, ``threshold``, ``largest``, ``finger_width`` and ``margin``.
    scale : float, optional
        The outline's scale, overriding the grasp's field.

    Returns
    -------
    list of Region

    Raises
    ------
    GraspError
        The grasp's field ``scale`` or ``alpha`` is not a number in range.
    """
    if contour is None:
        contour = extract_contour(image, threshold=threshold, largest=largest)
    if outline is None or outline.scale != DEFAULT_SCALE:
        outline = outline_contour(contour)
    if scale is None and "scale" not in grasp.meta:
        scale = planning_scale(outline, finger_width)
    scale = number(grasp.meta.get("scale") if scale is None else scale)
    if scale is None or not SCALE_MIN <= scale <= SCALE_MAX:
        raise GraspError(f"field scale: expected the outline's scale in [{SCALE_MIN:g}, {SCALE_MAX:g}], "
                         f"got {show(grasp.meta.get('scale'))}")
    if alpha is None:
        alpha = number(grasp.meta.get("alpha", ALPHA))
        if alpha is None or not 0 <= alpha <= ALPHA_MAX:
            raise GraspError(f"field alpha: expected a curvature threshold in [0, {ALPHA_MAX:g}] (fraction of "
                             f"the object's size), got {show(grasp.meta.get('alpha'))}")
    scale = float(scale)
    key = (scale, float(alpha))
    cache = {} if cache is None else cache
    if key not in cache:
        cache[scale], cache[key] = planning_regions(contour, scale=scale, alpha=key[1], finger_width=finger_width,
                                                    margin=margin, fine=outline)
    return list(cache[key])


def independent_grasp(outline: Outline, grasp: Grasp, *, regions: list[Region] | None = None,
                      symmetric: bool = True, tol: float | None = None, budget: int = SEARCH_BUDGET,
                      normal_tol: float = 0.0) -> IndependentRegions:
    """Independent contact regions of one grasp on an outline (module docstring).

    Parameters
    ----------
    outline : Outline
    grasp : Grasp
        Planar, contacts on the outline (within :data:`ON_OUTLINE` of its size).
    regions : list of Region, optional
        Feasible regions (default :func:`~qualgrasp.qualitative.synthesis.regions.feasible_regions` with
        its defaults).
    symmetric, tol, budget, normal_tol
        As for :func:`qualgrasp.certify.regions.independent_regions` (``tol`` in pixels,
        default ``1e-3`` of the object's size).

    Returns
    -------
    IndependentRegions

    Raises
    ------
    GraspError
        A contact off the outline or on a corner, a spatial grasp.

    Examples
    --------
    >>> from qualgrasp.qualitative.objects import render
    >>> from qualgrasp.qualitative.vision.outline import outline_image
    >>> from qualgrasp.qualitative.synthesis.pipeline import synthesize
    >>> image = render("square")
    >>> g = synthesize(image, fingers=2).grasps[0]
    >>> r = independent_grasp(outline_image(image), g)
    >>> r.status, r.slide > 0, r.slide == min(min(e) for e in r.extents) <= r.delta
    ('robust', True, True)
    """
    if grasp.dim != 2:
        raise GraspError("independent regions are planar: the grasp is spatial")
    regions = feasible_regions(outline) if regions is None else regions
    points, normals = outline_boundary(outline)
    limits = [contact_limits(outline, regions, points, c.p) for c in grasp.contacts]
    return independent_regions(points, normals, grasp, limits=limits, tol=tol, symmetric=symmetric,
                               budget=budget, normal_tol=normal_tol, on_boundary=ON_OUTLINE)


@dataclass
class IndependentSummary:
    """Counts of an :func:`independent_file` run: ``rows``, ``statuses``, ``seconds``, and the
    outline string of every scale whose regions were used (``outlines``, by scale)."""

    rows: int = 0
    statuses: dict[str, int] = field(default_factory=dict)
    seconds: float = 0.0
    outlines: dict[float, str] = field(default_factory=dict)

    @property
    def errors(self) -> int:
        """Error rows."""
        return self.statuses.get("error", 0)


def _row(gid, line, result: IndependentRegions | None = None, error: str | None = None) -> dict[str, Any]:
    if result is None:
        return {"id": gid, "line": line, "status": "error", "delta": None, "delta_fraction": None, "deltas": None,
                "regions": None, "certificate": None, "evaluations": 0, "seconds": 0.0, "error": error,
                "slide": None, "slide_fraction": None, "extents": None}
    if result.status == "robust":
        regions, cert = tuple_to_dict(result.regions), result.verdict.certificate
    else:
        regions, cert = None, {"kind": "grasp", "force": result.grasp_verdict.certificate.to_json()}
    return {"id": gid, "line": line, "status": result.status, "delta": result.delta,
            "delta_fraction": result.delta_fraction, "deltas": list(result.deltas), "regions": regions,
            "certificate": cert, "evaluations": result.evaluations, "seconds": result.seconds, "error": None,
            "slide": result.slide, "slide_fraction": result.slide_fraction,
            "extents": [list(e) for e in result.extents]}


def independent_file(image: ImageSource, grasps_path: str | Path, out_path: str | Path, *, symmetric: bool = True,
                     tol: float | None = None, budget: int = SEARCH_BUDGET, normal_tol: float = 0.0,
                     alpha: float | None = None, finger_width: float = FINGER_WIDTH, margin: float = MARGIN,
                     scale: float | None = None, threshold: float | None = None, largest: bool = False,
                     method: str = "otsu",
                     mask: ImageSource | None = None, rect: tuple[int, int, int, int] | None = None,
                     progress: Callable[[int], None] | None = None) -> IndependentSummary:
    """Independent contact regions of every grasp of a grasp set (JSON Lines) on an image's object.

    Parameters
    ----------
    image : str, pathlib.Path or numpy.ndarray
        The object's image (:func:`qualgrasp.qualitative.vision.contour.read_image`).
    grasps_path : path
        Grasp set in certify's format (JSON Lines).
    out_path : path
        Results (JSON Lines, module docstring); never the grasp set.
    symmetric, tol, budget, normal_tol
        As for :func:`independent_grasp`.
    alpha, finger_width, margin
        Feasible regions' parameters (:func:`~qualgrasp.qualitative.synthesis.regions.feasible_regions`);
        each grasp's regions are those it was planned on (:func:`planned_regions`: its fields
        ``scale`` and ``alpha``, ``alpha`` given overriding the latter).
    scale : float, optional
        The outline's scale of every grasp's regions, overriding its field ``scale`` (default:
        the field, else the finger's scale, :func:`planned_regions`).
    threshold, largest, method, mask, rect
        Segmentation (:func:`qualgrasp.qualitative.vision.contour.extract_contour`); the contour is
        extracted once, and every scale's outline computed from it.
    progress : callable, optional
        Called with 1 after each grasp line.

    Returns
    -------
    IndependentSummary

    Raises
    ------
    QualitativeError
        The image cannot be read or holds no single object.
    GraspFileError
        The grasp set cannot be read as a whole (:func:`qualgrasp.certify.files.reader.json_lines`: not
        a regular file, not JSON Lines); a bad line is an error row.
    OptionError
        The output is an input (the grasp set, the image, the mask; through any link), a
        folder, a FIFO or a device, or another run is writing it
        (:func:`qualgrasp.certify.files.outputs.atomic_output`).
    GraspError
        ``tol`` is below :data:`qualgrasp.certify.regions.boundary.TOL_FLOOR` of the object's size.
    """
    grasps_path, out_path = Path(grasps_path), Path(out_path)
    reads = [grasps_path, *(p for p in (image, mask) if isinstance(p, (str, Path)))]
    check_output(out_path, "-o", reads=reads)  # before the image's work
    contour = extract_contour(image, threshold=threshold, largest=largest, method=method, mask=mask, rect=rect)
    outline = outline_contour(contour)
    bisection_tol(tol, outline.size)
    cache: dict = {}
    summary = IndependentSummary()
    with atomic_output(out_path, "-o", reads=reads) as tmp, tmp.open("w", encoding="utf-8") as fh:
        for line, value in json_lines(grasps_path, "grasp set"):
            row = _line_row(image, line, value, outline, contour, cache, alpha=alpha, finger_width=finger_width,
                            margin=margin, scale=scale, symmetric=symmetric, tol=tol, budget=budget,
                            normal_tol=normal_tol)
            fh.write(json.dumps(row, allow_nan=False) + "\n")
            summary.rows += 1
            summary.statuses[row["status"]] = summary.statuses.get(row["status"], 0) + 1
            summary.seconds += row["seconds"]
            if progress is not None:
                progress(1)
    summary.outlines = {k: cache[k].string for k in sorted(k for k in cache if isinstance(k, float))}
    return summary


def _line_row(image, number: int, value: Any, outline: Outline, contour: np.ndarray, cache: dict, *, alpha,
              finger_width, margin, scale, symmetric, tol, budget, normal_tol) -> dict:
    """The results row of grasp line ``number`` (``value`` as :func:`qualgrasp.certify.files.reader.json_lines`
    reads it: a JSON value, or the error that made the line unreadable)."""
    gid = value.get("id") if isinstance(value, dict) and id_problem(value.get("id")) is None else None
    try:
        if isinstance(value, Exception):
            raise value
        grasp = grasp_from_dict(value)
        regions = planned_regions(image, grasp, alpha=alpha, finger_width=finger_width, margin=margin,
                                  outline=outline, contour=contour, cache=cache, scale=scale)
        result = independent_grasp(outline, grasp, regions=regions, symmetric=symmetric, tol=tol,
                                   budget=budget, normal_tol=normal_tol)
        return _row(gid, number, result)
    except (CertifyError, QualitativeError) as err:  # a bad grasp, or no outline at its scale
        return _row(gid, number, error=f"line {number}: {err}")

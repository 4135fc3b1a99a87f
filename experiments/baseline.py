"""Quantitative baseline: grasps of maximal certified epsilon on a densely sampled boundary.

The baseline sees exactly what the qualitative route sees: the object's contour extracted from the
image (:func:`boundary`: :func:`qualgrasp.qualitative.vision.contour.extract_contour`, resampled and smoothed by
:func:`qualgrasp.qualitative.vision.outline.outline_contour`, inward normals of the smoothed contour), and uses the
same torque scaling as :func:`qualgrasp.qualitative.synthesis.pipeline.synthesize`: ``center`` = the contour's area
centroid, ``length`` = its radius (:func:`qualgrasp.qualitative.synthesis.candidates.object_frame`). Epsilons of both
routes are therefore comparable.

Search (:func:`search`), on ``Budget.samples`` contacts evenly spaced by arc length:

* **2 fingers** (point contacts, friction ``mu``): every pair, ``M (M - 1) / 2`` candidates.
* **3 fingers** (point contacts, ``mu``): the ``Budget.extend`` best pairs (by 2-finger epsilon,
  then min-weight margin) each extended by every other sample, plus ``Budget.random`` random
  triples, then local improvement.
* **4 fingers** (frictionless): ``Budget.random`` random 4-tuples, then local improvement.
* **Local improvement** (3 and 4 fingers): from the ``Budget.starts`` best distinct candidates,
  coordinate ascent: for each finger in turn try every other sample in its place and keep the best
  if it improves epsilon; at most ``Budget.rounds`` rounds.

Every candidate is screened by :func:`qualgrasp.certify.batch.fastpath.planar_screen` (the compiled columnar
kernels of certify: force closure proved by the float re-check, exact planar L1 epsilon; 0 when not
proved). The ``Budget.keep`` best **distinct** candidates (each differing from every better one by
at least ``Budget.separation`` samples at some finger) are then certified one by one with
:func:`qualgrasp.certify.certify_grasp`; their certified L1 epsilon (0 unless force closure is certified and
both certificates re-verify) is what the baseline reports.

Default budget (:class:`Budget`, the study's ``full`` setting): 192 samples; 2 fingers: 18 336
pairs; 3 fingers: the 18 336 pairs ranked, 64 x 190 extended pairs, 20 000 random triples and
improvement (16 starts, up to 4 rounds of 3 x 192), about 80 000 candidates; 4 fingers: 20 000
random 4-tuples and improvement (16 starts, up to 4 rounds of 4 x 192), about 70 000 candidates.
Keep 5, separation 2. The study's ``quick`` setting uses 128 samples, 32 extended pairs, 4 000
random tuples, 8 starts and 2 rounds.

Every grasp records its field ``resolution`` (:func:`qualgrasp.qualitative.synthesis.pipeline.resolution`:
contact points known to a pixel, normals estimated over four smoothing standard deviations of the
outline, :func:`~qualgrasp.qualitative.synthesis.pipeline.normal_span`), so that the study judges it by the
rule it judges the qualitative grasps by (:func:`qualgrasp.qualitative.synthesis.pipeline.counted`): a
certified grasp whose epsilon is not above it (a frictionless closure of a disc's pixel polygon)
is not counted as found. Planned on an image, every grasp also records its field
``edge_strength`` (:func:`qualgrasp.qualitative.synthesis.pipeline.set_edge_strength`), so that a grasp on
a shadow's or a texture's boundary is not counted either, by the same rule.

Units: pixels of the image (x = column, y = row); normals are inward unit vectors; epsilon is
unit-free (torques divided by ``length``).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Sequence

import cv2
import numpy as np
import shapely
from scipy import ndimage
from shapely.geometry import Polygon

from qualgrasp.certify import Contact, Grasp, Report, certify_grasp
from qualgrasp.certify.batch import planar_screen
from qualgrasp.certify.quality import edge_samples
from qualgrasp.qualitative.synthesis.candidates import object_frame
from qualgrasp.qualitative.errors import QualitativeError
from qualgrasp.qualitative.vision.outline import DEFAULT_SCALE, Outline, outline_contour, resample
from qualgrasp.qualitative.synthesis.procedures import Procedure
from qualgrasp.qualitative.synthesis.pipeline import MU, choose, normal_span, resolution, set_edge_strength
from qualgrasp.qualitative.vision.contour import ImageSource, extract_contour

__all__ = ["MU", "Budget", "Boundary", "BaselineResult", "boundary", "boundary_of", "boundary_of_polygon", "search",
           "baseline", "screen_grasps"]

_CHUNK = 50_000  # rows per screening call (bounds memory)
_SAMPLES, _SMOOTHING = 1024, DEFAULT_SCALE  # outline_contour's defaults (the fallback below uses them)


@dataclass(frozen=True)
class Budget:
    """Size of the baseline's search (module notes).

    Attributes
    ----------
    samples : int
        Contacts on the boundary, evenly spaced by arc length.
    extend : int
        3 fingers: best pairs extended by every other sample.
    random : int
        3 and 4 fingers: random candidate tuples.
    starts, rounds : int
        Local improvement: starting candidates and largest number of rounds.
    keep : int
        Grasps returned (certified one by one).
    separation : int
        Smallest difference, in samples, between two returned grasps (at some finger).
    seed : int
        Seed of the random candidates.
    """

    samples: int = 192
    extend: int = 64
    random: int = 20_000
    starts: int = 16
    rounds: int = 4
    keep: int = 5
    separation: int = 2
    seed: int = 0


@dataclass(frozen=True, eq=False)
class Boundary:
    """An object's boundary: contour, inward normals and reference frame; as perceived
    (:func:`boundary`, :func:`boundary_of`) or exact (:func:`boundary_of_polygon`).

    Attributes
    ----------
    points : numpy.ndarray
        ``(n, 2)`` contour, positively oriented, pixels (as perceived: evenly spaced by arc
        length).
    normals : numpy.ndarray
        ``(n, 2)`` inward unit normals at the points (as perceived: of the smoothed contour).
    center : numpy.ndarray
        ``(2,)`` area centroid, pixels.
    length : float
        Radius about ``center`` (largest distance to the contour), pixels.
    size : float
        Diameter of the minimum enclosing circle, pixels.
    span : float or None
        Length over which the normals are estimated, pixels (as perceived:
        :func:`~qualgrasp.qualitative.synthesis.pipeline.normal_span` of the outline); None for an exact
        boundary, whose normals are not estimated.
    """

    points: np.ndarray
    normals: np.ndarray
    center: np.ndarray
    length: float
    size: float
    span: float | None = None


@dataclass(frozen=True, eq=False)
class BaselineResult:
    """Best grasps found by the baseline on one image.

    Attributes
    ----------
    fingers : int
        2 or 3 (point contacts with ``mu``) or 4 (frictionless).
    mu : float or None
        Friction coefficient (None with 4 frictionless fingers).
    grasps : tuple of certify.Grasp
        Best first; ``center``/``length`` those of the boundary.
    reports : tuple of certify.Report
        Their certification (with L1 and L-infinity epsilon).
    epsilons : tuple of float
        Certified L1 epsilon of each grasp (0 unless certified).
    screened : tuple of float
        The epsilon the screening gave each (equal to ``epsilons`` when certified).
    candidates : int
        Candidates screened.
    seconds : float
        Image to certified grasps (vision, search, certification), seconds.
    boundary : Boundary
        The boundary searched.
    """

    fingers: int
    mu: float | None
    grasps: tuple[Grasp, ...]
    reports: tuple[Report, ...]
    epsilons: tuple[float, ...]
    screened: tuple[float, ...]
    candidates: int
    seconds: float
    boundary: Boundary

    @property
    def certified(self) -> tuple[bool, ...]:
        """Per grasp: force closure certified and both certificates verified."""
        return tuple(r.certified for r in self.reports)


def boundary_of(outline: Outline) -> Boundary:
    """The boundary of a qualitative outline (its contour and smoothed normals, estimated over
    :func:`~qualgrasp.qualitative.synthesis.pipeline.normal_span` of it)."""
    center, length = object_frame(outline.contour)
    return Boundary(outline.contour, outline.normals(), center, length, outline.size, normal_span(outline))


def boundary_of_polygon(polygon: Polygon, spacing: float = 0.25) -> Boundary:
    """The exact boundary of a polygon's exterior: every vertex kept, edges subdivided to at most
    ``spacing`` pixels, each point with its edge's inward normal (a vertex: the normalised sum of
    its two edges' normals), positively oriented.

    The true object of an image rendered from known geometry (the built-in objects and the
    bundled silhouettes; :func:`qualgrasp.qualitative.objects.render_polygon` draws it to within
    a few hundredths of a pixel).

    Examples
    --------
    >>> from shapely.geometry import box
    >>> b = boundary_of_polygon(box(0, 0, 4, 2), spacing=1.0)
    >>> b.points[1].tolist(), b.normals[1].tolist()  # on the right side, pointing in
    ([4.0, 1.0], [-1.0, 0.0])
    >>> len(b.points), b.center.tolist(), round(b.size, 3)
    (12, [2.0, 1.0], 4.472)
    """
    ring = np.asarray(polygon.exterior.coords)[:-1]
    if not polygon.exterior.is_ccw:  # positive orientation: the interior on the left
        ring = ring[::-1]
    points, normals, _, s = edge_samples(ring, spacing)
    first = np.flatnonzero(s == 0)  # the vertices: between their edge and the one before
    normals[first] += normals[np.roll(first, 1)]
    keep = s < 1  # each vertex once, as the start of its edge
    points, normals = points[keep], normals[keep] / np.linalg.norm(normals[keep], axis=1, keepdims=True)
    center, length = object_frame(points)
    size = 2.0 * shapely.minimum_bounding_radius(Polygon(ring))
    return Boundary(points, normals, center, length, float(size))


def boundary(image: ImageSource, *, threshold: float | None = None, largest: bool = True) -> Boundary:
    """The boundary the qualitative route sees in an image.

    The contour of :func:`qualgrasp.qualitative.vision.contour.extract_contour` described by
    :func:`qualgrasp.qualitative.vision.outline.outline_contour` (resampled at 1024 points, smoothed at 0.4 % of the
    perimeter). When no well-formed qualitative description exists, the same resampling and
    smoothing are applied without it, so the baseline still runs where the qualitative route
    cannot.

    Raises
    ------
    ImageError, SegmentationError, ContourError
        No usable object in the image.
    """
    contour = extract_contour(image, threshold=threshold, largest=largest)
    try:
        return boundary_of(outline_contour(contour))
    except QualitativeError:
        points, perimeter = resample(contour, _SAMPLES)
        smoothed = ndimage.gaussian_filter1d(points, _SMOOTHING * _SAMPLES, axis=0, mode="wrap")
        size = 2.0 * cv2.minEnclosingCircle(points.astype(np.float32))[1]
        return boundary_of(Outline((), points, smoothed, perimeter, float(size), _SMOOTHING))


def _screen(points, normals, mu, center, length, idx: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Screened L1 epsilon and force-closure margin of the index tuples ``idx`` (B, m)."""
    eps, margin = np.zeros(len(idx)), np.full(len(idx), -np.inf)
    for a in range(0, len(idx), _CHUNK):
        rows = idx[a:a + _CHUNK]
        out = planar_screen(points[rows], normals[rows], mu, center, length)
        eps[a:a + _CHUNK], margin[a:a + _CHUNK] = out.eps_l1, out.margin
    return eps, margin


def _random_tuples(rng: np.random.Generator, n: int, m: int, count: int) -> np.ndarray:
    """``count`` random sorted ``m``-tuples of distinct indices below ``n``."""
    keys = rng.random((count, n))
    return np.sort(np.argpartition(keys, m, axis=1)[:, :m], axis=1)


def _improve(evaluate, idx: np.ndarray, eps: np.ndarray, n: int, rounds: int):
    """Coordinate ascent from the rows of ``idx``; returns every tuple evaluated and its epsilon."""
    seen_idx, seen_eps = [], []
    current, value = idx.copy(), eps.copy()
    others = np.arange(n)
    for _ in range(rounds):
        improved = False
        for j in range(idx.shape[1]):
            trial = np.repeat(current[:, None, :], n, axis=1)  # (S, n, m)
            trial[:, :, j] = others
            trial = trial.reshape(-1, idx.shape[1])
            ordered = np.sort(trial, axis=1)
            dup = (ordered[:, 1:] == ordered[:, :-1]).any(axis=1)  # a contact used twice
            e = np.full(len(trial), -1.0)
            e[~dup] = evaluate(trial[~dup])[0]
            seen_idx.append(trial[~dup])
            seen_eps.append(e[~dup])
            e = e.reshape(len(current), n)
            best = np.argmax(e, axis=1)
            better = e[np.arange(len(current)), best] > value
            current[better, j] = best[better]
            value[better] = e[better, best[better]]
            improved |= bool(better.any())
        if not improved:
            break
    return seen_idx, seen_eps


def _distinct(idx: np.ndarray, eps: np.ndarray, keep: int, separation: int, n: int) -> list[int]:
    """Rows of the ``keep`` best candidates, each differing from every better one by at least
    ``separation`` samples (cyclic) at some finger."""
    chosen: list[int] = []
    for r in np.argsort(-eps, kind="stable"):
        if len(chosen) == keep or eps[r] <= 0:
            break
        a = idx[r]
        ok = True
        for c in chosen:
            gap = np.abs(a[:, None] - idx[c][None, :])
            gap = np.minimum(gap, n - gap).min(axis=1).max()  # farthest finger of a from c's
            if gap < separation:
                ok = False
                break
        if ok:
            chosen.append(int(r))
    return chosen


def search(points: np.ndarray, normals: np.ndarray, fingers: int, mu: float, center, length: float,
           budget: Budget = Budget()) -> tuple[np.ndarray, np.ndarray, int]:
    """Search contact tuples of maximal screened L1 epsilon among given boundary contacts.

    Parameters
    ----------
    points, normals : numpy.ndarray
        ``(M, 2)`` candidate contacts and their inward unit normals (the search is over these).
    fingers : {2, 3, 4}
        Contacts per grasp.
    mu : float
        Friction coefficient (0: frictionless).
    center, length
        Torque reference point and length (pixels).
    budget : Budget
        Search size (``samples`` is ignored: the contacts are given).

    Returns
    -------
    idx : numpy.ndarray
        ``(k, fingers)`` indices into ``points`` of the best distinct tuples, best first
        (``k <= budget.keep``; only tuples with positive screened epsilon).
    eps : numpy.ndarray
        ``(k,)`` their screened epsilon.
    evaluated : int
        Number of candidates screened.
    """
    n = len(points)
    if fingers not in (2, 3, 4) or n < fingers:
        raise ValueError(f"need 2 to 4 fingers and at least as many contacts, got {fingers} and {n}")
    rng = np.random.default_rng(budget.seed)

    def evaluate(idx):
        return _screen(points, normals, mu, center, length, idx)

    pairs = np.column_stack(np.triu_indices(n, 1))
    if fingers == 2:
        pools = [pairs]
    else:
        pools = [_random_tuples(rng, n, fingers, budget.random)]
        if fingers == 3:
            eps2, margin2 = evaluate(pairs)
            top = pairs[np.lexsort((-margin2, -eps2))[: budget.extend]]
            ext = np.column_stack([np.repeat(top, n, axis=0), np.tile(np.arange(n), len(top))])
            pools.append(np.sort(ext[(ext[:, 2] != ext[:, 0]) & (ext[:, 2] != ext[:, 1])], axis=1))
    values = [evaluate(pool)[0] for pool in pools]
    if fingers > 2:
        idx, eps = np.vstack(pools), np.concatenate(values)
        starts = _distinct(idx, eps, budget.starts, budget.separation, n)
        if starts:
            more_idx, more_eps = _improve(evaluate, idx[starts], eps[starts], n, budget.rounds)
            pools += more_idx
            values += more_eps
    idx, eps = np.vstack(pools), np.concatenate(values)
    evaluated = len(idx) + (len(pairs) if fingers == 3 else 0)
    idx = np.sort(idx, axis=1)
    idx, first = np.unique(idx, axis=0, return_index=True)
    eps = eps[first]
    chosen = _distinct(idx, eps, budget.keep, budget.separation, n)
    return idx[chosen], eps[chosen], evaluated


#: Contact models whose grasps the baseline's compiled search evaluates.
SEARCHED_MODELS = ("point", "frictionless")


def _grasp(points, normals, rows, mu: float, center, length: float, gid: str, span: float | None) -> Grasp:
    """A baseline grasp, with its field ``resolution`` when its normals were estimated over ``span``."""
    contacts = tuple(Contact(tuple(points[i]), tuple(normals[i]), "point", mu) if mu > 0
                     else Contact(tuple(points[i]), tuple(normals[i])) for i in rows)
    grasp = Grasp(contacts, center=tuple(float(v) for v in center), length=float(length), id=gid,
                  meta={"procedure": "Baseline", "fingers": len(contacts)})
    if span is not None:
        grasp.meta["resolution"] = resolution(grasp, [span] * len(contacts))
    return grasp


def baseline(image: ImageSource | Boundary, procedure: int | str | Procedure, mu: float | None = MU,
             budget: Budget = Budget(), *, name: str = "image", threshold: float | None = None,
             largest: bool = True) -> BaselineResult:
    """The baseline's best grasps on the object of an image (module notes).

    Parameters
    ----------
    image : image file, array, or Boundary
        The image (its boundary is extracted by :func:`boundary`), or a boundary already extracted.
    procedure : Procedure, str or int
        The synthesis procedure whose fingers and contact model the baseline uses (a registered
        one, :mod:`qualgrasp.qualitative.synthesis.procedures`, by object, name, or finger count: 2 and 3
        point contacts with friction, 4 frictionless).
    mu : float
        Friction coefficient of procedures with friction (ignored for frictionless ones).
    budget : Budget
        Search size.
    name : str
        Used in grasp ids ``<name>-base<fingers>-<k>``.
    threshold, largest
        Segmentation (:func:`qualgrasp.qualitative.vision.contour.extract_contour`).

    Returns
    -------
    BaselineResult
    """
    start = time.perf_counter()
    proc = procedure if isinstance(procedure, Procedure) else choose(
        procedure if isinstance(procedure, int) else None, procedure if isinstance(procedure, str) else None)
    if proc.model not in SEARCHED_MODELS:
        raise ValueError(f"the baseline searches {' and '.join(SEARCHED_MODELS)} contacts; procedure "
                         f"{proc.name!r} uses {proc.model!r} contacts")
    fingers = proc.fingers
    bound = image if isinstance(image, Boundary) else boundary(image, threshold=threshold, largest=largest)
    friction = float(mu) if proc.friction else 0.0
    n = len(bound.points)
    pick = np.round(np.arange(budget.samples) * n / budget.samples).astype(int) % n
    points, normals = bound.points[pick], bound.normals[pick]
    idx, eps, evaluated = search(points, normals, fingers, friction, bound.center, bound.length, budget)
    grasps = tuple(_grasp(points, normals, rows, friction, bound.center, bound.length,
                          f"{name}-base{fingers}-{k:04d}", bound.span) for k, rows in enumerate(idx))
    if not isinstance(image, Boundary):
        set_edge_strength(grasps, image, bound.points, bound.normals)
    reports = tuple(certify_grasp(g) for g in grasps)
    epsilons = tuple(r.eps_l1 for r in reports)
    return BaselineResult(fingers, float(mu) if proc.friction else None, grasps, reports, epsilons,
                          tuple(float(e) for e in eps), evaluated, time.perf_counter() - start, bound)


def screen_grasps(grasps: Sequence[Grasp]) -> tuple[np.ndarray, np.ndarray]:
    """Certified force closure and L1 epsilon of many planar grasps.

    Grasps of point and frictionless contacts are grouped by contact pattern and screened
    columnar (:func:`qualgrasp.certify.batch.fastpath.planar_screen`); other contact models, and the
    rows the screen does not settle, are certified one by one
    with :func:`qualgrasp.certify.certify_grasp`. A grasp counts as certified when force closure is proved
    (columnar) or certified and verified (per grasp), as in :func:`qualgrasp.certify.batch.fastpath.certify_table`.

    Returns
    -------
    certified : numpy.ndarray
        ``(n,)`` bool.
    eps : numpy.ndarray
        ``(n,)`` L1 epsilon with each grasp's own ``center`` and ``length`` (0 unless certified).
    """
    certified, eps = np.zeros(len(grasps), dtype=bool), np.zeros(len(grasps))
    groups: dict[tuple, list[int]] = {}
    alone = []
    for i, g in enumerate(grasps):
        if all(c.model in SEARCHED_MODELS for c in g.contacts):
            groups.setdefault(tuple(c.mu for c in g.contacts), []).append(i)
        else:
            alone.append(i)
    for i in alone:
        report = certify_grasp(grasps[i])
        certified[i], eps[i] = report.certified, report.eps_l1
    for pattern, rows in groups.items():
        P = np.array([grasps[i].points for i in rows])
        N = np.array([grasps[i].normals for i in rows])
        out = planar_screen(P, N, np.broadcast_to(pattern, (len(rows), len(pattern))),
                            np.array([grasps[i].center for i in rows]),
                            np.array([grasps[i].length for i in rows]))
        for r, i in enumerate(rows):
            if out.settled[r]:
                certified[i], eps[i] = out.closure[r], out.eps_l1[r]
            else:
                report = certify_grasp(grasps[i])
                certified[i], eps[i] = report.certified, report.eps_l1
    return certified, eps

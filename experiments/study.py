"""Qualitative versus quantitative grasps: quality, time and robustness to vision errors.

:func:`compare` runs both routes on every object image and writes tables and plots.

Routes
------
* qualitative: :func:`qualgrasp.qualitative.synthesis.pipeline.synthesize` with every registered procedure
  (:mod:`qualgrasp.qualitative.synthesis.procedures`: FormGrasp with 4 frictionless fingers, ForceGrasp
  with 2 and 3 point contacts at ``mu``, 0.5);
* baseline: :func:`qualgrasp.experiments.baseline.baseline` for each procedure's fingers and contact model,
  the grasps of largest certified L1 epsilon on a densely sampled boundary (its docstring states
  the search and its budget).

Both see the same contour and use the same torque scaling (object centroid and radius), so their
L1 epsilons are comparable. A grasp is **certified** when force closure is certified (and its
certificates re-verify) by :mod:`qualgrasp.certify`; uncertified grasps have epsilon 0. ``seconds`` is image
to certified grasps (vision, search, certification) for both routes.

Both are judged by one rule (:func:`qualgrasp.qualitative.synthesis.pipeline.counted`): a certified grasp
is **counted** as found unless a reason of :data:`REASONS` applies, today a certified epsilon not
above the wrench change the image's uncertainty can cause (``below_resolution``: a closure of the
pixel polygon, such as four frictionless fingers on a disc). Grasps not counted weigh 0 in the
epsilons, are not the route's best grasp, are not planned in the robustness trials and are left
out of the plots; the tables count them per route and reason.

Robustness model
----------------
The **true object** is the geometry the image was rendered from, when it is known (the built-in
objects and the bundled silhouettes, :attr:`Subject.geometry`: its exact polygon with its edges'
normals, sharp corners included, :func:`qualgrasp.experiments.baseline.boundary_of_polygon`; the
images show it to within a few hundredths of a pixel), else the boundary perceived in the
unperturbed image (:func:`qualgrasp.experiments.baseline.boundary`: contour and smoothed inward
normals, corners rounded at the outline's smoothing scale, 0.4 % of the perimeter). Each
perturbation changes the image the routes plan on; the plans are then executed on the true
object (``none``, the unperturbed image, measures how many planned grasps are certified on the
true contour):

* ``rotation`` (degrees) and ``translation`` (pixels): a **pose error**. The image shows the object
  rotated about its true centroid by the size (+x towards +y, clockwise as displayed, in even
  trials; the other way in odd ones) or shifted by the size (random direction; the image is
  warped with bilinear interpolation), while the object really stays at its true pose. Plans
  made in image coordinates are executed unchanged in the world frame (= the unperturbed image's
  frame): the pose error is the perturbation itself.
* ``noise`` (grey levels, standard deviation of additive Gaussian noise; contrast 200),
  ``blur`` (pixels, standard deviation of a Gaussian defocus) and ``threshold`` (grey levels
  added to the unperturbed image's Otsu threshold, signed: positive grows a dark object): a
  **shape error** with no pose error; plans are executed unchanged.
* ``none`` (size 0): the unperturbed image itself (one trial per object).

``blur`` and ``threshold`` are deterministic: they get one trial whatever ``Settings.trials``.

**Execution** of a planned contact ``(p, n)``: the finger is pre-positioned at the standoff
``p - d n`` and moves along the planned inward normal ``n``; the contact is the first point where
it meets the true boundary, with the true inward normal there (normals of the true contour
interpolated along the edge hit). The planner chooses ``d`` on the object it perceived:
``standoff * size`` beyond the perceived surface along ``-n`` (``size`` the object's diameter;
``standoff`` 0.1 by default; a planned point may lie a little inside the perceived contour, e.g.
the qualitative route's points on a fitted straight line), or half-way to the next part of the
perceived object if that is closer (a contact in a pocket), so the pre-position is
collision-free on the perceived object. A finger that starts inside the true
object (``collision``) or never meets it (``miss``) fails the grasp.
Contact models, ``mu``, and the torque frame (true centroid and radius) are kept. The executed
grasp **holds** when it certifies. Robustness = held / planned, over the planned grasps that
certified on the perturbed image (the grasps the planner would use), pooled over objects and
trials.

Outputs (in ``out``)
--------------------
``objects.csv``/``.md`` (:data:`OBJECT_COLUMNS`), ``overall.csv``/``.md``
(:data:`OVERALL_COLUMNS`), ``robustness.csv``/``.md`` (:data:`ROBUSTNESS_COLUMNS`, aggregated) and
``robustness-trials.csv`` (one row per route and trial), ``grasps.csv`` (:data:`GRASP_COLUMNS`,
one row per nominal grasp) and the plots of :mod:`qualgrasp.experiments.study_plots` (PNG and PDF).
"""

from __future__ import annotations

import functools
import math
import time
import zlib
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any, Callable, Iterable, Sequence

import cv2
import numpy as np
from shapely.geometry import Polygon

from qualgrasp.certify import Contact, Grasp
from qualgrasp.certify.errors import GraspError
from qualgrasp.qualitative.synthesis import procedures
from qualgrasp.qualitative.errors import QualitativeError
from qualgrasp.qualitative.synthesis.formgrasp import ray_edges
from qualgrasp.qualitative.synthesis.independent import independent_grasp, planned_regions
from qualgrasp.qualitative.objects import NAMES, render, shape
from qualgrasp.qualitative.vision.outline import Outline, outline_image
from qualgrasp.qualitative.synthesis.pipeline import synthesize, unresolved_reasons
from qualgrasp.qualitative.vision.contour import read_image, segment

from .baseline import Boundary, Budget, baseline, boundary, boundary_of_polygon, screen_grasps
from .design import (BUILTINS, DETERMINISTIC, FULL, GRASP_COLUMNS, KINDS, OBJECT_COLUMNS,
                     OVERALL_COLUMNS, QUICK, REASONS, ROBUSTNESS_COLUMNS, ROUTES, SETTINGS, UNITS, Route,
                     RouteSummary, Settings, StudyResult, Subject, compared_procedure, routes)
from .silhouettes import Silhouette
from .study_plots import plot_all
from .study_tables import overall_rows, robustness_rows, summarise, write_tables

__all__ = ["BUILTINS", "KINDS", "UNITS", "ROUTES", "QUICK", "FULL", "SETTINGS", "REASONS", "OBJECT_COLUMNS",
           "OVERALL_COLUMNS", "ROBUSTNESS_COLUMNS", "GRASP_COLUMNS", "Settings", "Subject",
           "RouteSummary", "StudyResult", "subjects", "perturb", "execute", "evaluate_object",
           "robustness_trial", "not_counted", "best_tolerance", "warm_up", "workload", "compare"]

_ON = 1e-3  # a point this close to a contour (pixels) is on it

_VERTEX = 1e-9  # rounding allowed at the ends of an edge (fraction of the edge)

# --------------------------------------------------------------------------------------------------
# Subjects and perturbations


def _as_uint8(image: np.ndarray) -> np.ndarray:
    return np.clip(np.round(image), 0, 255).astype(np.uint8)


def subjects(images: Iterable[Any], skipped: list | None = None) -> list[Subject]:
    """Study subjects from built-in object names, image files, arrays or silhouettes.

    Parameters
    ----------
    images : iterable
        Each a built-in object name (:data:`qualgrasp.qualitative.objects.NAMES`, rendered at 512 x 512), an
        image path (name: the file's stem), a :class:`qualgrasp.experiments.silhouettes.Silhouette`, a
        :class:`Subject`, a ``(name, array)`` pair or an array (named ``image-<k>``).
    skipped : list, optional
        When given, an image that cannot be read is appended to it as ``(name, reason)`` and left
        out, instead of raising.

    Returns
    -------
    list of Subject
        Grey uint8 images (colour converted to luminance, other ranges rounded and clipped).

    Raises
    ------
    QualitativeError
        An image cannot be read (only when ``skipped`` is None).
    """
    out = []
    for k, item in enumerate(images):
        try:
            out.append(_subject(k, item))
        except QualitativeError as err:
            if skipped is None:
                raise
            name = Path(item).name if isinstance(item, (str, Path)) else f"image-{k}"
            skipped.append((name, f"{type(err).__name__}: {err}"))
    return out


def _subject(k: int, item: Any) -> Subject:
    if isinstance(item, Subject):
        return item
    if isinstance(item, Silhouette):
        return Subject(item.name, item.image(), item.polygon())
    if isinstance(item, str) and item in NAMES:
        return Subject(item, render(item), Polygon(shape(item).exterior))
    if isinstance(item, (str, Path)):
        return Subject(Path(item).stem, _as_uint8(read_image(item)))
    if isinstance(item, tuple):
        return Subject(str(item[0]), _as_uint8(read_image(item[1])))
    return Subject(f"image-{k}", _as_uint8(read_image(item)))


def _pose_matrix(center: np.ndarray, degrees: float, shift: Sequence[float]) -> np.ndarray:
    """2 x 3 affine map: rotation by ``degrees`` about ``center`` (+x towards +y), then ``shift``."""
    a = math.radians(degrees)
    R = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
    return np.column_stack([R, center - R @ center + np.asarray(shift, dtype=float)])


def perturb(image: np.ndarray, kind: str, size: float, rng: np.random.Generator,
            center: np.ndarray, level: float) -> tuple[np.ndarray, float | None]:
    """A perturbed image and the segmentation threshold to use on it (module notes).

    Parameters
    ----------
    image : numpy.ndarray
        Unperturbed grey uint8 image.
    kind : str
        ``none`` or one of :data:`KINDS`.
    size : float
        Perturbation size in the unit of :data:`UNITS`; rotations are signed (positive turns +x
        towards +y: clockwise as displayed, y pointing down).
    rng : numpy.random.Generator
        Source of the random direction or noise.
    center : numpy.ndarray
        True centroid of the object (centre of rotations), pixels.
    level : float
        Unperturbed segmentation threshold (grey level).

    Returns
    -------
    image : numpy.ndarray
        Perturbed uint8 image.
    threshold : float or None
        Threshold for ``threshold`` perturbations, else None (Otsu's on the perturbed image).
    """
    if kind == "none" or size == 0:
        return image, None
    if kind in ("rotation", "translation"):
        if kind == "rotation":
            matrix = _pose_matrix(center, size, (0.0, 0.0))
        else:
            phi = rng.uniform(0.0, 2 * math.pi)
            matrix = _pose_matrix(center, 0.0, (size * math.cos(phi), size * math.sin(phi)))
        rows, cols = image.shape
        return cv2.warpAffine(image, matrix, (cols, rows), flags=cv2.INTER_LINEAR,
                              borderMode=cv2.BORDER_REPLICATE), None
    if kind == "noise":
        return _as_uint8(image + rng.normal(0.0, size, image.shape)), None
    if kind == "blur":
        return _as_uint8(cv2.GaussianBlur(image.astype(np.float64), (0, 0), size,
                                          borderType=cv2.BORDER_REFLECT)), None
    if kind == "threshold":
        return image, level + size
    raise ValueError(f"unknown perturbation {kind!r}; use none or one of {', '.join(KINDS)}")


# --------------------------------------------------------------------------------------------------
# Execution on the true object


def _hits(start: np.ndarray, direction: np.ndarray, points: np.ndarray):
    """Crossings of the ray ``start + t direction`` (t > 0) with the closed polyline ``points``:
    ``(t, edge index, parameter u in [0, 1])`` arrays, by increasing ``t``. Edges are closed (to
    within rounding), so a ray through a vertex meets both of its edges."""
    t, u, den = ray_edges(start, direction, points)
    ok = (den != 0) & (t > 0) & (u >= -_VERTEX) & (u <= 1 + _VERTEX)
    k = np.flatnonzero(ok)
    order = np.argsort(t[k])
    return t[k][order], k[order], np.clip(u[k][order], 0.0, 1.0)


def _depth(contour: np.ndarray, point: np.ndarray) -> float:
    """Signed distance from ``point`` to the closed polyline ``contour``, positive inside, pixels."""
    polygon = contour.astype(np.float32).reshape(-1, 1, 2)
    return cv2.pointPolygonTest(polygon, (float(point[0]), float(point[1])), True)


def _free(p: np.ndarray, n: np.ndarray, perceived: np.ndarray | None, reach: float) -> float:
    """Pre-position distance along ``-n`` from ``p``: ``reach`` beyond the perceived surface, or
    half-way to the next part of the perceived object if that is closer (a pocket)."""
    if perceived is None:
        return reach
    t, _, _ = _hits(p, -n, perceived)
    exit_ = 0.0
    if _depth(perceived, p) > _ON and len(t):  # p lies a little inside: leave the object first
        exit_, t = t[0], t[1:]
    t = t[t > exit_ + _ON]
    nxt = t[0] if len(t) else np.inf
    return float(min(exit_ + reach, 0.5 * (exit_ + nxt)))


def execute(grasp: Grasp, truth: Boundary, standoff: float = 0.1,
            perceived: np.ndarray | None = None) -> tuple[Grasp | None, str]:
    """Execute a planned planar grasp on the true object (module notes, robustness model).

    Parameters
    ----------
    grasp : certify.Grasp
        Planned grasp, pixels of the world (unperturbed image) frame, inward normals.
    truth : Boundary
        The true object.
    standoff : float
        Largest finger pre-position distance before the planned contact, fraction of
        ``truth.size``.
    perceived : numpy.ndarray, optional
        ``(n, 2)`` contour the grasp was planned on: pre-positions are kept collision-free on it.

    Returns
    -------
    grasp : certify.Grasp or None
        The executed grasp (true contacts and normals, the truth's ``center`` and ``length``), or
        None when a finger fails.
    outcome : str
        ``contact``, ``miss`` (a finger never meets the object) or ``collision`` (a finger starts
        inside it).
    """
    contacts = []
    points, normals = truth.points, truth.normals
    for c in grasp.contacts:
        n, p = np.asarray(c.n, dtype=float), np.asarray(c.p, dtype=float)
        start = p - _free(p, n, perceived, standoff * truth.size) * n
        if _depth(points, start) >= 0:
            return None, "collision"  # the finger starts inside (or on) the true object
        t, k, u = _hits(start, n, points)
        if len(t) == 0:
            return None, "miss"
        p = start + t[0] * n
        k1 = (k[0] + 1) % len(points)
        normal = (1 - u[0]) * normals[k[0]] + u[0] * normals[k1]
        contacts.append(Contact(tuple(p), tuple(normal / np.linalg.norm(normal)), c.model, c.mu))
    return Grasp(tuple(contacts), center=tuple(truth.center), length=truth.length, id=grasp.id,
                 meta=dict(grasp.meta)), "contact"


# --------------------------------------------------------------------------------------------------
# One object, one perturbation


def _plan(image: np.ndarray, route: Route, settings: Settings, name: str, threshold: float | None,
          final: bool):
    """Plan with one route: ``(grasps, certified, eps, seconds, candidates, contour)``.

    ``final``: the nominal evaluation (qualitative grasps certified one by one with reports, as
    ``synthesize`` does); otherwise certified columnar (:func:`screen_grasps`)."""
    proc = route.procedure
    mu = settings.mu if proc.friction else None
    start = time.perf_counter()
    if route.method == "baseline":
        found = baseline(image, proc, mu, settings.budget, name=name, threshold=threshold)
        return (found.grasps, np.array(found.certified, dtype=bool), np.array(found.epsilons),
                found.seconds, found.candidates, found.boundary.points)
    s = synthesize(image, procedure=proc.name, mu=mu, name=name, certify=final, quality=final,
                   threshold=threshold, largest=True, tolerance=False, explain=False)
    if final:
        ok = np.array(s.certified, dtype=bool)
        eps = np.array([r.eps_l1 for r in s.reports])
    else:
        ok, eps = screen_grasps(s.grasps)
    return s.grasps, ok, eps, time.perf_counter() - start, None, s.outline.contour


def _route_fields(route: Route, settings: Settings) -> dict:
    """The columns every row of ``route`` starts with."""
    return {"route": route.name, "method": route.method, "procedure": route.procedure.name,
            "fingers": route.fingers}


def _stats(eps: np.ndarray) -> tuple[float | None, float | None]:
    return (float(np.median(eps)), float(np.max(eps))) if len(eps) else (None, None)


def not_counted(grasps: Sequence[Grasp], certified: np.ndarray, eps: np.ndarray) -> list[tuple[str, ...]]:
    """Per grasp, why it is not counted as found although certified
    (:func:`qualgrasp.qualitative.synthesis.pipeline.unresolved_reasons`, the rule of every route; empty
    for a grasp not certified, or certified and counted)."""
    return [unresolved_reasons(g, float(e)) if c else () for g, c, e in zip(grasps, certified, eps)]


def _reason_counts(why: list[tuple[str, ...]]) -> dict[str, int]:
    """Per reason of :data:`REASONS`, the grasps it applies to."""
    return {r: sum(r in w for w in why) for r in REASONS}


def evaluate_object(subject: Subject, settings: Settings = QUICK) -> tuple[list[dict], list[dict]]:
    """Both routes on one unperturbed image: per-route rows (:data:`OBJECT_COLUMNS`, ratios still
    empty) and per-grasp rows (:data:`GRASP_COLUMNS`)."""
    rows, grasp_rows = [], []
    try:
        outline = outline_image(subject.image, largest=True)
    except QualitativeError:
        outline = None  # every route reports the error below
    for route in routes():
        row = dict.fromkeys(OBJECT_COLUMNS)
        row.update(object=subject.name, **_route_fields(route, settings),
                   mu=settings.mu if route.procedure.friction else None)
        try:
            grasps, ok, eps, seconds, candidates, _ = _plan(subject.image, route, settings,
                                                            subject.name, None, True)
        except QualitativeError as err:
            row.update(grasps=0, certified=0, error=f"{type(err).__name__}: {err}")
            rows.append(row)
            continue
        why = not_counted(grasps, ok, eps)
        kept = ok & np.array([not w for w in why], dtype=bool)
        found = np.where(kept, eps, 0.0)
        median, best = _stats(found)
        row.update(grasps=len(grasps), certified=int(ok.sum()), eps_median=median, eps_best=best,
                   certified_fraction=float(ok.mean()) if len(ok) else None, seconds=seconds,
                   candidates=candidates, counted=int(kept.sum()), **_reason_counts(why))
        if kept.any() and outline is not None:
            row["slide_best"], row["delta_best"], row["delta_status"] = best_tolerance(
                outline, grasps[int(np.argmax(found))], subject.image)
        rows.append(row)
        grasp_rows += [{"object": subject.name, **_route_fields(route, settings), "certified": bool(c),
                        "eps": float(e), "counted": bool(k), **{r: r in w for r in REASONS}}
                       for c, e, k, w in zip(ok, eps, kept, why)]
    return _with_ratios(rows), grasp_rows


def best_tolerance(outline: Outline, grasp: Grasp,
                   image: np.ndarray | None = None) -> tuple[float, float, str]:
    """Certified tolerance of a certified grasp on the outline it was planned on: ``(slide, delta,
    status)`` (:data:`OBJECT_COLUMNS`): the certified slide (how far every finger may slide either
    way) and ``delta`` (the search's half-width before clipping), fractions of the object's size.
    A contact on a corner or off the outline's elements has no stretch to slide on: both 0,
    status ``none: <why>``.

    ``outline`` is the image's outline at the default scale; a qualitative grasp keeps the
    feasible regions it was planned on (its fields ``scale`` and ``alpha``, as
    :func:`qualgrasp.qualitative.synthesis.pipeline.synthesize` does), read from ``image``."""
    try:
        regions = None if image is None else planned_regions(image, grasp, largest=True, outline=outline)
        found = independent_grasp(outline, grasp, regions=regions)
    except GraspError as err:
        return 0.0, 0.0, f"none: {err}"
    return float(found.slide_fraction), float(found.delta_fraction), found.status


def _with_ratios(rows: list[dict]) -> list[dict]:
    """Fill ``ratio_best``/``ratio_median`` of qualitative rows from the baseline's best."""
    best = {r["procedure"]: r["eps_best"] for r in rows if r["method"] == "baseline"}
    for r in rows:
        if r["method"] != "qualitative":
            continue
        ref = best.get(compared_procedure(procedures.get(r["procedure"]), "baseline").name)
        if ref and r["eps_best"] is not None:
            r["ratio_best"] = r["eps_best"] / ref
            r["ratio_median"] = r["eps_median"] / ref
    return rows


def _seed(settings: Settings, name: str, kind: str, size: float, trial: int) -> np.random.Generator:
    key = zlib.crc32(f"{name}/{kind}/{size!r}/{trial}".encode())
    return np.random.default_rng([settings.seed, key])


def robustness_trial(subject: Subject, truth: Boundary, level: float, kind: str, size: float,
                     trial: int, settings: Settings = QUICK) -> list[dict]:
    """Plan with every route on one perturbed image and execute on the true object.

    Returns one row per route: ``object, route, method, procedure, fingers, kind, size, trial, planned``
    (grasps that certified on the perturbed image and are counted as found), ``held``, ``misses``,
    ``collisions``, ``eps_planned`` and ``eps_executed`` (lists, per planned grasp), ``error``, and
    per reason of :data:`REASONS` the certified grasps it kept from being planned.
    """
    rng = _seed(settings, subject.name, kind, size, trial)
    signed = -size if kind == "rotation" and trial % 2 else size
    image, threshold = perturb(subject.image, kind, signed, rng, truth.center, level)
    rows = []
    for route in routes():
        row = {"object": subject.name, **_route_fields(route, settings), "kind": kind,
               "size": size, "trial": trial, "planned": 0, "held": 0, "misses": 0, "collisions": 0,
               "eps_planned": [], "eps_executed": [], "error": None, **dict.fromkeys(REASONS, 0)}
        try:
            grasps, ok, eps, _, _, seen = _plan(image, route, settings, subject.name, threshold, False)
        except QualitativeError as err:
            row["error"] = f"{type(err).__name__}: {err}"
            rows.append(row)
            continue
        why = not_counted(grasps, ok, eps)
        row.update(_reason_counts(why))
        ok = ok & np.array([not w for w in why], dtype=bool)  # the planner uses counted grasps only
        runs = [execute(g, truth, settings.standoff, seen) for g, c in zip(grasps, ok) if c]
        executed, outcomes = tuple(r[0] for r in runs), [r[1] for r in runs]
        done = [g for g in executed if g is not None]
        held, eps_done = screen_grasps(done) if done else (np.zeros(0, bool), np.zeros(0))
        eps_exec = iter(np.where(held, eps_done, 0.0))
        row.update(planned=int(ok.sum()), held=int(held.sum()), misses=outcomes.count("miss"),
                   collisions=outcomes.count("collision"), eps_planned=[float(e) for e in eps[ok]],
                   eps_executed=[float(next(eps_exec)) if g is not None else 0.0 for g in executed])
        rows.append(row)
    return rows


# --------------------------------------------------------------------------------------------------
# The study


def _nominal(subject: Subject, settings: Settings):
    truth = boundary(subject.image) if subject.geometry is None else boundary_of_polygon(subject.geometry)
    level = segment(subject.image).level
    return subject.name, evaluate_object(subject, settings), truth, level


def _tasks(items: list[Subject], truths: dict, settings: Settings) -> list[tuple]:
    tasks = []
    for s in items:
        truth, level = truths[s.name]
        tasks.append((s, truth, level, "none", 0.0, 0, settings))
        for kind, sizes in settings.sizes:
            trials = 1 if kind in DETERMINISTIC else settings.trials
            for size in sizes:
                tasks += [(s, truth, level, kind, float(size), trial, settings)
                          for trial in range(trials)]
    return tasks


@functools.cache  # once per process: the first-call costs are paid then
def warm_up() -> None:
    """Run every route once on a small image, so that first-call costs (loading the compiled
    kernels, imports) do not count in the first object's time. Run in each worker process, once."""
    image = render("polygon", size=160)
    small = Settings(budget=Budget(samples=24, extend=4, random=50, starts=2, rounds=1))
    for route in routes():
        grasps = _plan(image, route, small, "warm-up", None, True)[0]
        screen_grasps(grasps)


def workload(objects: int, settings: str | Settings = "quick") -> int:
    """Number of progress messages :func:`compare` sends for ``objects`` objects: one per object,
    then one per robustness trial."""
    settings = SETTINGS[settings] if isinstance(settings, str) else settings
    per = 1 + sum(len(sizes) * (1 if kind in DETERMINISTIC else settings.trials)
                  for kind, sizes in settings.sizes)
    return objects * (1 + per)


def _run(fn, tasks: list[tuple], workers: int, progress, label: str) -> list:
    """``fn(*task)`` for every task, in order, in ``workers`` processes; progress per task."""
    say = progress or (lambda _msg: None)
    if workers <= 1:
        out = []
        for k, task in enumerate(tasks):
            out.append(fn(*task))
            say(f"{label} {k + 1}/{len(tasks)}")
        return out
    with ProcessPoolExecutor(workers, initializer=warm_up) as pool:
        futures = [pool.submit(fn, *task) for task in tasks]
        out = []
        for k, f in enumerate(futures):
            out.append(f.result())
            say(f"{label} {k + 1}/{len(tasks)}")
    return out


def compare(images: Iterable[Any], out: str | Path, *, settings: str | Settings = "quick",
            progress: Callable[[str], None] | None = None, plots: bool = True) -> StudyResult:
    """Compare the qualitative routes with the baseline on every image (module notes).

    Parameters
    ----------
    images : iterable
        Objects (see :func:`subjects`): built-in names, image paths, arrays, silhouettes.
    out : str or pathlib.Path
        Output folder (created).
    settings : {'quick', 'full'} or Settings
        Size of the work (:data:`QUICK`: about a minute on the 4 built-ins with 2 cores).
    progress : callable, optional
        Called with a short message after each object and each robustness trial.
    plots : bool
        Draw the plots (PNG and PDF).

    Returns
    -------
    StudyResult
    """
    start = time.perf_counter()
    settings = SETTINGS[settings] if isinstance(settings, str) else settings
    skipped: list = []
    items = []
    for subject in subjects(images, skipped):
        try:  # an image the vision cannot describe at all has no true object to execute on
            boundary(subject.image)
            items.append(subject)
        except QualitativeError as err:
            skipped.append((subject.name, f"{type(err).__name__}: {err}"))
    if not items:
        raise ValueError("no images to compare" + (f" (skipped: {skipped})" if skipped else ""))
    names = [s.name for s in items]
    if len(set(names)) != len(names):
        raise ValueError(f"object names must be unique, got {names}")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    if settings.workers <= 1:
        warm_up()
    nominal = _run(_nominal, [(s, settings) for s in items], settings.workers, progress, "objects")
    object_rows = [r for _, (rows, _), _, _ in nominal for r in rows]
    grasp_rows = [g for _, (_, grasps), _, _ in nominal for g in grasps]
    truths = {name: (truth, level) for name, _, truth, level in nominal}
    trials = _run(robustness_trial, _tasks(items, truths, settings), settings.workers, progress,
                  "robustness trials")
    trial_rows = [r for rows in trials for r in rows]
    robust = robustness_rows(trial_rows, settings)
    overall = overall_rows(object_rows, grasp_rows, trial_rows)
    files = write_tables(out, object_rows, overall, robust, trial_rows, grasp_rows)
    if plots:
        files += plot_all(out, object_rows, grasp_rows, robust)
    routes, by_kind = summarise(overall, trial_rows)
    return StudyResult(tuple(names), routes, by_kind, time.perf_counter() - start, tuple(files),
                       tuple(skipped))

"""The physical validation study: do certified grasps hold in a physics engine?

:func:`validate` runs it on the study's objects (:func:`qualgrasp.experiments.study.subjects`:
built-in names, silhouettes, images) and writes its tables.

Grasps, per object
------------------
* **qualitative**: every registered procedure's grasps
  (:func:`qualgrasp.qualitative.synthesis.pipeline.synthesize`, certified, with their certified tolerance),
  the ``per_route`` of largest certified epsilon;
* **baseline**: :func:`qualgrasp.experiments.baseline.baseline` with the same fingers and contact
  model, its ``per_route`` best, with their certified tolerance where one exists
  (:func:`qualgrasp.qualitative.synthesis.independent.independent_grasp` on the feasible regions of the
  default scale, as the comparison study's :func:`~qualgrasp.experiments.study.best_tolerance`);
* **random**: ``random`` grasps per procedure of uniformly random distinct contacts on the boundary
  the image shows (:func:`qualgrasp.experiments.baseline.boundary`), with its normals.

Every grasp is planned on the image and has its **certified verdict** and L1 epsilon there
(:func:`qualgrasp.certify.certify_grasp`). It is executed on the **true object** (the exact
polygon the image was rendered from, else the perceived contour) as the comparison study does
(:func:`qualgrasp.experiments.study.execute`: each finger moves along its planned inward normal
from a standoff until it meets the true boundary), and the executed grasp is certified again on
the true contacts and normals (``certified_true``, ``eps_true``): a planned grasp certified on the
image may not be on the true object, and that is the vision's error, not the engine's.

Physical trials (:mod:`qualgrasp.experiments.physics.planar`)
-------------------------------------------------------------
* **nominal**: the largest disturbance resisted in every direction (``resisted``, ``F0``) and
  whether the floor is resisted (``held``);
* **placements** (grasps with a certified tolerance): each finger ``i`` moved along the perceived
  outline by ``s_i = e delta_i sigma_i`` from its planned contact (``delta_i`` its certified
  tolerance, ``sigma_i`` a random sign, ``e`` uniform in ``(0, 1]`` for ``inside`` placements and
  in ``(1, outside_max]`` for ``outside`` ones); an inside placement stops at the finger's limits
  (its feasible region, where the certified regions stop too, less one boundary step), so it stays
  **inside the certified regions**; an outside one is beyond them. The **placement error** is
  ``max |s_i| / delta_i``. The finger approaches the moved point along its planned normal and meets
  the true object; ``held`` as above.

Summary (:func:`summarise`)
---------------------------
Precision and recall of the certified verdict (planned; and on the true contacts) against
``held`` at the nominal placement; Spearman's rank correlation of epsilon and of the certified
tolerance with ``resisted`` (certified grasps that held); held rate of the placements inside and
outside the certified regions, every placement inside that did not hold listed with its
explanation (:func:`explain`).

Outputs (in ``out``): ``trials.csv`` (:data:`COLUMNS`, one row per physical trial),
``closed-forms.csv`` (the simulator's error, :mod:`~qualgrasp.experiments.physics.closed_forms`,
at both physics settings), ``settings.csv`` (nominal trials of the first ``recheck`` objects at
the second setting), ``summary.md``, and the figures of :mod:`~qualgrasp.experiments.physics.plots`.
"""

from __future__ import annotations

import csv
import math
import time
import zlib
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any, Callable, Iterable, Mapping, Sequence

import numpy as np
from scipy.stats import spearmanr
from shapely.geometry import Polygon

from ...certify import Contact, Grasp, certify_grasp
from ...certify.errors import GraspError
from ...certify.regions import Boundary as ArcBoundary
from ...qualitative.errors import QualitativeError
from ...qualitative.synthesis.independent import independent_grasp, outline_boundary, planned_regions
from ...qualitative.vision.outline import outline_image
from ...qualitative.synthesis.pipeline import synthesize
from ..baseline import Boundary, Budget, baseline, boundary, boundary_of_polygon, screen_grasps
from ..design import QUICK, Route, Subject, routes
from ..study import execute, subjects
from . import closed_forms
from .planar import DIRECTIONS, Finger, Physics, PlanarObject, hold, holds, resistance
from .plots import plot_all, plot_filmstrip

__all__ = ["COLUMNS", "FINE", "STIFF", "Validation", "QUICK_VALIDATION", "FULL_VALIDATION", "VALIDATIONS",
           "ValidationResult", "grasps_of", "placement", "validate_object", "explain", "summarise", "summary_markdown",
           "read_trials", "read_closed_forms", "filmstrip", "report", "validate", "rate", "confusion", "cell"]

FINE = Physics(dt=5e-4, iterations=40, stiffness=1000.0)
"""The second physics setting: half the time step, twice the solver iterations, twice the
finger stiffness."""

STIFF = 1000.0
"""Finger stiffness (``F0`` per size) of the re-check of a placement inside that did not hold
(:func:`explain`: compliance)."""

COLUMNS = ("object", "source", "route", "procedure", "fingers", "mu", "grasp", "certified", "eps",
           "delta_fraction", "tolerance", "placement", "error", "error_fraction", "executed",
           "certified_true", "eps_true", "held", "resisted", "ejected", "weakest", "tests", "setting",
           "explanation")
"""Per physical trial: the object; the grasp's source (``qualitative``, ``baseline``, ``random``),
route (``ForceGrasp 2``, ``Baseline 2``, ``Random 2``), procedure, fingers, friction (0:
frictionless) and id; its certified verdict and L1 epsilon as planned; its certified tolerance
(fraction of the object's size; empty when none) and the tolerance's status; the placement
(``nominal``, ``inside``, ``outside``), its error in units of the tolerance and as a fraction of
the size (largest over fingers); the execution on the true object (``contact``, ``miss``,
``collision``), the executed grasp's verdict and epsilon on the true contacts; the physical
outcome: held, largest resisted disturbance (``F0``, nominal trials only), ejected by the
squeeze, weakest direction (index into
:data:`~qualgrasp.experiments.physics.planar.DIRECTIONS`), disturbance tests run; the physics
setting (``default`` or ``fine``); for a placement inside the certified regions that did not
hold, why (:func:`explain`)."""


@dataclass(frozen=True)
class Validation:
    """How much work the validation study does.

    Attributes
    ----------
    physics : Physics
        The main physics setting.
    per_route : int
        Qualitative and baseline grasps per route (largest certified epsilon first).
    random : int
        Random grasps per procedure.
    inside, outside : int
        Placements inside and outside the certified regions per grasp with a tolerance.
    outside_max : float
        Largest placement error outside, in units of the certified tolerance.
    directions : int
        Disturbance directions (the first of :data:`~qualgrasp.experiments.physics.planar.DIRECTIONS`:
        6 the axes, 14 with the diagonals).
    recheck : int
        Objects (the first) whose nominal trials are run again at :data:`FINE`.
    budget : Budget
        The baseline's search budget.
    standoff : float
        Finger start distance, fraction of the size (:func:`qualgrasp.experiments.study.execute`).
    mu : float
        Friction of the procedures with friction.
    workers : int
        Processes (1: this one).
    seed : int
    """

    physics: Physics = Physics()
    per_route: int = 2
    random: int = 3
    inside: int = 3
    outside: int = 3
    outside_max: float = 3.0
    directions: int = 14
    recheck: int = 4
    budget: Budget = QUICK.budget
    standoff: float = 0.1
    mu: float = QUICK.mu
    workers: int = 2
    seed: int = 0


QUICK_VALIDATION = Validation(per_route=1, random=2, inside=2, outside=2, directions=6, recheck=1)
FULL_VALIDATION = Validation()
VALIDATIONS = {"quick": QUICK_VALIDATION, "full": FULL_VALIDATION}


@dataclass(frozen=True)
class ValidationResult:
    """What :func:`validate` found and wrote: ``summary`` (:func:`summarise`), the closed-form
    rows per setting, the trial rows, wall ``seconds``, ``files`` written, ``skipped`` images."""

    summary: dict
    closed: dict
    rows: list
    seconds: float
    files: tuple[Path, ...] = field(default=())
    skipped: tuple[tuple[str, str], ...] = field(default=())


# --------------------------------------------------------------------------------------------------
# Grasps of one object


@dataclass(frozen=True, eq=False)
class _Planned:
    """A grasp to execute: its source, route, verdict, epsilon and certified tolerance."""

    source: str
    route: str
    procedure: str
    grasp: Grasp
    certified: bool
    eps: float
    tolerance: Any  # IndependentRegions or None
    status: str


def _tolerance(outline, regions, grasp: Grasp):
    """Certified tolerance of a grasp on the outline at the default scale within ``regions``:
    ``(IndependentRegions or None, status)``."""
    try:
        found = independent_grasp(outline, grasp, regions=regions)
    except GraspError as err:
        return None, f"none: {err}"
    return found, found.status


def _random_grasps(seen: Boundary, route: Route, mu: float, count: int, rng) -> list[Grasp]:
    proc = route.procedure
    out = []
    for k in range(count):
        idx = rng.choice(len(seen.points), size=proc.fingers, replace=False)
        contacts = tuple(Contact(tuple(seen.points[i]), tuple(seen.normals[i]), "point", mu) if proc.friction
                         else Contact(tuple(seen.points[i]), tuple(seen.normals[i])) for i in idx)
        out.append(Grasp(contacts, center=tuple(seen.center), length=float(seen.length),
                         id=f"random{proc.fingers}-{k:04d}"))
    return out


def grasps_of(subject: Subject, settings: Validation = QUICK_VALIDATION) -> tuple[list[_Planned], Any]:
    """The grasps the study executes on one object (module notes) and the perceived outline.

    Returns
    -------
    planned : list
        Records with ``source``, ``route``, ``procedure``, ``grasp``, ``certified``, ``eps``,
        ``tolerance`` (IndependentRegions or None) and ``status``.
    outline : Outline
        The image's outline at the default scale (the tolerances' boundary).
    """
    image = subject.image
    outline = outline_image(image, largest=True)
    seen = boundary(image)
    rng = np.random.default_rng([settings.seed, zlib.crc32(subject.name.encode())])
    out: list[_Planned] = []
    for route in routes():
        proc = route.procedure
        mu = settings.mu if proc.friction else None
        if route.method == "qualitative":
            try:  # tolerances of the chosen grasps only, as synthesize gives them (its regions, the fine outline)
                s = synthesize(image, procedure=proc.name, mu=mu, name=subject.name, quality=False,
                               largest=True, explain=False, tolerance=False)
            except QualitativeError:
                continue
            order = np.argsort([-r.eps_l1 for r in s.reports], kind="stable")[: settings.per_route]
            for i in order:
                t, status = _tolerance(outline, list(s.regions), s.grasps[i]) if s.reports[i].certified \
                    else (None, "none")
                out.append(_Planned("qualitative", route.name, proc.name, s.grasps[i], s.reports[i].certified,
                                    s.reports[i].eps_l1, t, status))
        else:
            found = baseline(image, proc, mu, settings.budget, name=subject.name)
            for g, ok, eps in list(zip(found.grasps, found.certified, found.epsilons))[: settings.per_route]:
                t, status = (_tolerance(outline, planned_regions(image, g, largest=True, outline=outline), g)
                             if ok else (None, "none"))
                out.append(_Planned("baseline", route.name, proc.name, g, ok, eps, t, status))
            for g in _random_grasps(seen, route, settings.mu if proc.friction else 0.0, settings.random, rng):
                report = certify_grasp(g, quality=True)
                out.append(_Planned("random", f"Random {proc.fingers}", proc.name, g, report.certified,
                                    report.eps_l1, None, "none"))
    return out, outline


# --------------------------------------------------------------------------------------------------
# Trials


def _fingers(obj: PlanarObject, executed: Grasp, planned: Grasp) -> list[Finger]:
    return [Finger(tuple(obj.to_world(e.p)), tuple(np.asarray(p.n, float) / np.linalg.norm(p.n)))
            for e, p in zip(executed.contacts, planned.contacts)]


def _mu(grasp: Grasp) -> float:
    return float(grasp.contacts[0].mu or 0.0)


def _moved(grasp: Grasp, arc: ArcBoundary, positions, shifts) -> Grasp:
    """The grasp with each finger's aim moved along the perceived boundary by ``shifts`` (pixels of
    arc), approaching along its planned normal."""
    contacts = tuple(Contact(arc.point_at(s + d), c.n, c.model, c.mu) for c, s, d in zip(grasp.contacts, positions, shifts))
    return Grasp(contacts, center=grasp.center, length=grasp.length, id=grasp.id, meta=dict(grasp.meta))


def placement(deltas: Sequence[float], positions: Sequence[float], limits, error: float, signs: Sequence[float],
              step: float = 0.0) -> list[float]:
    """Shifts along the outline (arc length) of a placement: ``error * delta_i * sign_i`` for finger
    ``i``, stopped at its limits ``(lo, hi)`` less ``step`` when ``limits`` are given (a placement
    inside the certified regions, which stop there too); a finger whose limits are narrower than
    ``2 step`` stays put.

    Examples
    --------
    A finger at arc length 10 with tolerance 4 and limits (8, 20) slides back at most to 8:

    >>> placement([4.0, 4.0], [10.0, 50.0], [(8.0, 20.0), (40.0, 60.0)], 1.0, [-1, 1])
    [-2.0, 4.0]
    >>> placement([4.0, 4.0], [10.0, 50.0], None, 2.0, [-1, 1])
    [-8.0, 8.0]
    """
    shifts = [error * d * s for d, s in zip(deltas, signs)]
    if limits is None:
        return shifts
    return [min(max(x + p, a + step), b - step) - p if b - a > 2 * step else 0.0
            for x, p, (a, b) in zip(shifts, positions, limits)]


def _trial(plan: _Planned, grasp: Grasp, truth: Boundary, obj: PlanarObject, perceived: np.ndarray,
           settings: Validation, physics: Physics, nominal: bool) -> dict:
    """Execute one (possibly moved) grasp on the true object and in physics: the outcome columns."""
    executed, outcome = execute(grasp, truth, settings.standoff, perceived)
    row = {"executed": outcome, "certified_true": False, "eps_true": 0.0, "held": False, "resisted": None,
           "ejected": None, "weakest": None, "tests": 0}
    if executed is None:
        if nominal:
            row["resisted"] = 0.0
        return row
    ok, eps = screen_grasps([executed])
    row.update(certified_true=bool(ok[0]), eps_true=float(eps[0]))
    fingers = _fingers(obj, executed, grasp)
    directions = DIRECTIONS[: settings.directions]
    if nominal:
        r = resistance(obj, fingers, _mu(grasp), physics, directions)
        row.update(held=r.held, resisted=r.magnitude, ejected=r.ejected, weakest=r.weakest, tests=r.tests)
    else:
        held, k = holds(obj, fingers, _mu(grasp), None, physics, directions)
        row.update(held=held, ejected=k == -1, weakest=None if k in (None, -1) else k, tests=1)
    return row


def explain(row: dict, physics: Physics = Physics()) -> str:
    """Why a placement inside the certified regions did not hold, from its row: the finger missed
    or started inside the true object; the executed grasp is not certified on the true object
    (the image's contour differs from it there: a vision error); its epsilon on the true object is
    below what the floor disturbance needs (``eps_true < floor / (fingers * max_force)``: even
    ideal fingers pressing ``max_force`` could not resist the floor; ``eps_true < floor / fingers``:
    the squeeze's total normal force, ``fingers * F0``, resists a ball of wrenches of radius
    ``eps_true * fingers`` F0 only, smaller than the floor, and friction forces do not grow with a
    push); the squeeze pushed the object
    out although the grasp is certified (the equal preloads found no balance); **compliance**: the
    same placement holds with fingers of stiffness :data:`STIFF` (the row's ``held_stiff``, which
    :func:`validate_object` fills in for such rows): a weak grasp is soft, and the floor load
    moves the object past the slip tolerance to a new rest pose without it escaping; or
    ``unexplained``.

    Examples
    --------
    >>> explain({"executed": "miss"})
    'a finger missed the true object'
    >>> explain({"executed": "contact", "certified_true": False})
    'not certified on the true object (vision error)'
    """
    if row.get("executed") == "miss":
        return "a finger missed the true object"
    if row.get("executed") == "collision":
        return "a finger started inside the true object"
    if not row.get("certified_true"):
        return "not certified on the true object (vision error)"
    eps, m = row.get("eps_true", 0.0), row.get("fingers", 1)
    if eps < physics.floor / (m * physics.max_force):
        return f"epsilon on the true object {eps:.3g}: too weak for the floor even at the largest finger force"
    if eps < physics.floor / m:
        return (f"epsilon on the true object {eps:.3g}: too weak for the floor at the squeeze force "
                f"(eps x {m} F0 = {eps * m:.3g} F0 < {physics.floor:g} F0)")
    if row.get("ejected"):
        return "certified on the true object, but the squeeze alone pushed it out (the preloads have no balance)"
    if row.get("held_stiff"):
        return (f"compliance: the fingers' springs let the object move past the slip tolerance to a new rest pose; "
                f"held with fingers {STIFF / physics.stiffness:g} times stiffer")
    return "unexplained"


def validate_object(subject: Subject, settings: Validation = QUICK_VALIDATION, recheck: bool = False,
                    planned: tuple[list[_Planned], Any] | None = None) -> list[dict]:
    """Every physical trial of one object (module notes): rows of :data:`COLUMNS`. ``planned`` is
    the object's :func:`grasps_of`, computed when not given."""
    planned, outline = planned if planned is not None else grasps_of(subject, settings)
    if subject.geometry is not None:
        truth, polygon = boundary_of_polygon(subject.geometry), subject.geometry
    else:
        truth = boundary(subject.image)
        polygon = Polygon(truth.points)
    obj = PlanarObject.from_polygon(polygon)
    arc = ArcBoundary.of(*outline_boundary(outline))
    perceived = outline.contour
    rng = np.random.default_rng([settings.seed + 1, zlib.crc32(subject.name.encode())])
    rows = []
    for plan in planned:
        g = plan.grasp
        base = {"object": subject.name, "source": plan.source, "route": plan.route, "procedure": plan.procedure,
                "fingers": len(g.contacts), "mu": _mu(g), "grasp": g.id, "certified": bool(plan.certified),
                "eps": float(plan.eps), "tolerance": plan.status,
                "delta_fraction": None if plan.tolerance is None or plan.status != "robust"
                else float(plan.tolerance.delta_fraction)}
        rows.append({**base, "placement": "nominal", "error": 0.0, "error_fraction": 0.0, "setting": "default",
                     **_trial(plan, g, truth, obj, perceived, settings, settings.physics, True)})
        if recheck:
            rows.append({**base, "placement": "nominal", "error": 0.0, "error_fraction": 0.0, "setting": "fine",
                         **_trial(plan, g, truth, obj, perceived, settings, FINE, True)})
        if plan.tolerance is None or plan.status != "robust":
            continue
        deltas, positions = plan.tolerance.deltas, plan.tolerance.positions
        step = arc.perimeter / len(arc.points)  # curved regions' limits are rounded inward to points
        for kind, count, lo, hi in (("inside", settings.inside, 0.0, 1.0),
                                    ("outside", settings.outside, 1.0, settings.outside_max)):
            for _ in range(count):
                e = float(hi - (hi - lo) * rng.random())  # in (lo, hi]
                signs = rng.choice((-1.0, 1.0), size=len(deltas))
                shifts = placement(deltas, positions, plan.tolerance.limits if kind == "inside" else None, e,
                                   signs, step)
                e = max(abs(x) / d for x, d in zip(shifts, deltas))
                row = {**base, "placement": kind, "error": e, "error_fraction": max(abs(x) for x in shifts) / truth.size,
                       "setting": "default",
                       **_trial(plan, _moved(g, arc, positions, shifts), truth, obj, perceived, settings,
                                settings.physics, False)}
                if kind == "inside" and not row["held"]:
                    row["explanation"] = explain(row, settings.physics)
                    if row["explanation"] == "unexplained":
                        stiff = _trial(plan, _moved(g, arc, positions, shifts), truth, obj, perceived, settings,
                                       replace(settings.physics, stiffness=STIFF), False)
                        row["explanation"] = explain({**row, "held_stiff": stiff["held"]}, settings.physics)
                rows.append(row)
    return [{c: r.get(c) for c in COLUMNS} for r in rows]


# --------------------------------------------------------------------------------------------------
# Summary


def rate(num: int, den: int) -> float | None:
    """``num / den``, None when ``den`` is 0."""
    return num / den if den else None


def confusion(rows: list[dict], predicted: str, outcome: str) -> dict:
    """The certified verdict ``predicted`` against the physical ``outcome`` of ``rows`` (truth
    values by key): ``certified``, ``held``, ``tp``, ``fp``, ``fn``, ``tn``, ``precision``, ``recall``."""
    tp = sum(1 for r in rows if r[predicted] and r[outcome])
    fp = sum(1 for r in rows if r[predicted] and not r[outcome])
    fn = sum(1 for r in rows if not r[predicted] and r[outcome])
    return {"certified": tp + fp, "held": tp + fn, "tp": tp, "fp": fp, "fn": fn, "tn": len(rows) - tp - fp - fn,
            "precision": rate(tp, tp + fp), "recall": rate(tp, tp + fn)}


def _confusion(rows: list[dict], verdict: str) -> dict:
    return {"grasps": len(rows), **confusion(rows, verdict, "held")}


def _spearman(x: Sequence[float], y: Sequence[float]) -> tuple[float | None, int]:
    x, y = np.asarray(x, float), np.asarray(y, float)
    if len(x) < 3 or np.ptp(x) == 0 or np.ptp(y) == 0:
        return None, len(x)
    return float(spearmanr(x, y).statistic), len(x)


def summarise(rows: list[dict]) -> dict:
    """Headline numbers of the trial rows (module notes): ``confusion`` (per source and pooled,
    for the planned and the true verdicts), ``spearman`` (per route and pooled: epsilon and
    tolerance against resisted), ``placements`` (held rates inside and outside) and
    ``exceptions`` (placements inside that did not hold, with their explanation)."""
    nominal = [r for r in rows if r["placement"] == "nominal" and r["setting"] == "default"]
    confusion = {}
    for verdict in ("certified", "certified_true"):
        for source in ("qualitative", "baseline", "random", "all"):
            sel = [r for r in nominal if source == "all" or r["source"] == source]
            confusion[(verdict, source)] = _confusion(sel, verdict)
    spearman = {}
    held = [r for r in nominal if r["certified"] and r["held"]]
    for route in sorted({r["route"] for r in nominal}) + ["all"]:
        sel = [r for r in held if route == "all" or r["route"] == route]
        tol = [r for r in sel if r["delta_fraction"] is not None]
        spearman[route] = {"eps": _spearman([r["eps"] for r in sel], [r["resisted"] for r in sel]),
                           "eps_true": _spearman([r["eps_true"] for r in sel], [r["resisted"] for r in sel]),
                           "tolerance": _spearman([r["delta_fraction"] for r in tol], [r["resisted"] for r in tol])}
    placements = {}
    for kind in ("inside", "outside"):
        sel = [r for r in rows if r["placement"] == kind]
        n_held = sum(1 for r in sel if r["held"])
        placements[kind] = {"placements": len(sel), "held": n_held, "rate": rate(n_held, len(sel))}
    exceptions = [r for r in rows if r["placement"] == "inside" and not r["held"]]
    return {"confusion": confusion, "spearman": spearman, "placements": placements, "exceptions": exceptions}


# --------------------------------------------------------------------------------------------------
# Files


def _fmt(v) -> str:
    if v is None:
        return ""
    if isinstance(v, float):
        return f"{v:.6g}"
    return str(v)


def _write_csv(path: Path, columns: Sequence[str], rows: Iterable[dict]) -> Path:
    with path.open("w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(columns)
        for r in rows:
            w.writerow([_fmt(r.get(c)) for c in columns])
    return path


def cell(v, spec=".3f") -> str:
    """A table cell: ``v`` formatted, ``-`` for None."""
    return "-" if v is None else format(v, spec)


def summary_markdown(summary: dict, closed: dict, settings: Validation, objects: int, seconds: float,
                     rows: list[dict]) -> str:
    """The Markdown summary of a validation run."""
    ph = settings.physics
    took = "" if math.isnan(seconds) else f", {seconds:.0f} s"
    lines = [f"# Physical validation: {objects} objects{took}", "",
             f"Physics ({ph.label()}; mass {ph.mass:g}, preload F0 = 1, finger force at most {ph.max_force:g} F0, "
             f"slip tolerance {ph.slip:g} of the size, floor {ph.floor:g} F0, {settings.directions} directions). "
             "A grasp **held** when it resisted the floor disturbance in every direction; **resisted** is the largest "
             "disturbance resisted in every direction (F0, torques over the object's radius).", "",
             "## The simulator on closed-form cases", "", *closed_forms.table_lines(closed, "+.3f", units=False)]
    lines += ["", "## Certified verdict against the physical outcome (nominal placement)", "",
              "| verdict | grasps | certified | held | certified and held | certified, not held | "
              "held, not certified | precision | recall |", "|---|---|---|---|---|---|---|---|---|"]
    for (verdict, source), c in summary["confusion"].items():
        name = {"certified": "as planned", "certified_true": "on the true object"}[verdict]
        lines.append(f"| {source}, {name} | {c['grasps']} | {c['certified']} | {c['held']} | {c['tp']} | {c['fp']} | "
                     f"{c['fn']} | {cell(c['precision'])} | {cell(c['recall'])} |")
    lines += ["", "## Rank correlation with the largest resisted disturbance (certified grasps that held)", "",
              "| route | Spearman eps (n) | Spearman eps on the true object (n) | Spearman tolerance (n) |",
              "|---|---|---|---|"]
    for route, s in summary["spearman"].items():
        cells = " | ".join(f"{cell(v, '+.2f')} ({n})" for v, n in (s["eps"], s["eps_true"], s["tolerance"]))
        lines.append(f"| {route} | {cells} |")
    lines += ["", "## Placements inside and outside the certified regions", "",
              "| placements | trials | held | held rate |", "|---|---|---|---|"]
    for kind, p in summary["placements"].items():
        lines.append(f"| {kind} | {p['placements']} | {p['held']} | {cell(p['rate'])} |")
    exc = summary["exceptions"]
    lines += ["", f"Placements inside that did not hold: {len(exc)}."]
    if exc:
        lines += ["", "| object | route | grasp | error (x tolerance) | executed | certified on the true object | "
                  "eps on the true object | explanation |", "|---|---|---|---|---|---|---|---|"]
        for r in exc:
            lines.append(f"| {r['object']} | {r['route']} | {r['grasp']} | {r['error']:.2f} | {r['executed']} | "
                         f"{r['certified_true']} | {r['eps_true']:.3g} | {r['explanation']} |")
    fine = [r for r in rows if r["setting"] == "fine"]
    if fine:
        pairs = _setting_pairs(rows)
        agree = sum(1 for a, b in pairs if a["held"] == b["held"])
        ratio = [b["resisted"] / a["resisted"] for a, b in pairs if a["resisted"] and b["resisted"]]
        lines += ["", "## The second physics setting", "",
                  f"{len(pairs)} nominal trials run again at {FINE.label()}: the held verdict agrees on {agree}; "
                  f"resisted (fine / default) median {cell(float(np.median(ratio)) if ratio else None)}, "
                  f"range {cell(min(ratio) if ratio else None)} to {cell(max(ratio) if ratio else None)}."]
    return "\n".join(lines) + "\n"


def _setting_pairs(rows: list[dict]) -> list[tuple[dict, dict]]:
    """Nominal trials run at both settings: ``(default row, fine row)`` pairs."""
    default = {(r["object"], r["route"], r["grasp"]): r for r in rows
               if r["placement"] == "nominal" and r["setting"] == "default"}
    return [(default[k], r) for r in rows if r["placement"] == "nominal" and r["setting"] == "fine"
            for k in [(r["object"], r["route"], r["grasp"])] if k in default]


def _closed_rows(closed: dict) -> list[dict]:
    return [{"setting": k, **asdict(c)} for k, cs in closed.items() for c in cs]


_BOOLS = ("certified", "certified_true", "held", "ejected")
_INTS = ("fingers", "weakest", "tests")
_FLOATS = ("mu", "eps", "delta_fraction", "error", "error_fraction", "eps_true", "resisted")


def _typed(column: str, text: str):
    if text == "":
        return None
    if column in _BOOLS:
        return text == "True"
    if column in _INTS:
        return int(text)
    if column in _FLOATS:
        return float(text)
    return text


def read_trials(path: str | Path) -> list[dict]:
    """The rows of a ``trials.csv`` written by :func:`validate`, typed as :func:`validate_object`
    gives them (numbers to 6 significant digits)."""
    with Path(path).open(newline="", encoding="utf-8") as fh:
        return [{c: _typed(c, r[c]) for c in COLUMNS} for r in csv.DictReader(fh)]


def read_closed_forms(path: str | Path) -> dict:
    """The closed-form rows of a ``closed-forms.csv`` written by :func:`validate`, per setting."""
    closed: dict = {}
    with Path(path).open(newline="", encoding="utf-8") as fh:
        for r in csv.DictReader(fh):
            closed.setdefault(r["setting"], []).append(closed_forms.ClosedForm(
                r["case"], r["formula"], float(r["exact"]), float(r["measured"]), float(r["error"]), r["unit"]))
    return closed


# --------------------------------------------------------------------------------------------------
# The study


def validate(images: Iterable[Any], out: str | Path, *, settings: str | Validation = "quick",
             progress: Callable[[str], None] | None = None, plots: bool = True) -> ValidationResult:
    """Run the physical validation study on every image (module notes) and write its files.

    Parameters
    ----------
    images : iterable
        Objects (:func:`qualgrasp.experiments.study.subjects`).
    out : str or pathlib.Path
        Output folder (created).
    settings : {'quick', 'full'} or Validation
    progress : callable, optional
        Called with a short message after the closed-form cases and after each object.
    plots : bool
        Draw the figures.

    Returns
    -------
    ValidationResult
    """
    start = time.perf_counter()
    settings = VALIDATIONS[settings] if isinstance(settings, str) else settings
    say = progress or (lambda _m: None)
    skipped: list = []
    items = subjects(images, skipped)
    if not items:
        raise ValueError("no images to validate" + (f" (skipped: {skipped})" if skipped else ""))
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    closed = {"default": closed_forms.cases(settings.physics), "fine": closed_forms.cases(FINE)}
    closed_file = _write_csv(out / "closed-forms.csv", ("setting", "case", "formula", "exact", "measured", "error",
                                                        "unit"), _closed_rows(closed))
    say("closed-form cases")
    tasks = [(s, settings, k < settings.recheck) for k, s in enumerate(items)]
    rows: list[dict] = []
    trials = out / "trials.csv"
    with trials.open("w", newline="", encoding="utf-8") as fh:  # rows as objects finish: a long run can be read early
        writer = csv.writer(fh)
        writer.writerow(COLUMNS)
        plans = {}  # each object's grasps, for the filmstrip
        for k, got in enumerate(_objects(tasks, settings.workers)):
            if isinstance(got, tuple):
                skipped.append(got)
            else:
                rows += got.rows
                plans[got.name] = got.planned
                writer.writerows([_fmt(r.get(c)) for c in COLUMNS] for r in got.rows)
                fh.flush()
            say(f"objects {k + 1}/{len(tasks)}")
    seconds = time.perf_counter() - start
    summary = summarise(rows)
    files = [trials, closed_file]
    pairs = _setting_pairs(rows)
    files.append(_write_csv(out / "settings.csv", ("object", "route", "grasp", "held_default", "held_fine",
                                                   "resisted_default", "resisted_fine"),
                            ({"object": a["object"], "route": a["route"], "grasp": a["grasp"],
                              "held_default": a["held"], "held_fine": b["held"], "resisted_default": a["resisted"],
                              "resisted_fine": b["resisted"]} for a, b in pairs)))
    md = out / "summary.md"
    md.write_text(summary_markdown(summary, closed, settings, len({r["object"] for r in rows}), seconds, rows),
                  encoding="utf-8")
    files.append(md)
    if plots:
        files += plot_all(out, rows, closed, settings.physics.floor, settings.outside_max,
                          {"default": settings.physics.label(), "fine": FINE.label()})
        film = filmstrip(items, rows, settings, plans)
        if film is not None:
            frames, obj, title = film
            files += plot_filmstrip(out, frames, obj.outline, settings.physics.finger_radius, obj.length, title)
    return ValidationResult(summary, closed, rows, time.perf_counter() - start, tuple(files), tuple(skipped))


def report(out: str | Path, settings: str | Validation = "full", images: Iterable[Any] | None = None,
           seconds: float | None = None) -> tuple[dict, list[Path]]:
    """Summary and figures again from the files of a run in ``out`` (``trials.csv`` and
    ``closed-forms.csv``; a run stopped early has the objects it finished): ``(summary, files)``.
    The filmstrip is drawn when ``images`` (the run's objects) are given.

    Examples
    --------
    >>> import tempfile
    >>> report(tempfile.mkdtemp())
    Traceback (most recent call last):
    ...
    FileNotFoundError: no trials.csv in ...
    """
    out = Path(out)
    settings = VALIDATIONS[settings] if isinstance(settings, str) else settings
    if not (out / "trials.csv").is_file() or not (out / "closed-forms.csv").is_file():
        raise FileNotFoundError(f"no trials.csv in {out} (or no closed-forms.csv): not a validation run")
    rows, closed = read_trials(out / "trials.csv"), read_closed_forms(out / "closed-forms.csv")
    summary = summarise(rows)
    md = out / "summary.md"
    md.write_text(summary_markdown(summary, closed, settings, len({r["object"] for r in rows}),
                                   math.nan if seconds is None else seconds, rows), encoding="utf-8")
    files = [md] + plot_all(out, rows, closed, settings.physics.floor, settings.outside_max,
                            {"default": settings.physics.label(), "fine": FINE.label()})
    if images is not None:
        film = filmstrip(subjects(images), rows, settings)
        if film is not None:
            files += plot_filmstrip(out, film[0], film[1].outline, settings.physics.finger_radius, film[1].length,
                                    film[2])
    return summary, files


def filmstrip(items: Sequence[Subject], rows: list[dict], settings: Validation,
              plans: Mapping[str, tuple[list[_Planned], Any]] | None = None):
    """A trial to show (``physics-filmstrip``): the qualitative grasp with the most fingers that held
    on the first object that has one, pushed in its weakest direction at 1.5 times what it
    resisted: ``(frames, object, title)``, or None when no qualitative grasp held. ``plans`` maps
    objects' names to their :func:`grasps_of` where the run kept them (else computed again)."""
    for subject in items:
        held = [r for r in rows if r["object"] == subject.name and r["source"] == "qualitative"
                and r["placement"] == "nominal" and r["setting"] == "default" and r["held"]]
        if not held:
            continue
        row = max(held, key=lambda r: (r["fingers"], r["resisted"]))
        planned, outline = (plans or {}).get(subject.name) or grasps_of(subject, settings)
        plan = next(p for p in planned if p.grasp.id == row["grasp"] and p.route == row["route"])
        truth = boundary_of_polygon(subject.geometry) if subject.geometry is not None else boundary(subject.image)
        obj = PlanarObject.from_polygon(subject.geometry if subject.geometry is not None else Polygon(truth.points))
        executed, _ = execute(plan.grasp, truth, settings.standoff, outline.contour)
        k = row["weakest"] if row["weakest"] is not None else 0
        w = 1.5 * row["resisted"] * DIRECTIONS[k]
        out = hold(obj, _fingers(obj, executed, plan.grasp), _mu(plan.grasp), w, settings.physics, record=10)
        title = (f"{subject.name}, {row['route']} (eps {row['eps']:.3f}): squeeze, then a push of 1.5 x the "
                 f"{row['resisted']:.2f} F0 it resisted, in its weakest direction "
                 f"({'held' if out.held else 'slips'})")
        return out.frames, obj, title
    return None


def _objects(tasks: list[tuple], workers: int):
    """:func:`_guarded` of every task, in order, in ``workers`` processes."""
    if workers <= 1:
        for task in tasks:
            yield _guarded(*task)
        return
    with ProcessPoolExecutor(workers) as pool:
        futures = [pool.submit(_guarded, *task) for task in tasks]
        for f in futures:
            yield f.result()


@dataclass(frozen=True)
class _Validated:
    """One object's trials (``rows``) and the grasps they executed (``planned``, :func:`grasps_of`)."""

    name: str
    rows: list
    planned: tuple


def _guarded(subject: Subject, settings: Validation, recheck: bool):
    """:func:`validate_object` as :class:`_Validated`, an image the vision cannot read becoming a
    skipped entry ``(name, reason)``."""
    try:
        planned = grasps_of(subject, settings)
        return _Validated(subject.name, validate_object(subject, settings, recheck, planned), planned)
    except (QualitativeError, ValueError) as err:  # unreadable image; a polygon the engine cannot take
        return subject.name, f"{type(err).__name__}: {err}"

"""The comparison study's design: its routes (generated from the procedure registry), the
perturbations, the settings and the columns of its tables.

:mod:`qualgrasp.experiments.study` runs the study, :mod:`qualgrasp.experiments.study_tables` and
:mod:`qualgrasp.experiments.study_plots` report it; all three share these definitions.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Mapping

import numpy as np
from shapely.geometry import Polygon

from ..qualitative.synthesis import procedures
from ..qualitative.synthesis.procedures import Procedure
from ..qualitative.synthesis.pipeline import NOT_COUNTED
from .baseline import MU, Budget

__all__ = ["Route", "routes", "compared_procedure", "KINDS", "UNITS", "BUILTINS", "ROUTES", "QUICK", "FULL",
           "SETTINGS", "REASONS", "OBJECT_COLUMNS", "OVERALL_COLUMNS", "ROBUSTNESS_COLUMNS", "GRASP_COLUMNS",
           "DETERMINISTIC", "Settings", "Subject", "RouteSummary", "StudyResult"]


@dataclass(frozen=True, eq=False)
class Route:
    """A route of the study: a registered synthesis procedure (``method`` ``qualitative``) or
    the quantitative baseline with the same fingers and contact model (``baseline``).

    ``name`` is ``'<Title> <fingers>'`` (``'ForceGrasp 2'``) or ``'Baseline <fingers>'``."""

    method: str
    procedure: Procedure

    @property
    def name(self) -> str:
        title = self.procedure.title if self.method == "qualitative" else "Baseline"
        return f"{title} {self.procedure.fingers}"

    @property
    def fingers(self) -> int:
        return self.procedure.fingers


def routes() -> tuple[Route, ...]:
    """Every route: one qualitative route per registered procedure, then one baseline per finger
    count and contact model (two procedures with three point contacts share ``Baseline 3``: the
    baseline searches contacts, not procedures), carrying the first such procedure."""
    procs = procedures.procedures()
    baselines = {(p.fingers, p.model): p for p in reversed(procs)}  # the first registered wins
    return tuple(Route("qualitative", p) for p in procs) + tuple(
        Route("baseline", p) for p in procs if baselines[(p.fingers, p.model)] is p)


def compared_procedure(procedure: Procedure, method: str) -> Procedure:
    """The procedure whose rows carry ``method``'s route for ``procedure``: itself for the
    qualitative route, else the procedure the baseline with the same fingers and contact model
    carries (:func:`routes`; PairGrasp 3 is compared with the baseline ForceGrasp 3 carries)."""
    if method == "qualitative":
        return procedure
    return next(r.procedure for r in routes() if r.method == method
                and (r.procedure.fingers, r.procedure.model) == (procedure.fingers, procedure.model))


KINDS = ("rotation", "translation", "noise", "blur", "threshold")
UNITS = {"none": "", "rotation": "deg", "translation": "px", "noise": "grey sd", "blur": "px sd",
         "threshold": "grey levels"}
BUILTINS = ("polygon", "nut", "disc", "figure3")
"""The built-in objects the demo and ``--builtins`` use."""
ROUTES = tuple((r.name.rsplit(" ", 1)[0], r.fingers) for r in routes())
"""``(method title, fingers)`` of every route, as in the tables' ``route`` column."""

REASONS = tuple(r.name for r in NOT_COUNTED)
"""Why a certified grasp is not counted as found, for every route alike
(:data:`qualgrasp.qualitative.synthesis.pipeline.NOT_COUNTED`: ``below_resolution``, a certified epsilon not
above the wrench change the image's uncertainty can cause); each is a column of the tables below."""

OBJECT_COLUMNS = ("object", "route", "method", "fingers", "mu", "grasps", "certified",
                  "certified_fraction", "eps_median", "eps_best", "ratio_best", "ratio_median",
                  "seconds", "candidates", "error", "procedure", "delta_best", "delta_status",
                  "counted", *REASONS, "slide_best")
"""Per object and route: grasps returned, certified (on the image's contour), certified fraction,
median and best certified L1 epsilon of the grasps **counted** as found (uncertified and
not-counted grasps count 0), the qualitative best and median over the baseline's best with the
same fingers (empty for the baseline), seconds (image to certified grasps), candidates screened
(baseline), error message (route failed on the image); the **certified slide** of the route's best
counted grasp (largest certified epsilon, the one the route would execute): how far every finger
may slide along the unperturbed outline either way with closure certified (the smallest certified
extent of its independent contact regions, fraction of the object's size;
:func:`qualgrasp.qualitative.synthesis.independent.independent_grasp`), ``slide_best``, with the status
(``robust``; ``undecided``: no sliding certified, 0; ``none: <why>``: a contact on a corner, where
no finger can slide, 0), ``delta_status``, and ``delta_best``, the search's half-width of the
stretches before they are clipped at the feasible regions (not how far a finger may slide);
``counted``, the certified grasps counted as found, and per reason of :data:`REASONS` the
certified grasps it excludes."""

OVERALL_COLUMNS = ("route", "method", "fingers", "objects", "objects_with_grasps", "grasps",
                   "certified_fraction", "eps_median", "eps_best", "ratio_best", "ratio_median",
                   "seconds_median", "seconds_total", "robustness", "robustness_paired", "procedure",
                   "delta_median", "delta_robust", "counted", *REASONS, "slide_median", "slide_robust")
"""Per route over all objects: objects, objects where the route found a counted grasp (certified
and not excluded by a reason of :data:`REASONS`), grasps, certified fraction (pooled), medians over
objects of the per-object median and best epsilon and of the ratios (objects where both routes
found grasps), median and total seconds, robustness pooled over every perturbation (not ``none``),
and the same over the trials where the route's partner planned a counted grasp too
(``robustness_paired``; the partner of a qualitative route is the baseline with the same fingers
and contact model, that of a baseline the qualitative route of the procedure it carries: the
qualitative route finds no grasp on some objects, where the baseline's grasps may be the most
fragile); the median over objects of the best grasp's certified slide
(``slide_median``, fraction of the size; objects where it was computed) and the share of those
objects where some sliding is certified (``slide_robust``), and the same of ``delta`` before
clipping (``delta_median``, ``delta_robust``); the grasps counted, and per reason the certified
grasps of the unperturbed images it excludes."""

ROBUSTNESS_COLUMNS = ("route", "method", "fingers", "kind", "size", "unit", "trials", "planned",
                      "held", "fraction", "misses", "collisions", "eps_planned", "eps_executed", "procedure",
                      *REASONS)
"""Per route, perturbation kind and size: trials (object x trial), planned grasps (certified on the
perturbed image and counted), how many hold on the true object, their fraction, fingers that
missed or collided, median epsilon of the planned and of the executed grasps (0 for those that
fail), and per reason of :data:`REASONS` the certified grasps it kept from being planned."""

GRASP_COLUMNS = ("object", "route", "method", "fingers", "certified", "eps", "procedure", "counted", *REASONS)
"""Per nominal grasp: certified, its certified L1 epsilon, counted as found, and whether each
reason of :data:`REASONS` applies."""

DETERMINISTIC = ("blur", "threshold")
"""Perturbations that get one trial whatever the settings."""

_FULL_SIZES = (("rotation", (1.0, 2.0, 4.0, 8.0)), ("translation", (1.0, 2.0, 4.0, 8.0)),
               ("noise", (10.0, 20.0, 40.0, 60.0)), ("blur", (1.0, 2.0, 4.0, 8.0)),
               ("threshold", (-60.0, -30.0, 30.0, 60.0)))
_QUICK_SIZES = (("rotation", (2.0, 8.0)), ("translation", (2.0, 8.0)), ("noise", (20.0, 60.0)),
                ("blur", (2.0, 8.0)), ("threshold", (-60.0, 60.0)))


@dataclass(frozen=True)
class Settings:
    """How much work the study does.

    Attributes
    ----------
    budget : Budget
        Baseline search budget (nominal images and every perturbed image).
    sizes : tuple of (str, tuple of float)
        Perturbation sizes per kind (units in :data:`UNITS`).
    trials : int
        Random trials per object, kind and size.
    mu : float
        Friction coefficient of the 2- and 3-finger routes.
    standoff : float
        Finger start distance before the planned contact, fraction of the object's diameter.
    workers : int
        Processes (1: run in this process).
    seed : int
        Seed of the perturbations.
    """

    budget: Budget = Budget()
    sizes: tuple[tuple[str, tuple[float, ...]], ...] = _FULL_SIZES
    trials: int = 2
    mu: float = MU
    standoff: float = 0.1
    workers: int = 2
    seed: int = 0


QUICK = Settings(budget=Budget(samples=128, extend=32, random=4000, starts=8, rounds=2),
                 sizes=_QUICK_SIZES, trials=1)
FULL = Settings()
SETTINGS = {"quick": QUICK, "full": FULL}


@dataclass(frozen=True, eq=False)
class Subject:
    """An object of the study: a name, its unperturbed grey image (uint8) and, when the image was
    rendered from known geometry (the built-in objects, the bundled silhouettes), that geometry in
    the image's pixels: the true object the study executes grasps on."""

    name: str
    image: np.ndarray
    geometry: Polygon | None = None


@dataclass(frozen=True)
class RouteSummary:
    """Headline numbers of one route (see :data:`OVERALL_COLUMNS`); None where undefined.
    ``not_counted``: ``(reason, certified grasps it excludes)`` per reason of :data:`REASONS`."""

    route: str
    fingers: int
    grasps: int
    certified_fraction: float | None
    eps_median: float | None
    eps_best: float | None
    ratio_best: float | None
    ratio_median: float | None
    seconds_median: float | None
    robustness: float | None
    robustness_paired: float | None
    delta_median: float | None = None
    delta_robust: float | None = None
    slide_median: float | None = None
    slide_robust: float | None = None
    not_counted: tuple[tuple[str, int], ...] = ()


@dataclass(frozen=True)
class StudyResult:
    """What :func:`compare` found and wrote.

    Attributes
    ----------
    objects : tuple of str
        Object names.
    routes : tuple of RouteSummary
        One per route of :data:`ROUTES`.
    robustness : mapping of (route, kind) to float
        Robustness pooled over sizes and objects, per route and perturbation kind.
    seconds : float
        Wall time of the study, seconds.
    files : tuple of pathlib.Path
        Tables and plots written.
    skipped : tuple of (str, str)
        Images left out, with the reason (unreadable, no single object).
    """

    objects: tuple[str, ...]
    routes: tuple[RouteSummary, ...]
    robustness: Mapping[tuple[str, str], float | None]
    seconds: float
    files: tuple[Path, ...] = field(default=())
    skipped: tuple[tuple[str, str], ...] = field(default=())



"""``qualgrasp bench``: time the certification routes on the same random grasps, in one run.

For each kind of grasp every route answers force closure, with its certificate, on the same
grasps (a prefix of them for the slow routes):

* **qualgrasp batch**: :func:`qualgrasp.certify.batch.fastpath.certify_table` on an Arrow table of the grasps,
  the path ``qualgrasp certify`` takes on Parquet input, per worker process. It does more than the
  others: force *and* form closure, both certificates and their rigorous re-check (epsilon off).
* **per-grasp fast route**: :func:`qualgrasp.certify.core.closure.force_closure` with the fast solver.
* **clarabel direct**: the same programme through clarabel's API with prebuilt structure.
* **scipy linprog (HiGHS)**: polyhedral kinds only.
* **cvxpy + Parameters** (the reference route) and **cvxpy rebuilt per grasp**.
* **exact verify**: the rational-arithmetic checker on the per-grasp certificates.

The table gives microseconds per grasp, grasps per second and each route's time per grasp as a
multiple of the batch path's. The **with quality** rows time the batch path with quality (the
offline job's default: closure, both epsilons and their evidence) on planar grasps of 3 and 10
point contacts, against the same grasps without quality and the per-grasp route with quality.
The **degenerate planar** rows time the batch path, without and with
quality, on a degenerate planar set (``qualgrasp sample --degenerate mixed``: normals through one
point, repeated or collinear contacts) and on a generic set of the same size, model and contact
count, in the same run; their ratio is the degenerate set's time per grasp as a multiple of the
generic set's. Every route is timed on a second pass over its grasps: the first loads every
kernel and solver they reach (and builds cvxpy's problems), as a worker's first chunk does. Speeds
are single-process; ``qualgrasp certify --workers N`` runs N
such processes, and ``qualgrasp bench`` times this table in a process whose memory allocator
is set as theirs (:func:`qualgrasp.certify.batch.engine.tune_allocator`).

``qualgrasp bench --single`` times one spatial grasp per call, as a planning loop calls the API:
:func:`~qualgrasp.certify.core.closure.force_closure` (exact cones, with its certificate) and
Dex-Net's ``force_closure_qp`` (8-edge cones, no certificate; loaded from a graspnetAPI sdist by
:mod:`qualgrasp.experiments.dexnet`) on the same grasps in the same run: per-call median, 95th
percentile and the ratio of the medians.

``qualgrasp bench --quality`` times epsilon on small grasps (bound gaps, the 8-edge linearisation
error); ``qualgrasp bench --contacts`` times one grasp in closure per size (3 to 1000 point
contacts, planar and spatial): closure (both certificates and their re-check) and quality (both
epsilons with their evidence), in seconds per grasp, without a time limit.
"""

from __future__ import annotations

import gc
import time
from dataclasses import dataclass, replace

import numpy as np
from rich.console import Console
from rich.progress import Progress
from rich.table import Table

from ..certify import models
from ..certify.batch import Options, certify_table, random_grasp_table, random_grasps
from ..certify.core import Grasp, force_closure, form_closure, grasp_to_dict, verify
from ..certify.core.problem import grasp_system
from ..certify.core.certificates import FLOAT_PROOF_CONTACTS
from ..certify.files import grasps_table
from ..certify.files.columns import grasp_columns
from ..certify.quality.bounds import check_norm, epsilon, epsilon_of_points, epsilons
from ..certify.report import certify_grasp
from ..certify.solvers import make_solver
from .dexnet import dexnet_inputs

__all__ = ["KINDS", "BATCH_QUALITY_KINDS", "DEGENERATE_KIND", "BenchRow", "run_bench", "print_bench", "SINGLE_KIND",
           "SINGLE_ROUND", "SingleRow", "run_single_bench", "print_single_bench", "CONTACTS", "ContactsRow",
           "epsilon_linearised", "run_contacts_bench", "print_contacts_bench"]

#: name -> keyword arguments of :func:`qualgrasp.certify.batch.samples.random_grasp`
#: (sizes chosen so that both verdicts are frequent: 17 % to 40 % of the grasps are in closure)
KINDS = {
    "planar frictionless, 5 contacts": dict(dim=2, n_contacts=5, model="frictionless"),
    "planar point, 3 contacts": dict(dim=2, n_contacts=3, model="point"),
    "spatial frictionless, 10 contacts": dict(dim=3, n_contacts=10, model="frictionless"),
    "spatial point, 3 contacts": dict(dim=3, n_contacts=3, model="point", spread=0.3),
    "spatial soft, 2 contacts": dict(dim=3, n_contacts=2, model="soft", spread=0.15),
}


#: The planar kinds also timed with quality (the offline job's default), one process: the batch
#: path against itself without quality and against the per-grasp route with quality.
BATCH_QUALITY_KINDS = {
    "planar point, 3 contacts": dict(dim=2, n_contacts=3, model="point"),
    "planar point, 10 contacts": dict(dim=2, n_contacts=10, model="point"),
}


#: The degenerate planar set of the benchmark, :func:`~qualgrasp.certify.batch.samples.random_grasp_table`'s
#: keyword arguments (its generic counterpart drops ``degenerate``).
DEGENERATE_KIND = dict(dim=2, n_contacts=4, model="point", degenerate="mixed")


@dataclass(frozen=True)
class BenchRow:
    kind: str
    route: str
    grasps: int
    seconds: float
    ratio: float  # time per grasp relative to the batch path

    @property
    def us_per_grasp(self) -> float:
        return 1e6 * self.seconds / self.grasps


def _time(fn, items) -> float:
    start = time.perf_counter()
    for item in items:
        fn(item)
    return time.perf_counter() - start


def _warm_seconds(fn, items) -> float:
    """Seconds of ``fn`` over ``items``, timed on a second pass, as :func:`_batch_seconds` times
    the batch path: the first, untimed, loads every kernel and solver the items reach (on a
    degenerate set, routes that its first grasp does not)."""
    _time(fn, items)
    return _time(fn, items)


def _batch_seconds(grasps, quality: bool = False, table=None) -> float:
    """Seconds of the columnar batch path on ``grasps`` (their ``table``, built outside the
    timing when not given), timed on a second pass: the first, untimed, loads or compiles every
    kernel and solver the set's rows reach, once per process as a worker does on its first
    chunk. (A few rows would do for a generic set, but not for a degenerate one, whose rarer
    routes would then load inside the timing: every set is judged warm.)"""

    table = grasps_table([grasp_to_dict(g) for g in grasps]) if table is None else table
    lines = list(range(1, len(grasps) + 1))
    options = Options(quality=quality)

    def slow(idx):
        return [certify_grasp(grasps[i], quality=quality).row(line=lines[i]) for i in idx]

    return _warm_seconds(lambda _: certify_table(table, lines, options, slow=slow), (table,))


def _quality_rows(n: int, seed: int, reference_n: int) -> list[BenchRow]:
    """The rows of :data:`BATCH_QUALITY_KINDS`: per kind, the batch path with quality (closure, both
    epsilons and their evidence) on ``n`` grasps, the same grasps without quality, and the
    per-grasp route with quality on the first ``reference_n``; ratios to the first."""
    rows = []
    for kind, kwargs in BATCH_QUALITY_KINDS.items():
        grasps = random_grasps(seed, n, **kwargs)
        table = grasps_table([grasp_to_dict(g) for g in grasps])
        base = _batch_seconds(grasps, True, table)
        plain = _batch_seconds(grasps, False, table)
        few = grasps[:max(reference_n, 1)]
        per = _warm_seconds(lambda g: certify_grasp(g, quality=True), few)
        label = f"{kind}, with quality"
        rows += [BenchRow(label, "qualgrasp batch, closure and both epsilons with evidence", n, base, 1.0),
                 BenchRow(label, "qualgrasp batch, closure only", n, plain, plain / base),
                 BenchRow(label, "per-grasp route with quality", len(few), per, (per / len(few)) / (base / n))]
    return rows


def _degenerate_rows(n: int, seed: int, reference_n: int) -> list[BenchRow]:
    """The degenerate planar rows: the batch path without and with quality on the degenerate
    set and on a generic one (same size, model and contacts, same run), ratio to the generic
    set; and the per-grasp fast route on the degenerate grasps, ratio to the generic batch."""
    generic = {k: v for k, v in DEGENERATE_KIND.items() if k != "degenerate"}
    label = (f"degenerate planar ({DEGENERATE_KIND['degenerate']}, {DEGENERATE_KIND['model']}, "
             f"{DEGENERATE_KIND['n_contacts']} contacts) vs generic")
    tables = {"generic": random_grasp_table(seed, n, **generic),
              "degenerate": random_grasp_table(seed, n, **DEGENERATE_KIND)}
    grasps = {name: grasp_columns(t).grasps(range(n)) for name, t in tables.items()}
    rows = []
    for quality in (False, True):
        base = _batch_seconds(grasps["generic"], quality, tables["generic"])
        deg = _batch_seconds(grasps["degenerate"], quality, tables["degenerate"])
        what = "with quality" if quality else "no quality"
        rows += [BenchRow(label, f"qualgrasp batch, generic set, {what}", n, base, 1.0),
                 BenchRow(label, f"qualgrasp batch, degenerate set, {what}", n, deg, deg / base)]
        if not quality:
            fast, few = make_solver("fast"), grasps["degenerate"][:max(reference_n, 1)]
            seconds = _warm_seconds(lambda g: certify_grasp(g, solver=fast, quality=False), few)
            rows.append(BenchRow(label, "per-grasp fast route (both certificates), degenerate set", len(few),
                                 seconds, (seconds / len(few)) / (base / n)))
    return rows


def run_bench(n: int = 20000, seed: int = 0, reference_n: int = 300,
              progress: bool = True) -> list[BenchRow]:
    """Time every route of the module docstring on ``n`` grasps per kind (``reference_n`` for the
    routes slower than a millisecond per grasp)."""

    rows = []
    with Progress(transient=True, disable=not progress) as bar:
        for kind, kwargs in KINDS.items():
            task = bar.add_task(kind, total=None)
            grasps = random_grasps(seed, n, **kwargs)
            few = grasps[:reference_n]
            t_batch = _batch_seconds(grasps) / len(grasps)
            routes = [("qualgrasp batch (force + form, certified)", len(grasps), t_batch * len(grasps))]
            solvers = [("per-grasp fast route", make_solver("fast"), grasps[: max(reference_n, n // 10)]),
                       ("clarabel direct", make_solver("clarabel"), few)]
            if models.get(kwargs["model"]).generators(kwargs["dim"]) is not None:  # a polyhedral cone: an LP
                solvers.append(("scipy linprog (HiGHS)", make_solver("linprog"), few))
            solvers += [("cvxpy + Parameters (reference)", make_solver("reference"), few),
                        ("cvxpy rebuilt per grasp", make_solver("reference-rebuilt"), few)]
            for name, solver, items in solvers:  # each timed on a second pass, as the batch path
                routes.append((name, len(items), _warm_seconds(lambda g: force_closure(g, solver=solver), items)))
                bar.advance(task)
            fast = make_solver("fast")
            pairs = [(g, force_closure(g, solver=fast)) for g in few]
            routes.append(("exact verify (rationals, no solver)", len(pairs),
                           _warm_seconds(lambda gv: verify(gv[0], gv[1].certificate), pairs)))
            for route, count, seconds in routes:
                rows.append(BenchRow(kind, route, count, seconds, (seconds / count) / t_batch))
            bar.remove_task(task)
        task = bar.add_task("planar with quality", total=None)
        rows += _quality_rows(n, seed, reference_n)
        bar.remove_task(task)
        task = bar.add_task("degenerate planar", total=None)
        rows += _degenerate_rows(n, seed, reference_n)
        bar.remove_task(task)
    return rows


def print_bench(rows: list[BenchRow]) -> None:
    """Print the benchmark table with rich."""

    table = Table(title="closure certification, time per grasp (same grasps, same run, one process)")
    for col in ("kind", "route", "grasps", "us/grasp", "grasps/s", "x batch"):
        table.add_column(col, justify="left" if col in ("kind", "route") else "right")
    for r in rows:
        table.add_row(r.kind, r.route, str(r.grasps), f"{r.us_per_grasp:.1f}",
                      f"{r.grasps / r.seconds:,.0f}", f"{r.ratio:.2f}")
    Console(width=max(120, Console().width)).print(table)


@dataclass(frozen=True)
class Agreement:
    """Verdicts of two routes on the same grasps."""

    kind: str
    grasps: int
    same_status: int
    statuses: dict
    max_margin_diff: float
    disagreements: tuple  # ids with contradicting statuses
    resolved: tuple = ()  # ids one route left degenerate and the other proved (exact re-check)

    @property
    def rate(self) -> float:
        return self.same_status / self.grasps


def compare_routes(grasps, kind: str = "", a: str = "fast", b: str = "reference",
                   frictionless: bool = False) -> Agreement:
    """Compare the verdicts of routes ``a`` and ``b`` on ``grasps`` (form closure if
    ``frictionless``): status counts of ``a``, agreement count, largest margin difference, the
    grasps on which they contradict each other, and those one route left degenerate (within
    tolerance of the boundary) that the other decided with a certificate passing the exact
    re-check."""

    test = form_closure if frictionless else force_closure
    sa, sb = make_solver(a), make_solver(b)
    same, diff, statuses, bad, resolved = 0, 0.0, {}, [], []
    for g in grasps:
        va, vb = test(g, solver=sa), test(g, solver=sb)
        statuses[va.status] = statuses.get(va.status, 0) + 1
        if va.status == vb.status:
            same += 1
            diff = max(diff, abs(va.margin - vb.margin))
        elif _proves(g, va if vb.status == "degenerate" else vb if va.status == "degenerate" else None,
                     frictionless):
            resolved.append(g.id)
        else:
            bad.append(g.id)
    return Agreement(kind, len(grasps), same, statuses, diff, tuple(bad), tuple(resolved))


def _proves(grasp, verdict, frictionless: bool) -> bool:
    """A decisive verdict whose certificate passes the exact re-check (False for None)."""

    return verdict is not None and verdict.status != "degenerate" and verify(
        grasp, verdict.certificate, status=verdict.status, frictionless=frictionless).ok


@dataclass(frozen=True)
class QualityRow:
    kind: str
    norm: str
    grasps: int
    median_gap: float
    worst_gap: float
    median_ms: float
    worst_ms: float
    lin8_median_err: float | None  # relative error of the 8-edge linearisation vs exact cones
    lin8_worst_err: float | None


QUALITY_KINDS = {
    "planar point, 3 contacts": dict(dim=2, n_contacts=3, model="point"),
    "spatial point, 3 contacts": dict(dim=3, n_contacts=3, model="point", spread=0.3),
    "spatial point, 4 contacts": dict(dim=3, n_contacts=4, model="point", spread=0.3),
    "spatial soft, 2 contacts": dict(dim=3, n_contacts=2, model="soft", spread=0.15),
}


def run_quality_bench(n: int = 30, seed: int = 0, budget: int = 200_000) -> list[QualityRow]:
    """Epsilon on ``n`` random grasps in closure per kind: the relative gap ``(hi - lo) / hi``
    reached and the time per grasp, and for point contacts how far the 8-edge linearisation's
    epsilon falls below the exact-cone value (relative to ``hi``; the true error lies between
    that and the same relative to ``lo``)."""

    rows = []
    for kind, kwargs in QUALITY_KINDS.items():
        grasps = [g for g in random_grasps(seed, 40 * n, **kwargs)
                  if force_closure(g).status == "closure"][:n]
        for norm in ("L1", "Linf"):
            gaps, times, errs = [], [], []
            for g in grasps:
                start = time.perf_counter()
                e = epsilon(g, norm, budget=budget)
                times.append(1e3 * (time.perf_counter() - start))
                gaps.append(e.gap)
                linear = kwargs["model"] == models.POINT.name and kwargs["dim"] == 3
                if linear and (norm == "L1" or kwargs["n_contacts"] <= 3):
                    errs.append((e.hi - epsilon_linearised(g, norm, 8)) / e.hi)
            rows.append(QualityRow(kind, norm, len(grasps), float(np.median(gaps)), max(gaps),
                                   float(np.median(times)), max(times),
                                   float(np.median(errs)) if errs else None,
                                   max(errs) if errs else None))
    return rows


def print_quality_bench(rows: list[QualityRow]) -> None:

    table = Table(title="Ferrari-Canny epsilon: bound gap, time per grasp, 8-edge linearisation error")
    for col in ("kind", "norm", "grasps", "gap median", "gap worst", "ms median", "ms worst",
                "8-edge err median", "8-edge err worst"):
        table.add_column(col, justify="left" if col in ("kind", "norm") else "right")
    pct = lambda v: "-" if v is None else f"{100 * v:.2f} %"
    for r in rows:
        table.add_row(r.kind, r.norm, str(r.grasps), pct(r.median_gap), pct(r.worst_gap),
                      f"{r.median_ms:.0f}", f"{r.worst_ms:.0f}", pct(r.lin8_median_err),
                      pct(r.lin8_worst_err))
    Console(width=max(140, Console().width)).print(table)


#: The grasps of ``qualgrasp bench --single``: :func:`~qualgrasp.certify.batch.samples.random_grasps`'
#: keyword arguments (spatial, three point contacts, about 9 % in closure).
SINGLE_KIND = dict(dim=3, n_contacts=3, model="point")


#: Grasps per turn of each route in ``qualgrasp bench --single``.
SINGLE_ROUND = 50


@dataclass(frozen=True)
class SingleRow:
    """Per-call times of one route on the grasps of ``qualgrasp bench --single``: ``median_us``
    and ``p95_us`` (microseconds, None when the route was not run), ``speedup`` (Dex-Net's median
    over this route's, None without Dex-Net) and a ``note``."""

    route: str
    grasps: int
    median_us: float | None
    p95_us: float | None
    speedup: float | None
    note: str = ""


def _per_call_us(fn, items, times: list) -> None:
    for item in items:
        start = time.perf_counter()
        fn(item)
        times.append(1e6 * (time.perf_counter() - start))


def run_single_bench(n: int = 2000, seed: int = 0, dexnet=None) -> list[SingleRow]:
    """Time one spatial grasp through the API, call by call: :func:`force_closure` as a user
    calls it (exact cones, with its certificate) and, with ``dexnet``
    (:func:`qualgrasp.experiments.dexnet.load_dexnet`), Dex-Net's ``force_closure_qp`` (8-edge
    cones, no certificate) on the same ``n`` grasps (:data:`SINGLE_KIND`), in the same run: the
    routes take turns over rounds of :data:`SINGLE_ROUND` grasps, so that both see the same
    machine load and each runs as in a planning loop (calls in a row), with the garbage collector
    off. The kernels compile, and cvxopt warms up, on 20 grasps before the clock. Dex-Net's inputs
    (:func:`~qualgrasp.experiments.dexnet.dexnet_inputs`) are built outside its clock."""
    grasps = random_grasps(seed, n, **SINGLE_KIND)
    inputs = [dexnet_inputs(g) for g in grasps] if dexnet is not None else None
    warm = random_grasps(seed + 1, 20, **SINGLE_KIND)
    for g in warm:
        force_closure(g)
        if dexnet is not None:
            dexnet.force_closure_qp(*dexnet_inputs(g))
    ours, theirs, verdicts, dex = [], [], [], []
    gc.collect()
    gc.disable()  # as timeit does: a collection would land on whichever call happens to trigger it
    try:
        for lo in range(0, n, SINGLE_ROUND):
            _per_call_us(lambda g: verdicts.append(force_closure(g).status), grasps[lo:lo + SINGLE_ROUND], ours)
            if dexnet is not None:
                _per_call_us(lambda args: dex.append(dexnet.force_closure_qp(*args)),
                             inputs[lo:lo + SINGLE_ROUND], theirs)
    finally:
        gc.enable()
    median = float(np.median(ours))
    closure = sum(v == "closure" for v in verdicts)
    rows = [SingleRow("qualgrasp force_closure (exact cones, certificate)", n, median,
                      float(np.percentile(ours, 95)), None,
                      f"{closure} in closure, {n - closure - verdicts.count('degenerate')} not, "
                      f"{verdicts.count('degenerate')} degenerate")]
    if dexnet is None:
        rows.append(SingleRow("Dex-Net force_closure_qp (8-edge cones, no certificate)", 0, None, None, None,
                              "not run: pass --dexnet PATH (graspnetAPI 1.2.11 sdist) and pip install cvxopt"))
        return rows
    theirs_median = float(np.median(theirs))
    rows[0] = replace(rows[0], speedup=theirs_median / median)
    both = sum(d == 1 and v == "closure" for d, v in zip(dex, verdicts))
    only_dex = sum(d == 1 and v != "closure" for d, v in zip(dex, verdicts))
    only_ours = sum(d == 0 and v == "closure" for d, v in zip(dex, verdicts))
    rows.append(SingleRow("Dex-Net force_closure_qp (8-edge cones, no certificate)", n, theirs_median,
                          float(np.percentile(theirs, 95)), 1.0,
                          f"closure: {both} both, {only_ours} only exact cones, {only_dex} only Dex-Net"))
    return rows


def print_single_bench(rows: list[SingleRow]) -> None:
    """Print the single-grasp benchmark table with rich."""
    first = rows[0]
    table = Table(title=f"one spatial grasp per call ({first.grasps} random grasps, {SINGLE_KIND['n_contacts']} "
                        f"{SINGLE_KIND['model']} contacts, same grasps, same run)")
    for col in ("route", "grasps", "median us", "p95 us", "x faster than Dex-Net", "note"):
        table.add_column(col, justify="left" if col in ("route", "note") else "right")
    num = lambda v, f: "-" if v is None else format(v, f)
    for r in rows:
        table.add_row(r.route, str(r.grasps), num(r.median_us, ".1f"), num(r.p95_us, ".1f"),
                      num(r.speedup, ".2f"), r.note)
    Console(width=max(150, Console().width)).print(table)


#: Contact counts of ``qualgrasp bench --contacts``.
CONTACTS = (3, 10, 50, 200, 1000)


@dataclass(frozen=True)
class ContactsRow:
    """Seconds for one grasp in closure with ``contacts`` point contacts: closure (force and form
    closure, certificates and their re-check) and quality (L1 and L-infinity epsilon with their
    evidence), with the relative gaps reached and whether a time limit was hit."""

    dim: int
    contacts: int
    closure_s: float
    quality_s: float
    gap_l1: float
    gap_linf: float
    limited: bool


def run_contacts_bench(contacts=CONTACTS, seed: int = 0, time_limit: float | None = None) -> list[ContactsRow]:
    """Time one grasp in closure per size and dimension (random point contacts, ``mu`` in
    [0.2, 1], the first of :func:`~qualgrasp.certify.batch.samples.random_grasps` in closure), after a
    warm-up that compiles the kernels."""
    rows = []
    for dim in (2, 3):
        extra = {"spread": 0.3} if dim == 3 else {}
        for n_warm in (4, FLOAT_PROOF_CONTACTS):  # the kernels of both routes of verify too
            warm = next(g for g in random_grasps(seed, 50, dim=dim, n_contacts=n_warm, **extra)
                        if force_closure(g).status == "closure")
            epsilons(warm, verdict=certify_grasp(warm, quality=False).force)
        for m in contacts:
            g = next((g for g in random_grasps(seed, 50, dim=dim, n_contacts=m, **extra)
                      if force_closure(g).status == "closure"), None)
            if g is None:
                continue
            start = time.perf_counter()
            report = certify_grasp(g, quality=False)
            t_closure = time.perf_counter() - start
            start = time.perf_counter()
            e = epsilons(g, verdict=report.force, time_limit=time_limit)
            t_quality = time.perf_counter() - start
            rows.append(ContactsRow(dim, m, t_closure, t_quality, e["L1"].gap, e["Linf"].gap,
                                    any(x.limited for x in e.values())))
    return rows


def print_contacts_bench(rows: list[ContactsRow]) -> None:
    """Print the contacts benchmark table with rich."""
    table = Table(title="one grasp in closure: seconds per grasp by contact count (point contacts)")
    for col in ("grasp", "contacts", "closure s", "quality s", "gap L1", "gap Linf", "time limit hit"):
        table.add_column(col, justify="left" if col == "grasp" else "right")
    for r in rows:
        table.add_row("planar" if r.dim == 2 else "spatial", str(r.contacts), f"{r.closure_s:.3f}",
                      f"{r.quality_s:.3f}", f"{100 * r.gap_l1:.2f} %", f"{100 * r.gap_linf:.2f} %",
                      "yes" if r.limited else "no")
    Console(width=max(120, Console().width)).print(table)


def epsilon_linearised(grasp: Grasp, norm: str = "L1", edges: int = 8) -> float:
    """Epsilon with every spatial friction cone replaced by ``edges`` inscribed edges (the
    linearisation other toolkits use, e.g. Dex-Net's 8 edges), exact for that polytope.

    Point contacts only (no torsion); frictionless contacts keep their normal. The result is a
    lower bound of the exact-cone epsilon. For ``Linf`` the Minkowski sum is enumerated, so keep
    ``(edges + 1) ** contacts`` small.
    """
    check_norm(norm)
    system = grasp_system(grasp, socp=True)
    theta = 2 * np.pi * np.arange(edges) / edges
    per_contact = []
    for b in system.blocks:
        cols = system.columns[:, list(b.cols)]
        if b.cone == "ray":
            per_contact.append(cols.T)
            continue
        if len(b.cols) > len(b.n):
            raise ValueError("epsilon_linearised handles point and frictionless contacts only")
        n = np.asarray(b.n, dtype=float) / np.linalg.norm(b.n)
        if len(n) == 2:
            t = np.array([[-n[1], n[0]], [n[1], -n[0]]])
        else:
            axis = np.eye(3)[np.argmin(np.abs(n))]
            t1 = np.cross(n, axis)
            t1 /= np.linalg.norm(t1)
            t2 = np.cross(n, t1)
            t = np.cos(theta)[:, None] * t1 + np.sin(theta)[:, None] * t2
        per_contact.append((n + float(b.mu) * t) @ cols.T)
    if norm == "L1":
        return epsilon_of_points(np.vstack([np.zeros(system.columns.shape[0])] + per_contact))
    sums = np.zeros((1, system.columns.shape[0]))
    for g in per_contact:
        with_zero = np.vstack([np.zeros(g.shape[1]), g])
        sums = (sums[:, None, :] + with_zero[None, :, :]).reshape(-1, g.shape[1])
    return epsilon_of_points(sums)

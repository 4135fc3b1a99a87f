"""The spatial validation study: do grasps certified to hold an object's weight hold it in MuJoCo?

:func:`validate_spatial` runs it on the real object meshes of installed packages
(:func:`qualgrasp.experiments.mesh_study.real_meshes`), filled up to :attr:`SpatialValidation.least`
meshes with the made-up ones (:func:`qualgrasp.experiments.mesh_study.made_up_meshes`).

Per mesh
--------
* **Poses**: :func:`qualgrasp.certify.meshes.sampling.sample_poses` (the Franka hand, friction
  ``mu``), contacts :func:`qualgrasp.certify.meshes.contacts.jaw_contacts`, certify's soft-contact
  grasp :func:`qualgrasp.certify.meshes.poses.grasp_of`.
* **Certified least grip force** ``F_min``: :func:`qualgrasp.certify.meshes.task.least_grip`
  against gravity ``-z`` with the same mass (:attr:`SpatialValidation.mass`, spread uniformly) and
  friction; ``certified at F`` is its verdict :func:`~qualgrasp.certify.meshes.task.hold_verdict`
  ``== 'holds'``.
* **Physical trials** (:func:`qualgrasp.experiments.physics.spatial.trial`) at ``F = r F_min`` for
  every ratio ``r`` of :attr:`SpatialValidation.ratios` (``F_min`` replaced by the mesh's median
  finite ``F_min`` when no grip force is certified): ``held`` (under gravity), ``held_shake``,
  slip; and the smallest grip force that holds in physics, ``F_phys``
  (:func:`~qualgrasp.experiments.physics.spatial.least_physical_grip` between ``F_min / 8`` and
  ``8 F_min``).

Summary (:func:`summarise_spatial`): precision and recall of ``certified at F`` against ``held``
(and ``held_shake``), per mesh and overall; held rate per ratio; Spearman's rank correlation of
``F_min`` with ``F_phys``; seconds per trial; the verdicts at the second physics setting on the
first :attr:`SpatialValidation.recheck` meshes.

Outputs (in ``out``): ``spatial-trials.csv`` (:data:`TRIAL_COLUMNS`), ``spatial-poses.csv``
(:data:`POSE_COLUMNS`), ``spatial-closed-forms.csv`` (both settings), ``spatial-summary.md``,
``spatial-held-rate.png``; the convex pieces of every mesh are kept in ``spatial-pieces/`` and
reused by a later run in the same folder.
"""

from __future__ import annotations

import csv
import hashlib
import math
import time
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Callable

import numpy as np
from scipy.stats import spearmanr

from ...certify.meshes.contacts import jaw_contacts
from ...certify.meshes.gripper import load_gripper
from ...certify.meshes.mesh import mass_properties
from ...certify.meshes.poses import grasp_of
from ...certify.meshes.rays import RayCaster
from ...certify.meshes.sampling import sample_poses
from ...certify.meshes.task import hold_verdict, least_grip
from ..mesh_study import made_up_meshes, real_meshes
from ..style import new_figure, save
from . import closed_forms
from .study import cell, confusion, rate
from .spatial import Jaw, SpatialObject, SpatialPhysics, convex_pieces, least_physical_grip, trial

__all__ = ["SETTLED", "SECOND", "TRIAL_COLUMNS", "POSE_COLUMNS", "SpatialValidation", "SPATIAL_VALIDATIONS", "study_meshes",
           "pieces_of", "validate_mesh", "summarise_spatial", "spatial_markdown", "plot_held_rate",
           "validate_spatial"]

SETTLED = 0.002
"""An object the squeeze moved farther than this (m) was re-seated in the pads: the certified
contacts, computed on the object as it was before closing, are not the ones it is held by."""

SECOND = SpatialPhysics(dt=2e-3, iterations=20, impratio=10.0)
"""The second physics setting: twice the time step, 20 solver iterations, impratio 10."""

TRIAL_COLUMNS = ("mesh", "source", "pose", "setting", "ratio", "force", "f_lo", "f_min", "verdict", "certified",
                 "held", "held_shake", "dropped", "slip_mm", "slip_shake_mm", "contacts", "settle_mm", "seconds")
"""Per physical trial: the mesh, its source and the pose's index; the physics setting
(``default``, ``second``); the grip force as a ratio of ``F_min`` (of the mesh's median when
``F_min`` is infinite) and in newtons; the certified bracket ``f_lo <= F_min`` (N, ``f_min`` its
upper end; empty when infinite); the certified verdict at the force (``holds``, ``slips``,
``undecided``) and ``certified`` (it is ``holds``); the physical outcome (held under gravity, after
the shake, dropped, slips in mm, contacts after closing, how far the squeeze moved the object in
mm) and the trial's wall-clock seconds."""

POSE_COLUMNS = ("mesh", "source", "pose", "pieces", "decomposition", "f_lo", "f_min", "f_phys", "f_phys_soft",
                "seconds")
"""Per pose: the mesh's convex pieces and how they were made, the certified least grip force and
the smallest that held in physics (N; empty when infinite; ``f_phys_soft`` with condim 4), seconds
of the two bisections."""


@dataclass(frozen=True)
class SpatialValidation:
    """How much work the spatial study does.

    Attributes
    ----------
    physics, second : SpatialPhysics
        The main and the second physics setting. Every trial also runs with the main setting's
        contacts of dimension 4 (setting ``soft``: certify's soft contacts, the torsional friction
        of the certified patch at each contact point).
    poses : int
        Poses sampled per mesh.
    ratios : tuple of float
        Grip forces tried, as multiples of ``F_min``.
    precision : float
        Ratio of the final bracket of ``F_phys``.
    least : int
        Meshes at least (made-up meshes fill up the real ones).
    recheck : int
        Meshes (the first) whose trials are run again at ``second``.
    mass : float
        Object mass, kg.
    mu : float
        Friction.
    seed : int
        Seed of the pose sampler.
    """

    physics: SpatialPhysics = field(default_factory=SpatialPhysics)
    second: SpatialPhysics = SECOND
    poses: int = 10
    ratios: tuple[float, ...] = (0.25, 0.5, 0.7, 0.9, 1.1, 1.5, 2.0, 4.0)
    precision: float = 1.05
    least: int = 20
    recheck: int = 5
    mass: float = 0.3
    mu: float = 0.5
    seed: int = 2


SPATIAL_VALIDATIONS = {"quick": SpatialValidation(poses=4, ratios=(0.5, 0.8, 1.25, 2.0), precision=1.15, recheck=2),
                       "full": SpatialValidation()}
"""The study's sizes, as ``validate --setting``."""


def study_meshes(least: int = 20) -> tuple[dict, list]:
    """The real meshes (``{name: (mesh, source)}``) filled up to ``least`` with the made-up ones, and
    the skipped real models ``[(name, why)]``."""
    meshes, skipped = real_meshes()
    for name, mesh in made_up_meshes().items():
        if len(meshes) >= least:
            break
        meshes[f"made-up/{name}"] = (mesh, "made up (mesh_study)")
    return meshes, skipped


def pieces_of(mesh, cache: Path | None = None) -> tuple[list, str]:
    """:func:`~qualgrasp.experiments.physics.spatial.convex_pieces` of ``mesh``, read from (and
    written to) ``cache`` (a folder; files named by a hash of the mesh) when given."""
    key = hashlib.sha1(np.ascontiguousarray(mesh.vertices).tobytes()
                       + np.ascontiguousarray(mesh.faces).tobytes()).hexdigest()[:16]
    path = None if cache is None else cache / f"{key}.npz"
    if path is not None and path.is_file():
        with np.load(path) as z:
            return [z[f"p{i}"] for i in range(len(z.files) - 1)], str(z["method"])
    pieces, method = convex_pieces(mesh)
    if path is not None:
        cache.mkdir(parents=True, exist_ok=True)
        np.savez(path, method=method, **{f"p{i}": v for i, v in enumerate(pieces)})
    return pieces, method


def _finite(v: float) -> float | None:
    return float(v) if math.isfinite(v) else None


def _grasps(mesh, settings: SpatialValidation) -> list:
    """``(pose, jaw parameters (T, width, torsions), grasp, bound)`` of every sampled pose with
    contacts."""
    gripper = load_gripper("franka_panda")
    caster = RayCaster(mesh)
    props = mass_properties(mesh, mass=settings.mass)
    out = []
    for k, p in enumerate(sample_poses(mesh, gripper, settings.poses, mu=settings.mu, seed=settings.seed,
                                       caster=caster)):
        o = jaw_contacts(mesh, gripper, p.T[None], np.array([p.width]), caster=caster)[0]
        if not o.ok:
            continue
        grasp = grasp_of(o, settings.mu, "soft", props)
        bound = least_grip(grasp, props.mass, props.com, (0, 0, -1))
        jaw = Jaw(p.T, p.width, gripper, settings.mu, tuple(float(q.torsion) for q in o.patches[:2]))
        out.append((k, jaw, bound))
    return out


def validate_mesh(name: str, mesh, source: str, settings: SpatialValidation, *, cache: Path | None = None,
                  recheck: bool = False) -> tuple[list[dict], list[dict]]:
    """Trials and poses of one mesh (module notes): ``(trial rows, pose rows)``."""
    pieces, method = pieces_of(mesh, cache)
    obj = SpatialObject(tuple(pieces), mass_properties(mesh, mass=settings.mass))
    grasps = _grasps(mesh, settings)
    finite = [b.hi for _, _, b in grasps if math.isfinite(b.hi)]
    fallback = float(np.median(finite)) if finite else settings.mass * 9.80665 / (2 * settings.mu)
    trials, poses = [], []
    settings_run = [("default", settings.physics), ("soft", replace(settings.physics, condim=4))]
    settings_run += [("second", settings.second)] if recheck else []
    for k, jaw, b in grasps:
        ref = b.hi if math.isfinite(b.hi) else fallback
        for label, physics in settings_run:
            for r in settings.ratios:
                force = r * ref
                t = trial(obj, jaw, force, physics)
                verdict = hold_verdict(b.lo, b.hi, force)
                trials.append({"mesh": name, "source": source, "pose": k, "setting": label, "ratio": r, "force": force,
                               "f_lo": _finite(b.lo), "f_min": _finite(b.hi), "verdict": verdict,
                               "certified": verdict == "holds", "held": t.held, "held_shake": t.held_shake,
                               "dropped": t.dropped, "slip_mm": 1000 * t.slip, "slip_shake_mm": 1000 * t.slip_shake,
                               "contacts": t.contacts, "settle_mm": 1000 * t.settle, "seconds": t.seconds})
        t0 = time.perf_counter()
        f_phys = least_physical_grip(obj, jaw, ref / 8, 8 * ref, settings.physics, precision=settings.precision)
        f_soft = least_physical_grip(obj, jaw, ref / 8, 8 * ref, settings_run[1][1], precision=settings.precision)
        poses.append({"mesh": name, "source": source, "pose": k, "pieces": len(pieces), "decomposition": method,
                      "f_lo": _finite(b.lo), "f_min": _finite(b.hi), "f_phys": _finite(f_phys), "f_phys_soft": _finite(f_soft),
                      "seconds": time.perf_counter() - t0})
    return trials, poses


def _pr(rows: list[dict], outcome: str) -> dict:
    return {"trials": len(rows), **confusion(rows, "certified", outcome)}


def summarise_spatial(trials: list[dict], poses: list[dict]) -> dict:
    """Headline numbers (module notes): ``overall`` and ``per_mesh`` precision/recall (against
    ``held`` and ``held_shake``), ``by_ratio`` held rates, ``spearman`` of ``F_min`` with ``F_phys``,
    ``seconds`` per trial (median, 95th percentile), ``second`` (agreement of the held verdicts
    at the two settings), ``settled`` (trials the squeeze moved more than :data:`SETTLED`, per
    confusion cell), ``unmoved`` (precision/recall on the others), ``false_positives``.

    Examples
    --------
    >>> rows = [{"mesh": "m", "pose": 0, "setting": "default", "ratio": r, "certified": r > 1, "held": r > 0.9,
    ...          "held_shake": r > 1.5, "seconds": 0.1} for r in (0.5, 0.95, 2.0)]
    >>> s = summarise_spatial(rows, [])
    >>> s["overall"]["held"]["precision"], s["overall"]["held"]["recall"], s["overall"]["held_shake"]["recall"]
    (1.0, 0.5, 1.0)
    """
    main = [r for r in trials if r["setting"] == "default"]
    soft = [r for r in trials if r["setting"] == "soft"]
    out = {"overall": {o: _pr(main, o) for o in ("held", "held_shake")},
           "soft": {o: _pr(soft, o) for o in ("held", "held_shake")}, "per_mesh": {}, "by_ratio": {}}
    for mesh in dict.fromkeys(r["mesh"] for r in main):
        out["per_mesh"][mesh] = {o: _pr([r for r in main if r["mesh"] == mesh], o) for o in ("held", "held_shake")}
        out["per_mesh"][mesh]["soft"] = _pr([r for r in soft if r["mesh"] == mesh], "held")
    for ratio in sorted({r["ratio"] for r in main}):
        sel = [r for r in main if r["ratio"] == ratio]
        sel_soft = [r for r in soft if r["ratio"] == ratio]
        out["by_ratio"][ratio] = {"trials": len(sel), "held": rate(sum(r["held"] for r in sel), len(sel)),
                                  "held_shake": rate(sum(r["held_shake"] for r in sel), len(sel)),
                                  "held_soft": rate(sum(r["held"] for r in sel_soft), len(sel_soft)),
                                  "certified": rate(sum(r["certified"] for r in sel), len(sel))}
    for key, column in (("spearman", "f_phys"), ("spearman_soft", "f_phys_soft")):
        both = [p for p in poses if p["f_min"] is not None and p.get(column) is not None]
        rho = (float(spearmanr([p["f_min"] for p in both], [p[column] for p in both]).statistic)
               if len(both) >= 3 else None)
        ratio = [p[column] / p["f_min"] for p in both]
        out[key] = {"rho": rho, "n": len(both), "poses": len(poses),
                    "finite": sum(1 for p in poses if p["f_min"] is not None),
                    "ratio_median": float(np.median(ratio)) if ratio else None,
                    "ratio_range": (float(min(ratio)), float(max(ratio))) if ratio else None}
    groups = {"certified and held": (True, True), "certified, not held": (True, False),
              "held, not certified": (False, True), "neither": (False, False)}
    out["settled"] = {}
    for label, rows in (("default", main), ("soft", soft)):
        out["settled"][label] = {}
        for name, (cert, held) in groups.items():
            sel = [r for r in rows if r["certified"] == cert and r["held"] == held]
            out["settled"][label][name] = (len(sel), sum(1 for r in sel if r.get("settle_mm", 0.0) > 1000 * SETTLED))
    out["unmoved"] = {label: _pr([r for r in rows if r.get("settle_mm", 0.0) <= 1000 * SETTLED], "held")
                      for label, rows in (("default", main), ("soft", soft))}
    out["false_positives"] = [r for r in main + soft if r["certified"] and not r["held"]]
    seconds = np.array([r["seconds"] for r in main])
    out["seconds"] = (float(np.median(seconds)), float(np.percentile(seconds, 95))) if len(seconds) else (None, None)
    second = {(r["mesh"], r["pose"], r["ratio"]): r for r in trials if r["setting"] == "second"}
    pairs = [(r, second[k]) for r in main for k in [(r["mesh"], r["pose"], r["ratio"])] if k in second]
    out["second"] = {"pairs": len(pairs), "agree": sum(a["held"] == b["held"] for a, b in pairs),
                     "default": _pr([a for a, _ in pairs], "held"), "second": _pr([b for _, b in pairs], "held")}
    return out


def spatial_markdown(summary: dict, closed: dict, settings: SpatialValidation, meshes: dict, seconds: float) -> str:
    """The Markdown summary of a spatial run."""
    ph = settings.physics
    sources = {}
    for _, source in meshes.values():
        sources[source] = sources.get(source, 0) + 1
    grasped = len(summary["per_mesh"])
    lines = [f"# Spatial validation (MuJoCo): {len(meshes)} meshes, {seconds:.0f} s", "",
             "Meshes: " + ", ".join(f"{n} from {s}" for s, n in sources.items()) + f"; {grasped} with at least "
             "one sampled pose whose pads touch it (the others are wider than the hand opens, or no pose was "
             "found).", "",
             f"Physics: {ph.label()}; pads of the Franka hand, mass {settings.mass:g} kg, mu {settings.mu:g}; "
             f"close, release under gravity for {ph.hold:g} s (**held**: slip at most {1000 * ph.slip:g} mm), "
             f"shake (peak {ph.shake_accel:.2f} m/s^2 along and {ph.shake_alpha:g} rad/s^2 about each axis of "
             f"the hand, {ph.shake_freq:g} Hz). Second setting: {settings.second.label()}.", "",
             "## The simulator on closed-form cases", "", *closed_forms.table_lines(closed, "+.4f", units=True)]
    lines += ["", "## Certified to hold at F against held in physics", "",
              "Outcomes: `held` (under gravity, point contacts: condim 3), `held_shake` (and after the shake), "
              "`soft` (held under gravity with condim 4: the certified soft contact's torsional friction).", "",
              "| meshes | outcome | trials | certified | held | certified and held | certified, not held | "
              "held, not certified | precision | recall |", "|---|---|---|---|---|---|---|---|---|---|"]
    rows = [("all", {**summary["overall"], "soft": summary["soft"]["held"]})] + list(summary["per_mesh"].items())
    for mesh, c in rows:
        for outcome in ("held", "held_shake", "soft"):
            s = c[outcome]
            lines.append(f"| {mesh} | {outcome} | {s['trials']} | {s['certified']} | {s['held']} | {s['tp']} | "
                         f"{s['fp']} | {s['fn']} | {cell(s['precision'])} | {cell(s['recall'])} |")
    lines += ["", "## Held rate against the grip force", "",
              "| F / F_min | trials | certified | held | held after the shake | held (soft, condim 4) |",
              "|---|---|---|---|---|---|"]
    for ratio, b in summary["by_ratio"].items():
        lines.append(f"| {ratio:g} | {b['trials']} | {cell(b['certified'])} | {cell(b['held'])} | "
                     f"{cell(b['held_shake'])} | {cell(b['held_soft'])} |")
    lines += ["", "## The smallest grip force that holds in physics", "",
              f"F_phys by bisection between F_min / 8 and 8 F_min (the mesh's median F_min when it is infinite), to "
              f"the ratio {settings.precision:g}.", "",
              "| contacts | poses | finite F_min | finite F_min and F_phys | Spearman F_min, F_phys | "
              "F_phys / F_min median | range |", "|---|---|---|---|---|---|---|"]
    for key, name in (("spearman", "condim 3"), ("spearman_soft", "condim 4 (soft)")):
        sp = summary[key]
        rng = sp["ratio_range"]
        lines.append(f"| {name} | {sp['poses']} | {sp['finite']} | {sp['n']} | {cell(sp['rho'], '+.3f')} | "
                     f"{cell(sp['ratio_median'])} | {cell(rng[0] if rng else None)} to "
                     f"{cell(rng[1] if rng else None)} |")
    lines.append("")
    lines += ["", "## Objects the squeeze re-seated", "",
              f"Trials in which closing the pads moved the object more than {1000 * SETTLED:g} mm (centre of mass "
              "plus radius times rotation): the certified contacts are those of the object before closing.", "",
              "| contacts | " + " | ".join(summary["settled"]["default"]) + " |",
              "|---|" + "---|" * len(summary["settled"]["default"])]
    for label, groups in summary["settled"].items():
        lines.append(f"| {label} | " + " | ".join(f"{k} of {n}" for n, k in groups.values()) + " |")
    lines += ["", "Certified to hold at F against held, on the trials in which the squeeze moved the object at most "
              f"{1000 * SETTLED:g} mm (the certified contacts are then those it is held by):", "",
              "| contacts | trials | certified | held | certified and held | certified, not held | held, not certified | "
              "precision | recall |", "|---|---|---|---|---|---|---|---|---|"]
    for label, c in summary["unmoved"].items():
        lines.append(f"| {label} | {c['trials']} | {c['certified']} | {c['held']} | {c['tp']} | {c['fp']} | {c['fn']} | "
                     f"{cell(c['precision'])} | {cell(c['recall'])} |")
    fps = summary["false_positives"]
    lines += ["", f"## Certified to hold, not held: {len(fps)} trials", ""]
    if fps:
        lines += ["| mesh | pose | contacts | F / F_min | F (N) | slip (mm) | dropped | squeeze moved it (mm) |",
                  "|---|---|---|---|---|---|---|---|"]
        for r in fps:
            lines.append(f"| {r['mesh']} | {r['pose']} | {r['setting']} | {r['ratio']:g} | {r['force']:.3g} | "
                         f"{r['slip_mm']:.1f} | {r['dropped']} | {r.get('settle_mm', 0.0):.1f} |")
    lines.append("")
    med, p95 = summary["seconds"]
    lines.append(f"Seconds per trial (close, release, shake): median {cell(med)}, 95th percentile {cell(p95)}.")
    sec = summary["second"]
    if sec["pairs"]:
        lines += ["", "## The second physics setting", "",
                  f"{sec['pairs']} trials run again at {settings.second.label()}: the held verdict agrees on "
                  f"{sec['agree']}; precision/recall {cell(sec['default']['precision'])}/"
                  f"{cell(sec['default']['recall'])} at the default setting, "
                  f"{cell(sec['second']['precision'])}/{cell(sec['second']['recall'])} at the second."]
    return "\n".join(lines) + "\n"


def plot_held_rate(out: Path, trials: list[dict]) -> Path:
    """``spatial-held-rate.png``: held rate against the grip force over ``F_min``, one thin line per
    mesh, the overall rate thick; the certified threshold (ratio 1) marked."""
    main = [r for r in trials if r["setting"] == "default" and r["f_min"] is not None]
    ratios = sorted({r["ratio"] for r in main})
    fig = new_figure(6.4, 4.2)
    ax = fig.subplots()
    for mesh in dict.fromkeys(r["mesh"] for r in main):
        rate = [np.mean([r["held"] for r in main if r["mesh"] == mesh and r["ratio"] == x] or [np.nan])
                for x in ratios]
        ax.plot(ratios, rate, color="0.6", lw=0.7, alpha=0.7)
    overall = [np.mean([r["held"] for r in main if r["ratio"] == x]) for x in ratios]
    shaken = [np.mean([r["held_shake"] for r in main if r["ratio"] == x]) for x in ratios]
    soft = [np.mean([r["held"] for r in trials if r["setting"] == "soft" and r["f_min"] is not None
                     and r["ratio"] == x] or [np.nan]) for x in ratios]
    ax.plot(ratios, overall, color="tab:blue", lw=2.5, marker="o", label="held under gravity, all meshes (condim 3)")
    ax.plot(ratios, shaken, color="tab:orange", lw=2.0, ls="--", marker="s", label="held after the shake")
    ax.plot(ratios, soft, color="tab:green", lw=2.0, ls="-.", marker="^", label="held, soft contacts (condim 4)")
    ax.axvline(1.0, color="k", lw=0.8, ls=":", label="certified least grip force")
    ax.set_xscale("log")
    ax.set_xticks(ratios, [f"{x:g}" for x in ratios])
    ax.minorticks_off()
    ax.set_ylim(-0.03, 1.03)
    ax.set_xlabel("grip force / certified least grip force F_min")
    ax.set_ylabel("held rate")
    ax.set_title(f"MuJoCo: {len({r['mesh'] for r in main})} meshes (thin: each mesh), poses with finite F_min",
                 fontsize=9)
    ax.legend(fontsize=8, loc="lower right")
    return save(fig, out, "spatial-held-rate", ("png",))[0]


def _write(path: Path, columns, rows) -> Path:
    with path.open("w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(columns)
        for r in rows:
            w.writerow(["" if r.get(c) is None else (f"{r[c]:.6g}" if isinstance(r[c], float) else r[c])
                        for c in columns])
    return path


def validate_spatial(out: str | Path, *, settings: str | SpatialValidation = "quick",
                     progress: Callable[[str], None] | None = None, plots: bool = True) -> dict:
    """Run the spatial study (module notes) and write its files in ``out``.

    Parameters
    ----------
    out : str or pathlib.Path
        Output folder (created).
    settings : {'quick', 'full'} or SpatialValidation
    progress : callable, optional
        Called with a short message after the closed-form cases and after each mesh.
    plots : bool
        Draw the figure.

    Returns
    -------
    dict
        ``summary``, ``closed`` (closed-form rows per setting), ``meshes``, ``skipped``, ``files``,
        ``seconds``.
    """
    start = time.perf_counter()
    settings = SPATIAL_VALIDATIONS[settings] if isinstance(settings, str) else settings
    say = progress or (lambda _m: None)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    closed = {"default": closed_forms.spatial_cases(settings.physics),
              "second": closed_forms.spatial_cases(settings.second)}
    files = [_write(out / "spatial-closed-forms.csv", ("setting", "case", "formula", "exact", "measured", "error",
                                                       "unit"),
                    [{"setting": k, **asdict(c)} for k, cs in closed.items() for c in cs])]
    say("spatial closed-form cases")
    meshes, skipped = study_meshes(settings.least)
    trials, poses = [], []
    for i, (name, (mesh, source)) in enumerate(meshes.items()):
        t, p = validate_mesh(name, mesh, source, settings, cache=out / "spatial-pieces", recheck=i < settings.recheck)
        trials += t
        poses += p
        say(f"meshes {i + 1}/{len(meshes)}")
    files.append(_write(out / "spatial-trials.csv", TRIAL_COLUMNS, trials))
    files.append(_write(out / "spatial-poses.csv", POSE_COLUMNS, poses))
    summary = summarise_spatial(trials, poses)
    seconds = time.perf_counter() - start
    md = out / "spatial-summary.md"
    md.write_text(spatial_markdown(summary, closed, settings, meshes, seconds), encoding="utf-8")
    files.append(md)
    if plots and trials:
        files.append(plot_held_rate(out, trials))
    return {"summary": summary, "closed": closed, "meshes": {k: s for k, (_, s) in meshes.items()},
            "skipped": skipped, "files": files, "seconds": time.perf_counter() - start,
            "trials": trials, "poses": poses}

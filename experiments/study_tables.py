"""Tables of the comparison study (:mod:`qualgrasp.experiments.study`): aggregation, CSV and Markdown.

Column meanings are documented with the column tuples in :mod:`qualgrasp.experiments.design`. Empty cells
(CSV) and ``-`` (Markdown) mark values that are undefined (no grasp, no baseline grasp, no trial).
"""

from __future__ import annotations

import csv
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from qualgrasp.certify.files import atomic_output

from .design import (GRASP_COLUMNS, KINDS, OBJECT_COLUMNS, OVERALL_COLUMNS, REASONS, ROBUSTNESS_COLUMNS,
                     UNITS, Route, RouteSummary, Settings, compared_procedure, routes)

__all__ = ["robustness_rows", "partner", "overall_rows", "summarise", "write_csv", "write_markdown",
           "write_tables"]

_TRIAL_COLUMNS = ("object", "route", "method", "fingers", "kind", "size", "trial", "planned",
                  "held", "misses", "collisions", "eps_planned", "eps_executed", "error", "procedure",
                  *REASONS)


def _median(values: Sequence[float]) -> float | None:
    values = [v for v in values if v is not None]
    return float(np.median(values)) if values else None


def robustness_rows(trial_rows: list[dict], settings: Settings) -> list[dict]:
    """Aggregate trials per route, kind and size (:data:`ROBUSTNESS_COLUMNS`), ``none`` first."""
    sizes = [("none", 0.0)] + [(k, float(s)) for k, values in settings.sizes for s in values]
    out = []
    for route in routes():
        for kind, size in sizes:
            rows = [r for r in trial_rows if r["route"] == route.name and r["kind"] == kind and r["size"] == size]
            if not rows:
                continue
            planned, held = sum(r["planned"] for r in rows), sum(r["held"] for r in rows)
            out.append({
                "route": route.name, "method": route.method, "procedure": route.procedure.name,
                "fingers": route.fingers, "kind": kind, "size": size,
                "unit": UNITS[kind], "trials": len(rows), "planned": planned, "held": held,
                "fraction": held / planned if planned else None,
                "misses": sum(r["misses"] for r in rows), "collisions": sum(r["collisions"] for r in rows),
                "eps_planned": _median([e for r in rows for e in r["eps_planned"]]),
                "eps_executed": _median([e for r in rows for e in r["eps_executed"]]),
                **{reason: sum(r.get(reason, 0) for r in rows) for reason in REASONS},
            })
    return out


def partner(route: Route) -> str:
    """The route whose trials ``route``'s paired robustness is restricted to: the baseline with the
    same fingers and contact model for a qualitative route, the qualitative route of the procedure
    it carries for a baseline."""
    if route.method == "qualitative":
        return Route("baseline", compared_procedure(route.procedure, "baseline")).name
    return Route("qualitative", route.procedure).name


def _pooled(trial_rows: list[dict], route: str, kinds: Sequence[str], partner: str | None = None) -> float | None:
    """Held over planned for ``route`` and ``kinds``; with ``partner`` only the trials where the
    partner route planned a certified grasp too."""
    rows = [r for r in trial_rows if r["route"] == route and r["kind"] in kinds]
    if partner is not None:
        key = lambda r: (r["object"], r["kind"], r["size"], r["trial"])  # noqa: E731
        both = {key(r) for r in trial_rows if r["route"] == partner and r["planned"]}
        rows = [r for r in rows if key(r) in both]
    planned = sum(r["planned"] for r in rows)
    return sum(r["held"] for r in rows) / planned if planned else None


def overall_rows(object_rows: list[dict], grasp_rows: list[dict], trial_rows: list[dict]) -> list[dict]:
    """One row per route over all objects (:data:`OVERALL_COLUMNS`)."""
    out = []
    for r_ in routes():
        route = r_.name
        rows = [r for r in object_rows if r["route"] == route]
        grasps = [g for g in grasp_rows if g["route"] == route]
        seconds = [r["seconds"] for r in rows if r["seconds"] is not None]
        deltas = [r["delta_best"] for r in rows if r.get("delta_best") is not None]
        slides = [r["slide_best"] for r in rows if r.get("slide_best") is not None]
        out.append({
            "route": route, "method": r_.method, "procedure": r_.procedure.name, "fingers": r_.fingers,
            "objects": len(rows),
            "objects_with_grasps": sum(1 for r in rows if r.get("counted")),
            "grasps": len(grasps),
            "certified_fraction": sum(g["certified"] for g in grasps) / len(grasps) if grasps else None,
            "eps_median": _median([r["eps_median"] for r in rows]),
            "eps_best": _median([r["eps_best"] for r in rows]),
            "ratio_best": _median([r["ratio_best"] for r in rows]),
            "ratio_median": _median([r["ratio_median"] for r in rows]),
            "seconds_median": _median(seconds), "seconds_total": float(sum(seconds)),
            "robustness": _pooled(trial_rows, route, KINDS),
            "robustness_paired": _pooled(trial_rows, route, KINDS, partner(r_)),
            "delta_median": _median(deltas),
            "delta_robust": sum(d > 0 for d in deltas) / len(deltas) if deltas else None,
            "slide_median": _median(slides),
            "slide_robust": sum(d > 0 for d in slides) / len(slides) if slides else None,
            "counted": sum(r.get("counted") or 0 for r in rows),
            **{reason: sum(r.get(reason) or 0 for r in rows) for reason in REASONS},
        })
    return out


def summarise(overall: list[dict], trial_rows: list[dict]):
    """Headline :class:`RouteSummary` per route, and robustness per (route, kind)."""
    routes = tuple(RouteSummary(r["route"], r["fingers"], r["grasps"], r["certified_fraction"],
                                r["eps_median"], r["eps_best"], r["ratio_best"], r["ratio_median"],
                                r["seconds_median"], r["robustness"], r["robustness_paired"],
                                r["delta_median"], r["delta_robust"], r["slide_median"], r["slide_robust"],
                                tuple((reason, r[reason]) for reason in REASONS))
                   for r in overall)
    by_kind = {(r["route"], kind): _pooled(trial_rows, r["route"], (kind,))
               for r in overall for kind in KINDS}
    return routes, by_kind


def _cell(value: Any, markdown: bool) -> str:
    if value is None:
        return "-" if markdown else ""
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        return f"{value:.4g}"
    if isinstance(value, (list, tuple)):
        return " ".join(_cell(v, markdown) for v in value)
    return str(value).replace("|", "/") if markdown else str(value)


def write_csv(path: Path, rows: list[dict], columns: Sequence[str]) -> Path:
    """Rows as CSV with a header, in the given column order; lists space-separated."""
    with atomic_output(path, "--out") as tmp, tmp.open("w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(columns)
        writer.writerows([[_cell(r.get(c), False) for c in columns] for r in rows])
    return path


def write_markdown(path: Path, rows: list[dict], columns: Sequence[str], title: str,
                   note: str = "") -> Path:
    """Rows as a GitHub Markdown table under a title (and a note)."""
    lines = [f"# {title}", ""] + ([note, ""] if note else [])
    lines += ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    lines += ["| " + " | ".join(_cell(r.get(c), True) for c in columns) + " |" for r in rows]
    with atomic_output(path, "--out") as tmp:
        tmp.write_text("\n".join(lines) + "\n")
    return path


_COUNTED = ("counted: certified grasps counted as found, by one rule for every route; "
            + ", ".join(REASONS) + ": certified grasps not counted for that reason (below_resolution: "
            "certified epsilon not above the wrench change the image's uncertainty can cause)")

_NOTES = {
    "objects": "Certified L1 epsilon (object centroid and radius) of the counted grasps; ratios: "
               "qualitative over the baseline's best with the same fingers; seconds: image to certified "
               "grasps; slide_best: how far every finger of the best counted grasp may slide either way "
               "with closure certified (fraction of the size; delta_best: the search's half-width before "
               f"clipping); {_COUNTED}.",
    "overall": "Medians over objects; robustness: executed grasps that still certify on the true "
               "object over planned counted grasps, pooled over every perturbation; paired: only "
               "the trials where both methods planned a grasp with these fingers; slide_median: median "
               f"certified slide of the best grasps; {_COUNTED}.",
    "robustness": "fraction = held / planned (planned: grasps certified on the perturbed image and "
                  "counted; held: executed on the true object, still certified); "
                  + ", ".join(REASONS) + ": certified grasps not planned for that reason.",
}


def write_tables(out: Path, object_rows, overall, robust, trial_rows, grasp_rows) -> list[Path]:
    """Write every table (CSV, and Markdown for the three summaries); the paths written."""
    files = []
    for stem, rows, columns, title in (
            ("objects", object_rows, OBJECT_COLUMNS, "Per object and route"),
            ("overall", overall, OVERALL_COLUMNS, "Overall, per route"),
            ("robustness", robust, ROBUSTNESS_COLUMNS, "Robustness to vision errors")):
        files.append(write_csv(out / f"{stem}.csv", rows, columns))
        files.append(write_markdown(out / f"{stem}.md", rows, columns, title, _NOTES[stem]))
    files.append(write_csv(out / "robustness-trials.csv", trial_rows, _TRIAL_COLUMNS))
    files.append(write_csv(out / "grasps.csv", grasp_rows, GRASP_COLUMNS))
    return files

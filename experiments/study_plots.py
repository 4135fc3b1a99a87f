"""Plots of the comparison study (:mod:`qualgrasp.experiments.study`), in the figures' style.

Every plot is written as PNG and PDF with :func:`qualgrasp.experiments.style.save`:

* ``study-epsilon``: certified L1 epsilon of every counted grasp returned (certified and not
  excluded by a reason such as ``below_resolution``, the same rule for every route; the baseline
  returns its best few per object), per route, one panel per finger count (boxes: qualitative and
  baseline; dots: each object's best; tick labels: objects with a counted grasp, and the grasps
  not counted);
* ``study-quality-time``: each object's best certified epsilon against the time from image to
  certified grasps, per route;
* ``study-robustness``: fraction of planned grasps that still certify on the true object against
  the perturbation size, one row per finger count and one column per perturbation kind (size 0:
  the unperturbed image);
* ``study-tolerance``: certified slide of each object's best grasp (how far every finger may
  slide along the outline either way with force closure certified: the smallest certified extent,
  fraction of the object's size; 0 when none is certified), per route, one panel per finger
  count, beside the route's sampled robustness (pooled fraction held, in the tick labels).

Panels and labels come from the procedure registry (:mod:`qualgrasp.qualitative.synthesis.procedures`):
one panel (or row) per registered procedure, with its baseline; colours tell the procedure
(:func:`~qualgrasp.experiments.style.procedure_colour`), line
style and marker the method (solid and circles: qualitative; dashed and triangles: baseline).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

from ..qualitative.synthesis import procedures
from .design import KINDS, UNITS, compared_procedure
from .style import context, new_figure, procedure_colour, save

__all__ = ["plot_epsilon", "plot_quality_time", "plot_robustness", "plot_tolerance", "plot_all"]

_METHOD = {"qualitative": ("-", "o", "qualitative"), "baseline": ("--", "^", "baseline")}
_FORMATS = ("png", "pdf")


def _mu(rows: list[dict], name: str) -> float | None:
    """The friction coefficient the rows of procedure ``name`` used (None: frictionless)."""
    return next((r["mu"] for r in rows if r["procedure"] == name and r.get("mu") is not None), None)


def _short(p, mu) -> str:
    return f"{p.fingers} fingers, mu {mu:g}" if p.friction and mu is not None else (
        f"{p.fingers} fingers" if p.friction else f"{p.fingers} frictionless")


def _jitter(n: int, center: float, rng: np.random.Generator) -> np.ndarray:
    return center + rng.uniform(-0.12, 0.12, n)


def plot_epsilon(out: Path, object_rows: list[dict], grasp_rows: list[dict]) -> list[Path]:
    """Epsilon distributions per route (``study-epsilon``)."""
    rng = np.random.default_rng(0)
    with context():
        procs = procedures.procedures()
        fig = new_figure(2.4 * len(procs), 2.7)
        axes = fig.subplots(1, len(procs), sharey=True, squeeze=False)[0]
        for ax, p in zip(axes, procs):
            ticks = []
            for x, method in enumerate(("qualitative", "baseline")):
                name = compared_procedure(p, method).name
                eps = [g["eps"] for g in grasp_rows
                       if g["procedure"] == name and g["method"] == method and g["counted"]]
                best = [r["eps_best"] for r in object_rows if r["procedure"] == name
                        and r["method"] == method and r["eps_best"] is not None and r["counted"]]
                dropped = sum(g["certified"] and not g["counted"] for g in grasp_rows
                              if g["procedure"] == name and g["method"] == method)
                color = procedure_colour(p)
                if eps:
                    ax.boxplot([eps], positions=[x], widths=0.5, showfliers=False,
                               medianprops={"color": color, "linewidth": 1.6},
                               boxprops={"color": "0.4"}, whiskerprops={"color": "0.4"},
                               capprops={"color": "0.4"})
                ax.scatter(_jitter(len(best), x, rng), best, s=9, color=color, alpha=0.8,
                           marker=_METHOD[method][1], zorder=3, linewidths=0)
                total = sum(1 for r in object_rows if r["procedure"] == name and r["method"] == method)
                ticks.append(f"{method}\n{len(best)}/{total} objects"
                             + (f"\n{dropped} not counted" if dropped else ""))
            ax.set_xticks([0, 1], ticks)
            ax.set_xlim(-0.6, 1.6)
            ax.set_title(p.label(_mu(object_rows, p.name)))
            ax.grid(axis="y", color="0.9", linewidth=0.6)
        axes[0].set_ylabel("certified L1 epsilon")
        fig.suptitle("Grasp quality: boxes = every counted grasp returned, dots = best per object")
        return save(fig, out, "study-epsilon", _FORMATS)


def plot_quality_time(out: Path, object_rows: list[dict]) -> list[Path]:
    """Best epsilon against time per object and route (``study-quality-time``)."""
    with context():
        fig = new_figure(7.2, 3.6)
        ax = fig.subplots()
        for p in procedures.procedures():
            for method, (_, marker, name) in _METHOD.items():
                rows = [r for r in object_rows if r["procedure"] == p.name and r["method"] == method
                        and r["seconds"] is not None]
                ax.scatter([r["seconds"] for r in rows], [r["eps_best"] or 0.0 for r in rows],
                           s=16, marker=marker, color=procedure_colour(p),
                           facecolors=procedure_colour(p) if method == "baseline" else "none",
                           linewidths=0.9, label=f"{name}, {_short(p, _mu(object_rows, p.name))}",
                           alpha=0.85)
        ax.set_xscale("log")
        # plain labels at 1, 2 and 5 per decade: the default labels minor ticks on a short range, overlapping
        ax.xaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
        ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_xlabel("time from image to certified grasps (s, log scale)")
        ax.set_ylabel("best certified L1 epsilon (0: none found)")
        ax.grid(color="0.9", linewidth=0.6)
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0))
        fig.suptitle("Quality against time, one point per object and route")
        return save(fig, out, "study-quality-time", _FORMATS)


def _curve(robust: list[dict], route: str, kind: str):
    zero = [r for r in robust if r["route"] == route and r["kind"] == "none"]
    rows = sorted([r for r in robust if r["route"] == route and r["kind"] == kind] + zero,
                  key=lambda r: r["size"])
    return [r["size"] for r in rows], [np.nan if r["fraction"] is None else r["fraction"] for r in rows]


def plot_robustness(out: Path, robust: list[dict], mu: dict | None = None) -> list[Path]:
    """Robustness against perturbation size (``study-robustness``): one row per procedure, one
    column per perturbation kind, qualitative and baseline in each panel (``mu``: friction per
    procedure name, for the row labels)."""
    procs = procedures.procedures()
    with context():
        fig = new_figure(9.0, 1.9 * len(procs))
        axes = fig.subplots(len(procs), len(KINDS), sharey=True, sharex="col", squeeze=False)
        for row, p in enumerate(procs):
            for ax, kind in zip(axes[row], KINDS):
                for method in ("qualitative", "baseline"):
                    name = compared_procedure(p, method).name
                    routes = {r["route"] for r in robust if r["procedure"] == name and r["method"] == method}
                    for route in routes:
                        x, y = _curve(robust, route, kind)
                        style, marker, name = _METHOD[method]
                        ax.plot(x, y, linestyle=style, marker=marker, markersize=3.5,
                                color=procedure_colour(p), label=name,
                                linewidth=2.2 if method == "qualitative" else 1.2,
                                alpha=0.55 if method == "qualitative" else 1.0)
                ax.set_ylim(-0.05, 1.05)
                ax.grid(color="0.9", linewidth=0.6)
                if row == 0:
                    ax.set_title(kind)
                if row == len(procs) - 1:
                    ax.set_xlabel(f"size ({UNITS[kind]})")
            axes[row][0].set_ylabel(f"{_short(p, (mu or {}).get(p.name))}\nfraction held")
        handles, labels = axes[0][0].get_legend_handles_labels()
        fig.legend(handles, labels, loc="outside lower center", ncols=2)
        fig.suptitle("Robustness to vision errors: planned grasps that still certify on the true object")
        return save(fig, out, "study-robustness", _FORMATS)


def _held(robust: list[dict], procedure: str, method: str) -> float | None:
    """Pooled fraction held over every perturbation (not ``none``) of one route."""
    rows = [r for r in robust if r["procedure"] == procedure and r["method"] == method and r["kind"] != "none"]
    planned = sum(r["planned"] for r in rows)
    return sum(r["held"] for r in rows) / planned if planned else None


def plot_tolerance(out: Path, object_rows: list[dict], robust: list[dict]) -> list[Path]:
    """Certified slide of each object's best grasp per route, beside its sampled robustness
    (``study-tolerance``)."""
    rng = np.random.default_rng(0)
    with context():
        procs = procedures.procedures()
        fig = new_figure(2.8 * len(procs), 3.0)
        axes = fig.subplots(1, len(procs), sharey=True, squeeze=False)[0]
        for ax, p in zip(axes, procs):
            ticks = []
            for x, method in enumerate(("qualitative", "baseline")):
                name = compared_procedure(p, method).name
                delta = [r["slide_best"] for r in object_rows if r["procedure"] == name
                         and r["method"] == method and r.get("slide_best") is not None]
                if delta:
                    ax.boxplot([delta], positions=[x], widths=0.5, showfliers=False,
                               medianprops={"color": procedure_colour(p), "linewidth": 1.6},
                               boxprops={"color": "0.4"}, whiskerprops={"color": "0.4"},
                               capprops={"color": "0.4"})
                ax.scatter(_jitter(len(delta), x, rng), delta, s=9, color=procedure_colour(p), alpha=0.8,
                           marker=_METHOD[method][1], zorder=3, linewidths=0)
                held = _held(robust, name, method)
                positive = sum(d > 0 for d in delta)
                ticks.append(f"{method}\n{positive}/{len(delta)}: slide > 0\n"
                             f"held {'-' if held is None else format(held, '.3f')}")
            ax.set_xticks([0, 1], ticks)
            ax.set_xlim(-0.6, 1.6)
            ax.set_title(p.label(_mu(object_rows, p.name)))
            ax.grid(axis="y", color="0.9", linewidth=0.6)
        axes[0].set_ylabel("certified slide, either way\n(fraction of the object's size)")
        fig.suptitle("How far every finger of each object's best grasp may slide (certified), and sampled "
                     "robustness (held)")
        return save(fig, out, "study-tolerance", _FORMATS)


def plot_all(out: Path, object_rows: list[dict], grasp_rows: list[dict], robust: list[dict]) -> list[Path]:
    """Every plot of the study into ``out``; the paths written."""
    mu = {p.name: _mu(object_rows, p.name) for p in procedures.procedures()}
    return (plot_epsilon(out, object_rows, grasp_rows) + plot_quality_time(out, object_rows)
            + plot_robustness(out, robust, mu) + plot_tolerance(out, object_rows, robust))

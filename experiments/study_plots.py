"""Plots of the comparison study (:mod:`qualgrasp.experiments.study`), in the figures' style.

Every plot is written as PNG and PDF with :func:`qualgrasp.experiments.style.save`:

* ``study-epsilon``: certified L1 epsilon of every certified grasp returned (the baseline returns
  its best few per object), per route, one panel per finger count (boxes: qualitative and
  baseline; dots: each object's best; tick labels: objects with a certified grasp);
* ``study-quality-time``: each object's best certified epsilon against the time from image to
  certified grasps, per route;
* ``study-robustness``: fraction of planned grasps that still certify on the true object against
  the perturbation size, one row per finger count and one column per perturbation kind (size 0:
  the unperturbed image).

Colours tell the finger count, line style and marker the method (solid and circles:
qualitative; dashed and triangles: baseline).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .style import context, new_figure, save
from .study import KINDS, UNITS

__all__ = ["FINGER_COLORS", "plot_epsilon", "plot_quality_time", "plot_robustness", "plot_all"]

FINGER_COLORS = {2: "tab:blue", 3: "tab:orange", 4: "tab:purple"}
_METHOD = {"qualitative": ("-", "o", "qualitative"), "baseline": ("--", "^", "baseline")}
_LABEL = {2: "2 fingers, mu = 0.5 (ForceGrasp)", 3: "3 fingers, mu = 0.5 (ForceGrasp)",
          4: "4 frictionless (FormGrasp)"}
_SHORT = {2: "2 fingers, mu 0.5", 3: "3 fingers, mu 0.5", 4: "4 frictionless"}
_FORMATS = ("png", "pdf")


def _jitter(n: int, center: float, rng: np.random.Generator) -> np.ndarray:
    return center + rng.uniform(-0.12, 0.12, n)


def plot_epsilon(out: Path, object_rows: list[dict], grasp_rows: list[dict]) -> list[Path]:
    """Epsilon distributions per route (``study-epsilon``)."""
    rng = np.random.default_rng(0)
    with context():
        fig = new_figure(7.2, 2.7)
        axes = fig.subplots(1, 3, sharey=True)
        for ax, fingers in zip(axes, (2, 3, 4)):
            ticks = []
            for x, method in enumerate(("qualitative", "baseline")):
                eps = [g["eps"] for g in grasp_rows
                       if g["fingers"] == fingers and g["method"] == method and g["certified"]]
                best = [r["eps_best"] for r in object_rows if r["fingers"] == fingers
                        and r["method"] == method and r["eps_best"] is not None and r["certified"]]
                color = FINGER_COLORS[fingers]
                if eps:
                    ax.boxplot([eps], positions=[x], widths=0.5, showfliers=False,
                               medianprops={"color": color, "linewidth": 1.6},
                               boxprops={"color": "0.4"}, whiskerprops={"color": "0.4"},
                               capprops={"color": "0.4"})
                ax.scatter(_jitter(len(best), x, rng), best, s=9, color=color, alpha=0.8,
                           marker=_METHOD[method][1], zorder=3, linewidths=0)
                total = sum(1 for r in object_rows if r["fingers"] == fingers and r["method"] == method)
                ticks.append(f"{method}\n{len(best)}/{total} objects")
            ax.set_xticks([0, 1], ticks)
            ax.set_xlim(-0.6, 1.6)
            ax.set_title(_LABEL[fingers])
            ax.grid(axis="y", color="0.9", linewidth=0.6)
        axes[0].set_ylabel("certified L1 epsilon")
        fig.suptitle("Grasp quality: boxes = every certified grasp returned, dots = best per object")
        return save(fig, out, "study-epsilon", _FORMATS)


def plot_quality_time(out: Path, object_rows: list[dict]) -> list[Path]:
    """Best epsilon against time per object and route (``study-quality-time``)."""
    with context():
        fig = new_figure(4.8, 3.4)
        ax = fig.subplots()
        for fingers in (2, 3, 4):
            for method, (_, marker, name) in _METHOD.items():
                rows = [r for r in object_rows if r["fingers"] == fingers and r["method"] == method
                        and r["seconds"] is not None]
                ax.scatter([r["seconds"] for r in rows], [r["eps_best"] or 0.0 for r in rows],
                           s=16, marker=marker, color=FINGER_COLORS[fingers],
                           facecolors=FINGER_COLORS[fingers] if method == "baseline" else "none",
                           linewidths=0.9, label=f"{name}, {fingers} fingers", alpha=0.85)
        ax.set_xscale("log")
        ax.set_xlabel("time from image to certified grasps (s, log scale)")
        ax.set_ylabel("best certified L1 epsilon (0: none found)")
        ax.grid(color="0.9", linewidth=0.6)
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0))
        ax.set_title("Quality against time, one point per object and route")
        return save(fig, out, "study-quality-time", _FORMATS)


def _curve(robust: list[dict], route: str, kind: str):
    zero = [r for r in robust if r["route"] == route and r["kind"] == "none"]
    rows = sorted([r for r in robust if r["route"] == route and r["kind"] == kind] + zero,
                  key=lambda r: r["size"])
    return [r["size"] for r in rows], [np.nan if r["fraction"] is None else r["fraction"] for r in rows]


def plot_robustness(out: Path, robust: list[dict]) -> list[Path]:
    """Robustness against perturbation size (``study-robustness``): one row per finger count, one
    column per perturbation kind, qualitative and baseline in each panel."""
    with context():
        fig = new_figure(9.0, 5.6)
        axes = fig.subplots(3, len(KINDS), sharey=True, sharex="col")
        for row, fingers in enumerate((2, 3, 4)):
            for ax, kind in zip(axes[row], KINDS):
                for method in ("qualitative", "baseline"):
                    routes = {r["route"] for r in robust if r["fingers"] == fingers and r["method"] == method}
                    for route in routes:
                        x, y = _curve(robust, route, kind)
                        style, marker, name = _METHOD[method]
                        ax.plot(x, y, linestyle=style, marker=marker, markersize=3.5,
                                color=FINGER_COLORS[fingers], label=name,
                                linewidth=2.2 if method == "qualitative" else 1.2,
                                alpha=0.55 if method == "qualitative" else 1.0)
                ax.set_ylim(-0.05, 1.05)
                ax.grid(color="0.9", linewidth=0.6)
                if row == 0:
                    ax.set_title(kind)
                if row == 2:
                    ax.set_xlabel(f"size ({UNITS[kind]})")
            axes[row][0].set_ylabel(f"{_SHORT[fingers]}\nfraction held")
        handles, labels = axes[0][0].get_legend_handles_labels()
        fig.legend(handles, labels, loc="outside lower center", ncols=2)
        fig.suptitle("Robustness to vision errors: planned grasps that still certify on the true object")
        return save(fig, out, "study-robustness", _FORMATS)


def plot_all(out: Path, object_rows: list[dict], grasp_rows: list[dict], robust: list[dict]) -> list[Path]:
    """Every plot of the study into ``out``; the paths written."""
    return (plot_epsilon(out, object_rows, grasp_rows) + plot_quality_time(out, object_rows)
            + plot_robustness(out, robust))

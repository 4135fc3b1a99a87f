"""Figures of the physical validation study (:mod:`qualgrasp.experiments.physics.study`), PNG and
PDF in the figures' style (:mod:`qualgrasp.experiments.style`):

* ``physics-resisted``: the largest disturbance each grasp resisted in every direction against
  its certified L1 epsilon, one panel per finger count, colours by source (qualitative, baseline,
  random), grasps that did not hold on a strip at the bottom;
* ``physics-placements``: held rate against the placement error in units of the certified
  tolerance (1: the edge of the certified regions), per source, with the trials per bin;
* ``physics-settings``: the simulator's relative error on the closed-form cases at both physics
  settings, and the resisted disturbance of the same grasps at both;
* ``physics-filmstrip``: frames of one planar trial (object, fingers, the disturbance).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from matplotlib.patches import Circle, FancyArrowPatch, Polygon as PolygonPatch

from ..style import BAD, GOOD, OBJECT, context, new_figure, save

__all__ = ["plot_resisted", "plot_placements", "plot_settings", "plot_filmstrip", "plot_all"]

_FORMATS = ("png", "pdf")
_SOURCE = {"qualitative": ("tab:blue", "o"), "baseline": ("tab:orange", "^"), "random": ("0.45", "x")}


def _nominal(rows: list[dict], setting: str = "default") -> list[dict]:
    return [r for r in rows if r["placement"] == "nominal" and r["setting"] == setting]


def plot_resisted(out: Path, rows: list[dict], floor: float) -> list[Path]:
    """Largest resisted disturbance against epsilon (``physics-resisted``)."""
    nominal = _nominal(rows)
    fingers = sorted({r["fingers"] for r in nominal})
    with context():
        fig = new_figure(2.9 * max(1, len(fingers)), 3.1)
        axes = fig.subplots(1, max(1, len(fingers)), sharey=True, squeeze=False)[0]
        low = floor / 2.2
        for ax, m in zip(axes, fingers):
            sel = [r for r in nominal if r["fingers"] == m]
            for source, (colour, marker) in _SOURCE.items():
                pts = [r for r in sel if r["source"] == source]
                if not pts:
                    continue
                x = np.array([r["eps"] for r in pts])
                y = np.array([r["resisted"] if r["held"] else low for r in pts])
                ax.scatter(x, y, s=16, c=colour, marker=marker, alpha=0.75, linewidths=0.8,
                           label=f"{source} ({len(pts)})")
            ax.axhline(floor, color="0.6", lw=0.6, ls=":")
            ax.set_yscale("log")
            mu = next((r["mu"] for r in sel if r["mu"]), 0.0)
            ax.set_title(f"{m} fingers, mu {mu:g}" if mu else f"{m} frictionless fingers")
            ax.set_xlabel("certified L1 epsilon (as planned)")
            ax.legend(loc="upper left")
        for ax in axes:
            ax.text(0.98, low * 1.25, "did not hold", ha="right", va="bottom", fontsize=7, color="0.3",
                    transform=ax.get_yaxis_transform())
            ax.text(0.98, floor * 1.08, "floor", ha="right", va="bottom", fontsize=7, color="0.45",
                    transform=ax.get_yaxis_transform())
        axes[0].set_ylabel("largest disturbance resisted (F0)")
        fig.suptitle("Does a larger epsilon resist a larger push in physics?")
        return save(fig, out, "physics-resisted", _FORMATS)


def _bins(top: float) -> np.ndarray:
    inner = np.linspace(0.0, 1.0, 5)
    return np.concatenate([inner, np.arange(1.5, top + 0.5, 0.5)])


def plot_placements(out: Path, rows: list[dict], outside_max: float) -> list[Path]:
    """Held rate against placement error in units of the certified tolerance (``physics-placements``)."""
    moved = [r for r in rows if r["placement"] in ("inside", "outside")]
    edges = _bins(outside_max)
    centres = (edges[:-1] + edges[1:]) / 2
    with context():
        fig = new_figure(5.6, 3.1)
        ax = fig.subplots()
        ax.axvspan(0, 1, ymin=0.15 / 1.23, color=GOOD, alpha=0.08, lw=0)
        ax.axvline(1.0, color=GOOD, lw=1.0, ls="--")
        ax.text(0.5, 0.45, "inside the certified\nregions", ha="center", va="center", fontsize=8, color="darkgreen")
        ax.text(1.03, 1.03, "certified tolerance", ha="left", va="bottom", fontsize=8, color="darkgreen")
        for source in ("qualitative", "baseline"):
            sel = [r for r in moved if r["source"] == source]
            if not sel:
                continue
            e = np.array([r["error"] for r in sel])
            h = np.array([bool(r["held"]) for r in sel])
            k = np.clip(np.digitize(e, edges[1:-1], right=True), 0, len(centres) - 1)
            rate = np.array([h[k == b].mean() if (k == b).any() else np.nan for b in range(len(centres))])
            count = np.array([(k == b).sum() for b in range(len(centres))])
            colour, marker = _SOURCE[source]
            ax.plot(centres, rate, marker=marker, color=colour, label=f"{source} ({len(sel)} placements)")
            row = -0.13 if source == "qualitative" else -0.075  # trials per bin, in rows below the rates
            for x, y, c in zip(centres, rate, count):
                if c and not math.isnan(y):
                    ax.text(x, row, str(c), ha="center", va="bottom", fontsize=6.5, color=colour)
        ax.set_ylim(-0.15, 1.08)
        ax.set_yticks(np.linspace(0, 1, 6))
        ax.axhline(0, color="0.75", lw=0.6)
        ax.set_xlim(0, edges[-1])
        ax.set_xlabel("placement error (x certified tolerance; each finger slid this far along the outline)")
        ax.set_ylabel("held rate")
        ax.legend(loc="upper right", bbox_to_anchor=(1.0, 0.93))
        ax.set_title("Held rate of placements inside and outside the certified regions\n(numbers below zero: trials per bin)")
        return save(fig, out, "physics-placements", _FORMATS)


def plot_settings(out: Path, rows: list[dict], closed: dict, labels: dict) -> list[Path]:
    """The simulator's error at both settings, and the resisted disturbance at both (``physics-settings``)."""
    default = {(r["object"], r["route"], r["grasp"]): r for r in _nominal(rows)}
    pairs = [(default[k], r) for r in _nominal(rows, "fine") for k in [(r["object"], r["route"], r["grasp"])]
             if k in default]
    colours = ("tab:blue", "tab:purple")
    with context():
        fig = new_figure(9.0, 3.6)
        a, b = fig.subplots(1, 2, width_ratios=(1.5, 1))
        names = [c.case for c in next(iter(closed.values())) if c.exact]
        y = np.arange(len(names))
        for j, (key, cs) in enumerate(closed.items()):
            err = [c.error for c in cs if c.exact]
            a.barh(y + (j - 0.5) * 0.38, err, height=0.36, label=f"{key}: {labels.get(key, key)}",
                   color=colours[j % 2])
        a.axvline(0, color="0.3", lw=0.6)
        a.set_yticks(y, names, fontsize=7.5)
        a.invert_yaxis()
        a.set_xlabel("relative error against the closed form")
        zero = [c for c in next(iter(closed.values())) if not c.exact and c.unit.startswith("F0")]
        resisted = ", ".join(f"{c.case}: {max(cs[i].measured for cs in closed.values()):g}"
                             for i, c in enumerate(next(iter(closed.values()))) if c in zero)
        a.set_title("Closed-form cases" + (f"\n(exact 0 -> {resisted})" if resisted else ""), fontsize=8)
        if pairs:
            x = np.array([p[0]["resisted"] for p in pairs])
            z = np.array([p[1]["resisted"] for p in pairs])
            floor = min([v for v in np.concatenate([x, z]) if v > 0], default=0.02)
            low = floor / 2
            b.scatter(np.where(x > 0, x, low), np.where(z > 0, z, low), s=14, c="tab:purple", alpha=0.7)
            top = max(x.max(), z.max(), floor) * 1.5
            b.plot([low, top], [low, top], color="0.5", lw=0.6, ls="--")
            b.set_xscale("log")
            b.set_yscale("log")
            agree = sum(1 for p, q in pairs if p["held"] == q["held"])
            b.set_title(f"The same {len(pairs)} grasps at both settings\n(held agrees on {agree})", fontsize=8)
        b.set_xlabel("largest resisted, default (F0)")
        b.set_ylabel("largest resisted, fine (F0)")
        fig.legend(*a.get_legend_handles_labels(), loc="outside lower center", ncols=2, fontsize=7.5)
        fig.suptitle("The simulator's own error, and the effect of the time step, iterations and stiffness")
        return save(fig, out, "physics-settings", _FORMATS)


def plot_filmstrip(out: Path, frames: tuple, outline: np.ndarray, radius: float, length: float,
                   title: str, count: int = 6) -> list[Path]:
    """Frames of one planar trial (``physics-filmstrip``): the object, the fingers and the
    disturbance (arrow: force; curved arrow: torque), at ``count`` evenly spaced times.

    ``frames`` as recorded by :func:`qualgrasp.experiments.physics.planar.hold`, ``outline`` the
    object's ring and ``radius`` the fingers', world units."""
    pushed = [i for i, f in enumerate(frames) if any(f[3])]
    first = pushed[0] if pushed else len(frames)
    pick = [0, max(first - 1, 0)] + [pushed[int(round(j))] for j in np.linspace(0, len(pushed) - 1, count - 2)
                                     if pushed]
    pick = sorted(set(pick))
    peak = max(max(math.hypot(f[3][0], f[3][1]), abs(f[3][2])) for f in frames) or 1.0
    with context():
        fig = new_figure(1.75 * len(pick), 2.35)
        axes = fig.subplots(1, len(pick), squeeze=False)[0]
        for ax, i in zip(axes, pick):
            t, (x, y, th), fingers, w = frames[i]
            R = np.array([[math.cos(th), -math.sin(th)], [math.sin(th), math.cos(th)]])
            ring = outline @ R.T + (x, y)
            ax.add_patch(PolygonPatch(outline, closed=True, fill=False, ec="0.7", lw=0.6, ls=":"))
            ax.add_patch(PolygonPatch(ring, closed=True, fc=str(OBJECT), ec="0.25", lw=0.8))
            for p in fingers:
                ax.add_patch(Circle(p, max(radius, 0.012), color=BAD, zorder=3))
            force = R @ np.array(w[:2]) / peak * 0.35
            if np.hypot(*force) > 1e-3:
                ax.add_patch(FancyArrowPatch((x, y), (x + force[0], y + force[1]), arrowstyle="-|>",
                                             mutation_scale=9, color="tab:blue", lw=1.4, zorder=4))
            if abs(w[2]) > 1e-3 * peak:
                sweep = 200 * abs(w[2]) / peak
                a0 = 0.0
                arc = np.radians(np.linspace(a0, a0 + math.copysign(sweep, w[2]), 30))
                r = 0.55 * length
                ax.plot(x + r * np.cos(arc), y + r * np.sin(arc), color="tab:purple", lw=1.2, zorder=4)
                ax.add_patch(FancyArrowPatch((x + r * np.cos(arc[-2]), y + r * np.sin(arc[-2])),
                                             (x + r * np.cos(arc[-1]), y + r * np.sin(arc[-1])), arrowstyle="-|>",
                                             mutation_scale=8, color="tab:purple", lw=1.2, zorder=4))
            ax.set_xlim(-0.62, 0.62)
            ax.set_ylim(0.62, -0.62)  # image convention: y down
            ax.set_aspect("equal")
            ax.set_xticks([])
            ax.set_yticks([])
            mag = math.sqrt(w[0] ** 2 + w[1] ** 2 + w[2] ** 2)
            phase = "squeeze" if i < first else "push"
            ax.set_title(f"{phase}, t = {t:.2f} s\n|w| = {mag:.2f} F0", fontsize=8)
        fig.suptitle(title, fontsize=9.5)
        return save(fig, out, "physics-filmstrip", _FORMATS)


def plot_all(out: Path, rows: list[dict], closed: dict, floor: float, outside_max: float,
             labels: dict) -> list[Path]:
    """Every figure of the study but the filmstrip (module notes)."""
    return (plot_resisted(out, rows, floor) + plot_placements(out, rows, outside_max)
            + plot_settings(out, rows, closed, labels))

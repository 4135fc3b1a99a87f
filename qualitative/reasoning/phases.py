"""Grasp phases and finger placement order as ST0 formulas, and a kinematic trace generator.

The regions are those of :mod:`qualgrasp.qualitative.reasoning.scene`: the object ``O``, the approach zone ``A``
(the object dilated by a margin) and the fingers ``F1..Fk``. With ``k`` fingers the phases are
state formulas (no temporal operator), mutually exclusive on any real scene:

============  ===================================================================================
phase         formula and meaning
============  ===================================================================================
idle          ``DC(F1,A) & ... & DC(Fk,A)``: every finger away from the approach zone
approach      ``!idle & !in_zone & clear``: some finger at or in the approach zone, not all in
              it, none touching the object; ``in_zone = {TPP,NTPP}(F1,A) & ...`` (every finger
              inside the zone), ``clear = DC(F1,O) & ...`` (no finger touching the object)
pregrasp      ``in_zone & clear``: every finger in the approach zone, none touching
placing       ``in_zone & {DC,EC}(F1,O) & ... & (EC(F1,O) | ...) & !(EC(F1,O) & ...)``: the grasp
              proper, finger by finger: some but not all fingers touch the object, none
              penetrates it (never true with one finger)
grasp         ``EC(F1,O) & ... & EC(Fk,O)``: every finger touches the object
============  ===================================================================================

Temporal formulas (``G``: always, ``U``: until, ``O``: once; see :mod:`qualgrasp.qualitative.reasoning.st0`):

- :func:`phase_sequence`: ``idle & (idle U (approach & (approach U (pregrasp & (pregrasp U
  (placing U G grasp))))))``: the trace starts idle, and leaves each phase only for the next
  one: idle, then approach, then pregrasp (each for at least one instant), then possibly
  placing, then grasp, which lasts to the end of the trace.
- :func:`placement_order`: ``G(EC(Fb,O) -> O EC(Fa,O))`` for each consecutive pair ``a, b`` of
  the planned order: finger b touches the object only once finger a has touched it (at the same
  instant or before; the paper's formula).
- :func:`no_penetration`: ``G(!{PO,TPP,NTPP,EQ,TPPi,NTPPi}(Fi,O))`` for every finger: a finger
  never shares interior with the object. The six relations are exactly those in which the
  interiors meet, so this is ``G {DC,EC}(Fi,O)``; the paper's ``{PO,TPP,NTPP}`` would miss a
  finger swallowing the object (``NTPPi``) or a degenerate ``EQ``.

Fingers are numbered from 1 in region names (``F1`` is contact 0) and from 0 in indices of
contact arrays and of ``order``.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from shapely.geometry import Polygon

from ..errors import FormulaError, RegionError
from .scene import grasp_scene
from .st0 import Formula, parse

__all__ = ["PHASES", "phase_formulas", "phase_sequence", "placement_order", "no_penetration",
           "phases_of", "grasp_trace"]

#: The phases, in the order a grasp goes through them.
PHASES = ("idle", "approach", "pregrasp", "placing", "grasp")


def _fingers(k: int) -> list[str]:
    if not (isinstance(k, int | np.integer) and k >= 1):
        raise FormulaError(f"the number of fingers must be an integer >= 1, got {k!r}")
    return [f"F{i + 1}" for i in range(k)]


def _phase_texts(k: int) -> dict[str, str]:
    fingers = _fingers(k)

    def every(template: str) -> str:
        return " & ".join(template.format(f=f) for f in fingers)

    def some(template: str) -> str:
        return "(" + " | ".join(template.format(f=f) for f in fingers) + ")"

    idle = every("DC({f},A)")
    in_zone = every("{{TPP,NTPP}}({f},A)")
    clear = every("DC({f},O)")
    touching = every("EC({f},O)")
    return {
        "idle": idle,
        "approach": f"!({idle}) & !({in_zone}) & {clear}",
        "pregrasp": f"{in_zone} & {clear}",
        "placing": f"{in_zone} & {every('{{DC,EC}}({f},O)')} & {some('EC({f},O)')} & !({touching})",
        "grasp": touching,
    }


def phase_formulas(k: int) -> dict[str, Formula]:
    """The state formula of each phase (module docstring) for ``k`` fingers, in phase order."""
    return {name: parse(text) for name, text in _phase_texts(k).items()}


def phase_sequence(k: int) -> Formula:
    """The phases happen in order, starting idle and ending in a grasp that lasts."""
    p = {name: f"({text})" for name, text in _phase_texts(k).items()}
    return parse(f"{p['idle']} & ({p['idle']} U ({p['approach']} & ({p['approach']} U "
                 f"({p['pregrasp']} & ({p['pregrasp']} U ({p['placing']} U G{p['grasp']}))))))")


def placement_order(order: Sequence[int]) -> Formula:
    """Fingers touch the object in the given order (0-based finger indices; ties allowed)."""
    order = [int(i) for i in order]
    if len(order) < 2 or len(set(order)) != len(order) or min(order) < 0:
        raise FormulaError(f"a placement order lists at least two distinct finger indices >= 0, "
                         f"got {order!r}")
    return parse(" & ".join(f"G(EC(F{b + 1},O) -> O EC(F{a + 1},O))"
                            for a, b in zip(order, order[1:])))


def no_penetration(k: int) -> Formula:
    """No finger ever overlaps the object's interior."""
    return parse(" & ".join(f"G(!{{PO,TPP,NTPP,EQ,TPPi,NTPPi}}({f},O))" for f in _fingers(k)))


def phases_of(trace: Sequence, k: int) -> list[str | None]:
    """The phase of each frame of a trace (None where no phase formula holds)."""
    values = {name: f.evaluate(trace) for name, f in phase_formulas(k).items()}
    labels = []
    for t in range(len(trace)):
        holding = [name for name in PHASES if values[name][t]]
        labels.append(holding[0] if holding else None)
    return labels


def grasp_trace(obj: Polygon, contacts: np.ndarray, normals: np.ndarray, radius: float, *,
                order: Sequence[int] | None = None, margin: float | None = None, steps: int = 4,
                depth: float | Sequence[float] = 0.0,
                regions: Sequence[Sequence[Sequence[float]]] = (), region_width: float = 1.0,
                tol: float | None = None) -> list[dict[tuple[str, str], str]]:
    """Frames of a planned grasp executed by straight finger moves along the contact normals.

    Finger ``i`` (region ``F{i+1}``) moves along the line ``p_i - s n_i`` (``p_i`` the contact
    point, ``n_i`` the inward unit normal, pixels), ``s`` being the distance of its centre from
    the contact point against the normal:

    1. every finger starts at ``s = margin + 2 radius``, clear of the approach zone (for convex
       objects, where the contact's nearest boundary is its own side);
    2. in ``order``, each finger moves to ``s = margin / 2``, inside the zone and clear of the
       object (approach, then pregrasp once all are in);
    3. in ``order``, each finger closes to ``s = radius - depth_i``: tangent to the boundary at
       the contact for ``depth_i = 0``, pressed ``depth_i`` pixels into the object otherwise.

    Each move takes ``steps`` frames; frame 0 is the start. Every frame is
    :func:`qualgrasp.qualitative.reasoning.scene.grasp_scene` of the current discs at tolerance ``tol``.

    Parameters
    ----------
    obj : shapely Polygon
    contacts, normals : array_like, shape (k, 2)
        Contact points and inward normals (normalised here).
    radius : float
        Finger radius (pixels).
    order : sequence of int, optional
        Planned placement order (0-based contact indices); default ``0, 1, ..., k-1``.
    margin : float, optional
        Approach zone width; default ``4 radius``. Must exceed ``2 radius + 2 tol``.
    steps : int
        Frames per finger move, >= 1.
    depth : float or sequence of float
        Penetration of each finger past its contact (pixels), default 0.
    regions, region_width
        Feasible grasp regions ``R1..`` as in :func:`qualgrasp.qualitative.reasoning.scene.scene_regions`.
    tol : float, optional
        RCC-8 tolerance (pixels); default ``radius / 100``, above the disc polygon's error.

    Returns
    -------
    list of dict
        The trace: ``1 + 2 k steps`` frames mapping region pairs to base relation names.
    """
    p = np.asarray(contacts, dtype=float).reshape(-1, 2)
    n = np.asarray(normals, dtype=float).reshape(-1, 2)
    k = len(p)
    if k == 0 or n.shape != p.shape:
        raise RegionError("give one inward normal per contact point (arrays of shape (k, 2), k >= 1)")
    lengths = np.linalg.norm(n, axis=1)
    if not np.all(lengths > 0) or not np.all(np.isfinite(p)):
        raise RegionError("contact points must be finite and normals non-zero")
    n = n / lengths[:, None]
    order = list(range(k)) if order is None else [int(i) for i in order]
    if sorted(order) != list(range(k)):
        raise RegionError(f"order must be a permutation of 0..{k - 1}, got {order!r}")
    margin = 4.0 * radius if margin is None else float(margin)
    tol = radius / 100 if tol is None else float(tol)
    if not margin > 2 * radius + 2 * tol:
        raise RegionError(f"approach margin {margin} must exceed 2 radius + 2 tol = "
                          f"{2 * radius + 2 * tol} so that a finger fits in the zone clear of "
                          f"the object")
    if not (isinstance(steps, int | np.integer) and steps >= 1):
        raise RegionError(f"steps must be an integer >= 1, got {steps!r}")
    depth = np.broadcast_to(np.asarray(depth, dtype=float), (k,))

    s = np.full(k, margin + 2 * radius)
    moves = [(i, margin / 2) for i in order] + [(i, radius - depth[i]) for i in order]
    positions = [s.copy()]
    for i, target in moves:
        start = s[i]
        for value in np.linspace(start, target, steps + 1)[1:]:
            s[i] = value
            positions.append(s.copy())
    return [grasp_scene(obj, p - si[:, None] * n, radius, margin=margin, regions=regions,
                        region_width=region_width, tol=tol) for si in positions]

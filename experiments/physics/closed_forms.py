"""The simulator's own error, measured on cases with closed-form answers.

The physics engine is a witness, not the judge: before its verdicts on real grasps are read, its
error is measured where the answer is known exactly. Units as in
:mod:`qualgrasp.experiments.physics.planar`: lengths in the object's size (its minimum enclosing
circle's diameter), forces in the preload ``F0``, torques divided by the object's radius ``L``.

Cases (:func:`cases`)
---------------------
* **Square, preload.** A square of side ``a = 1 / sqrt 2`` (diameter 1, ``L = 1 / 2``) squeezed by
  two fingers at the centres of opposite faces: at rest each finger presses with exactly ``F0``
  (the spring's target is ``F0 / k`` past the touch point). Measured: the normal contact force the
  engine reports (its impulse over the step) and the penetration of the finger into the square.
* **Square, push along the faces.** A force ``T`` at the centroid along the faces: each finger's
  normal force stays ``F0`` (the push has no component along the grasp axis and no moment about
  the centroid), so static friction holds while ``T <= 2 mu F0`` and the square slips beyond:
  **``T* = 2 mu F0``**, for ``mu`` in :data:`MUS`.
* **Square, push along the grasp axis.** A force ``P`` along the axis compresses one finger's
  spring and relaxes the other's: the pushed finger presses ``min(F0 + k u, Fmax)``, the other
  ``max(F0 - k u, 0)`` at displacement ``u``; the largest force balanced is
  **``P* = min(Fmax, 2 (Fmax - F0))``** (``Fmax`` once the other finger has let go, when
  ``Fmax >= 2 F0``).
* **Square, torque.** A torque about the centroid: the two friction forces, each at most
  ``mu F0`` at lever ``a / 2``, form a couple: **``tau* = mu F0 a``**, i.e. ``tau* / L = 2 mu a F0``.
* **Frictionless square, push along the faces.** ``mu = 0``: nothing resists, **``T* = 0``**.
* **Frictionless disc, torque.** Three frictionless fingers at 120 degrees on an exact disc (a
  pymunk circle, no facets): every contact force passes through the centre, so **no torque is
  resisted**, ``tau* = 0``, however small.

Spatial cases
-------------
:func:`spatial_cases`, in MuJoCo (:mod:`qualgrasp.experiments.physics.spatial`), SI units:

* **Box, grip force.** A box of 50 x 60 x 70 mm and mass :data:`BOX_MASS` squeezed by the two pads
  across its 50 mm faces, at their centres, without gravity: each pad's normal contact force is
  **the grip force ``F``** (5 N); also the deepest penetration.
* **Box, least grip force.** The same grasp with gravity along the faces (``-z``): the two friction
  forces, each at most ``mu F``, hold the weight iff ``2 mu F >= m g``: **``F* = m g / (2 mu)``**,
  for ``mu`` in :data:`MUS`; measured by :func:`~qualgrasp.experiments.physics.spatial.least_physical_grip`
  to the ratio :data:`SPATIAL_PRECISION` (the upper end of the final bracket is reported: the
  error lies within ``[-0.2 %, 0]`` of the one stated).
* **Box, weight along the closing axis.** The same box gripped across its 70 mm faces with the
  closing axis vertical: the pads are coupled (the hand closes them with ``2 F`` in all), so the
  lower pad carries the weight while ``2 F >= m g``: **``F* = m g / 2``** (certify's least grip
  force is ``m g``: there each pad's normal force is at most ``F``, here the lower one's is
  ``F + m g / 2``).
* **Box, creep at 2 F*.** The slip under gravity (``Physics.hold`` seconds) at twice ``F*``, ``mu``
  0.5: static friction holds, **slip 0**; a soft-constraint engine lets it creep (the error is the
  slip in mm).

Each measured value is the bisection of :func:`qualgrasp.experiments.physics.planar.resistance`
in the one direction of the case (to the ratio :data:`PRECISION`, floor :data:`FLOOR`), whose
lower end is reported; the relative error is ``measured / closed form - 1`` (the absolute value
when the closed form is 0). The error combines the engine's (penetration lowering the preload, the
solver's iterations, the time step) with the trial's own resolution (a wrench must exceed what is
resisted by ``Physics.detect`` to be seen within the hold time).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
import trimesh
from shapely.geometry import box

from ...certify.meshes.gripper import load_gripper
from ...certify.meshes.mesh import mass_properties
from ...certify.meshes.task import G
from .planar import Finger, Physics, PlanarObject, resistance, squeeze
from .spatial import Jaw, SpatialObject, SpatialPhysics, convex_pieces, least_physical_grip, squeeze_forces, trial

__all__ = ["MUS", "PRECISION", "FLOOR", "SPATIAL_PRECISION", "BOX_MASS", "ClosedForm", "square_grasp", "disc_grasp", "cases", "box_grasp",
           "spatial_cases", "table_lines"]

MUS = (0.25, 0.5, 1.0)
"""Friction coefficients of the push along the faces."""

PRECISION = 1.01
"""Ratio of the bisection's final bracket in the closed-form cases."""

FLOOR = 1e-3
"""Smallest magnitude tested in the closed-form cases (``F0``)."""

SPATIAL_PRECISION = 1.002
"""Ratio of the bisection's final bracket in the spatial cases."""

BOX_MASS = 0.3
"""Mass of the spatial cases' box, kg."""


@dataclass(frozen=True)
class ClosedForm:
    """One closed-form case: what the formula says and what the engine measured.

    Attributes
    ----------
    case : str
        Name of the case.
    formula : str
        The closed form.
    exact : float
        Its value (``F0``; torques over ``L``; metres of penetration: size units).
    measured : float
        The engine's value.
    error : float
        ``measured / exact - 1``, or ``measured`` when ``exact`` is 0.
    unit : str
    """

    case: str
    formula: str
    exact: float
    measured: float
    error: float
    unit: str


def square_grasp() -> tuple[PlanarObject, list[Finger]]:
    """The square of side ``1 / sqrt 2`` (diameter 1) and two fingers at the centres of the faces
    ``x = +-a / 2``, pressing along ``-+x``."""
    obj = PlanarObject.from_polygon(box(-1, -1, 1, 1))
    fingers = [Finger(tuple(obj.to_world((1, 0))), (-1.0, 0.0)), Finger(tuple(obj.to_world((-1, 0))), (1.0, 0.0))]
    return obj, fingers


def disc_grasp() -> tuple[PlanarObject, list[Finger]]:
    """An exact disc of diameter 1 and three fingers at 90, 210 and 330 degrees pressing towards
    its centre."""
    obj = PlanarObject.disc()
    fingers = []
    for deg in (90.0, 210.0, 330.0):
        u = np.array([math.cos(math.radians(deg)), math.sin(math.radians(deg))])
        fingers.append(Finger(tuple(0.5 * u), tuple(-u)))
    return obj, fingers


def _measure(obj, fingers, mu, direction, physics: Physics) -> float:
    ph = replace(physics, floor=FLOOR, precision=PRECISION)
    return resistance(obj, fingers, mu, ph, np.array([direction], dtype=float)).magnitude


def table_lines(closed: dict[str, list[ClosedForm]], error_spec: str, *, units: bool) -> list[str]:
    """Markdown table of the closed-form cases measured at several settings (``closed``: the
    cases by setting name, in the same order): case, formula, exact value (with its unit when
    ``units``), then the measured value and the error (formatted by ``error_spec``) per setting."""
    lines = ["| case | closed form | exact | " + " | ".join(f"measured ({k}) | error ({k})" for k in closed) + " |",
             "|---|---|---|" + "---|---|" * len(closed)]
    for i, c in enumerate(next(iter(closed.values()))):
        cells = " | ".join(f"{closed[k][i].measured:.4g} | {format(closed[k][i].error, error_spec)}" for k in closed)
        exact = f"{c.exact:.4g} {c.unit}" if units else f"{c.exact:.4g}"
        lines.append(f"| {c.case} | {c.formula} | {exact} | {cells} |")
    return lines


def _row(case, formula, exact, measured, unit) -> ClosedForm:
    error = measured / exact - 1.0 if exact else measured
    return ClosedForm(case, formula, float(exact), float(measured), float(error), unit)


def _preload(physics: Physics) -> tuple[float, float]:
    """Mean normal contact force (``F0``) and largest penetration (size) of the squeezed square."""
    obj, fingers = square_grasp()
    world, _ = squeeze(obj, fingers, 0.5, physics)
    forces, depths = [], []

    def read(arbiter):
        forces.append(arbiter.total_impulse.length / physics.dt)
        depths.extend(-p.distance for p in arbiter.contact_point_set.points)

    world.body.each_arbiter(read)
    return float(np.mean(forces)), float(max(depths))


def cases(physics: Physics = Physics()) -> list[ClosedForm]:
    """Every closed-form case of the module notes, measured with ``physics``.

    Examples
    --------
    >>> rows = cases()
    >>> [r.case for r in rows][:2]
    ['square: preload', 'square: penetration']
    """
    obj, fingers = square_grasp()
    a = 1 / math.sqrt(2)
    force, depth = _preload(physics)
    rows = [_row("square: preload", "F0", 1.0, force, "F0"),
            ClosedForm("square: penetration", "0 (slop allowed)", 0.0, depth, depth / physics.slop - 1.0,
                       "size (error: over the allowed slop, minus 1)")]
    for mu in MUS:
        rows.append(_row(f"square: push along the faces, mu {mu:g}", "2 mu F0", 2 * mu,
                         _measure(obj, fingers, mu, (0, 1, 0), physics), "F0"))
    fmax = physics.max_force
    rows.append(_row("square: push along the axis, mu 0.5", "min(Fmax, 2 (Fmax - F0))", min(fmax, 2 * (fmax - 1)),
                     _measure(obj, fingers, 0.5, (1, 0, 0), physics), "F0"))
    rows.append(_row("square: torque, mu 0.5", "mu F0 a / L", 0.5 * a / obj.length,
                     _measure(obj, fingers, 0.5, (0, 0, 1), physics), "F0 (torque / L)"))
    rows.append(_row("square: push along the faces, frictionless", "0", 0.0,
                     _measure(obj, fingers, 0.0, (0, 1, 0), physics), "F0"))
    disc, three = disc_grasp()
    rows.append(_row("disc, 3 frictionless fingers: torque", "0", 0.0,
                     _measure(disc, three, 0.0, (0, 0, 1), physics), "F0 (torque / L)"))
    return rows


def box_grasp(mu: float = 0.5):
    """The spatial cases' box (50 x 60 x 70 mm, :data:`BOX_MASS`) and the Franka hand's pads across
    its 50 mm faces at their centres, opened to 60 mm: ``(SpatialObject, Jaw)``."""
    box = trimesh.creation.box((0.05, 0.06, 0.07))
    obj = SpatialObject(tuple(convex_pieces(box)[0]), mass_properties(box, mass=BOX_MASS))
    return obj, Jaw(np.eye(4), 0.06, load_gripper("franka_panda"), mu, (0.0, 0.0))


def spatial_cases(physics=None) -> list[ClosedForm]:
    """Every spatial closed-form case of the module notes, measured with ``physics``
    (:class:`~qualgrasp.experiments.physics.spatial.SpatialPhysics`, default its defaults); needs
    mujoco.

    Examples
    --------
    >>> rows = spatial_cases()
    >>> [r.case for r in rows][:2]
    ['box: grip force', 'box: penetration']
    """
    physics = physics or SpatialPhysics()
    obj, jaw = box_grasp()
    grip = 5.0
    forces, depth = squeeze_forces(obj, jaw, grip, physics)
    rows = [_row("box: grip force", "F", grip, float(forces.mean()), "N"),
            ClosedForm("box: penetration", "0", 0.0, 1000 * depth, 1000 * depth, "mm")]
    for mu in MUS:
        obj, jaw = box_grasp(mu)
        exact = BOX_MASS * G / (2 * mu)
        # a bracket whose log-midpoints never land on the closed form itself
        measured = least_physical_grip(obj, jaw, exact / 3, exact * 3.7, physics, precision=SPATIAL_PRECISION)
        rows.append(_row(f"box: least grip force, mu {mu:g}", "m g / (2 mu)", exact, measured, "N"))
    obj, jaw = box_grasp(0.5)
    T = np.eye(4)
    T[:3, :3] = ((0, 0, 1), (0, 1, 0), (-1, 0, 0))  # the hand's closing axis x along -z
    vertical = replace(jaw, T=T, width=0.08)
    exact = BOX_MASS * G / 2
    rows.append(_row("box: weight along the closing axis", "m g / 2", exact,
                     least_physical_grip(obj, vertical, exact / 3, exact * 3.7, physics, precision=SPATIAL_PRECISION),
                     "N"))
    slip = trial(obj, jaw, 2 * BOX_MASS * G, physics, shake=False).slip
    rows.append(ClosedForm("box: creep at 2 F*, mu 0.5", "0", 0.0, 1000 * slip, 1000 * slip, "mm"))
    return rows

"""Planar grasps in a physics engine (pymunk, Chipmunk2D): squeeze, then push until the object slips.

The world
---------
Lengths are in units of the object's size (the diameter of its minimum enclosing circle; the
object's area centroid at the origin), forces in units of the fingers' **preload** ``F0`` (the
squeeze force), masses and times as stated in :class:`Physics`. The plane is the table: no gravity,
no table friction, no damping of the object (it slides freely once it slips).

* **Object.** One rigid body, its polygon split into convex pieces exactly
  (:func:`pymunk.autogeometry.convex_decomposition` with tolerance 0: the pieces' union is the
  polygon, checked by :func:`convex_pieces`); its mass ``Physics.mass`` spread uniformly over the
  polygon (moment of inertia of the whole polygon). Only the pieces within ``Physics.reach`` of a
  finger are given to the engine, each clipped to the square of half-side ``reach`` around the
  finger (still convex): the object moves less than ``reach / 2`` before a trial ends, so the rest
  can never touch a finger, and a polygon of hundreds of pieces, or a piece of a thousand
  vertices (a disc), would cost 3 to 30 times more per step.
* **Fingers.** Small discs of radius ``Physics.finger_radius`` that do not rotate, each on a
  frictionless groove along its **approach line** (the direction it moves in, towards the
  object): a rigid gripper holds it sideways. Along the groove a position-controlled spring pushes
  it: force ``clip(k (s_target - s) - c ds/dt, 0, Physics.max_force)`` (``s`` the position along
  the approach; a finger pushes, never pulls), stiffness ``k = Physics.stiffness`` and damping
  ``c = 2 Physics.damping sqrt(k Physics.mass)``. The target is ``F0 / k`` past the point where the
  finger touches the object, so a finger at rest on the object presses with ``F0`` and can press
  up to ``max_force`` when the object is pushed into it.
* **Contacts.** Coulomb friction ``mu`` between finger and object (``mu = 0``: frictionless
  fingers), no restitution, allowed penetration ``Physics.slop``; Chipmunk's iterative impulse
  solver with ``Physics.iterations`` iterations and a fixed step ``Physics.dt``.

The trial
---------
1. **Squeeze** (:func:`squeeze`): the fingers start a finger radius short of the object along their
   approach lines; their targets move in over ``Physics.ramp`` seconds, then the world settles for
   ``Physics.settle`` seconds, and longer (up to ``Physics.settle_max``) until the object is at
   rest (its speed, centroid plus ``L`` times angular, below ``Physics.rest``). Equal preloads are
   rarely an internal force the grasp balances as they are: the object shifts or turns a little
   until the springs balance, and is then held there. If it is not at rest by then, or moved
   more than ``reach / 2``, the squeeze alone pushed it out (``ejected``).
2. **Disturbance** (:func:`hold`): a wrench ``w (fx, fy, tau / L)`` applied at the centroid in the
   object's frame (the force turns with the object; ``L`` the object's radius about its centroid,
   the torque scaling of certify's epsilon), ramped in over ``Physics.ramp`` seconds and then held
   for ``t(w) = clip(sqrt(2 slip mass / (detect w)), hold_min, hold_max)`` seconds: long enough that
   a wrench exceeding what the grasp resists by the fraction ``Physics.detect`` moves the object
   by the slip tolerance. The grasp **resists** it when the object's displacement (centroid
   displacement plus ``L`` times its rotation, a bound on the motion of every boundary point) stays
   below ``Physics.slip`` of the size.
3. **Largest resisted disturbance** (:func:`resistance`): the largest magnitude ``w`` (in ``F0``)
   resisted in **every** direction of :data:`DIRECTIONS` (the 6 axes and 8 diagonals of the
   normalised wrench space ``(fx, fy, tau / L)``), by bisection in ``log w`` between
   ``Physics.floor`` and ``Physics.ceiling`` to the ratio ``Physics.precision``; 0 when the floor is
   not resisted in some direction (or the squeeze ejects the object). The grasp **holds** when it
   resists the floor in every direction (:func:`holds`). Each test starts from a fresh squeeze:
   results do not depend on the order of tests.

Everything is deterministic: the same inputs give the same numbers (Chipmunk steps in a fixed
order, no randomness here).

The simulator's own errors (penetration, the solver's iterations, the time step) are measured on
cases with closed-form answers by :mod:`qualgrasp.experiments.physics.closed_forms`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np
import shapely
from shapely.geometry import Polygon

__all__ = ["Physics", "DIRECTIONS", "PlanarObject", "Finger", "World", "Hold", "Resistance", "convex_pieces",
           "squeeze", "hold", "holds", "resistance", "hold_time"]


@dataclass(frozen=True)
class Physics:
    """Parameters of the planar world and trial (module notes). Lengths: fraction of the object's
    size; forces: the preload ``F0 = 1``; seconds.

    Attributes
    ----------
    dt : float
        Time step, seconds.
    iterations : int
        Iterations of Chipmunk's impulse solver per step.
    stiffness : float
        Finger spring stiffness ``k`` (``F0`` per size): the finger's target is ``1 / k`` past the
        touch point.
    max_force : float
        Largest force a finger exerts (``F0``).
    damping : float
        Finger spring damping, fraction of critical for the object's mass.
    mass : float
        Object mass.
    finger_mass : float
        Mass of each finger.
    finger_radius : float
        Finger disc radius.
    slop : float
        Penetration Chipmunk allows before correcting it.
    ramp, settle, settle_max : float
        Seconds over which the squeeze (and a disturbance) is ramped in; least and most seconds of
        settling after the squeeze ramp.
    rest : float
        Largest speed of an object at rest (size per second).
    slip : float
        Slip tolerance: largest displacement of the object (centroid plus ``L`` times rotation)
        still counted as held.
    detect : float
        A wrench this fraction above what the grasp resists must move the object by ``slip``
        within the hold time.
    hold_min, hold_max : float
        Bounds on the hold time, seconds.
    floor, ceiling : float
        Smallest and largest disturbance magnitudes tested (``F0``); the floor is the **held**
        threshold.
    precision : float
        Ratio of the bisection's final bracket.
    reach : float
        The engine gets the object's convex pieces within this distance of a finger, clipped to
        the square of this half-side around it.
    """

    dt: float = 1e-3
    iterations: int = 20
    stiffness: float = 500.0
    max_force: float = 2.0
    damping: float = 1.0
    mass: float = 0.1
    finger_mass: float = 0.05
    finger_radius: float = 0.005
    slop: float = 1e-5
    ramp: float = 0.05
    settle: float = 0.15
    settle_max: float = 0.5
    rest: float = 0.01
    slip: float = 0.01
    detect: float = 0.1
    hold_min: float = 0.1
    hold_max: float = 1.5
    floor: float = 0.02
    ceiling: float = 8.0
    precision: float = 1.1
    reach: float = 0.05

    def label(self) -> str:
        """Short description: ``'dt 0.001 s, 20 iterations, k 500'``."""
        return f"dt {self.dt:g} s, {self.iterations} iterations, k {self.stiffness:g}"


def _directions() -> np.ndarray:
    axes = np.vstack([np.eye(3), -np.eye(3)])
    corners = np.array([[a, b, c] for a in (1, -1) for b in (1, -1) for c in (1, -1)], float) / math.sqrt(3)
    return np.vstack([axes, corners])


DIRECTIONS = _directions()
"""``(14, 3)`` unit disturbance directions ``(fx, fy, tau / L)`` in the object's frame: the 6 axes,
then the 8 diagonals."""


def convex_pieces(polygon: Polygon) -> list[np.ndarray]:
    """Exact convex decomposition of a simple polygon's exterior.

    Parameters
    ----------
    polygon : shapely.geometry.Polygon

    Returns
    -------
    list of numpy.ndarray
        ``(k, 2)`` vertex arrays of convex pieces whose union is the polygon.

    Raises
    ------
    ValueError
        The polygon is not valid, or the pieces do not tile it (relative area error above 1e-9).

    Examples
    --------
    >>> from shapely.geometry import Polygon
    >>> pieces = convex_pieces(Polygon([(0, 0), (2, 0), (2, 2), (1, 1), (0, 2)]))
    >>> len(pieces), sum(Polygon(p).area for p in pieces)
    (2, 3.0)
    """
    from pymunk.autogeometry import convex_decomposition

    if not polygon.is_valid or polygon.is_empty:
        raise ValueError("the object's polygon is not a valid simple polygon")
    ring = np.asarray(polygon.exterior.coords)
    pieces = [np.asarray(p, dtype=float) for p in convex_decomposition([tuple(v) for v in ring], 0.0)]
    union = shapely.union_all([Polygon(p) for p in pieces])
    if union.symmetric_difference(Polygon(ring)).area > 1e-9 * polygon.area:
        raise ValueError("the convex decomposition does not tile the polygon")
    return [p[:-1] if np.allclose(p[0], p[-1]) else p for p in pieces]


def _polar_moment(ring: np.ndarray) -> tuple[float, np.ndarray, float]:
    """Area, centroid and polar second moment about the centroid (per unit density) of a ring."""
    x, y = ring[:, 0], ring[:, 1]
    x1, y1 = np.roll(x, -1), np.roll(y, -1)
    cross = x * y1 - x1 * y
    area = cross.sum() / 2
    cx = ((x + x1) * cross).sum() / (6 * area)
    cy = ((y + y1) * cross).sum() / (6 * area)
    jo = ((x * x + x * x1 + x1 * x1 + y * y + y * y1 + y1 * y1) * cross).sum() / 12
    return abs(area), np.array([cx, cy]), abs(jo - area * (cx * cx + cy * cy))


@dataclass(frozen=True, eq=False)
class PlanarObject:
    """A rigid planar object in the world's units (module notes).

    Attributes
    ----------
    pieces : tuple of numpy.ndarray
        Convex pieces, world units (size 1, centroid at the origin).
    shapes : tuple of shapely.geometry.Polygon
        The same pieces as polygons (to choose those near the fingers).
    center : numpy.ndarray
        Area centroid in the input's units (pixels).
    size : float
        Diameter of the minimum enclosing circle in the input's units.
    length : float
        Radius about the centroid (largest distance to the boundary), world units: the torque
        scaling ``L`` of disturbances.
    inertia : float
        Polar moment of inertia per unit mass, world units squared.
    outline : numpy.ndarray
        ``(n, 2)`` the exterior ring, world units (for drawing).
    circle : bool
        The object is an exact disc of diameter 1 (closed-form cases), not a polygon.
    """

    pieces: tuple[np.ndarray, ...]
    shapes: tuple[Polygon, ...]
    center: np.ndarray
    size: float
    length: float
    inertia: float
    outline: np.ndarray
    circle: bool = False

    @classmethod
    def from_polygon(cls, polygon: Polygon) -> "PlanarObject":
        """The object of a simple polygon (its exterior), in any unit (pixels).

        Examples
        --------
        >>> from shapely.geometry import box
        >>> o = PlanarObject.from_polygon(box(0, 0, 4, 4))
        >>> o.center.tolist(), round(o.size, 6), round(o.length, 6), round(o.inertia, 6)
        ([2.0, 2.0], 5.656854, 0.5, 0.083333)
        """
        ring = np.asarray(polygon.exterior.coords)[:-1]
        area, center, polar = _polar_moment(ring)
        size = 2.0 * shapely.minimum_bounding_radius(polygon)
        world = (ring - center) / size
        pieces = tuple((p - center) / size for p in convex_pieces(polygon))
        length = float(np.hypot(*world.T).max())
        return cls(pieces, tuple(Polygon(p) for p in pieces), center, float(size), length,
                   float(polar / area / size ** 2), world)

    @classmethod
    def disc(cls) -> "PlanarObject":
        """An exact disc of diameter 1 centred at the origin (a pymunk circle, no facets)."""
        angle = np.linspace(0, 2 * math.pi, 721)[:-1]
        ring = 0.5 * np.column_stack([np.cos(angle), np.sin(angle)])
        return cls((), (), np.zeros(2), 1.0, 0.5, 0.125, ring, circle=True)

    def to_world(self, points) -> np.ndarray:
        """Points in the input's units to world units."""
        return (np.asarray(points, dtype=float) - self.center) / self.size


@dataclass(frozen=True)
class Finger:
    """A finger: where it touches the object and the direction it moves in (world units).

    Attributes
    ----------
    touch : tuple of float
        The point of the object's boundary the finger meets moving along its approach line.
    approach : tuple of float
        Unit direction of motion, towards the object (the planned inward normal).
    """

    touch: tuple[float, float]
    approach: tuple[float, float]


@dataclass(eq=False)
class World:
    """A pymunk world holding one object and its fingers (built by :func:`squeeze`)."""

    space: object
    body: object
    fingers: list
    starts: np.ndarray
    approaches: np.ndarray
    physics: Physics
    obj: PlanarObject
    time: float = 0.0
    targets: np.ndarray = field(default_factory=lambda: np.zeros(0))

    def __post_init__(self) -> None:
        self._starts = [tuple(p) for p in np.asarray(self.starts, dtype=float).tolist()]
        self._approaches = [tuple(n) for n in np.asarray(self.approaches, dtype=float).tolist()]

    def pose(self) -> tuple[float, float, float]:
        """Object position and angle ``(x, y, theta)``."""
        p = self.body.position
        return float(p.x), float(p.y), float(self.body.angle)

    def speed(self) -> float:
        """Object speed: centroid speed plus ``L`` times the angular speed."""
        v = self.body.velocity
        return math.hypot(v.x, v.y) + self.obj.length * abs(self.body.angular_velocity)

    def finger_positions(self) -> np.ndarray:
        """``(m, 2)`` finger centres."""
        return np.array([[f.position.x, f.position.y] for f in self.fingers])

    def step(self, target: float, wrench=None) -> None:
        """One step: finger springs towards ``target`` (fraction of the preload depth), the wrench
        ``(fx, fy, tau)`` (forces in the object's frame, absolute torque) at the centroid."""
        ph = self.physics
        k = ph.stiffness
        c = 2.0 * ph.damping * math.sqrt(k * ph.mass)
        depth = target / k
        # Python floats and one read of each finger's state: this loop is most of a study's time
        for f, (sx, sy), (nx, ny) in zip(self.fingers, self._starts, self._approaches):
            (px, py), (vx, vy) = f.position, f.velocity
            s = (px - sx) * nx + (py - sy) * ny
            v = vx * nx + vy * ny
            force = min(max(k * (depth - s) - c * v, 0.0), ph.max_force)
            f.apply_force_at_local_point((force * nx, force * ny), (0.0, 0.0))
        if wrench is not None:
            self.body.apply_force_at_local_point((wrench[0], wrench[1]), self.body.center_of_gravity)
            self.body.torque += wrench[2]
        self.space.step(ph.dt)
        self.time += ph.dt


def _displacement(pose, origin, length: float) -> float:
    return math.hypot(pose[0] - origin[0], pose[1] - origin[1]) + length * abs(pose[2] - origin[2])


def _build(obj: PlanarObject, fingers: Sequence[Finger], mu: float, ph: Physics) -> World:
    import pymunk

    space = pymunk.Space()
    space.iterations = ph.iterations
    space.collision_slop = ph.slop
    body = pymunk.Body(ph.mass, ph.mass * obj.inertia)
    space.add(body)
    group = pymunk.ShapeFilter(group=1)  # fingers never touch each other
    if obj.circle:
        space.add(_shape(pymunk.Circle(body, 0.5)))
    else:
        for f in fingers:
            x, y = f.touch
            square = shapely.box(x - ph.reach, y - ph.reach, x + ph.reach, y + ph.reach)
            for part in shapely.intersection(np.asarray(obj.shapes, dtype=object), square):
                if isinstance(part, Polygon) and part.area > 1e-12:
                    space.add(_shape(pymunk.Poly(body, [tuple(v) for v in np.asarray(part.exterior.coords)[:-1]])))
    bodies, starts, approaches = [], [], []
    r = ph.finger_radius
    for f in fingers:
        n = np.asarray(f.approach, dtype=float)
        n = n / np.linalg.norm(n)
        start = np.asarray(f.touch, dtype=float) - r * n  # the centre when the disc touches
        b = pymunk.Body(ph.finger_mass, math.inf)
        b.position = tuple(start - r * n)  # a radius short: an inclined surface is met first
        disc = pymunk.Circle(b, r)
        disc.friction = mu
        disc.filter = group
        groove = pymunk.GrooveJoint(space.static_body, b, tuple(start - 0.5 * n), tuple(start + 0.5 * n), (0, 0))
        space.add(b, disc, groove)
        bodies.append(b)
        starts.append(start)
        approaches.append(n)
    return World(space, body, bodies, np.array(starts), np.array(approaches), ph, obj)


def _shape(shape):
    shape.friction = 1.0  # the pair's friction is the product: the finger's mu
    shape.elasticity = 0.0
    return shape


@dataclass(frozen=True)
class Hold:
    """Outcome of one disturbance test.

    Attributes
    ----------
    held : bool
        The squeeze brought the object to rest and the disturbance moved it less than the slip
        tolerance from there.
    ejected : bool
        The squeeze alone pushed it out (module notes).
    displacement : float
        Largest displacement of the object from its squeezed pose during the disturbance (from
        its initial pose when ejected), fraction of the size.
    seconds : float
        Simulated time of the disturbance.
    frames : tuple
        Recorded states ``(time, (x, y, theta), finger centres, wrench)`` when asked for.
    """

    held: bool
    ejected: bool
    displacement: float
    seconds: float
    frames: tuple = ()


def squeeze(obj: PlanarObject, fingers: Sequence[Finger], mu: float, physics: Physics = Physics(),
            frames: list | None = None, every: int = 10) -> tuple[World, float]:
    """Build the world and squeeze (module notes): ``(world, displacement)`` with the object's
    largest displacement from its initial pose, fraction of the size (``world.speed()`` tells
    whether it came to rest).

    Examples
    --------
    Two fingers across a square's faces hold it still:

    >>> from shapely.geometry import box
    >>> o = PlanarObject.from_polygon(box(-1, -1, 1, 1))
    >>> fingers = [Finger(tuple(o.to_world((1, 0))), (-1.0, 0.0)), Finger(tuple(o.to_world((-1, 0))), (1.0, 0.0))]
    >>> world, moved = squeeze(o, fingers, 0.5)
    >>> moved < 1e-3
    True
    """
    world = _build(obj, fingers, mu, physics)
    origin = world.pose()
    ramp = max(1, round(physics.ramp / physics.dt))
    least = ramp + max(1, round(physics.settle / physics.dt))
    most = ramp + max(1, round(physics.settle_max / physics.dt))
    lift = physics.finger_radius * physics.stiffness  # the start is a radius short of the touch
    moved = 0.0
    for i in range(most):
        a = min(1.0, (i + 1) / ramp)
        world.step(-lift + a * (1.0 + lift))
        if frames is not None and i % every == 0:
            frames.append((world.time, world.pose(), world.finger_positions(), (0.0, 0.0, 0.0)))
        moved = max(moved, _displacement(world.pose(), origin, obj.length))
        if i + 1 >= least and world.speed() <= physics.rest:
            break
    return world, moved


def hold_time(magnitude: float, physics: Physics = Physics()) -> float:
    """Seconds a disturbance of ``magnitude`` (``F0``) is held after its ramp (module notes).

    Examples
    --------
    >>> round(hold_time(1.0), 3), hold_time(1e-6)
    (0.141, 1.5)
    """
    t = math.sqrt(2.0 * physics.slip * physics.mass / (physics.detect * magnitude)) if magnitude > 0 else math.inf
    return min(max(t, physics.hold_min), physics.hold_max)


def hold(obj: PlanarObject, fingers: Sequence[Finger], mu: float, wrench, physics: Physics = Physics(),
         record: int = 0) -> Hold:
    """Squeeze, then apply the disturbance ``wrench = w (fx, fy, tau / L)`` (``F0``, object frame)
    and report whether the grasp resists it (module notes).

    Parameters
    ----------
    obj : PlanarObject
    fingers : sequence of Finger
    mu : float
        Coulomb friction between fingers and object (0: frictionless).
    wrench : sequence of 3 float
        ``(fx, fy, tau / L)`` in units of ``F0``.
    physics : Physics
    record : int
        Record a frame every ``record`` steps (0: none), squeeze included.

    Returns
    -------
    Hold
    """
    frames: list | None = [] if record else None
    world, moved = squeeze(obj, fingers, mu, physics, frames, record or 10)
    if moved > physics.reach / 2 or world.speed() > physics.rest:
        return Hold(False, True, moved, 0.0, tuple(frames or ()))
    w = np.asarray(wrench, dtype=float)
    magnitude = float(np.linalg.norm(w))
    ramp = max(1, round(physics.ramp / physics.dt))
    steps = ramp + max(1, round(hold_time(magnitude, physics) / physics.dt))
    origin = world.pose()
    worst, t0 = 0.0, world.time
    wx, wy, wt = w.tolist()
    for i in range(steps):
        a = min(1.0, (i + 1) / ramp)
        applied = (a * wx, a * wy, a * wt * obj.length)
        world.step(1.0, applied)
        worst = max(worst, _displacement(world.pose(), origin, obj.length))
        if frames is not None and i % record == 0:
            frames.append((world.time, world.pose(), world.finger_positions(), (a * wx, a * wy, a * wt)))
        if worst > physics.slip:
            if frames is None:
                break
            if worst > 5 * physics.slip:  # enough of the object leaving for a picture
                break
    return Hold(worst <= physics.slip, False, worst, world.time - t0, tuple(frames or ()))


def holds(obj: PlanarObject, fingers: Sequence[Finger], mu: float, magnitude: float | None = None,
          physics: Physics = Physics(), directions: np.ndarray = DIRECTIONS) -> tuple[bool, int | None]:
    """Whether the grasp resists a disturbance of ``magnitude`` (default ``physics.floor``) in every
    direction: ``(held, index of the first direction not resisted or None)``; -1 when the squeeze
    ejects the object.

    Examples
    --------
    Frictionless fingers across a square cannot resist a push along its faces:

    >>> from shapely.geometry import box
    >>> o = PlanarObject.from_polygon(box(-1, -1, 1, 1))
    >>> fingers = [Finger(tuple(o.to_world((1, 0))), (-1.0, 0.0)), Finger(tuple(o.to_world((-1, 0))), (1.0, 0.0))]
    >>> holds(o, fingers, 0.0)
    (False, 1)
    """
    magnitude = physics.floor if magnitude is None else magnitude
    ok, k, _ = _holds(obj, fingers, mu, magnitude, physics, directions, range(len(directions)))
    return ok, k


def _holds(obj, fingers, mu, magnitude, physics, directions, order) -> tuple[bool, int | None, int]:
    """``(held, first direction not resisted (-1: ejected) or None, tests run)``, directions in
    ``order``."""
    for count, k in enumerate(order, start=1):
        out = hold(obj, fingers, mu, magnitude * directions[k], physics)
        if out.ejected:
            return False, -1, count
        if not out.held:
            return False, k, count
    return True, None, len(order)


@dataclass(frozen=True)
class Resistance:
    """Largest disturbance a grasp resists in every direction (module notes).

    Attributes
    ----------
    magnitude : float
        Largest magnitude resisted in every direction of the set (``F0``; the bisection's lower
        end), 0 when the floor is not, ``physics.ceiling`` when the ceiling is.
    held : bool
        The floor is resisted in every direction.
    ejected : bool
        The squeeze alone pushed the object out.
    weakest : int or None
        Index into the directions of the last direction not resisted (the weakest found).
    tests : int
        Disturbance tests run.
    """

    magnitude: float
    held: bool
    ejected: bool
    weakest: int | None
    tests: int


def resistance(obj: PlanarObject, fingers: Sequence[Finger], mu: float, physics: Physics = Physics(),
               directions: np.ndarray = DIRECTIONS) -> Resistance:
    """Largest disturbance resisted in every direction, by bisection in ``log w`` (module notes).

    A direction that failed is tried first in the next test, so a failing test usually ends after
    one direction.

    Examples
    --------
    A square squeezed across two faces with ``mu = 0.5`` resists a push along its faces up to
    ``2 mu F0 = 1`` (closed form), and less in the diagonal directions:

    >>> from shapely.geometry import box
    >>> o = PlanarObject.from_polygon(box(-1, -1, 1, 1))
    >>> fingers = [Finger(tuple(o.to_world((1, 0))), (-1.0, 0.0)), Finger(tuple(o.to_world((-1, 0))), (1.0, 0.0))]
    >>> r = resistance(o, fingers, 0.5)
    >>> r.held, 0.3 < r.magnitude < 1.0
    (True, True)
    """
    order = list(range(len(directions)))
    tests = 0
    weakest = None

    def test(w: float) -> tuple[bool, int | None]:
        nonlocal tests, order
        ok, k, count = _holds(obj, fingers, mu, w, physics, directions, order)
        tests += count
        if k is not None and k >= 0:
            order = [k] + [j for j in order if j != k]
        return ok, k

    ok, k = test(physics.floor)
    if not ok:
        return Resistance(0.0, False, k == -1, None if k == -1 else k, tests)
    ok, weakest = test(physics.ceiling)
    if ok:
        return Resistance(physics.ceiling, True, False, None, tests)
    lo, hi = physics.floor, physics.ceiling
    while hi / lo > physics.precision:
        mid = math.sqrt(lo * hi)
        ok, k = test(mid)
        if ok:
            lo = mid
        else:
            hi, weakest = mid, k
    return Resistance(lo, True, False, weakest, tests)

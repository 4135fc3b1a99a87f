"""Parallel-jaw grasps on meshes in a physics engine (MuJoCo): close, release under gravity, shake.

The world
---------
SI units throughout (metres, kilograms, newtons, seconds); the world frame is the mesh's frame and
gravity points along ``-z`` of it (the models' up axis, as the certification of
:mod:`qualgrasp.experiments.mesh_study` assumes).

* **Object.** One free body whose mass, centre of mass and inertia tensor are those the
  certification uses (:func:`qualgrasp.certify.meshes.mesh.mass_properties`); its collision
  geometry is a set of convex pieces (:func:`convex_pieces`: coacd's approximate convex
  decomposition when coacd is installed, else the convex hull), because MuJoCo collides the convex
  hull of every mesh geom. Only the pieces within ``SpatialPhysics.reach`` of a pad's region are
  given to the engine: the trial ends once the object has moved ``reach / 2``, so no other piece
  can touch a pad (nothing else is in the world: no table, no fingers, no palm).
* **Gripper.** A hand body at the grasp pose (``qualgrasp`` convention,
  :mod:`qualgrasp.certify.meshes.gripper`: origin midway between the pads, closing axis ``x``)
  carrying two box pads of the gripper's pad size (pad width along ``y``, pad height along ``z``,
  finger thickness along ``x``), each on a slide joint along ``x`` driven by a force actuator: pad A
  (at ``x = +width / 2``) is pushed along ``-x`` and pad B along ``+x``, each with the grip force
  ``F`` (``F`` ramped in over ``SpatialPhysics.close`` seconds). The two slides are coupled
  (an equality constraint keeps the pads symmetric about the hand's origin, as the Franka hand's
  fingers are): the hand bears any net force along the closing axis, so the pads press with
  ``F -+ lambda`` where the weight pushes the object towards one of them. Two pads pressed by
  independent forces could bear none, and would let every object whose weight has a component
  along the closing axis slide down with them. The pads' slide joints are damped
  (``F / SpatialPhysics.close_speed``) while they close, so that they meet the object slowly, and
  undamped afterwards. The hand itself has
  six joints (three slides, three hinges about its origin) whose motion is prescribed (positions
  and velocities set before every step; the hand is heavy and its weight compensated), so the pads
  move with the hand's true velocity and friction sees it.
* **Contacts.** Elliptic friction cones; MuJoCo's multi-point convex collisions (``multiccd``)
  put several contact points where a pad meets a piece. ``condim = 3`` (the default): Coulomb
  friction ``mu`` at each point, the patch's resistance to twisting coming only from the points'
  spread. ``condim = 4``: each point also carries torsional friction with MuJoCo's cone
  ``f_t1^2 / mu^2 + f_t2^2 / mu^2 + m^2 / mu_s^2 <= f_n^2``, ``mu_s = mu torsion`` (``torsion``
  the certified patch's torsional length): exactly certify's ``soft`` contact, ``norm((f_t,
  m / torsion)) <= mu f_n``, for one point per pad, and more torsion than certified when a pad
  has several points. The pads' friction wins over the object's (a higher ``priority``). ``impratio`` (the friction
  constraints' stiffness relative to the normal's) and the solver's iterations and time step are
  :class:`SpatialPhysics` fields.

The trial (:func:`trial`)
-------------------------
1. **Close**, without gravity: the pads start open at the pose's width and close with the force
   ramped to ``F``; the world then settles for ``SpatialPhysics.settle`` seconds. The object's
   pose in the hand's frame then is the reference.
2. **Release**: gravity on for ``SpatialPhysics.hold`` seconds (equivalent to lifting the object
   off a table at constant speed). The **slip** is the object's displacement relative to the hand
   since the reference: its centre of mass's displacement plus the object's radius times its
   rotation angle (a bound on the motion of every point of it), in metres. The grasp **held**
   when the slip stays within ``SpatialPhysics.slip`` (5 mm). MuJoCo's friction is a soft
   constraint: under a load the cone can bear, the object still creeps, slowly and steadily (the
   closed-form box: 0.07 mm in a second at twice its least grip force; grasps on curved meshes
   whose patches bear a torque about the grasp axis: 1 to 4 mm); a load the cone cannot bear
   accelerates the object, which leaves the pads (15 mm) within the second. 5 mm tells the two
   apart.
3. **Shake**: the hand moves by ``A (1 - cos 2 pi f t)`` for one period along each of its axes
   (peak acceleration ``SpatialPhysics.shake_accel``) and turns by ``Theta (1 - cos 2 pi f t)``
   about each (peak angular acceleration ``SpatialPhysics.shake_alpha``), one axis after the
   other; ``held_shake`` when the slip is still within ``slip`` at the end.

A trial stops early (``dropped``) once the slip exceeds ``reach / 2``. Everything is
deterministic: the same inputs give the same numbers.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Sequence

import numpy as np
import trimesh

from ...certify.meshes.gripper import ParallelJaw
from ...certify.meshes.mesh import MassProperties
from ...certify.meshes.task import G

__all__ = ["SpatialPhysics", "MUJOCO_DEFAULTS", "SpatialObject", "Jaw", "Trial", "convex_pieces", "world_xml",
           "squeeze_forces", "trial", "least_physical_grip"]


@dataclass(frozen=True)
class SpatialPhysics:
    """Parameters of the spatial world and trial (module notes); SI units.

    Attributes
    ----------
    dt : float
        Time step, s.
    iterations : int
        Iterations of MuJoCo's constraint solver (Newton) per step.
    cone : {'elliptic', 'pyramidal'}
        Friction cone.
    impratio : float
        Ratio of the friction constraints' impedance to the normal's (higher: stiffer friction,
        less creep).
    condim : int
        Contact dimension: 3 (sliding friction), 4 (and torsional: certify's soft contact).
    pad_mass : float
        Mass of each pad, kg.
    close, settle, hold : float
        Seconds of closing (force ramp), of settling after it, and under gravity.
    close_speed : float
        Speed at which a pad pushed by ``F`` meets the object (sets the slide's damping), m/s.
    shake_accel : float
        Peak linear acceleration of the shake, m/s^2.
    shake_alpha : float
        Peak angular acceleration of the shake, rad/s^2.
    shake_freq : float
        Frequency of the shake, Hz.
    slip : float
        Largest slip counted as held, m.
    reach : float
        Pieces farther than this from a pad's region are left out, m; a trial ends (dropped) at a
        slip of ``reach / 2``.
    """

    dt: float = 1e-3
    iterations: int = 50
    cone: str = "elliptic"
    impratio: float = 100.0
    condim: int = 3
    pad_mass: float = 0.05
    close: float = 0.2
    settle: float = 0.3
    hold: float = 1.0
    close_speed: float = 0.2
    shake_accel: float = 0.1 * G
    shake_alpha: float = 4.0
    shake_freq: float = 2.0
    slip: float = 0.005
    reach: float = 0.03

    def label(self) -> str:
        """Short description: ``'dt 0.001 s, 50 iterations, elliptic cones, impratio 100, condim 3'``."""
        return (f"dt {self.dt:g} s, {self.iterations} iterations, {self.cone} cones, impratio {self.impratio:g}, "
                f"condim {self.condim}")


MUJOCO_DEFAULTS = SpatialPhysics(dt=2e-3, iterations=100, cone="pyramidal", impratio=1.0)
"""MuJoCo's own defaults for the time step, iterations, cone and impratio (the closed-form cases show
why the study does not use them: friction creeps)."""


@dataclass(frozen=True)
class SpatialObject:
    """A rigid object: convex pieces (metres, the mesh frame) and the certification's mass
    properties."""

    pieces: tuple[np.ndarray, ...]
    props: MassProperties


@dataclass(frozen=True)
class Jaw:
    """A parallel-jaw grasp to execute: pose ``T`` (4x4, ``qualgrasp`` convention, gripper to
    object), opening ``width`` (m), the gripper (pad size), friction ``mu`` and each pad's
    torsional length ``torsion`` (m: pad A at ``+x``, pad B at ``-x``; 0 for no torsional
    friction)."""

    T: np.ndarray
    width: float
    gripper: ParallelJaw
    mu: float
    torsion: tuple[float, float]


@dataclass(frozen=True)
class Trial:
    """The outcome of one trial (module notes).

    Attributes
    ----------
    held : bool
        Slip within ``SpatialPhysics.slip`` after the release under gravity.
    held_shake : bool
        And still after the shake.
    dropped : bool
        The slip exceeded ``reach / 2`` (the trial stopped).
    slip, slip_shake : float
        Slip after the release, and after the shake (m; the slip when the trial stopped).
    contacts : int
        Contacts between the pads and the object at the reference (after closing).
    settle : float
        How far the squeeze moved the object (m; as the slip, from its pose before closing to the
        reference): it re-seats an object its pads first touch at their edges.
    seconds : float
        Wall-clock time of the trial.
    """

    held: bool
    held_shake: bool
    dropped: bool
    slip: float
    slip_shake: float
    contacts: int
    settle: float
    seconds: float


def convex_pieces(mesh: trimesh.Trimesh, threshold: float = 0.08, max_pieces: int = 24) -> tuple[list, str]:
    """Convex pieces covering ``mesh``, body by body (a mesh of several closed bodies, such as a
    V-HACD output, is split first): a convex body is one piece, any other is decomposed by coacd's
    approximate convex decomposition (concavity ``threshold``, at most ``max_pieces`` per body) when
    coacd is installed, else replaced by its convex hull; ``(vertex arrays, method)`` with method
    ``'convex'`` (every body convex), ``'coacd'`` or ``'hull'``.

    Examples
    --------
    >>> pieces, how = convex_pieces(trimesh.creation.box((0.1, 0.2, 0.3)))
    >>> len(pieces), how
    (1, 'convex')
    """
    bodies = mesh.split(only_watertight=False) if mesh.body_count > 1 else [mesh]
    pieces, method = [], "convex"
    for body in bodies:
        if body.is_convex:
            pieces.append(np.asarray(body.vertices, float))
            continue
        try:
            import coacd
        except ImportError:
            pieces.append(np.asarray(body.convex_hull.vertices, float))
            method = "hull"
            continue
        coacd.set_log_level("error")
        parts = coacd.run_coacd(coacd.Mesh(np.asarray(body.vertices, float), np.asarray(body.faces, np.int32)),
                                threshold=threshold, max_convex_hull=max_pieces, preprocess_mode="off",
                                resolution=1000, mcts_iterations=60, mcts_max_depth=2, mcts_nodes=10, seed=1)
        pieces += [np.asarray(v, float) for v, _ in parts]
        method = "coacd"
    return pieces, method


def _near(pieces: Sequence[np.ndarray], jaw: Jaw, reach: float) -> list[np.ndarray]:
    """The pieces whose points come within ``reach`` of the box swept by the pads (hand frame)."""
    g = jaw.gripper
    half = np.array([jaw.width / 2 + g.finger_thickness, g.pad_width / 2, g.pad_height / 2]) + reach
    keep = []
    for v in pieces:
        local = (v - jaw.T[:3, 3]) @ jaw.T[:3, :3]
        lo, hi = local.min(axis=0), local.max(axis=0)
        if np.all(lo <= half) and np.all(hi >= -half):
            keep.append(v)
    return keep


def _quat(R: np.ndarray) -> np.ndarray:
    return trimesh.transformations.quaternion_from_matrix(np.vstack([np.column_stack([R, np.zeros(3)]),
                                                                     [0, 0, 0, 1]]))


def _fmt(values) -> str:
    return " ".join(f"{float(v):.9g}" for v in np.ravel(values))


def world_xml(obj: SpatialObject, jaw: Jaw, force: float, physics: SpatialPhysics = SpatialPhysics()) -> str:
    """The MuJoCo model (MJCF) of one trial: the object's pieces near the pads, the hand at the
    pose with its two pads, their force actuators (``ctrl`` in newtons, limited to ``2 force``),
    gravity ``-z`` (switched off by the trial while closing)."""
    g = jaw.gripper
    pieces = _near(obj.pieces, jaw, physics.reach)
    if not pieces:
        raise ValueError("no piece of the object lies near the pads")
    p = obj.props
    assets = "".join(f'<mesh name="piece{i}" vertex="{_fmt(v)}"/>' for i, v in enumerate(pieces))
    geoms = "".join(f'<geom type="mesh" mesh="piece{i}" friction="0 0 0" condim="{physics.condim}"/>'
                    for i in range(len(pieces)))
    I = np.asarray(p.inertia)
    inertia = _fmt([I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]])
    half = _fmt([g.finger_thickness / 2, g.pad_width / 2, g.pad_height / 2])
    damping = force / physics.close_speed
    dims = np.array([g.finger_thickness, g.pad_width, g.pad_height])
    pad_i = _fmt(physics.pad_mass * ((dims ** 2).sum() - dims ** 2) / 12)  # a solid box's
    pads = ""
    for name, side, torsion in (("a", 1.0, jaw.torsion[0]), ("b", -1.0, jaw.torsion[1])):
        x = side * (jaw.width / 2 + g.finger_thickness / 2)
        pads += (f'<body name="pad_{name}" pos="{x:.9g} 0 0"><joint name="slide_{name}" type="slide" axis="1 0 0" '
                 f'damping="{damping:.9g}"/><inertial pos="0 0 0" mass="{physics.pad_mass:g}" diaginertia="{pad_i}"/>'
                 f'<geom type="box" size="{half}" priority="1" '
                 f'condim="{physics.condim}" friction="{jaw.mu:.9g} {max(jaw.mu * torsion, 1e-9):.9g} 0"/></body>')
    hand_joints = "".join(f'<joint name="hand_{k}" type="{kind}" axis="{_fmt(np.eye(3)[i])}"/>'
                          for k, (kind, i) in enumerate([("slide", 0), ("slide", 1), ("slide", 2),
                                                         ("hinge", 0), ("hinge", 1), ("hinge", 2)]))
    return (f'<mujoco><compiler inertiafromgeom="false"/>'
            f'<option timestep="{physics.dt:g}" iterations="{physics.iterations}" cone="{physics.cone}" '
            f'impratio="{physics.impratio:g}" gravity="0 0 {-G}"><flag multiccd="enable"/></option>'
            f'<asset>{assets}</asset><worldbody>'
            f'<body name="object"><freejoint/><inertial pos="{_fmt(p.com)}" mass="{p.mass:.9g}" '
            f'fullinertia="{inertia}"/>{geoms}</body>'
            f'<body name="hand" pos="{_fmt(jaw.T[:3, 3])}" quat="{_fmt(_quat(jaw.T[:3, :3]))}" gravcomp="1">'
            f'{hand_joints}<inertial pos="0 0 0" mass="1000" diaginertia="10 10 10"/>{pads}</body>'
            f'</worldbody><equality><joint joint1="slide_a" joint2="slide_b" polycoef="0 -1 0 0 0"/></equality>'
            f'<actuator><motor name="grip_a" joint="slide_a" gear="-1"/>'
            f'<motor name="grip_b" joint="slide_b" gear="1"/></actuator></mujoco>')


def _shake_schedule(physics: SpatialPhysics) -> tuple[np.ndarray, float]:
    """Amplitudes of the six hand joints' shakes (m or rad) and each shake's duration (s)."""
    omega = 2 * math.pi * physics.shake_freq
    amplitude = np.array([physics.shake_accel] * 3 + [physics.shake_alpha] * 3) / omega**2
    return amplitude, 1.0 / physics.shake_freq


class _World:
    """One trial's model and data, and the reference pose of the object in the hand's frame."""

    def __init__(self, obj: SpatialObject, jaw: Jaw, force: float, physics: SpatialPhysics):
        import mujoco
        self.mj = mujoco
        self.model = mujoco.MjModel.from_xml_string(world_xml(obj, jaw, force, physics))
        self.data = mujoco.MjData(self.model)
        mujoco.mj_forward(self.model, self.data)  # the bodies' poses, read before the first step
        self.object = self.model.body("object").id
        self.hand = self.model.body("hand").id
        self.hand_q = np.array([self.model.jnt_qposadr[self.model.joint(f"hand_{k}").id] for k in range(6)])
        self.hand_v = np.array([self.model.jnt_dofadr[self.model.joint(f"hand_{k}").id] for k in range(6)])
        self.com = np.asarray(obj.props.com, float)
        self.radius = obj.props.radius
        self.reference: tuple[np.ndarray, np.ndarray] | None = None

    def step(self, q: np.ndarray | None = None, v: np.ndarray | None = None) -> None:
        """One step, the hand's joints set to ``q`` and ``v`` (zero when None) before it."""
        self.data.qpos[self.hand_q] = 0.0 if q is None else q
        self.data.qvel[self.hand_v] = 0.0 if v is None else v
        self.mj.mj_step(self.model, self.data)

    def relative(self) -> tuple[np.ndarray, np.ndarray]:
        """The object's centre of mass and rotation in the hand's frame."""
        Rh, ph = self.data.xmat[self.hand].reshape(3, 3), self.data.xpos[self.hand]
        Ro, po = self.data.xmat[self.object].reshape(3, 3), self.data.xpos[self.object]
        return Rh.T @ (po + Ro @ self.com - ph), Rh.T @ Ro

    def slip(self) -> float:
        """Displacement of the object relative to the hand since the reference (module notes), m."""
        return self.moved(*self.reference)

    def moved(self, c0: np.ndarray, R0: np.ndarray) -> float:
        """Displacement of the object relative to the hand since it was at ``c0``, ``R0`` (hand frame):
        its centre of mass's plus the radius times its rotation angle, m."""
        c, R = self.relative()
        angle = math.acos(max(-1.0, min(1.0, (np.trace(R0.T @ R) - 1) / 2)))
        return float(np.linalg.norm(c - c0) + self.radius * angle)

    def contacts(self) -> int:
        """Contacts between a pad and the object."""
        body = self.model.geom_bodyid
        return sum(1 for c in self.data.contact[:self.data.ncon]
                   if self.object in (body[c.geom1], body[c.geom2]))

    def pad_forces(self) -> tuple[np.ndarray, float]:
        """Total normal contact force on each pad (N; pads A, B) and the deepest penetration (m)."""
        body = self.model.geom_bodyid
        pads = [self.model.body("pad_a").id, self.model.body("pad_b").id]
        forces, depth, f6 = np.zeros(2), 0.0, np.zeros(6)
        for i, c in enumerate(self.data.contact[:self.data.ncon]):
            self.mj.mj_contactForce(self.model, self.data, i, f6)
            for k, pad in enumerate(pads):
                if pad in (body[c.geom1], body[c.geom2]):
                    forces[k] += f6[0]
            depth = max(depth, -c.dist)
        return forces, depth


def _close(world: _World, force: float, physics: SpatialPhysics) -> None:
    """Close the pads with the force ramped to ``force``, without gravity, then settle."""
    world.model.opt.gravity[:] = 0.0
    ramp = max(1, round(physics.close / physics.dt))
    for k in range(ramp + round(physics.settle / physics.dt)):
        world.data.ctrl[:] = force * min(1.0, (k + 1) / ramp)
        world.step()
    world.model.opt.gravity[:] = (0.0, 0.0, -G)
    # the damping only slows the pads' approach: a hand squeezing with F does not resist the
    # pads' slow motion, and a damper would hold a slowly sliding pair (an error of 2 % at m g / 2)
    for pad in ("slide_a", "slide_b"):
        world.model.dof_damping[world.model.jnt_dofadr[world.model.joint(pad).id]] = 0.0
    world.reference = world.relative()


def _release(world: _World, physics: SpatialPhysics) -> float:
    """Gravity on for ``physics.hold`` seconds; the slip at the end (or when it passed reach / 2)."""
    for _ in range(round(physics.hold / physics.dt)):
        world.step()
        if world.slip() > physics.reach / 2:
            break
    return world.slip()


def _shake(world: _World, physics: SpatialPhysics) -> float:
    """The shake along and about each axis of the hand, one after the other; the slip at the end."""
    amplitude, period = _shake_schedule(physics)
    omega = 2 * math.pi * physics.shake_freq
    steps = round(period / physics.dt)
    for axis in range(6):
        for k in range(1, steps + 1):
            t = k * physics.dt
            q, v = np.zeros(6), np.zeros(6)
            q[axis] = amplitude[axis] * (1 - math.cos(omega * t))
            v[axis] = amplitude[axis] * omega * math.sin(omega * t)
            world.step(q, v)
            if world.slip() > physics.reach / 2:
                return world.slip()
    world.step()
    return world.slip()


def squeeze_forces(obj: SpatialObject, jaw: Jaw, force: float,
                   physics: SpatialPhysics = SpatialPhysics()) -> tuple[np.ndarray, float]:
    """Close the pads with grip force ``force`` (N) without gravity: the normal contact force on each
    pad (N) and the deepest penetration (m) the engine reports at the end.

    Examples
    --------
    >>> import trimesh
    >>> from qualgrasp.certify.meshes.gripper import load_gripper
    >>> from qualgrasp.certify.meshes.mesh import mass_properties
    >>> box = trimesh.creation.box((0.05, 0.06, 0.07))
    >>> obj = SpatialObject(tuple(convex_pieces(box)[0]), mass_properties(box, mass=0.3))
    >>> forces, depth = squeeze_forces(obj, Jaw(np.eye(4), 0.06, load_gripper("franka_panda"), 0.5, (0, 0)), 5.0)
    >>> np.round(forces, 2).tolist(), depth < 1e-3
    ([5.0, 5.0], True)
    """
    world = _World(obj, jaw, force, physics)
    _close(world, force, physics)
    return world.pad_forces()


def trial(obj: SpatialObject, jaw: Jaw, force: float, physics: SpatialPhysics = SpatialPhysics(), *,
          shake: bool = True) -> Trial:
    """Close with grip force ``force`` (N), release under gravity, shake (module notes).

    Parameters
    ----------
    obj : SpatialObject
    jaw : Jaw
    force : float
        Grip force of each pad, N.
    physics : SpatialPhysics
    shake : bool
        Shake after the release (else ``held_shake`` is ``held``).

    Returns
    -------
    Trial

    Examples
    --------
    >>> import trimesh
    >>> from qualgrasp.certify.meshes.gripper import load_gripper
    >>> from qualgrasp.certify.meshes.mesh import mass_properties
    >>> box = trimesh.creation.box((0.05, 0.06, 0.07))
    >>> obj = SpatialObject(tuple(convex_pieces(box)[0]), mass_properties(box, mass=0.3))
    >>> jaw = Jaw(np.eye(4), 0.06, load_gripper("franka_panda"), 0.5, (0.005, 0.005))
    >>> [trial(obj, jaw, f, shake=False).held for f in (1.0, 6.0)]      # m g / (2 mu) = 2.94 N
    [False, True]
    """
    if not (math.isfinite(force) and force > 0):
        raise ValueError(f"the grip force must be a finite positive number of newtons, got {force}")
    start = time.perf_counter()
    world = _World(obj, jaw, force, physics)
    before = world.relative()
    _close(world, force, physics)
    contacts, settle = world.contacts(), world.moved(*before)
    slip = _release(world, physics)
    dropped = slip > physics.reach / 2
    slip_shake = slip if dropped or not shake else _shake(world, physics)
    dropped = dropped or slip_shake > physics.reach / 2
    return Trial(slip <= physics.slip, slip_shake <= physics.slip, dropped, slip, slip_shake, contacts, settle,
                 time.perf_counter() - start)


def least_physical_grip(obj: SpatialObject, jaw: Jaw, lo: float, hi: float,
                        physics: SpatialPhysics = SpatialPhysics(), *, precision: float = 1.05) -> float:
    """The smallest grip force (N) that holds the object under gravity in physics, by bisection in
    ``log F`` between ``lo`` and ``hi`` to the ratio ``precision`` (the upper end of the final
    bracket; ``lo`` when ``lo`` already holds, ``inf`` when ``hi`` does not). Assumes holding is
    monotone in the force.

    Examples
    --------
    >>> import trimesh
    >>> from qualgrasp.certify.meshes.gripper import load_gripper
    >>> from qualgrasp.certify.meshes.mesh import mass_properties
    >>> box = trimesh.creation.box((0.05, 0.06, 0.07))
    >>> obj = SpatialObject(tuple(convex_pieces(box)[0]), mass_properties(box, mass=0.3))
    >>> jaw = Jaw(np.eye(4), 0.06, load_gripper("franka_panda"), 0.5, (0.005, 0.005))
    >>> 2.5 < least_physical_grip(obj, jaw, 1.0, 10.0, precision=1.1) < 3.5   # m g / (2 mu) = 2.94 N
    True
    """
    if trial(obj, jaw, lo, physics, shake=False).held:
        return lo
    if not trial(obj, jaw, hi, physics, shake=False).held:
        return math.inf
    while hi / lo > precision:
        mid = math.sqrt(lo * hi)
        if trial(obj, jaw, mid, physics, shake=False).held:
            hi = mid
        else:
            lo = mid
    return hi

"""A mesh with its certified parallel-jaw grasps drawn: pads, contact patches and friction cones,
coloured by the weight-holding verdict and the least grip force (matplotlib 3-D axes, headless).

``python -m qualgrasp.experiments.mesh_figure OUT.png`` draws a made-up object (a capsule, or
``--mesh FILE``) with antipodal poses of the Franka hand, each certified to hold the object's
weight against gravity ``-z`` with a grip force of at most ``--hold`` newtons.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib
import matplotlib.ticker

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib import cm, colors  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection  # noqa: E402
import trimesh  # noqa: E402

from ..certify.meshes.contacts import jaw_contacts  # noqa: E402
from ..certify.meshes.gripper import load_gripper  # noqa: E402
from ..certify.meshes.mesh import load_mesh, mass_properties  # noqa: E402
from ..certify.meshes.poses import grasp_of  # noqa: E402
from ..certify.meshes.sampling import sample_poses  # noqa: E402
from ..certify.meshes.task import hold_verdict, least_grip  # noqa: E402

__all__ = ["draw_grasps", "main"]

_HOLDS, _SLIP, _UNDECIDED = "#2ca02c", "#d62728", "#ff7f0e"


def _pad_corners(T: np.ndarray, x: float, gripper) -> np.ndarray:
    """Corners of the pad face at gripper coordinate ``x``, object frame."""
    hy, hz = gripper.pad_width / 2, gripper.pad_height / 2
    local = np.array([[x, -hy, -hz], [x, hy, -hz], [x, hy, hz], [x, -hy, hz]])
    return local @ T[:3, :3].T + T[:3, 3]


def _cone_lines(p: np.ndarray, n: np.ndarray, mu: float, length: float, k: int = 12) -> list:
    """Generators of the friction cone at ``p`` about the outward direction ``-n`` (drawn outside
    the object, where the finger pushes from)."""
    a = np.eye(3)[np.argmin(np.abs(n))]
    t1 = np.cross(n, a)
    t1 /= np.linalg.norm(t1)
    t2 = np.cross(n, t1)
    rim = []
    for th in np.linspace(0, 2 * np.pi, k, endpoint=False):
        v = -(n + mu * (np.cos(th) * t1 + np.sin(th) * t2))
        rim.append(p + length * v / np.linalg.norm(v))
    return [[p, q] for q in rim] + [[rim[i], rim[(i + 1) % k]] for i in range(k)]


def draw_grasps(mesh, gripper, grasps: list[dict], path: str | Path, *, title: str = "", mu: float = 0.5,
                budget: float | None = None) -> Path:
    """Draw ``mesh`` and its grasps into ``path`` (PNG, PDF, ...).

    Parameters
    ----------
    mesh : trimesh.Trimesh
    gripper : ParallelJaw
    grasps : list of dict
        Each with ``T`` (4x4, qualgrasp convention), ``width``, ``patches`` (a list of
        :class:`qualgrasp.certify.meshes.contacts.Patch`), ``status`` (``holds``, ``slips`` or
        ``undecided``) and ``grip`` (the certified least grip force, N, or None).
    path : str or pathlib.Path
    title : str
    mu : float
        Friction coefficient of the cones drawn.
    budget : float, optional
        The grip force of the verdicts, for the legend.

    Returns
    -------
    pathlib.Path
    """
    fig = plt.figure(figsize=(7.5, 6.5), dpi=150)
    ax = fig.add_subplot(projection="3d")
    faces = mesh.vertices[mesh.faces]
    light = np.clip(0.55 + 0.45 * mesh.face_normals @ np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8]), 0, 1)
    shade = np.column_stack([light * 0.75, light * 0.78, light * 0.82, np.full(len(light), 0.35)])
    ax.add_collection3d(Poly3DCollection(faces, facecolors=shade, edgecolors="none"))
    # pads coloured by the certified least grip force (every grasp), cones by the verdict
    grips = [g["grip"] for g in grasps if g["grip"] is not None]
    lo_g, hi_g = min(grips, default=1.0), max(grips, default=10.0)
    norm = colors.LogNorm(vmin=lo_g, vmax=max(hi_g, lo_g * 1.5))
    cmap = cm.viridis
    size = float(np.linalg.norm(mesh.extents))
    for g in grasps:
        verdict = _HOLDS if g["status"] == "holds" else (_SLIP if g["status"] == "slips" else _UNDECIDED)
        colour = "white" if g["grip"] is None else cmap(norm(g["grip"]))
        for side, patch in zip((1.0, -1.0), g["patches"]):
            x = side * (g["width"] / 2 - patch.travel)  # the pad where it touched
            ax.add_collection3d(Poly3DCollection([_pad_corners(g["T"], x, gripper)], facecolors=[colour],
                                                 edgecolors="k", linewidths=0.4, alpha=0.45))
            pts = patch.points
            ax.scatter(*pts[:: max(1, len(pts) // 60)].T, s=1.5, color="k", depthshade=False)
            ax.add_collection3d(Line3DCollection(_cone_lines(patch.centroid, patch.normal, mu, 0.07 * size),
                                                 colors=[verdict], linewidths=0.8))
    lo, hi = mesh.bounds
    centre, half = (lo + hi) / 2, (hi - lo).max() / 2 + 0.06 * size
    for setter, c in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), centre):
        setter(c - half, c + half)
    ax.set_box_aspect((1, 1, 1))
    ax.set_xlabel("x (m)", fontsize=8)
    ax.set_ylabel("y (m)", fontsize=8)
    ax.set_zlabel("z (m)", fontsize=8)
    ax.tick_params(labelsize=6)
    ax.view_init(elev=22, azim=-58)
    mappable = cm.ScalarMappable(norm=norm, cmap=cmap)
    bar = fig.colorbar(mappable, ax=ax, shrink=0.55, pad=0.08)
    bar.set_label("pads: least grip force that holds (N, certified; white: none)", fontsize=8)
    bar.ax.yaxis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
    bar.ax.yaxis.set_minor_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
    bar.ax.tick_params(which="both", labelsize=7)
    counts = {s: sum(g["status"] == s for g in grasps) for s in ("holds", "slips", "undecided")}
    at = f" at {budget:g} N" if budget is not None else ""
    handles = [plt.Line2D([], [], color=_HOLDS, lw=2, label=f"friction cones: holds{at} ({counts['holds']})"),
               plt.Line2D([], [], color=_SLIP, lw=2, label=f"friction cones: slips{at} ({counts['slips']})")]
    if counts["undecided"]:
        handles.append(plt.Line2D([], [], color=_UNDECIDED, lw=3, label=f"undecided ({counts['undecided']})"))
    ax.legend(handles=handles, loc="upper left", fontsize=8, frameon=False)
    ax.set_title(title, fontsize=10)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, bbox_inches="tight")
    plt.close(fig)
    return path


def main(argv: list[str] | None = None) -> Path:
    """Command line (module docstring)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out")
    parser.add_argument("--mesh", default=None)
    parser.add_argument("--units", default="m")
    parser.add_argument("--n", type=int, default=8)
    parser.add_argument("--mass", type=float, default=0.3)
    parser.add_argument("--hold", type=float, default=8.0)
    parser.add_argument("--mu", type=float, default=0.5)
    parser.add_argument("--seed", type=int, default=4)
    args = parser.parse_args(argv)
    if args.mesh:
        mesh = load_mesh(args.mesh, units=args.units)
        name = Path(args.mesh).stem
    else:
        mesh = trimesh.creation.capsule(height=0.08, radius=0.025, count=[48, 48])
        mesh.apply_transform(trimesh.transformations.rotation_matrix(0.35, (1, 0, 0)))
        name = "capsule"
    gripper = load_gripper("franka_panda")
    props = mass_properties(mesh, mass=args.mass)
    poses = sample_poses(mesh, gripper, args.n, mu=args.mu, seed=args.seed)
    outs = jaw_contacts(mesh, gripper, np.array([p.T for p in poses]), np.array([p.width for p in poses]))
    grasps = []
    for p, o in zip(poses, outs):
        if not o.ok:
            continue
        b = least_grip(grasp_of(o, args.mu, "soft", props), props.mass, props.com, (0, 0, -1))
        status = hold_verdict(b.lo, b.hi, args.hold)
        grasps.append({"T": p.T, "width": p.width, "patches": o.patches, "status": status,
                       "grip": None if np.isinf(b.hi) else b.hi})
    title = (f"{name}, {props.mass:g} kg: Franka hand poses, soft patch contacts (mu = {args.mu:g}),\n"
             f"gravity -z, certified to hold with grip force <= {args.hold:g} N")
    return draw_grasps(mesh, gripper, grasps, args.out, title=title, mu=args.mu, budget=args.hold)


if __name__ == "__main__":
    print(main())

"""Evaluation of contacts from poses and of the weight-holding certificate on made-up meshes.

``python -m qualgrasp.experiments.mesh_study --poses 10000 --out OUT.json`` reports, over
antipodal poses of the Franka hand (shaken by a few millimetres and degrees, so that some collide
or miss) on six made-up meshes (box, sphere, cylinder, capsule, torus, L-bracket):

* **independent route**: the first touch of each pad from dense surface samples
  (``trimesh.sample``) inside the pad's prism, nearest the open pad along the closing axis,
  against the ray-cast contacts: agreement within the penetration tolerance;
* **time per pose** of contacts and of certification (least grip force against gravity ``-z``,
  both certificates made and re-checked): median and 95th percentile;
* **error rows** by reason, and the share of grasps that hold the weight at ``--hold`` newtons;
* **8-edge cones**: the same hold question with Dex-Net's linearisation (an 8-edge pyramid
  inscribed in each friction cone, torsion as separate columns ``|m| <= mu torsion f_n``, as
  Dex-Net's soft fingers add them), by linear programming; how many verdicts differ from the
  exact, certified ones.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np
import trimesh
from scipy.optimize import linprog

from ..certify.meshes.contacts import TOLERANCE, jaw_contacts
from ..certify.meshes.gripper import load_gripper
from ..certify.meshes.mesh import check_mesh, mass_properties
from ..certify.meshes.poses import grasp_of
from ..certify.meshes.rays import RayCaster
from ..certify.meshes.sampling import sample_poses
from ..certify.meshes.task import G, check_holds, check_slips, hold_verdict, least_grip
from ..certify.core.wrench import contact_frame, wrench

__all__ = ["made_up_meshes", "independent_travel", "edge8_holds", "main"]


def made_up_meshes() -> dict:
    """The study's objects, in metres."""
    L = np.array([(-0.05, -0.01), (0.05, -0.01), (0.05, 0.09), (0.03, 0.09), (0.03, 0.01), (-0.05, 0.01)])
    V = np.vstack([np.column_stack([L, np.full(6, -0.03)]), np.column_stack([L, np.full(6, 0.03)])])
    cap = np.array([(0, 1, 4), (0, 4, 5), (1, 2, 3), (1, 3, 4)])
    sides = [f for i in range(6) for f in ((i, (i + 1) % 6, (i + 1) % 6 + 6), (i, (i + 1) % 6 + 6, i + 6))]
    meshes = {"box": trimesh.creation.box((0.05, 0.07, 0.09)), "sphere": trimesh.creation.icosphere(4, 0.03),
              "cylinder": trimesh.creation.cylinder(0.025, 0.1, sections=128),
              "capsule": trimesh.creation.capsule(0.08, 0.025, count=[48, 48]),
              "torus": trimesh.creation.torus(0.045, 0.014, major_sections=96, minor_sections=48),
              "l_bracket": trimesh.Trimesh(V, np.vstack([cap + 6, cap[:, ::-1], sides]))}
    for m in meshes.values():
        check_mesh(m)
    return meshes


def independent_travel(points: np.ndarray, T: np.ndarray, width: float, gripper) -> tuple[float, float]:
    """Each pad's travel to its first touch from surface samples in the pad's prism (inf: none)."""
    local = (points - T[:3, 3]) @ T[:3, :3]
    inside = (np.abs(local[:, 1]) <= gripper.pad_width / 2) & (np.abs(local[:, 2]) <= gripper.pad_height / 2)
    x = local[inside, 0]
    a = x[x <= width / 2]
    b = x[x >= -width / 2]
    return (width / 2 - a.max() if len(a) else np.inf), (b.min() + width / 2 if len(b) else np.inf)


def edge8_holds(grasp, mass, com, direction, budget) -> bool:
    """Dex-Net-style check: 8-edge inscribed friction pyramids, torsion as two columns
    ``+-mu torsion n`` per soft contact, each contact's normal force (the sum of its edge and
    torsion weights) at most ``budget``; feasible by linear programming."""
    cols, owner = [], []
    c, L = np.asarray(grasp.center), grasp.length
    for i, ct in enumerate(grasp.contacts):
        n = np.asarray(ct.n)
        t1, t2 = contact_frame(n[None])
        for th in np.arange(8) * np.pi / 4:
            f = n + ct.mu * (np.cos(th) * t1[0] + np.sin(th) * t2[0])
            cols.append(wrench(np.asarray(ct.p), f, c, L))
            owner.append(i)
        if ct.torsion:
            for s in (1.0, -1.0):
                cols.append(np.concatenate([n, s * ct.mu * ct.torsion * n / L]))
                owner.append(i)
    A = np.array(cols).T
    w = wrench(np.asarray(com, float), np.asarray(direction, float) * mass * G, c, L)
    owner = np.array(owner)
    A_ub = np.array([(owner == i).astype(float) for i in range(len(grasp.contacts))])
    res = linprog(np.zeros(A.shape[1]), A_ub=A_ub, b_ub=np.full(len(A_ub), budget), A_eq=A, b_eq=-w,
                  bounds=(0, None), method="highs")
    return res.status == 0


def main(argv: list[str] | None = None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--poses", type=int, default=10000)
    parser.add_argument("--hold", type=float, default=5.0)
    parser.add_argument("--mass", type=float, default=0.3)
    parser.add_argument("--mu", type=float, default=0.5)
    parser.add_argument("--certify", type=int, default=600, help="grasps certified per mesh (timing, verdicts)")
    parser.add_argument("--out", default=None)
    args = parser.parse_args(argv)
    gripper = load_gripper("franka_panda")
    rng = np.random.default_rng(0)
    meshes = made_up_meshes()
    per = args.poses // len(meshes)
    report = {"poses": 0, "agree": 0, "ok_both": 0, "decision_differs": 0, "reasons": {}, "t_contacts": [],
              "t_certify": [], "holds": 0, "certified": 0, "verified": 0, "edge8_differs": 0,
              "edge8_optimistic": 0, "edge8_pessimistic": 0, "undecided": 0, "worst_travel_error": 0.0}
    for name, mesh in meshes.items():
        caster = RayCaster(mesh)
        points = trimesh.sample.sample_surface(mesh, 400_000, seed=1)[0]
        poses = sample_poses(mesh, gripper, per, mu=args.mu, seed=2, caster=caster)
        T = np.array([p.T for p in poses])
        W = np.array([p.width for p in poses])
        # shake: 2 mm and 3 degrees
        for k in range(len(T)):
            axis = rng.normal(size=3)
            R = trimesh.transformations.rotation_matrix(np.radians(3) * rng.uniform(), axis)[:3, :3]
            T[k, :3, :3] = R @ T[k, :3, :3]
            T[k, :3, 3] += rng.normal(scale=0.002, size=3)
        outs = []
        for k in range(len(T)):
            t0 = time.perf_counter()
            outs += jaw_contacts(mesh, gripper, T[k:k + 1], W[k:k + 1], caster=caster)
            report["t_contacts"].append(time.perf_counter() - t0)
        props = mass_properties(mesh, mass=args.mass)
        certified = 0
        for k, o in enumerate(outs):
            report["poses"] += 1
            report["reasons"][o.reason or "contacts"] = report["reasons"].get(o.reason or "contacts", 0) + 1
            if o.reason in ("too_wide", "too_narrow", "collision"):
                continue  # the independent route does not decide collisions
            ta, tb = independent_travel(points, T[k], W[k], gripper)
            if not o.ok:
                report["decision_differs"] += int(np.isfinite(ta) and np.isfinite(tb))
                report["agree"] += int(not (np.isfinite(ta) and np.isfinite(tb)))
                continue
            report["ok_both"] += 1
            err = max(abs(o.patches[0].travel - ta), abs(o.patches[1].travel - tb))
            report["worst_travel_error"] = max(report["worst_travel_error"], float(err))
            report["agree"] += int(err <= TOLERANCE)
            if certified >= args.certify:
                continue
            certified += 1
            grasp = grasp_of(o, args.mu, "soft", props)
            t0 = time.perf_counter()
            b = least_grip(grasp, props.mass, props.com, (0, 0, -1))
            ok = (np.isinf(b.hi) or check_holds(grasp, props.mass, props.com, (0, 0, -1), b.hi * (1 + 1e-12), b.forces)) \
                and (b.lo == 0 or check_slips(grasp, props.mass, props.com, (0, 0, -1), b.slip))
            report["t_certify"].append(time.perf_counter() - t0)
            report["certified"] += 1
            report["verified"] += int(bool(ok))
            verdict = hold_verdict(b.lo, b.hi, args.hold)
            report["holds"] += int(verdict == "holds")
            if verdict == "undecided":
                report["undecided"] += 1
                continue
            e8 = edge8_holds(grasp, props.mass, props.com, (0, 0, -1), args.hold)
            if e8 != (verdict == "holds"):
                report["edge8_differs"] += 1
                report["edge8_optimistic" if e8 else "edge8_pessimistic"] += 1
        print(name, len(outs), "poses", flush=True)
    tc, tq = np.array(report.pop("t_contacts")), np.array(report.pop("t_certify"))
    report["contacts_s_median"], report["contacts_s_p95"] = float(np.median(tc)), float(np.percentile(tc, 95))
    report["certify_s_median"], report["certify_s_p95"] = float(np.median(tq)), float(np.percentile(tq, 95))
    if args.out:
        Path(args.out).write_text(json.dumps(report, indent=1))
    print(json.dumps(report, indent=1))
    return report


if __name__ == "__main__":
    main()

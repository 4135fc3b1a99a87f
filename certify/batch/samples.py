"""Sample grasps: random grasps for tests and benchmarks, and textbook grasps for the demo."""

from __future__ import annotations

import json

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from .. import models as registry
from ..core.grasp import Contact, Grasp
from ..files.outputs import atomic_output
from ..files.reader import contact_type, grasp_schema, is_parquet

__all__ = ["RANGES", "parameter_ranges", "DEGENERATE", "random_grasp", "random_grasps", "textbook_grasps",
           "random_grasp_table", "degenerate_geometry", "write_random_grasp_file"]


#: Ranges of the uniform draws of each model parameter (a patch's radius 1.5 times the torsion's,
#: so that its torsional length ``2 radius / 3`` spans the soft finger's).
RANGES = {"mu": (0.2, 1.0), "torsion": (0.05, 0.5), "width": (0.05, 0.6), "radius": (0.075, 0.75)}


def parameter_ranges(model: str, **given: tuple[float, float]) -> dict[str, tuple[float, float]]:
    """The ranges the parameters of ``model`` are drawn from: ``given`` (by parameter name), else
    :data:`RANGES`.

    Raises
    ------
    ValueError
        Naming a parameter without a range (of a model registered outside the package).

    Examples
    --------
    >>> parameter_ranges("patch", mu=(0.5, 0.5))
    {'mu': (0.5, 0.5), 'radius': (0.075, 0.75)}
    """
    ranges = {**RANGES, **given}
    names = [par.name for par in registry.get(model).params]
    missing = [name for name in names if name not in ranges]
    if missing:
        raise ValueError(f"no range to draw the parameter{'s' * (len(missing) > 1)} {', '.join(missing)} "
                         f"of model {model!r} from (known: {', '.join(RANGES)})")
    return {name: ranges[name] for name in names}


def random_grasp(rng: np.random.Generator, *, dim: int = 2, n_contacts: int = 3,
                 model: str = "point", mu: tuple[float, float] = RANGES["mu"],
                 torsion: tuple[float, float] = RANGES["torsion"],
                 width: tuple[float, float] = RANGES["width"], spread: float = 0.7) -> Grasp:
    """A random grasp on a blob around the origin.

    Contact points lie at radius 0.7 to 1.3 in uniformly random directions; each inward normal is
    the direction to the origin plus Gaussian noise of size ``spread``, so that roughly half of
    the grasps are in closure for the default sizes. ``model`` is any registered contact model;
    its parameters are drawn uniformly from the ranges ``mu``, ``torsion``, ``width``, others from
    :data:`RANGES` (:func:`parameter_ranges`; in the model's parameter order, after the normal).
    """
    ranges = parameter_ranges(model, mu=mu, torsion=torsion, width=width)
    contacts = []
    for _ in range(n_contacts):
        u = rng.normal(size=dim)
        u /= np.linalg.norm(u)
        p = u * rng.uniform(0.7, 1.3)
        n = -u + spread * rng.normal(size=dim)
        params = {name: rng.uniform(*bounds) for name, bounds in ranges.items()}
        contacts.append(Contact(p, n, model, **params))
    return Grasp(tuple(contacts))


def random_grasps(seed: int, count: int, **kwargs) -> list[Grasp]:
    """``count`` grasps from :func:`random_grasp` with a fixed seed; ids ``r0, r1, ...``."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(count):
        g = random_grasp(rng, **kwargs)
        out.append(Grasp(g.contacts, id=f"r{i}"))
    return out


def _square(offsets, signs) -> tuple[Contact, ...]:
    """Frictionless contacts on the four sides of the square [-1, 1]^2 (right, top, left, bottom),
    each shifted along its side by ``offset * sign``."""
    (a, b, c, e), (sa, sb, sc, se) = offsets, signs
    return (
        Contact((1, sa * a), (-1, 0)),
        Contact((sb * b, 1), (0, -1)),
        Contact((-1, sc * c), (1, 0)),
        Contact((se * e, -1), (0, 1)),
    )


def _on_cube(p) -> Contact:
    """Frictionless contact at ``p`` on a face of [-1, 1]^3 with the face's inward normal."""
    axis = int(np.argmax(np.abs(p)))
    n = [0.0, 0.0, 0.0]
    n[axis] = -float(np.sign(p[axis]))
    return Contact(p, n)


#: Seven frictionless contacts on the cube [-1, 1]^3 in form closure (found by a random search
#: over face points; the verdict is re-derived in the tests, not assumed).
CUBE_7: tuple[Contact, ...] = tuple(_on_cube(p) for p in (
    (1.0, 0.5, 0.75), (-1.0, -0.75, 0.0), (0.25, 1.0, 0.0), (-0.75, -1.0, 0.75),
    (0.0, -0.75, 1.0), (0.5, 0.75, -1.0), (1.0, -0.25, -0.75),
))


def textbook_grasps() -> list[Grasp]:
    """Grasps whose verdicts every textbook states, with ids saying what they are.

    * ``square-form``: 4 frictionless contacts on a square's sides whose torques cancel
      (form closure); ``square-pinwheel``: the same offsets all turning one way (not).
    * ``disc-4``: 4 frictionless contacts on the unit disc (never form closure: rotation is free).
    * ``antipodal-2d``: two opposite point contacts with friction (force closure).
    * ``antipodal-3d-point``: the same in space (not: rotation about the grasp line is free);
      ``antipodal-3d-soft``: soft contacts (force closure).
    * ``cube-7``: 7 frictionless contacts on the cube's faces (spatial form closure).
    * ``pads-2d-frictionless``: two frictionless flat pads on opposite faces (they resist rotation
      but not sliding along the faces: not in closure); ``pads-2d``: the same with friction
      (force closure).
    """
    s = 0.5
    disc = [(np.cos(a), np.sin(a)) for a in (0.3, 1.9, 3.4, 5.0)]
    gs = [
        Grasp(_square((s, s, s, s), (1, 1, -1, -1)), id="square-form"),
        Grasp(_square((s, s, s, s), (1, -1, -1, 1)), id="square-pinwheel"),
        Grasp(tuple(Contact(p, (-p[0], -p[1])) for p in disc), center=(0, 0), id="disc-4"),
        Grasp((Contact((1, 0), (-1, 0), "point", 0.5), Contact((-1, 0), (1, 0), "point", 0.5)),
              id="antipodal-2d"),
        Grasp((Contact((0, 0, 1), (0, 0, -1), "point", 0.5),
               Contact((0, 0, -1), (0, 0, 1), "point", 0.5)), id="antipodal-3d-point"),
        Grasp((Contact((0, 0, 1), (0, 0, -1), "soft", 0.5, 0.1),
               Contact((0, 0, -1), (0, 0, 1), "soft", 0.5, 0.1)), id="antipodal-3d-soft"),
        Grasp(CUBE_7, center=(0, 0, 0), id="cube-7"),
        Grasp((Contact((1, 0), (-1, 0), "pad", mu=0.0, width=0.4),
               Contact((-1, 0), (1, 0), "pad", mu=0.0, width=0.4)), center=(0, 0), id="pads-2d-frictionless"),
        Grasp((Contact((1, 0), (-1, 0), "pad", mu=0.5, width=0.4),
               Contact((-1, 0), (1, 0), "pad", mu=0.5, width=0.4)), center=(0, 0), id="pads-2d"),
    ]
    return gs


#: Kinds of degenerate planar grasp sets (:func:`degenerate_geometry`), each with what it draws.
DEGENERATE = {
    "antipodal-disc": "antipodal pairs of contacts on a disc, normals through its centre "
                      "(an odd count leaves the last contact without its partner)",
    "centre-disc": "contacts at random angles on a disc, normals through its centre",
    "centre-square": "contacts at the middles of a square's sides (right, left, top, bottom, then "
                     "again), normals through its centre",
    "duplicated": "random contacts each given twice (contact 2j+1 repeats contact 2j)",
    "collinear": "contacts on one line, normals across it on alternating sides",
    "mixed": "each grasp one of the kinds above, drawn at random",
}


def _rotation(angle: np.ndarray) -> np.ndarray:
    """``(B, 2)`` unit vectors at the given angles."""
    return np.stack([np.cos(angle), np.sin(angle)], axis=-1)


def degenerate_geometry(kind: str, rng: np.random.Generator, count: int, n_contacts: int):
    """Contact points and inward normals ``(count, n_contacts, 2)`` of planar grasps whose
    wrenches are degenerate: every normal through one point (discs, squares grasped through
    the centre), repeated contacts, or contacts on one line with parallel normals.

    Each grasp is placed at a random centre in ``[-1, 1]^2``, with a random size in
    ``[0.5, 1.5]`` and a random rotation; ``kind`` is a key of :data:`DEGENERATE`.

    Raises
    ------
    ValueError
        Unknown ``kind``, or fewer than 2 contacts.

    Examples
    --------
    >>> import numpy as np
    >>> p, n = degenerate_geometry("antipodal-disc", np.random.default_rng(0), 1, 2)
    >>> d = p[0, 1] - p[0, 0]  # the second contact lies on the first one's normal line
    >>> bool(np.allclose(n[0, 0], -n[0, 1])), bool(abs(d[0] * n[0, 0, 1] - d[1] * n[0, 0, 0]) < 1e-12)
    (True, True)
    """
    if kind not in DEGENERATE:
        raise ValueError(f"degenerate kind must be one of {', '.join(DEGENERATE)}, got {kind!r}")
    if n_contacts < 2:
        raise ValueError(f"degenerate grasps need at least 2 contacts, got {n_contacts}")
    m = n_contacts
    centre = rng.uniform(-1, 1, size=(count, 1, 2))
    size = rng.uniform(0.5, 1.5, size=(count, 1, 1))
    turn = rng.uniform(0, 2 * np.pi, size=(count, 1))
    kinds = [k for k in DEGENERATE if k != "mixed"]
    which = rng.integers(len(kinds), size=count) if kind == "mixed" else np.full(count, kinds.index(kind))
    j = np.arange(m)
    angle = {
        "antipodal-disc": rng.uniform(0, 2 * np.pi, size=(count, (m + 1) // 2)).repeat(2, axis=1)[:, :m]
        + np.pi * (j % 2),
        "centre-disc": rng.uniform(0, 2 * np.pi, size=(count, m)),
        "centre-square": turn + np.array([0, np.pi, np.pi / 2, 3 * np.pi / 2])[j % 4],
    }
    p = np.empty((count, m, 2))
    n = np.empty((count, m, 2))
    for w, name in enumerate(kinds):
        rows = which == w
        if not rows.any():
            continue
        if name in angle:  # every normal through the centre
            u = _rotation(angle[name][rows])
            p[rows], n[rows] = centre[rows] + size[rows] * u, -u
        elif name == "duplicated":
            u = rng.normal(size=(int(rows.sum()), (m + 1) // 2, 2))
            u /= np.linalg.norm(u, axis=2, keepdims=True)
            q = u * rng.uniform(0.7, 1.3, size=u.shape[:2] + (1,))
            v = -u + 0.7 * rng.normal(size=u.shape)
            p[rows] = (centre[rows] + size[rows] * q).repeat(2, axis=1)[:, :m]
            n[rows] = v.repeat(2, axis=1)[:, :m]
        else:  # collinear
            along = _rotation(turn[rows])
            across = np.stack([-along[..., 1], along[..., 0]], axis=-1)
            s = rng.uniform(-1, 1, size=(int(rows.sum()), m, 1))
            p[rows] = centre[rows] + size[rows] * s * along
            n[rows] = np.where((j % 2 == 0)[None, :, None], 1.0, -1.0) * across
    return p, n


def random_grasp_table(seed: int, count: int, *, dim: int = 2, n_contacts: int = 3,
                       model: str = "point", mu: tuple[float, float] = RANGES["mu"],
                       torsion: tuple[float, float] = RANGES["torsion"],
                       width: tuple[float, float] = RANGES["width"], spread: float = 0.7,
                       start: int = 0, degenerate: str | None = None):
    """An Arrow grasp table (:func:`qualgrasp.certify.files.reader.grasp_schema`) of ``count`` random grasps drawn
    like :func:`random_grasp` (same distribution, vectorised; not the same draws), ids
    ``r{start}, r{start+1}, ...``; ``center`` and ``length`` left to their defaults.
    ``degenerate``: a kind of :data:`DEGENERATE` (planar only), whose contact points and normals
    :func:`degenerate_geometry` draws instead (``spread`` unused); the model parameters are
    drawn as above."""

    rng = np.random.default_rng(seed)
    m = n_contacts
    if degenerate is not None:
        if dim != 2:
            raise ValueError(f"degenerate grasp sets are planar (dim 2), got dim {dim}")
        p, n = degenerate_geometry(degenerate, rng, count, m)
    else:
        u = rng.normal(size=(count, m, dim))
        u /= np.linalg.norm(u, axis=2, keepdims=True)
        p = u * rng.uniform(0.7, 1.3, size=(count, m, 1))
        n = -u + spread * rng.normal(size=(count, m, dim))
    total = count * m
    lists = lambda a: pa.ListArray.from_arrays(pa.array(np.arange(0, total * dim + 1, dim, dtype=np.int32)),
                                               pa.array(a.reshape(-1)))
    fields = {"p": lists(p), "n": lists(n), "model": pa.array(np.full(total, model, dtype=object))}
    for name, bounds in parameter_ranges(model, mu=mu, torsion=torsion, width=width).items():
        fields[name] = pa.array(rng.uniform(*bounds, size=total))
    contacts = pa.StructArray.from_arrays(
        [fields.get(f.name, pa.nulls(total, f.type)) for f in contact_type()], fields=list(contact_type()))
    per_row = pa.ListArray.from_arrays(pa.array(np.arange(0, total + 1, m, dtype=np.int32)), contacts)
    ids = pa.array([f"r{i}" for i in range(start, start + count)])
    return pa.table({"id": ids, "contacts": per_row, "center": pa.nulls(count, pa.list_(pa.float64())),
                     "length": pa.nulls(count, pa.float64())}, schema=grasp_schema())


def write_random_grasp_file(path, count: int, *, seed: int = 0, chunk: int = 500_000, **kwargs) -> int:
    """Write ``count`` random grasps (:func:`random_grasp_table`) to a Parquet or JSON Lines file,
    ``chunk`` at a time, so that memory stays bounded; return how many were written. The file is
    written by :func:`qualgrasp.certify.files.outputs.atomic_output` (a temporary renamed at the end,
    one writer at a time, never a FIFO or a device).

    Raises
    ------
    OptionError
        The output is refused or cannot be written (a one-line message).
    """
    written = 0
    with atomic_output(path, "OUT") as tmp:
        writer = pq.ParquetWriter(tmp, grasp_schema()) if is_parquet(path) else None
        fh = None if writer else open(tmp, "w", encoding="utf-8")
        try:
            for start in range(0, count, chunk):
                n = min(chunk, count - start)
                table = random_grasp_table(seed + start, n, start=start, **kwargs)
                if writer:
                    writer.write_table(table)
                else:
                    for row in table.to_pylist():
                        row["contacts"] = [{k: v for k, v in c.items() if v is not None} for c in row["contacts"]]
                        fh.write(json.dumps({k: v for k, v in row.items() if v is not None}) + "\n")
                written += n
        finally:
            if writer:
                writer.close()
            if fh:
                fh.close()
    return written

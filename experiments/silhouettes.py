"""Real object silhouettes for the comparison study: cell outlines, mosquito wings and
scikit-image's horse.

Sources and licences
--------------------
* **Cells.** Outlines of mouse osteosarcoma cells (two cell lines, ``dlm8`` and ``dunn``, each
  under three treatments, ``control``, ``cytd`` and ``jasp``; 650 outlines) from geomstats
  (``geomstats/datasets/data/cells/cells.txt`` with ``cell_lines.txt`` and ``treatments.txt``,
  MIT licence, copyright 2018 Nina Miolane). The 133 outlines that pass the selection rule's
  steps 1 to 4 are shipped with this package, unchanged (integer source pixels), in
  ``experiments/data/cells.npz`` with the licence notice ``experiments/data/LICENSE-geomstats.md``;
  :func:`write_cell_data` regenerates the file from geomstats' text files (geomstats is not a
  dependency).
* **Wings.** Outlines of 126 mosquito wings (11 genera, coded ``AE``, ``CX``, ``PS``, ...; 100
  points each, in a common normalised frame) from ktch 0.11.1 (``ktch/datasets/data/
  outline_mosquito_wings``, Apache License 2.0, Koji Noshita), shipped unchanged in
  ``experiments/data/wings.npz`` with the licence ``experiments/data/LICENSE-ktch.md``;
  :func:`write_wing_data` regenerates it from ktch's CSV files (ktch is not a dependency). Each
  outline is interpolated by a periodic cubic spline through its 100 points (:data:`WING_POINTS`
  points; a wing's margin is smooth, and its polygon's vertices would otherwise read as corners).
  Selection (:func:`select_wings`): the valid, not thin outlines (steps 2 and 4 below), shared
  among the genera in decreasing order of size as in step 5, ranked by solidity within a genus.
* **Horse.** scikit-image's ``skimage.data.horse()`` (bundled with scikit-image, offline; BSD
  licence), a binary silhouette; its outline is the mask's outer pixel contour
  (:func:`cv2.findContours`), resampled and smoothed like the cells' (Gaussian of 1 pixel).

Selection rule (deterministic)
------------------------------
1. Parse every cell; drop repeated consecutive points and a repeated closing point.
2. Keep the **valid** ones: a simple polygon (shapely ``is_valid``: no self-intersection), at least
   40 vertices, bounding box at least :data:`MIN_EXTENT` pixels in both directions (smaller cells
   are magnified so much that their pixel staircase dominates).
3. Smooth (:func:`smooth_outline`): resample by arc length at 1 source pixel, periodic Gaussian of
   :data:`SMOOTHING` source pixels (removes the digitisation staircase, keeps the shape), keep
   every second point; drop the cell if the smoothed outline is not a simple polygon.
4. Drop **degenerate** shapes, those with filaments thinner than a finger could touch or a camera
   resolve: normalised to a unit bounding circle, the outline eroded by :data:`THIN` must stay in
   one piece and its opening (erosion then dilation by :data:`THIN`) must keep at least 90 % of
   the area (at the rendered scale, no part thinner than about 7 pixels).
5. Share the ``n`` cells among the six (cell line, treatment) groups, one at a time round the
   groups in a fixed order while a group has cells left; within a group, sort by **solidity**
   (area over convex-hull area, a measure of concavity) and take its share at evenly spaced ranks,
   from the least to the most solid. The subset therefore spans both cell lines, the three
   treatments and convex to strongly concave shapes.

Rendering
---------
Each outline is normalised to a unit minimum bounding circle (:func:`qualgrasp.qualitative.objects.normalise`)
and drawn like the built-in objects (:func:`qualgrasp.qualitative.objects.render_polygon`: anti-aliased,
dark object ``FOREGROUND`` on a light background ``BACKGROUND``), in a 512 x 512 image, its minimum
bounding circle of radius ``RADIUS * 512`` (about 108 pixels) centred in the image (the fraction
used for the built-ins, :data:`qualgrasp.qualitative.objects.RADIUS`).
"""

from __future__ import annotations

from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import cv2
import numpy as np
import shapely
from qualgrasp.certify.files import atomic_output
from qualgrasp.qualitative.objects import normalise, place, render_polygon
from scipy import ndimage
from scipy.interpolate import splev, splprep
from shapely.geometry import Polygon
from skimage import data

__all__ = ["MIN_EXTENT", "THIN", "SMOOTHING", "SIZE", "WING_POINTS", "Silhouette", "available_silhouettes",
           "available_wings", "parse_cells", "write_cell_data", "read_cells", "smooth_outline", "select_cells",
           "parse_wings", "write_wing_data", "read_wings", "wing_outline", "select_wings", "horse", "silhouettes",
           "write_silhouettes"]

MIN_EXTENT = 50
"""Smallest bounding-box side of a kept cell outline, source pixels."""

THIN = 0.03
"""Half the thinnest part a kept outline may have, fraction of its bounding-circle radius."""

SMOOTHING = 1.5
"""Standard deviation of the Gaussian smoothing of outlines, source pixels."""

SIZE = 512
"""Side of the rendered images, pixels."""

WING_POINTS = 400
"""Points of a wing outline after spline interpolation."""

_GROUPS = (("dlm8", "control"), ("dlm8", "cytd"), ("dlm8", "jasp"),
           ("dunn", "control"), ("dunn", "cytd"), ("dunn", "jasp"))


@dataclass(frozen=True, eq=False)
class Silhouette:
    """A real outline, normalised, ready to be placed in an image.

    Attributes
    ----------
    name : str
        ``cell-NNN-<line>-<treatment>`` (``NNN`` the index in ``cells.txt``),
        ``wing-NNN-<genus>`` (``NNN`` the specimen) or ``horse``.
    template : shapely.geometry.Polygon
        The outline with a unit minimum bounding circle centred at the origin, positively oriented
        (:func:`qualgrasp.qualitative.objects.normalise`); :func:`qualgrasp.qualitative.objects.place` puts it into an
        image.
    source : str
        Where it comes from (package and file).
    solidity : float
        Area over convex-hull area.
    kind : str
        What the object is: ``cell``, ``wing`` or ``animal``.
    """

    name: str
    template: Polygon
    source: str
    solidity: float
    kind: str = "cell"

    def polygon(self, size: int = SIZE, rotation: float = 0.0,
                offset: tuple[float, float] = (0.0, 0.0)) -> Polygon:
        """Exact geometry in pixels of a ``size`` image (see :func:`qualgrasp.qualitative.objects.place`)."""
        return place(self.template, size, rotation, 1.0, offset)

    def image(self, size: int = SIZE, rotation: float = 0.0, offset: tuple[float, float] = (0.0, 0.0),
              noise: float = 0.0, seed: int = 0) -> np.ndarray:
        """``(size, size)`` uint8 synthetic camera image (:func:`qualgrasp.qualitative.objects.render_polygon`)."""
        return render_polygon(self.polygon(size, rotation, offset), size, noise=noise, seed=seed)


def _data(name: str):
    """A file shipped in ``qualgrasp/experiments/data``."""
    return resources.files("qualgrasp.experiments") / "data" / name


def parse_cells(folder: str | Path) -> list[tuple[np.ndarray, str, str]]:
    """Every cell outline of geomstats' text files in ``folder`` (``cells.txt``,
    ``cell_lines.txt``, ``treatments.txt``): ``(m, 2)`` integer source pixels (repeated
    consecutive and closing points removed), cell line and treatment, in file order."""
    folder = Path(folder)
    lines_of = lambda name: [v.strip() for v in (folder / name).read_text().split("\n") if v.strip()]  # noqa: E731
    blocks = [b for b in (folder / "cells.txt").read_text().split("\n\n") if b.strip()]
    out = []
    for block, line, treatment in zip(blocks, lines_of("cell_lines.txt"), lines_of("treatments.txt")):
        xy = np.array([[float(v) for v in row.split()] for row in block.strip().split("\n")])
        keep = np.any(xy != np.roll(xy, -1, axis=0), axis=1)  # drops repeats and the closing point
        out.append((xy[keep], line, treatment))
    return out


def write_cell_data(folder: str | Path, path: str | Path) -> int:
    """Write the cells that pass the selection rule's steps 1 to 4 (from geomstats' text files in
    ``folder``, see :func:`parse_cells`) to ``path`` (``.npz``: ``xy`` all points (int16),
    ``offsets``, ``index`` in ``cells.txt``, ``line``, ``treatment``); return how many."""
    kept = [(i, xy, line, treatment) for i, (xy, line, treatment) in enumerate(parse_cells(folder))
            if _passes(xy)]
    np.savez_compressed(
        path, xy=np.concatenate([xy for _, xy, _, _ in kept]).astype(np.int16),
        offsets=np.cumsum([0] + [len(xy) for _, xy, _, _ in kept]),
        index=np.array([i for i, *_ in kept]), line=np.array([v for _, _, v, _ in kept]),
        treatment=np.array([v for *_, v in kept]))
    return len(kept)


def read_cells() -> list[tuple[int, np.ndarray, str, str]]:
    """The shipped cell outlines: ``(index in cells.txt, (m, 2) float outline in source pixels,
    cell line, treatment)``, in file order."""
    with _data("cells.npz").open("rb") as fh, np.load(fh) as d:
        xy, offsets = d["xy"].astype(np.float64), d["offsets"]
        return [(int(i), xy[a:b], str(line), str(treatment)) for i, a, b, line, treatment
                in zip(d["index"], offsets[:-1], offsets[1:], d["line"], d["treatment"])]


def smooth_outline(xy: np.ndarray, sigma: float = SMOOTHING) -> np.ndarray:
    """Resample a closed outline at unit arc length and smooth it with a periodic Gaussian.

    Parameters
    ----------
    xy : numpy.ndarray
        ``(m, 2)`` closed outline, closing point not repeated, source pixels.
    sigma : float
        Standard deviation of the Gaussian, source pixels.

    Returns
    -------
    numpy.ndarray
        ``(k, 2)`` smoothed outline, one point every 2 source pixels.
    """
    closed = np.vstack([xy, xy[:1]])
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(closed, axis=0), axis=1))])
    t = np.arange(0.0, s[-1], 1.0)
    points = np.column_stack([np.interp(t, s, closed[:, 0]), np.interp(t, s, closed[:, 1])])
    return ndimage.gaussian_filter1d(points, sigma, axis=0, mode="wrap")[::2]


def _solidity(poly: Polygon) -> float:
    return float(poly.area / poly.convex_hull.area)


def _passes(xy: np.ndarray) -> bool:
    """Rule steps 1 to 4 on a raw outline (source pixels)."""
    extent = np.ptp(xy, axis=0) if len(xy) else np.zeros(2)
    if len(xy) < 40 or extent.min() < MIN_EXTENT or not Polygon(xy).is_valid:
        return False
    poly = Polygon(smooth_outline(xy))
    return poly.is_valid and not _thin(normalise(poly))


def _valid_cells() -> dict[tuple[str, str], list[tuple[int, Polygon]]]:
    """Kept cells (rule steps 1 to 4) per (cell line, treatment), as smoothed polygons."""
    groups: dict[tuple[str, str], list[tuple[int, Polygon]]] = {g: [] for g in _GROUPS}
    for index, xy, line, treatment in read_cells():
        if (line, treatment) in groups and _passes(xy):
            groups[(line, treatment)].append((index, Polygon(smooth_outline(xy))))
    return groups


def _thin(template: Polygon) -> bool:
    """True when a unit template has parts thinner than ``2 * THIN`` (rule step 4)."""
    eroded = template.buffer(-THIN)
    pieces = len(getattr(eroded, "geoms", [eroded]))
    return pieces != 1 or eroded.buffer(THIN).area < 0.9 * template.area


def select_cells(n: int = 24) -> list[Silhouette]:
    """A deterministic, varied subset of ``n`` cell outlines (module notes, selection rule).

    Raises
    ------
    ValueError
        Fewer than ``n`` cells pass the rule.
    """
    groups = _valid_cells()
    total = sum(len(v) for v in groups.values())
    if total < n:
        raise ValueError(f"only {total} cells pass the selection rule, {n} asked for")
    share = dict.fromkeys(_GROUPS, 0)
    while sum(share.values()) < n:
        for g in _GROUPS:
            if share[g] < len(groups[g]) and sum(share.values()) < n:
                share[g] += 1
    chosen = []
    for g in _GROUPS:
        ranked = sorted(groups[g], key=lambda item: _solidity(item[1]))
        picks = np.round(np.linspace(0, len(ranked) - 1, share[g])).astype(int) if share[g] else []
        for k in picks:
            index, poly = ranked[k]
            chosen.append(Silhouette(f"cell-{index:03d}-{g[0]}-{g[1]}", normalise(poly),
                                     "geomstats cells.txt, shipped as experiments/data/cells.npz (MIT)",
                                     _solidity(poly)))
    return chosen


def horse() -> Silhouette:
    """scikit-image's horse silhouette (bundled, offline), its outline smoothed like the cells'."""

    mask = ~data.horse()  # True on the horse
    found, _ = cv2.findContours(mask.astype(np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    xy = max(found, key=len)[:, 0, :].astype(np.float64)
    poly = Polygon(smooth_outline(xy, 1.0))
    if not poly.is_valid:  # keep the largest simple piece
        poly = max(getattr(shapely.make_valid(poly), "geoms", []), key=lambda g: g.area)
    return Silhouette("horse", normalise(poly), "skimage.data.horse (BSD-3-Clause)", _solidity(poly), "animal")


def parse_wings(folder: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """ktch's mosquito wing outlines in ``folder`` (``data_outline_mosquito_wings.csv``: columns
    specimen_id, coord_id, x, y; ``meta_outline_mosquito_wings.csv``: specimen_id, genus):
    ``(126, 100, 2)`` outlines and the genus code of each specimen.

    Raises
    ------
    ValueError
        The files do not have that layout.
    """
    folder = Path(folder)
    rows = np.loadtxt(folder / "data_outline_mosquito_wings.csv", delimiter=",", skiprows=1)
    specimens = np.unique(rows[:, 0]).astype(int)
    points = len(rows) // len(specimens)
    if len(rows) != len(specimens) * points or not (rows[:, 0].reshape(-1, points) == specimens[:, None]).all():
        raise ValueError(f"{folder}: rows are not {points} points per specimen, in order")
    meta = [line.split(",") for line in (folder / "meta_outline_mosquito_wings.csv").read_text().split("\n")[1:]
            if line.strip()]
    genus = {int(k): g.strip() for k, g in meta}
    return rows[:, 2:4].reshape(len(specimens), points, 2), np.array([genus[int(k)] for k in specimens])


def write_wing_data(folder: str | Path, path: str | Path) -> int:
    """Write ktch's wing outlines (:func:`parse_wings`) to ``path`` (``.npz``: ``outlines``
    float32, ``genus``), as shipped; return how many."""
    outlines, genus = parse_wings(folder)
    np.savez_compressed(path, outlines=outlines.astype(np.float32), genus=genus)
    return len(outlines)


def read_wings() -> list[tuple[int, np.ndarray, str]]:
    """The shipped wing outlines: ``(specimen, (100, 2) float outline, genus)``, in order."""
    with _data("wings.npz").open("rb") as fh, np.load(fh) as d:
        return [(k, xy.astype(np.float64), str(g)) for k, (xy, g) in enumerate(zip(d["outlines"], d["genus"]))]


def wing_outline(xy: np.ndarray, points: int = WING_POINTS) -> np.ndarray:
    """A closed outline through the points ``xy`` (``(m, 2)``, closing point not repeated):
    periodic cubic spline interpolation, ``points`` points evenly spaced in the spline's
    parameter."""
    tck, _ = splprep([xy[:, 0], xy[:, 1]], s=0, per=True)
    x, y = splev(np.linspace(0.0, 1.0, points, endpoint=False), tck)
    return np.column_stack([x, y])


def _valid_wings() -> dict[str, list[tuple[int, Polygon]]]:
    """Kept wings (valid, not thin) per genus, as polygons."""
    groups: dict[str, list[tuple[int, Polygon]]] = {}
    for k, xy, genus in read_wings():
        poly = Polygon(wing_outline(xy))
        if poly.is_valid and not _thin(normalise(poly)):
            groups.setdefault(genus, []).append((k, poly))
    return groups


def available_wings() -> int:
    """How many wing outlines pass the selection rule."""
    return sum(len(v) for v in _valid_wings().values())


def select_wings(n: int = 36) -> list[Silhouette]:
    """A deterministic, varied subset of ``n`` wing outlines (module notes).

    Raises
    ------
    ValueError
        Fewer than ``n`` wings pass the rule.
    """
    groups = _valid_wings()
    order = sorted(groups, key=lambda g: (-len(groups[g]), g))  # larger genera first
    total = sum(len(v) for v in groups.values())
    if total < n:
        raise ValueError(f"only {total} wings pass the selection rule, {n} asked for")
    share = dict.fromkeys(order, 0)
    while sum(share.values()) < n:
        for g in order:
            if share[g] < len(groups[g]) and sum(share.values()) < n:
                share[g] += 1
    chosen = []
    for g in order:
        ranked = sorted(groups[g], key=lambda item: _solidity(item[1]))
        picks = np.round(np.linspace(0, len(ranked) - 1, share[g])).astype(int) if share[g] else []
        for k in picks:
            index, poly = ranked[k]
            chosen.append(Silhouette(f"wing-{index:03d}-{g.lower()}", normalise(poly),
                                     "ktch outline_mosquito_wings, shipped as experiments/data/wings.npz "
                                     "(Apache-2.0)", _solidity(poly), "wing"))
    return chosen


def available_silhouettes() -> int:
    """How many real silhouettes are bundled: the cells that pass the selection rule, and the
    horse (wings: :func:`available_wings`)."""
    return sum(len(v) for v in _valid_cells().values()) + 1


def silhouettes(n: int = 24, with_horse: bool = True, wings: int = 0) -> list[Silhouette]:
    """The study's real silhouettes: ``n`` cells (:func:`select_cells`), the horse and ``wings``
    mosquito wings (:func:`select_wings`). The study's real objects are ``silhouettes(24, True,
    36)``: 61 objects of three kinds."""
    return select_cells(n) + ([horse()] if with_horse else []) + (select_wings(wings) if wings else [])


def write_silhouettes(out_dir: str | Path, n: int = 24, *, with_horse: bool = True, wings: int = 0,
                      size: int = SIZE) -> list[Path]:
    """Render the silhouettes as PNG images (``<name>.png``) into ``out_dir``.

    Parameters
    ----------
    out_dir : str or pathlib.Path
        Folder, created if needed.
    n : int
        Number of cells.
    with_horse : bool
        Also write ``horse.png``.
    wings : int
        Number of mosquito wings.
    size : int
        Image side, pixels.

    Returns
    -------
    list of pathlib.Path
        The files written: cells, the horse, wings.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for item in silhouettes(n, with_horse, wings):
        path = out / f"{item.name}.png"
        ok, png = cv2.imencode(".png", item.image(size))
        if not ok:
            raise OSError(f"cannot encode {path}")
        with atomic_output(path, "--out") as tmp:
            tmp.write_bytes(png.tobytes())
        paths.append(path)
    return paths

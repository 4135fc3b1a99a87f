"""The qualitative-versus-quantitative study: silhouettes, baseline, execution, robustness, tables."""

import csv
import subprocess
import sys
from itertools import combinations

import cv2
import numpy as np
import pytest
import shapely
from shapely.geometry import Polygon

from qualgrasp.certify import Contact, Grasp, certify_grasp
from qualgrasp.certify.quality import epsilon
from qualgrasp.experiments.baseline import Boundary, Budget, baseline, boundary, boundary_of_polygon, search
from qualgrasp.experiments.silhouettes import horse, select_cells, write_silhouettes
from qualgrasp.experiments.study import (GRASP_COLUMNS, OBJECT_COLUMNS, OVERALL_COLUMNS, ROBUSTNESS_COLUMNS,
                                         ROUTES, Settings, compare, execute, perturb, robustness_trial,
                                         subjects)
from qualgrasp.qualitative.objects import render, render_polygon, shape
from qualgrasp.qualitative.synthesis.pipeline import synthesize
from qualgrasp.qualitative.vision.contour import extract_contour, segment

TINY = Budget(samples=48, extend=8, random=300, starts=3, rounds=2, keep=3)


@pytest.fixture(scope="module")
def cells():
    return select_cells(24)


@pytest.fixture(scope="module")
def polygon_image():
    return render("polygon")


# --- silhouettes ----------------------------------------------------------------------------------


def test_silhouettes_are_valid_varied_and_deterministic(cells):
    assert len(cells) == 24
    assert len({c.name for c in cells}) == 24
    for c in cells + [horse()]:
        poly = c.template
        assert poly.is_valid and poly.geom_type == "Polygon"
        assert shapely.minimum_bounding_radius(poly.exterior) == pytest.approx(1.0)
        x, y = np.asarray(poly.exterior.coords).T
        assert np.sum(x[:-1] * y[1:] - x[1:] * y[:-1]) > 0  # the project's orientation
        assert 0.3 < c.solidity <= 1.0
    groups = {tuple(c.name.split("-")[2:]) for c in cells}
    assert len(groups) == 6  # both cell lines, three treatments
    assert max(c.solidity for c in cells) - min(c.solidity for c in cells) > 0.2
    assert [c.name for c in select_cells(24)] == [c.name for c in cells]


def test_cells_are_read_without_importing_geomstats():
    code = ("import sys; from experiments.silhouettes import select_cells; "
            "assert len(select_cells(6)) == 6; assert 'geomstats' not in sys.modules")
    subprocess.run([sys.executable, "-c", code], check=True)


def test_written_silhouettes_are_seen_as_their_polygon(tmp_path):
    paths = write_silhouettes(tmp_path, n=2, with_horse=False)
    chosen = select_cells(2)
    assert [p.name for p in paths] == [f"{c.name}.png" for c in chosen]
    for path, cell in zip(paths, chosen):
        image = cv2.imread(str(path), cv2.IMREAD_GRAYSCALE)
        assert image.shape == (512, 512)
        contour = extract_contour(image)
        seen = Polygon(contour)
        truth = cell.polygon()
        assert seen.symmetric_difference(truth).area < 0.01 * truth.area


def test_render_polygon_is_render_of_the_shape():
    for name in ("polygon", "nut"):
        assert np.array_equal(render(name, rotation=17, noise=3, seed=4),
                              render_polygon(shape(name, rotation=17), noise=3, seed=4))


# --- baseline -------------------------------------------------------------------------------------


@pytest.mark.parametrize("fingers", [2, 3, 4])
def test_baseline_best_grasps_certify(polygon_image, fingers):
    result = baseline(polygon_image, fingers, 0.5, TINY)
    assert 1 <= len(result.grasps) <= TINY.keep
    assert all(result.certified)
    assert list(result.epsilons) == sorted(result.epsilons, reverse=True)
    assert result.epsilons == pytest.approx(result.screened, abs=1e-12)
    g = result.grasps[0]
    assert g.center == pytest.approx(tuple(result.boundary.center)) and g.length == result.boundary.length
    assert all(c.model == ("frictionless" if fingers == 4 else "point") for c in g.contacts)


def test_two_finger_search_is_exhaustive_by_brute_force():
    """The search's best pair equals the best pair found by certifying every pair one by one."""
    b = boundary(render("figure3"))
    pick = np.arange(20) * 1024 // 20
    points, normals = b.points[pick], b.normals[pick]
    idx, eps, evaluated = search(points, normals, 2, 0.5, b.center, b.length, Budget(keep=1))
    assert evaluated == 20 * 19 // 2
    best = 0.0
    for i, j in combinations(range(20), 2):
        g = Grasp((Contact(points[i], normals[i], "point", 0.5), Contact(points[j], normals[j], "point", 0.5)),
                  center=tuple(b.center), length=b.length)
        r = certify_grasp(g)
        if r.force.status == "closure" and r.verified:
            best = max(best, r.epsilons["L1"].hi)
    assert eps[0] == pytest.approx(best, abs=1e-12)


def test_baseline_beats_a_qualitative_grasp_on_a_shared_contact_set(polygon_image):
    """With the qualitative pair added to the sampled contacts, the exhaustive pair search finds at
    least its epsilon (same center and length)."""
    s = synthesize(polygon_image, 2, name="polygon")
    q = s.grasps[0]
    b = boundary(polygon_image)
    pick = np.arange(0, 1024, 16)
    points = np.vstack([b.points[pick], q.points])
    normals = np.vstack([b.normals[pick], q.normals])
    idx, eps, _ = search(points, normals, 2, 0.5, s.center, s.length, Budget(keep=1))
    assert eps[0] >= epsilon(q, "L1").hi - 1e-12


# --- execution on the true object -------------------------------------------------------------------


def _square_truth(half=50.0, center=(100.0, 100.0), per_side=200) -> Boundary:
    c = np.array(center)
    corners = c + half * np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]])
    inward = np.array([[0, 1], [-1, 0], [0, -1], [1, 0]], dtype=float)  # y down, positive area
    s = np.linspace(0, 1, per_side, endpoint=False)[:, None]
    points = np.vstack([a + s * (b - a) for a, b in zip(corners, np.roll(corners, -1, axis=0))])
    normals = np.repeat(inward, per_side, axis=0)
    return Boundary(points, normals, c, half * np.sqrt(2), 2 * half * np.sqrt(2))


def test_execution_maps_contacts_to_the_square_by_hand():
    truth = _square_truth()
    # top edge y = 50 (inward normal +y): a finger planned 3 px too high lands on the edge
    planned = Grasp((Contact((120.0, 47.0), (0.0, 1.0)), Contact((80.0, 152.0), (0.0, -1.0))))
    done, outcome = execute(planned, truth, standoff=0.1)
    assert outcome == "contact"
    assert done.points == pytest.approx(np.array([[120.0, 50.0], [80.0, 150.0]]), abs=1e-9)
    assert done.normals == pytest.approx(np.array([[0.0, 1.0], [0.0, -1.0]]), abs=1e-9)
    assert done.center == (100.0, 100.0) and done.length == pytest.approx(50 * np.sqrt(2))
    # a tilted approach meets the left edge x = 50 where its line does, with the edge's normal
    d = np.array([1.0, 0.5]) / np.hypot(1.0, 0.5)
    done, _ = execute(Grasp((Contact((40.0, 95.0), tuple(d)),)), truth, standoff=0.1)
    assert done.points[0] == pytest.approx([50.0, 100.0], abs=1e-9)
    assert done.normals[0] == pytest.approx([1.0, 0.0], abs=1e-9)
    # a finger beside the object misses it; one that starts inside it collides
    assert execute(Grasp((Contact((170.0, 30.0), (0.0, 1.0)),)), truth)[1] == "miss"
    assert execute(Grasp((Contact((100.0, 100.0), (1.0, 0.0)),)), truth)[1] == "collision"


@pytest.mark.parametrize("name", ["disc", "figure3"])
def test_contacts_on_the_true_contour_stay_put(name):
    """A contact planned at any vertex of the true contour, with its normal, lands on itself (rays
    through a vertex meet its edges despite rounding)."""
    truth = boundary(render(name, rotation=13))
    for p, n in zip(truth.points[::3], truth.normals[::3]):
        done, outcome = execute(Grasp((Contact(tuple(p), tuple(n)),)), truth, perceived=truth.points)
        assert outcome == "contact"
        assert done.points[0] == pytest.approx(p, abs=1e-6)
        assert done.normals[0] == pytest.approx(n, abs=1e-6)


def test_execution_on_the_perceived_disc():
    image = render("disc")
    truth = boundary(image)
    radius = 0.21 * 512
    c = np.array([255.5, 255.5])
    for angle in np.radians([0, 37, 90, 200]):
        u = np.array([np.cos(angle), np.sin(angle)])
        done, outcome = execute(Grasp((Contact(tuple(c + (radius + 4) * u), tuple(-u)),)), truth)
        assert outcome == "contact"
        assert np.linalg.norm(done.points[0] - (c + radius * u)) < 0.1
        assert done.normals[0] == pytest.approx(-u, abs=0.01)


def test_exact_boundary_of_a_polygon():
    """Every vertex kept, points on the exterior, normals of the edges pointing in (a vertex: the
    bisector), whatever the polygon's orientation; the perceived boundary lies within a tenth of
    a pixel of it in the median."""
    poly = shape("polygon")
    for ring in (poly, Polygon(list(poly.exterior.coords)[::-1])):
        b = boundary_of_polygon(ring)
        on = shapely.distance(poly.exterior, shapely.points(b.points))
        assert on.max() < 1e-9
        assert shapely.distance(shapely.points(np.asarray(poly.exterior.coords)), shapely.MultiPoint(b.points)).max() < 1e-9
        inside = shapely.contains_xy(poly, *(b.points + 0.05 * b.normals).T)
        assert inside.all() and np.allclose(np.linalg.norm(b.normals, axis=1), 1.0)
        gaps = np.linalg.norm(np.diff(b.points, axis=0), axis=1)
        assert gaps.max() <= 0.25 + 1e-9
    seen = boundary(render("polygon"))
    assert np.median(shapely.distance(poly.exterior, shapely.points(seen.points))) < 0.1


def test_subjects_of_known_geometry_are_executed_on_it(cells):
    subject, = subjects([cells[0]])
    assert subject.geometry.equals(cells[0].polygon())
    assert subjects(["nut"])[0].geometry.equals(Polygon(shape("nut").exterior))  # fingers stay outside
    assert subjects([("x", render("nut"))])[0].geometry is None
    # the qualitative grasps of the polygon hold on its exact geometry, sharp corners and all
    subject = subjects(["polygon"])[0]
    rows = robustness_trial(subject, boundary_of_polygon(subject.geometry), segment(subject.image).level,
                            "none", 0.0, 0, Settings(budget=TINY, workers=1))
    qualitative = [r for r in rows if r["method"] == "qualitative"]
    assert all(r["held"] == r["planned"] > 0 for r in qualitative), qualitative


# --- perturbations and robustness ---------------------------------------------------------------


def test_perturbations():
    image = render("polygon")
    rng = np.random.default_rng(0)
    level = segment(image).level
    c = np.array([255.5, 255.5])
    assert perturb(image, "none", 0.0, rng, c, level)[0] is image
    assert perturb(image, "threshold", -30.0, rng, c, level) == (image, level - 30.0)
    moved, thr = perturb(image, "translation", 5.0, rng, c, level)
    a, b = Polygon(extract_contour(image)).centroid, Polygon(extract_contour(moved)).centroid
    assert thr is None and np.hypot(b.x - a.x, b.y - a.y) == pytest.approx(5.0, abs=0.1)
    turned, _ = perturb(image, "rotation", 90.0, rng, c, level)
    assert Polygon(extract_contour(turned)).symmetric_difference(
        shape("polygon", rotation=90)).area < 0.01 * shape("polygon").area
    noisy, _ = perturb(image, "noise", 20.0, rng, c, level)
    assert 15 < np.std(noisy.astype(float) - image) < 25
    with pytest.raises(ValueError):
        perturb(image, "shear", 1.0, rng, c, level)


@pytest.mark.parametrize("name", ["polygon", "disc"])
def test_zero_perturbation_keeps_every_certified_grasp(name):
    subject = subjects([name])[0]
    truth = boundary(subject.image)
    rows = robustness_trial(subject, truth, segment(subject.image).level, "none", 0.0, 0,
                            Settings(budget=TINY, workers=1))
    assert {r["route"] for r in rows} == {f"{m} {f}" for m, f in ROUTES}
    for r in rows:
        assert r["held"] == r["planned"] and r["misses"] == r["collisions"] == 0, r["route"]
        assert r["eps_executed"] == pytest.approx(r["eps_planned"], rel=0.02, abs=1e-3)
    assert sum(r["planned"] for r in rows) > (5 if name == "disc" else 10)
    if name == "disc":  # a frictionless closure of the disc's pixel polygon is not planned, but counted as such
        four = next(r for r in rows if r["route"] == "Baseline 4")
        assert four["planned"] == 0 and four["below_resolution"] > 0


# --- the study's tables ---------------------------------------------------------------------------


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    out = tmp_path_factory.mktemp("study")
    settings = Settings(budget=TINY, sizes=(("rotation", (4.0,)), ("threshold", (40.0,))), trials=1,
                        workers=1)
    return out, compare(["square"], out, settings=settings)


def _header(path):
    with path.open() as fh:
        return tuple(next(csv.reader(fh)))


def test_tables_have_the_documented_columns(study):
    out, result = study
    assert _header(out / "objects.csv") == OBJECT_COLUMNS
    assert _header(out / "overall.csv") == OVERALL_COLUMNS
    assert _header(out / "robustness.csv") == ROBUSTNESS_COLUMNS
    assert _header(out / "grasps.csv") == GRASP_COLUMNS
    for stem, columns in (("objects", OBJECT_COLUMNS), ("overall", OVERALL_COLUMNS),
                          ("robustness", ROBUSTNESS_COLUMNS)):
        lines = (out / f"{stem}.md").read_text().splitlines()
        assert "| " + " | ".join(columns) + " |" in lines
    with (out / "robustness.csv").open() as fh:
        kinds = {(row["kind"], row["size"]) for row in csv.DictReader(fh)}
    assert kinds == {("none", "0"), ("rotation", "4"), ("threshold", "40")}


def test_study_result_and_files(study):
    out, result = study
    assert result.objects == ("square",)
    assert [r.route for r in result.routes] == [f"{m} {f}" for m, f in ROUTES]
    for r in result.routes:
        assert r.grasps == 0 or r.certified_fraction == 1.0
        if r.route.startswith("Baseline"):
            assert r.eps_best > 0 and r.ratio_best is None
    by_route = {r.route: r for r in result.routes}
    for route in ("ForceGrasp 2", "FormGrasp 4"):  # the square has no ForceGrasp triplet
        assert 0 < by_route[route].ratio_best <= 1.2
    names = {p.name for p in result.files}
    for stem in ("study-epsilon", "study-quality-time", "study-robustness", "study-tolerance"):
        assert {f"{stem}.png", f"{stem}.pdf"} <= names
    assert all(p.is_file() and p.stat().st_size > 0 for p in result.files)
    assert set(result.robustness) == {(r.route, k) for r in result.routes
                                      for k in ("rotation", "translation", "noise", "blur", "threshold")}


# --- command line ---------------------------------------------------------------------------------


def test_silhouettes_and_compare_commands(tmp_path):
    from typer.testing import CliRunner

    from qualgrasp.cli import app

    runner = CliRunner()
    result = runner.invoke(app, ["silhouettes", "--out", str(tmp_path / "sil"), "--n", "2", "--no-horse"])
    assert result.exit_code == 0, result.output
    assert len(list((tmp_path / "sil").glob("*.png"))) == 2
    result = runner.invoke(app, ["compare", "--out", str(tmp_path / "cmp")])
    assert result.exit_code == 2 and "no images" in result.output
    result = runner.invoke(app, ["compare", str(tmp_path / "sil"), "--setting", "huge"])
    assert result.exit_code == 2


def test_route_names_are_unique_and_baselines_one_per_contact_pattern():
    """Two procedures with three point contacts (forcegrasp3, pairgrasp3) share one baseline."""
    from qualgrasp.experiments.design import routes
    names = [r.name for r in routes()]
    assert len(names) == len(set(names))
    patterns = [(r.fingers, r.procedure.model) for r in routes() if r.method == "baseline"]
    assert len(patterns) == len(set(patterns))


def test_every_qualitative_route_is_compared_with_the_baseline_of_its_contacts():
    """PairGrasp 3 has no baseline of its own: its ratios, paired robustness and plot panels use
    Baseline 3 (its rows carry forcegrasp3), and Baseline 3's paired robustness ForceGrasp 3's."""
    from qualgrasp.experiments.design import compared_procedure, routes
    from qualgrasp.experiments.study import _with_ratios
    from qualgrasp.experiments.study_tables import overall_rows, partner
    from qualgrasp.qualitative.synthesis import procedures
    assert compared_procedure(procedures.get("pairgrasp3"), "baseline").name == "forcegrasp3"
    assert compared_procedure(procedures.get("pairgrasp3"), "qualitative").name == "pairgrasp3"
    by_name = {r.name: r for r in routes()}
    assert partner(by_name["PairGrasp 3"]) == "Baseline 3" == partner(by_name["ForceGrasp 3"])
    assert partner(by_name["Baseline 3"]) == "ForceGrasp 3"
    rows = [{"method": "baseline", "procedure": "forcegrasp3", "eps_best": 0.4},
            {"method": "qualitative", "procedure": "pairgrasp3", "eps_best": 0.1, "eps_median": 0.05}]
    assert _with_ratios(rows)[1]["ratio_best"] == pytest.approx(0.25)
    trial = {"object": "o", "kind": "rotation", "size": 8.0, "trial": 0, "planned": 1}
    trials = [dict(trial, route="PairGrasp 3", held=1), dict(trial, route="Baseline 3", held=0),
              dict(trial, route="PairGrasp 3", trial=1, held=0)]  # the baseline planned nothing here
    pair = next(r for r in overall_rows([], [], trials) if r["route"] == "PairGrasp 3")
    assert pair["robustness"] == 0.5 and pair["robustness_paired"] == 1.0

"""Synthesis end to end: image -> grasps in certify's format -> certified; the command and the plots."""

import json
import math

import cv2
import numpy as np
import pytest
import shapely
from matplotlib.figure import Figure
from skimage import data
from typer.testing import CliRunner

from qualgrasp.certify import grasp_from_dict
from qualgrasp.certify.files import read_results
from qualgrasp.cli import app
from qualgrasp.qualitative.synthesis.candidates import object_frame
from qualgrasp.qualitative.errors import QualitativeError, SynthesisError
from qualgrasp.qualitative.plots.grasp import plot_grasp, synthesis_figure
from qualgrasp.qualitative.objects import render, shape
from qualgrasp.qualitative.synthesis.pipeline import synthesize

runner = CliRunner()
OBJECTS = ("polygon", "nut", "figure3", "disc")


@pytest.fixture(scope="module")
def results():
    """Every procedure on the four objects of the paper (mu = 0.5 for ForceGrasp). Without the
    certified tolerance (nine tenths of the time here): test_tolerance and test_extents check it on
    these objects."""
    return {(name, fingers): synthesize(render(name), fingers, name=name, tolerance=False)
            for name in OBJECTS for fingers in (2, 3, 4)}


@pytest.mark.parametrize("name", OBJECTS)
@pytest.mark.parametrize("fingers", [2, 3, 4])
def test_expected_grasps_all_certified(results, name, fingers):
    s = results[(name, fingers)]
    if fingers == 4 and name == "disc":
        assert s.grasps == () and s.certified_fraction is None  # a disc cannot be immobilised
        return
    assert len(s.grasps) >= 1
    assert s.certified_fraction == 1.0
    for report in s.reports:
        assert report.force.status == "closure" and report.verified
        assert report.epsilons["L1"].hi > 0


@pytest.mark.parametrize("name", OBJECTS)
def test_grasp_format(results, name):
    poly = shape(name)
    exterior = shapely.Polygon(poly.exterior)
    for fingers in (2, 3, 4):
        s = results[(name, fingers)]
        center, radius = object_frame(s.outline.contour)
        for k, (g, found) in enumerate(zip(s.grasps, s.found)):
            tag = {2: "force2", 3: "force3", 4: "form"}[fingers]
            assert g.id == f"{name}-{tag}-{k:04d}"
            assert g.meta["procedure"] == ("FormGrasp" if fingers == 4 else "ForceGrasp")
            assert g.meta["regions"] == list(found.regions)
            assert all(0 <= r < len(s.regions) for r in g.meta["regions"])
            assert len(g.contacts) == fingers
            np.testing.assert_allclose(g.center, center)
            assert g.length == pytest.approx(radius)
            for c in g.contacts:
                assert c.model == ("frictionless" if fingers == 4 else "point")
                assert c.mu == (0.0 if fingers == 4 else 0.5)
                p, n = np.array(c.p), np.array(c.n)
                assert exterior.exterior.distance(shapely.Point(p)) < 0.5  # on the boundary, pixels
                assert exterior.contains(shapely.Point(p + 2 * n))  # inward normal
            # the JSON line round-trips with its extra fields
            again = grasp_from_dict(json.loads(json.dumps(_dict(g))))
            assert again.meta["regions"] == g.meta["regions"] and again.contacts == g.contacts


def _dict(g):
    from qualgrasp.certify import grasp_to_dict

    return grasp_to_dict(g)


def test_center_and_length_are_the_objects(results):
    """Epsilons of FormGrasp and ForceGrasp grasps of one object use the same torque scaling."""
    frames = {tuple(g.center) + (g.length,) for f in (2, 3, 4) for g in results[("polygon", f)].grasps}
    assert len(frames) == 1
    c = np.array(shapely.Polygon(shape("polygon").exterior).centroid.coords[0])
    assert np.linalg.norm(np.array(next(iter(frames))[:2]) - c) < 0.5


def test_theta_min_is_atan_mu():
    a = synthesize(render("nut"), 2, mu=0.3, certify=False)
    b = synthesize(render("nut"), 2, theta_min=math.atan(0.3), certify=False)
    assert [g.contacts for g in a.grasps] == [g.contacts for g in b.grasps]
    assert a.mu == pytest.approx(0.3) and b.theta_min == pytest.approx(math.atan(0.3))
    low = synthesize(render("nut"), 2, mu=0.05, certify=False)  # 2.9 degree cones: only exact opposites
    assert len(low.grasps) <= len(a.grasps)


def test_horse():
    image = data.horse()
    for fingers in (2, 3, 4):
        s = synthesize(image, fingers, name="horse")
        assert s.grasps and s.certified_fraction == 1.0


def test_bad_parameters():
    image = render("square", size=200)
    for kwargs, message in [({"fingers": 5}, "fingers"), ({"fingers": 4, "mu": 0.5}, "frictionless"),
                            ({"fingers": 2, "mu": 0.5, "theta_min": 0.3}, "not both"),
                            ({"fingers": 3, "mu": -1.0}, "mu"), ({"fingers": 2, "alpha": -1.0}, "alpha")]:
        with pytest.raises(SynthesisError, match=message):
            synthesize(image, **kwargs)
    with pytest.raises(QualitativeError):
        synthesize(np.zeros((50, 50)), 2)


# ----------------------------------------------------------------------------------- command


@pytest.fixture(scope="module")
def images(tmp_path_factory):
    folder = tmp_path_factory.mktemp("synthesis")
    paths = {}
    for name in ("polygon", "disc"):
        paths[name] = folder / f"{name}.png"
        cv2.imwrite(str(paths[name]), render(name))
    return paths


@pytest.mark.parametrize("fingers", ["2", "3", "4"])
def test_command_output_certifies(images, tmp_path, fingers):
    grasps, results_path, plot = tmp_path / "g.jsonl", tmp_path / "r.jsonl", tmp_path / "p.png"
    # the certified tolerance of FormGrasp's 74 grasps takes 30 s; with two and three fingers it runs
    tolerance = ["--no-tolerance"] if fingers == "4" else []
    result = runner.invoke(app, ["synthesize", str(images["polygon"]), "--fingers", fingers,
                                 "-o", str(grasps), "--plot", str(plot), *tolerance])
    assert result.exit_code == 0, result.output
    lines = grasps.read_text().splitlines()
    assert lines and "100 % certified" in result.stdout
    first = json.loads(lines[0])
    assert first["id"] == f"polygon-{'form' if fingers == '4' else 'force' + fingers}-0000"
    assert {"regions", "procedure", "center", "length"} <= set(first)
    assert cv2.imread(str(plot)) is not None
    result = runner.invoke(app, ["certify", str(grasps), "-o", str(results_path), "--no-quality", "-q",
                                 "--workers", "1"])
    assert result.exit_code == 0, result.output
    rows = list(read_results(results_path))
    assert len(rows) == len(lines)
    assert all(r["status"] == "closure" and r["verified"] for r in rows)


def test_command_theta_min_in_degrees(images, tmp_path):
    out = tmp_path / "g.jsonl"
    result = runner.invoke(app, ["synthesize", str(images["polygon"]), "--fingers", "2", "--theta-min",
                                 "26.565051177", "-o", str(out)])
    assert result.exit_code == 0
    mu = [c["mu"] for line in out.read_text().splitlines() for c in json.loads(line)["contacts"]]
    assert mu and mu == pytest.approx([0.5] * len(mu), abs=1e-9)


def test_command_no_grasp_writes_an_empty_file(images, tmp_path):
    out = tmp_path / "g.jsonl"
    result = runner.invoke(app, ["synthesize", str(images["disc"]), "--fingers", "4", "-o", str(out),
                                 "--plot", str(tmp_path / "p.png")])
    assert result.exit_code == 0
    assert "no grasp found" in result.output
    assert out.exists() and out.read_text() == ""
    assert (tmp_path / "p.png").exists()
    result = runner.invoke(app, ["certify", str(out), "-o", str(tmp_path / "r.jsonl"), "-q"])
    assert result.exit_code == 0


@pytest.mark.parametrize("args, message", [
    (["--fingers", "5"], "fingers"),
    (["--fingers", "4", "--mu", "0.5"], "frictionless"),
    (["--fingers", "2", "--mu", "0.5", "--theta-min", "20"], "not both"),
    (["--fingers", "2", "--theta-min", "95"], "theta_min"),
])
def test_command_errors(images, tmp_path, args, message):
    result = runner.invoke(app, ["synthesize", str(images["polygon"]), *args, "-o", str(tmp_path / "g.jsonl")])
    assert result.exit_code == 2
    assert message in result.output


def test_command_missing_image(tmp_path):
    result = runner.invoke(app, ["synthesize", str(tmp_path / "none.png"), "--fingers", "2", "-o",
                                 str(tmp_path / "g.jsonl")])
    assert result.exit_code == 2 and "no such image file" in result.output


# ------------------------------------------------------------------------------------- plots


@pytest.mark.parametrize("fingers", [2, 3, 4])
def test_figures(results, fingers):
    s = results[("figure3", fingers)]
    fig = synthesis_figure(s, render("figure3"))
    fig.canvas.draw()
    axes = [ax for ax in fig.axes if ax.get_xlabel()]
    assert len(axes) >= min(len(s.grasps), 4)
    for ax in axes:
        bottom, top = ax.get_ylim()
        assert bottom > top and ax.get_aspect() == 1.0  # image frame: y down, equal aspect
    if fingers == 4:  # zones of freedom after each contact, ending empty
        titles = [ax.get_title() for ax in axes[:4]]
        assert "Z empty" in titles[3] and all("depth" in t for t in titles[:3])
        assert any(p.get_hatch() for ax in axes[:3] for p in ax.patches)
    else:  # one friction cone per finger, and the contacts
        ax = axes[0]
        assert sum(p.get_facecolor()[:3] == pytest.approx((1.0, 0.498, 0.055), abs=0.01)
                   for p in ax.patches) >= fingers


def test_figure_without_grasps(results):
    fig = synthesis_figure(results[("disc", 4)])
    assert "no grasp" in fig.axes[0].get_title()


def test_plot_grasp_on_given_axes(results):
    s = results[("nut", 3)]
    fig = Figure()
    ax = fig.subplots()
    plot_grasp(ax, s, 0)
    assert s.grasps[0].id in ax.get_title()

"""The baseline and the qualitative routes are judged by the same rules (issue 22, part 2): a
certified grasp below the image's resolution is not counted as found by any route, and the
tables say how many each route lost that way, per reason."""

import csv

import cv2
import numpy as np
from shapely.geometry import LineString, Point
from typer.testing import CliRunner

from qualgrasp.certify import Contact, Grasp, certify_grasp
from qualgrasp.cli import app
from qualgrasp.experiments import study
from qualgrasp.experiments.baseline import baseline
from qualgrasp.experiments.design import QUICK, REASONS, Settings
from qualgrasp.experiments.study import compare, evaluate_object, subjects
from qualgrasp.experiments.study_tables import overall_rows
from qualgrasp.qualitative.synthesis import pipeline
from qualgrasp.qualitative.objects import render, render_polygon
from qualgrasp.qualitative.synthesis.pipeline import NOT_COUNTED, counted, synthesize

STADIUM = LineString([(156, 256), (356, 256)]).buffer(30, quad_segs=64)
"""A stadium 260 px long and 60 px wide (as in tests/test_finger_scale.py): round ends centred
at x = 156 and x = 356."""

SMALL = Settings(budget=QUICK.budget, sizes=(("rotation", (4.0,)),), trials=1, workers=1)


def _rows(path):
    with path.open() as fh:
        return list(csv.DictReader(fh))


def test_no_route_counts_a_frictionless_closure_of_the_disc(tmp_path, monkeypatch):
    """The baseline closes the disc's pixel polygon with four frictionless fingers (epsilon about
    0.005); no disc has such a grasp. The study reports those grasps as below resolution, in every
    table, and counts none as found."""
    evaluated = []  # the study's own rows of the disc (one process: workers=1), then its files

    def spy(subject, settings):
        evaluated.append(evaluate_object(subject, settings))
        return evaluated[-1]

    monkeypatch.setattr(study, "evaluate_object", spy)
    result = compare(["disc"], tmp_path, settings=SMALL, plots=False)
    assert SMALL.budget == QUICK.budget and len(evaluated) == 1
    rows, grasp_rows = evaluated[0]
    by_route = {r["route"]: r for r in rows}
    base = by_route["Baseline 4"]
    assert base["certified"] > 0 and base["below_resolution"] == base["certified"]  # reported, not dropped
    for r in rows:
        if r["fingers"] == 4:  # frictionless: FormGrasp and the baseline
            assert r["counted"] == 0 and r["eps_best"] in (None, 0.0) and r["slide_best"] is None, r["route"]
        else:  # with friction a disc is held, and resolved
            assert r["counted"] == r["certified"] > 0 and r["below_resolution"] == 0, r["route"]
    mine = [g for g in grasp_rows if g["route"] == "Baseline 4"]
    assert mine and all(g["certified"] and not g["counted"] and g["below_resolution"] for g in mine)
    overall = {o["route"]: o for o in overall_rows(rows, grasp_rows, [])}
    assert overall["Baseline 4"]["objects_with_grasps"] == 0
    assert overall["Baseline 4"]["below_resolution"] == base["certified"]
    # the files written: a column per reason, in objects.csv, overall.csv and robustness.csv
    objects = {r["route"]: r for r in _rows(tmp_path / "objects.csv")}
    assert objects["Baseline 4"]["below_resolution"] == str(base["certified"]) and objects["Baseline 4"]["counted"] == "0"
    assert {r["route"]: r for r in _rows(tmp_path / "overall.csv")}["Baseline 4"]["objects_with_grasps"] == "0"
    robust = [r for r in _rows(tmp_path / "robustness.csv") if r["route"] == "Baseline 4"]
    assert all(r["planned"] == "0" for r in robust) and sum(int(r["below_resolution"]) for r in robust) > 0
    assert dict(next(r for r in result.routes if r.route == "Baseline 4").not_counted) == {
        "below_resolution": base["certified"], "weak_edge": 0}


def test_frictionless_closures_counted_on_the_stadium_are_real():
    """Unlike a disc, a stadium is closed by four frictionless fingers, even on its round ends
    alone (two on each: a turn about either end's centre is blocked by the other end; on one end
    alone the inward normals all point one way and cannot balance a push). Every frictionless
    grasp a route counts is a closure of the true stadium (its contacts moved onto the exact
    outline, with the exact normals), not of its pixel polygon, and none has all its fingers on
    one round end."""
    image = render_polygon(STADIUM)
    for method in ("qualitative", "baseline"):
        if method == "baseline":
            grasps = baseline(image, "formgrasp", name="stadium").grasps
        else:
            grasps = synthesize(image, procedure="formgrasp", quality=False, tolerance=False).grasps
        reports = [certify_grasp(g) for g in grasps]
        kept = [g for g, r in zip(grasps, reports) if counted(g, r.certified, r.eps_l1)]
        assert kept, method
        for g in kept:
            ends = {0 if c.p[0] < 156 else 1 if c.p[0] > 356 else None for c in g.contacts}
            assert ends != {0} and ends != {1}, (method, g.id)
            exact = []
            for c in g.contacts:
                near = STADIUM.exterior.interpolate(STADIUM.exterior.project(Point(c.p)))
                p = np.array([near.x, near.y])
                x = min(max(p[0], 156.0), 356.0)
                n = np.array([x, 256.0]) - p  # towards the spine: the inward normal
                exact.append(Contact(tuple(p), tuple(n / np.linalg.norm(n))))
            assert certify_grasp(Grasp(tuple(exact), center=g.center, length=g.length)).force.status == "closure"


def test_one_rule_for_both_routes(monkeypatch, tmp_path):
    """With a coarser image (every grasp's resolution made larger than any epsilon), the
    qualitative grasps are flagged by the same function as the baseline's, in synthesis, its
    command and the study alike."""
    assert REASONS == tuple(r.name for r in NOT_COUNTED) == ("below_resolution", "weak_edge")
    image = render("polygon")
    s = synthesize(image, procedure="forcegrasp2", quality=False, tolerance=False)
    assert s.grasps and all(s.resolved) and s.summary()["below_resolution"] == 0
    assert s.resolved == tuple(counted(g, c, r.eps_l1) for g, c, r in zip(s.grasps, s.certified, s.reports))
    monkeypatch.setattr(pipeline, "resolution", lambda grasp, spans: 10.0)
    monkeypatch.setattr("qualgrasp.experiments.baseline.resolution", lambda grasp, spans: 10.0)
    s = synthesize(image, procedure="forcegrasp2", quality=False, tolerance=False)
    assert s.grasps and not any(s.resolved) and s.summary()["below_resolution"] == len(s.grasps)
    assert all(why == ("below_resolution",) for why in s.not_counted)
    path = tmp_path / "polygon.png"
    cv2.imwrite(str(path), image)
    out = CliRunner().invoke(app, ["synthesize", str(path), "--fingers", "2", "--no-tolerance",
                                   "-o", str(tmp_path / "g.jsonl")])
    assert out.exit_code == 0, out.output
    assert out.output.count("verified, BELOW IMAGE RESOLUTION") == len(s.grasps)
    assert f"note: {len(s.grasps)} certified grasp(s) are below the image's resolution" in out.output
    rows, _ = study.evaluate_object(subjects(["polygon"])[0], Settings(budget=QUICK.budget, workers=1))
    for r in rows:
        assert r["counted"] == 0 and r["below_resolution"] == r["certified"], r["route"]
        assert r["eps_best"] in (None, 0.0)

"""Certified tolerance of synthesised grasps (issue 14, part 3): every certified grasp reports the
independent contact regions certified around it, a grasp whose contacts are displaced anywhere
inside them holds, and the study reports the tolerance per route."""

import json

import cv2
import numpy as np
import pytest
from typer.testing import CliRunner

from qualgrasp.certify import Contact, Grasp, force_closure
from qualgrasp.certify.regions import StraightRegion
from qualgrasp.certify.regions import verify_regions
from qualgrasp.cli import app
from qualgrasp.experiments.study import evaluate_object, subjects
from qualgrasp.experiments.study_tables import overall_rows
from qualgrasp.qualitative.objects import render
from qualgrasp.qualitative.synthesis.pipeline import synthesize


# FormGrasp on figure 3 (28 grasps, straight and curved sides): on the polygon it finds 74, whose
# tolerances take three times as long
@pytest.fixture(scope="module", params=[("forcegrasp2", "polygon"), ("forcegrasp3", "polygon"), ("formgrasp", "figure3")],
                ids=["forcegrasp2", "forcegrasp3", "formgrasp"])
def synthesis(request):
    procedure, name = request.param
    return synthesize(render(name), procedure=procedure, quality=False)


def _choices(region, rng, count):
    """Contacts ``(p, n)`` inside a certified region: anywhere on a straight one, at the stated
    points of a curved one (points of the curve, with their normals)."""
    if isinstance(region, StraightRegion):
        lam = rng.random(count)
        lam[:2] = (0.0, 1.0)  # both ends
        a, b = np.array(region.a), np.array(region.b)
        return [(a + s * (b - a), np.array(region.n)) for s in lam]
    k = rng.integers(0, len(region.points), count)
    return [(region.points[i], region.normals[i]) for i in k]


def test_every_certified_grasp_reports_its_certified_tolerance(synthesis):
    assert synthesis.grasps and len(synthesis.tolerances) == len(synthesis.grasps)
    size = None
    for grasp, ok, found in zip(synthesis.grasps, synthesis.certified, synthesis.tolerances):
        assert ok and found is not None
        assert grasp.meta["delta"] == found.delta >= 0
        assert grasp.meta["delta_fraction"] == found.delta_fraction
        assert grasp.meta["slide"] == found.slide == min(map(min, found.extents))
        ratio = found.delta / found.delta_fraction if found.delta_fraction else None
        if ratio is not None:  # one object size for every grasp
            size = ratio if size is None else size
            assert ratio == pytest.approx(size, rel=1e-9)
        if found.status == "robust":
            assert found.delta > 0 and found.slide >= 0
            assert bool(verify_regions(found.regions, found.verdict))
    assert synthesis.summary()["median_delta_fraction"] == pytest.approx(
        float(np.median([d for d in synthesis.deltas if d is not None])))


def test_contacts_displaced_anywhere_inside_the_certified_regions_hold(synthesis):
    """A trial whose contacts stay within a grasp's certified regions must hold: 100 random
    choices of one contact per region, per robust grasp, are all in force closure."""
    rng = np.random.default_rng(3)
    robust = [(g, f) for g, f in zip(synthesis.grasps, synthesis.tolerances) if f.status == "robust"]
    assert robust
    for grasp, found in robust[:4]:
        per_region = [_choices(r, rng, 100) for r in found.regions.regions]
        for k in range(100):
            contacts = tuple(Contact(tuple(per_region[i][k][0]), tuple(per_region[i][k][1]), c.model, c.mu)
                             for i, c in enumerate(grasp.contacts))
            moved = Grasp(contacts, center=grasp.center, length=grasp.length)
            assert force_closure(moved).status == "closure", (grasp.id, k)


def test_regions_are_where_the_grasp_is():
    s = synthesize(render("square"), procedure="forcegrasp2", quality=False)
    for grasp, found in zip(s.grasps, s.tolerances):
        for c, region in zip(grasp.contacts, found.regions.regions):
            a, b = np.array(region.a), np.array(region.b)
            p = np.array(c.p)
            # the contact lies on its region's segment (within a pixel: the contact's line is fitted)
            t = np.clip((p - a) @ (b - a) / ((b - a) @ (b - a)), 0, 1)
            assert np.linalg.norm(a + t * (b - a) - p) < 1.0


def test_no_tolerance_skips_it():
    s = synthesize(render("polygon"), procedure="forcegrasp2", quality=False, tolerance=False)
    assert s.tolerances == () and all("delta" not in g.meta and "slide" not in g.meta for g in s.grasps)
    assert s.summary()["median_delta_fraction"] is None and s.summary()["median_slide_fraction"] is None


def test_synthesize_command_prints_and_writes_the_tolerance(tmp_path):
    image = tmp_path / "polygon.png"
    cv2.imwrite(str(image), render("polygon"))
    out = tmp_path / "g.jsonl"
    result = CliRunner().invoke(app, ["synthesize", str(image), "--fingers", "2", "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert "slide" in result.output and "extents" in result.output and "median certified slide" in result.output
    written = [json.loads(line) for line in out.read_text().splitlines()]
    assert all(g["slide"] <= min(map(min, g["extents"])) + 1e-12 and g["delta_fraction"] is not None for g in written)
    for g in written:  # each line prints the slide and the extents it writes
        extents = " ".join(f"{a:.1f}/{b:.1f}" for a, b in g["extents"])
        assert f"slide {g['slide']:.1f} px ({g['slide_fraction']:.3f}), extents {extents} px" in result.output
    result = CliRunner().invoke(app, ["synthesize", str(image), "--fingers", "2", "-o", str(out), "--no-tolerance"])
    assert result.exit_code == 0 and "slide" not in result.output and "delta" not in result.output


def test_the_study_reports_the_certified_tolerance_per_route():
    rows, grasp_rows = evaluate_object(subjects(["square"])[0])
    for r in rows:
        if r["counted"]:
            assert r["delta_best"] is not None and 0 <= r["delta_best"] < 1 and 0 <= r["slide_best"] < 1
            assert r["delta_status"] in ("robust", "undecided") or r["delta_status"].startswith("none: ")
        else:
            assert r["delta_best"] is None and r["slide_best"] is None
    overall = overall_rows(rows, grasp_rows, [])
    for o in overall:
        for key in ("delta", "slide"):
            mine = [r[f"{key}_best"] for r in rows if r["route"] == o["route"] and r[f"{key}_best"] is not None]
            assert o[f"{key}_median"] == (float(np.median(mine)) if mine else None)

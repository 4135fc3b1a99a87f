"""Certified tolerance states what the certificate covers (issue 22, part 1): per finger and side
the certified extent (arc length from the contact to the end of its certified region) and the
certified slide (the smallest extent), where ``delta``, the bisection's half-width before
clipping, claims more on contacts near the ends of their limits.

Every placement of the fingers within the stated extents (sampled densely along the boundary,
not along the certified regions) is in closure by an independent oracle (scipy's linprog on the
friction cones' edge wrenches), and the stated extents are those of the region tuple the
certificate is about."""

import json

import cv2
import numpy as np
import pytest
from typer.testing import CliRunner

from extents_oracle import Polygon, closure_margin, every_choice_holds, placements_within, region_extents
from qualgrasp.certify import Contact, Grasp
from qualgrasp.certify.regions import independent_regions, tuple_from_dict, verify_regions
from qualgrasp.cli import app
from qualgrasp.qualitative.synthesis.candidates import object_frame
from qualgrasp.qualitative.synthesis.independent import independent_grasp, outline_boundary
from qualgrasp.qualitative.objects import render
from qualgrasp.qualitative.vision.outline import outline_image
from qualgrasp.qualitative.synthesis.pipeline import synthesize

RECTANGLE = [(0, 0), (4, 0), (4, 2), (0, 2)]
L_SHAPE = [(0, 0), (4, 0), (4, 1), (1, 1), (1, 3), (0, 3)]


def _exact(vertices, per_edge=8):
    """Boundary points and inward normals of a counter-clockwise polygon, every edge sampled at
    ``per_edge`` points from its start to its end (each corner twice, once per side)."""
    V = np.asarray(vertices, float)
    pts, nrm = [], []
    for a, b in zip(V, np.roll(V, -1, axis=0)):
        d = (b - a) / np.linalg.norm(b - a)
        for lam in np.linspace(0, 1, per_edge):
            pts.append(a + lam * (b - a))
            nrm.append((-d[1], d[0]))
    return np.array(pts), np.array(nrm)


def _near_ends(vertices, fingers, rng):
    """Contacts on distinct random edges, each within 2 to 15 % of an end of its edge."""
    V = np.asarray(vertices, float)
    edges = rng.choice(len(V), fingers, replace=False)
    out = []
    for e in edges:
        a, b = V[e], V[(e + 1) % len(V)]
        lam = rng.uniform(0.02, 0.15)
        lam = lam if rng.random() < 0.5 else 1 - lam
        d = (b - a) / np.linalg.norm(b - a)
        out.append((a + lam * (b - a), np.array([-d[1], d[0]])))
    return out


def _check(found, boundary: Polygon, grasp: Grasp, rng, count=9, random=200):
    """The stated extents are the certified regions', the slide their smallest, and every
    placement within them holds by the oracle."""
    assert found.status == "robust" and bool(verify_regions(found.regions, found.verdict))
    assert len(found.extents) == len(grasp.contacts)
    scale = found.size
    choices = []
    for c, region, (before, after) in zip(grasp.contacts, found.regions.regions, found.extents):
        s = boundary.arc(c.p)
        on = boundary.at(s)[0]
        assert region_extents(region, on) == pytest.approx((before, after), abs=1e-6 * scale)
        choices.append(placements_within(boundary, s, before, after, count))
    assert found.slide == min(min(e) for e in found.extents)
    assert found.slide_fraction == pytest.approx(found.slide / found.size)
    mus = [c.mu for c in grasp.contacts]
    held, worst = every_choice_holds(choices, mus, grasp.center, grasp.length, rng, random)
    assert held, (grasp.id, worst)


@pytest.mark.parametrize("vertices", [RECTANGLE, L_SHAPE], ids=["rectangle", "L"])
@pytest.mark.parametrize("fingers, mu", [(2, 0.5), (3, 0.5), (4, 0.0)])
def test_extents_on_polygons_with_contacts_near_corners(vertices, fingers, mu):
    """Contacts near the ends of their edges: each stretch is clipped at the corner, so ``delta``
    claims more than the regions cover there; the extents and the slide state what they do."""
    pts, nrm = _exact(vertices)
    boundary = Polygon(pts, nrm)
    rng = np.random.default_rng(fingers)
    V = np.asarray(vertices, float)
    center, length = V.mean(axis=0), float(np.linalg.norm(V - V.mean(axis=0), axis=1).max())
    checked = clipped = 0
    for trial in range(400):
        if checked == 4:
            break
        if fingers > len(V):
            break
        placed = _near_ends(vertices, fingers, rng)
        if closure_margin([p for p, _ in placed], [n for _, n in placed], [mu] * fingers, center, length) <= 1e-3:
            continue
        grasp = Grasp(tuple(Contact(tuple(p), tuple(n), "point" if mu else "frictionless", mu or None)
                            for p, n in placed), center=tuple(center), length=length, id=f"g{trial}")
        found = independent_regions(pts, nrm, grasp)
        if found.status != "robust":
            continue
        _check(found, boundary, grasp, rng)
        checked += 1
        clipped += found.slide < found.delta - 1e-9
    assert checked >= 2
    assert clipped, "no contact was clipped: the test does not reach the case it is about"


# dense sampling: the two curved objects (about 10 s each) in the slow set
@pytest.mark.parametrize("name", ["figure3", "polygon", pytest.param("nut", marks=pytest.mark.slow),
                                  pytest.param("disc", marks=pytest.mark.slow)])
def test_extents_on_the_builtin_objects(name):
    """Random two- and three-finger grasps on the outline of each built-in object, and the
    qualitative route's grasps, with the feasible regions as limits."""
    image = render(name)
    outline = outline_image(image)
    pts, nrm = outline_boundary(outline)
    boundary = Polygon(pts, nrm)
    center, length = object_frame(outline.contour)
    rng = np.random.default_rng(len(name))
    grasps = list(synthesize(image, procedure="forcegrasp3", quality=False, tolerance=False).grasps[:2])
    grasps += list(synthesize(image, procedure="forcegrasp2", quality=False, tolerance=False).grasps[:1])
    tries = 0
    while len(grasps) < 6 and tries < 200:
        tries += 1
        k = int(rng.integers(2, 4))
        idx = rng.choice(len(pts), k, replace=False)
        if closure_margin(pts[idx], nrm[idx], [0.5] * k, center, length) <= 1e-3:
            continue
        grasps.append(Grasp(tuple(Contact(tuple(pts[i]), tuple(nrm[i]), "point", 0.5) for i in idx),
                            center=tuple(center), length=length, id=f"{name}-random-{tries}"))
    checked = 0
    for grasp in grasps:
        try:
            found = independent_grasp(outline, grasp)
        except Exception as err:  # a contact on a corner: no stretch to state
            assert "corner" in str(err) or "cusp" in str(err) or "angle" in str(err), err
            continue
        if found.status != "robust":
            continue
        _check(found, boundary, grasp, rng, count=7, random=120)
        checked += 1
    assert checked >= 2


def test_the_independent_regions_command_states_the_slide(tmp_path):
    """``qualgrasp independent-regions`` writes the extents and the slide of the regions it
    certifies (computed here from the regions written), and prints the slide."""
    image = tmp_path / "polygon.png"
    cv2.imwrite(str(image), render("polygon"))
    runner = CliRunner()
    out = runner.invoke(app, ["synthesize", str(image), "--fingers", "3", "--no-tolerance",
                              "-o", str(tmp_path / "g.jsonl")])
    assert out.exit_code == 0, out.output
    grasps = [json.loads(line) for line in (tmp_path / "g.jsonl").read_text().splitlines()]
    out = runner.invoke(app, ["independent-regions", str(image), str(tmp_path / "g.jsonl"),
                              "-o", str(tmp_path / "r.jsonl")])
    assert out.exit_code == 0, out.output
    rows = [json.loads(line) for line in (tmp_path / "r.jsonl").read_text().splitlines()]
    pts, nrm = outline_boundary(outline_image(render("polygon")))
    boundary = Polygon(pts, nrm)
    clipped = 0
    for g, row in zip(grasps, rows):
        assert row["status"] == "robust"
        regions = tuple_from_dict(row["regions"]).regions
        mine = [region_extents(r, boundary.at(boundary.arc(c["p"]))[0]) for r, c in zip(regions, g["contacts"])]
        assert np.allclose(row["extents"], mine, rtol=0, atol=1e-6)
        assert row["slide"] == pytest.approx(min(min(e) for e in mine), abs=1e-6)
        assert row["slide"] <= row["delta"] + 1e-9
        clipped += row["slide"] < row["delta"] - 1e-6
        assert f"slide {row['slide']:.2f} px" in out.output
    assert clipped  # on the polygon's grasps delta claims more than the regions cover


def test_synthesis_records_the_slide_in_the_grasps_fields():
    s = synthesize(render("polygon"), procedure="forcegrasp3", quality=False)
    for grasp, found in zip(s.grasps, s.tolerances):
        assert grasp.meta["slide"] == found.slide and grasp.meta["slide_fraction"] == found.slide_fraction
        assert grasp.meta["extents"] == [list(e) for e in found.extents]
        assert grasp.meta["delta"] == found.delta  # kept, with its own meaning
    assert s.summary()["median_slide_fraction"] == pytest.approx(
        float(np.median([g.meta["slide_fraction"] for g in s.grasps])))


def test_a_finger_on_a_closed_outline_slides_both_ways():
    """The disc's feasible region is its whole outline, which has no end: a finger at the sample
    where the outline starts slides both ways as far as any other (no seam cuts its stretch)."""
    s = synthesize(render("disc"), procedure="forcegrasp2", quality=False)
    found = s.tolerances[0]
    assert found.status == "robust"
    before, after = zip(*found.extents)
    assert min(before) > 0.9 * max(after) > 0 and found.slide == min(before + after) > 0.1 * found.size

"""The fast three-finger ForceGrasp search returns exactly the grasps of the plain search.

:func:`qualgrasp.qualitative.synthesis.forcegrasp.triplet_grasps` shares per-candidate work
between region triplets and skips triplets whose normals cannot span with the margin (issue 27,
part 5); :mod:`forcegrasp_reference` keeps the search as it was (every triplet scored, nothing
shared). Both must give the same grasps, compared exactly: contacts, regions, angles, margin and
meeting point, bit for bit. A gear (many small straight regions, most triplets pruned) and
built-in objects with curved regions (a region used twice or thrice: the combinations' route).
"""

import math

import pytest

from forcegrasp_reference import best_triplet_score_reference, triplet_grasps_reference
from qualgrasp.qualitative.objects import gear, render, render_polygon
from qualgrasp.qualitative.synthesis.candidates import candidates
from qualgrasp.qualitative.synthesis.forcegrasp import MARGIN, best_triplet_margins, triplet_grasps
from qualgrasp.qualitative.synthesis.regions import feasible_regions
from qualgrasp.qualitative.vision.outline import outline_image

THETA = math.atan(0.5)
IMAGES = {"gear8": lambda: render_polygon(gear(8)), "polygon": lambda: render("polygon"),
          "figure3": lambda: render("figure3"), "disc": lambda: render("disc")}


@pytest.fixture(scope="module", params=list(IMAGES))
def search(request):
    outline = outline_image(IMAGES[request.param]())
    return request.param, outline, candidates(outline, feasible_regions(outline))


def _key(found):
    return [(g.contacts, g.regions, g.angles, g.margin, tuple(g.point.tolist()), g.theta_min) for g in found]


@pytest.mark.parametrize("margin", [MARGIN, 0.0, 0.5])
def test_same_grasps_as_the_plain_search(search, margin):
    name, outline, cands = search
    fast = triplet_grasps(cands, outline.contour, THETA, outline.size, margin=margin)
    plain = triplet_grasps_reference(cands, outline.contour, THETA, outline.size, margin=margin)
    assert _key(fast) == _key(plain)
    if name == "gear8" and margin < 0.5:
        assert len(plain) > 10  # the comparison is not vacuous: many triplets to keep or prune


def test_same_best_margin_as_the_plain_search(search):
    """The near-miss numbers of a search that found nothing (no pruning there) are unchanged too."""
    _, outline, cands = search
    _, best = best_triplet_margins(cands, outline.contour, THETA, outline.size)
    assert best == best_triplet_score_reference(cands, outline.contour, THETA, outline.size)

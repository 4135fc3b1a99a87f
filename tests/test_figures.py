"""The paper's figures 3 to 8 (``experiments.figures``): they build, they are written, and what
they show is what the toolkit computes."""

import math
import re
from collections import Counter

import matplotlib
import numpy as np
import pytest
from matplotlib.figure import Figure
from matplotlib.patches import Circle
from matplotlib.path import Path as MplPath
from PIL import Image
from typer.testing import CliRunner

from extents_oracle import region_extents
from qualgrasp.experiments import figures, style
from qualgrasp.cli import app
from qualgrasp.experiments.figures import (STEMS, fig3_outline, fig4_regions, fig5_zones, fig6_two_fingers,
                                           fig7_three_fingers, fig8_spanning, fig9_regions, form_example, make_figures,
                                           nguyen_example, spanning_examples)
from qualgrasp.certify import force_closure
from qualgrasp.certify.regions import certify_regions
from qualgrasp.certify.regions import verify_regions
from qualgrasp.qualitative.synthesis.forcegrasp import friction_zone, nguyen_angles, positively_spans
from qualgrasp.qualitative.objects import render
from qualgrasp.qualitative.vision.outline import outline_image
from qualgrasp.qualitative.synthesis.regions import feasible_regions
from qualgrasp.qualitative.synthesis.pipeline import synthesize


@pytest.fixture(scope="module")
def image():
    return render(figures.OBJECT)


class _Syntheses(dict):
    """The syntheses figures 5 to 9 draw, by finger count, each computed once on first use; with
    the certified tolerance for three fingers only (figure 9's), as :func:`figures.make_figures`."""

    def __init__(self, image):
        super().__init__()
        self.image = image

    def __missing__(self, fingers):
        self[fingers] = synthesize(self.image, fingers, mu=None if fingers == 4 else figures.MU,
                                   name=figures.OBJECT, tolerance=fingers == 3)
        return self[fingers]


@pytest.fixture(scope="module")
def synths(image):
    return _Syntheses(image)


def _image_axes(fig: Figure) -> list:
    """Panels drawn in the image frame (y pointing down, equal aspect, no ticks)."""
    axes = [ax for ax in fig.axes if ax.images]
    for ax in axes:
        bottom, top = ax.get_ylim()
        assert bottom > top and ax.get_aspect() == 1.0
        assert not ax.get_xticks().size and not ax.get_yticks().size  # pixel axes hidden
    return axes


def test_fig3_shows_the_canonical_string():
    img = render("figure3")
    outline = outline_image(img)
    fig = fig3_outline(img)
    (ax,) = _image_axes(fig)
    assert ax.get_title() == f"string  {outline.string}"
    assert Counter(outline.string) == {"/": 2, ")": 1, "(": 1, ">": 1, "<": 1, "}": 1, "{": 1}  # the paper's count
    symbols = [t for t in ax.texts if t.get_text() in set(outline.string)]
    assert sorted(t.get_text() for t in symbols) == sorted(outline.string)  # one symbol per segment
    where = np.array([t.xyann for t in symbols])
    assert not MplPath(outline.contour).contains_points(where).any()  # every symbol off the object
    assert "2 straight lines" in ax.get_xlabel()
    fig.canvas.draw()


def test_fig4_regions_per_object():
    fig = fig4_regions()
    axes = _image_axes(fig)
    assert len(axes) == 3
    for ax, (name, label) in zip(axes, figures.FIG4_OBJECTS):
        regions = feasible_regions(outline_image(render(name)))
        assert ax.get_title().startswith(f"{'abc'[axes.index(ax)]}. {label}")
        assert f"{len(regions)} feasible region" in ax.get_title()
        curved = any(r.type != "/" for r in regions)
        assert any(isinstance(p, Circle) for p in ax.patches) == curved  # threshold circle on curves only
    assert "$\\rho$ =" in axes[2].get_title()
    fig.canvas.draw()


def test_fig5_zone_shrinks_to_empty(synths, image):
    synth = synths[4]
    k, steps = form_example(synth)
    assert [z.status for z in steps] == ["no_closure"] * 3 + ["closure"]
    assert all(z.depth > 0 for z in steps[:3]) and steps[-1].depth < 0
    assert synth.reports[k].force.status == "closure"
    assert synth.reports[k].force.margin >= (1 - figures.NEAR_BEST) * max(r.force.margin for r in synth.reports)
    fig = fig5_zones(synth, image)
    axes = _image_axes(fig)
    titles = [ax.get_title() for ax in axes]
    assert len(axes) == 4
    assert all("≠ ∅" in t for t in titles[:3]) and "Z = ∅, form closure" in titles[3]
    assert f"{synth.reports[k].force.margin:.3f}" in titles[3]
    assert synth.grasps[k].id in fig.get_suptitle()
    labels = {t.get_text() for t in axes[0].texts}
    assert {"Z+", "Z-"} <= labels  # one contact: both half-planes named
    assert "E" in {t.get_text() for t in axes[1].texts}  # where the first two lines of action cross
    fig.canvas.draw()


def test_fig6_nguyen_angles(synths, image):
    synth = synths[2]
    k = nguyen_example(synth)
    g = synth.found[k]
    t1, t2 = nguyen_angles(g.points[0], g.normals[0], g.points[1], g.normals[1])
    assert max(t1, t2) < synth.theta_min and synth.certified[k]
    assert max(t1, t2) == max(max(f.angles) for f, ok in zip(synth.found, synth.certified) if ok)
    fig = fig6_two_fingers(synth, image)
    (ax,) = _image_axes(fig)
    assert f"{math.degrees(t1):.1f}°" in ax.get_title() and f"{math.degrees(t2):.1f}°" in ax.get_title()
    assert "certify: closure" in ax.get_title()
    fig.canvas.draw()


def test_fig7_friction_zone_not_empty(synths, image):
    synth = synths[3]
    k = figures.best_grasp(synth)
    g = synth.found[k]
    assert not friction_zone(g.points, g.normals, g.theta_min, 2 * synth.outline.size).is_empty
    assert positively_spans(g.normals)
    fig = fig7_three_fingers(synth, image)
    (ax,) = _image_axes(fig)
    assert "friction zone non-empty" in ax.get_title()
    assert f"margin {synth.reports[k].force.margin:.3f}" in ax.get_title()
    assert not ax.child_axes  # the normals have a figure of their own (8)
    fig.canvas.draw()


def test_fig8_verdicts_differ(synths, image):
    synth = synths[3]
    good, bad = spanning_examples(synth)
    assert good.spans and not bad.spans
    assert good.gap < math.pi < bad.gap
    assert (good.certified.status, bad.certified.status) == ("closure", "no_closure")  # LP agrees with the gap rule
    assert (good.report.force.status, bad.report.force.status) == ("closure", "no_closure")
    np.testing.assert_allclose(bad.points[:2], good.points[:2])  # only the third contact moved
    fig = fig8_spanning(synth, image)
    assert len(_image_axes(fig)) == 2
    verdicts = [ax.get_xlabel() for ax in fig.axes if not ax.images]
    assert "positively span the plane" in verdicts[0] and "closure" in verdicts[0]
    assert "half-plane" in verdicts[1] and "no closure" in verdicts[1]
    fig.canvas.draw()


def test_fig9_certified_regions_beside_a_witness(synths, image):
    synth = synths[3]
    k, verdict = figures.regions_example(synth)
    found = synth.tolerances[k]
    assert found.status == "robust" and found.slide > 0
    assert bool(verify_regions(found.regions, found.verdict))
    whole = figures.feasible_tuple(synth, k)
    assert verdict.status == "not_robust" and bool(verify_regions(whole, verdict))
    assert force_closure(verdict.witness).status == "no_closure"
    # no other certified grasp with not-robust whole regions has a larger certified slide
    assert all(f.slide <= found.slide for f in synth.tolerances if f is not None and f.status == "robust"
               and certify_regions(figures.feasible_tuple(synth, synth.tolerances.index(f))).status == "not_robust")
    fig = fig9_regions(synth, image)
    left, right = _image_axes(fig)
    # what the caption claims every finger may slide, either way, is covered by the certified regions:
    # at most the arc from each contact to either end of its region (measured here from the regions)
    claimed = float(re.search(r"may slide ([0-9.]+) px = ([0-9.]+) of the size either way", left.get_title()).group(1))
    grasp = synth.grasps[k]
    reach = [region_extents(r, c.p) for r, c in zip(found.regions.regions, grasp.contacts)]
    assert claimed <= min(map(min, reach)) + 0.05
    assert claimed == pytest.approx(min(map(min, reach)), abs=0.05 + 1e-3 * synth.outline.size)
    for i, (before, after) in enumerate(reach, start=1):
        assert f"{i}: {before:.1f}/{after:.1f}" in left.get_xlabel()
    assert "not robust" in right.get_title() and "Farkas" in right.get_title()
    fig.canvas.draw()


def test_make_figures_writes_every_file(tmp_path, synths, monkeypatch):
    # the syntheses are the module's (tested above); this test is about drawing and writing
    monkeypatch.setattr(figures, "synthesize", lambda image, fingers, **kw: synths[fingers])
    before = dict(matplotlib.rcParams)
    said = []
    paths = make_figures(tmp_path / "figs", formats=("png",), progress=said.append)
    assert [p.name for p in paths] == [f"{stem}.png" for stem in STEMS]
    assert len(said) == len(STEMS)
    for path in paths:
        assert path.stat().st_size > 30_000  # non-trivial
        with Image.open(path) as im:
            assert min(im.size) > 600  # about 200 dpi
    assert dict(matplotlib.rcParams) == before  # the style does not leak
    import matplotlib.pyplot as plt

    assert not plt.get_fignums()  # nor do figures into pyplot


def test_pdf_output(tmp_path):
    (path,) = style.save(fig3_outline(), tmp_path, "fig3", ["pdf"])
    data = path.read_bytes()
    assert data.startswith(b"%PDF") and len(data) > 10_000
    assert b"FontFile2" in data  # TrueType fonts embedded: text stays text


def test_bad_format_fails_before_any_work(tmp_path):
    with pytest.raises(ValueError, match="cannot write figures as bmpx"):
        make_figures(tmp_path / "never", formats=("png", "bmpx"))
    assert not (tmp_path / "never").exists()


def test_cli_is_a_thin_layer(tmp_path, monkeypatch):
    seen = {}

    def fake(out, *, formats, progress):
        seen.update(out=out, formats=formats)
        progress("drawing fig3_outline")
        return [out / "fig3_outline.svg"]

    monkeypatch.setattr(figures, "make_figures", fake)
    result = CliRunner().invoke(app, ["figures", "--out", str(tmp_path), "--formats", "svg, PDF"])
    assert result.exit_code == 0, result.output
    assert seen == {"out": tmp_path, "formats": ("svg", "pdf")}
    assert "fig3_outline.svg" in result.output and "drawing fig3_outline" in result.output
    bad = CliRunner().invoke(app, ["figures", "--out", str(tmp_path), "--formats", "nope"])
    assert bad.exit_code == 2 and "nope" in bad.output

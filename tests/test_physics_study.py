"""The physical validation study (experiments/physics/study.py) and ``qualgrasp validate``
(experiments/physics/cli.py)."""

from dataclasses import replace

import cv2
import pytest
import typer
from typer.testing import CliRunner

pytest.importorskip("pymunk", reason="the physical validation needs pymunk (pip install 'qualgrasp[physics]')")

from qualgrasp.experiments.physics.cli import register  # noqa: E402
from qualgrasp.experiments.physics.study import (COLUMNS, VALIDATIONS, Validation, explain,  # noqa: E402
                                                 read_trials, summarise, validate)
from qualgrasp.qualitative.objects import render  # noqa: E402

TINY = Validation(per_route=1, random=1, inside=2, outside=1, directions=6, recheck=1, workers=1)


@pytest.fixture(scope="module")
def square_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("validate")
    return out, validate(["square"], out, settings=TINY)


def test_files_and_columns(square_run):
    out, result = square_run
    names = {p.name for p in result.files}
    assert {"trials.csv", "closed-forms.csv", "settings.csv", "summary.md", "physics-resisted.png",
            "physics-placements.png", "physics-settings.png", "physics-filmstrip.png"} <= names
    assert all(p.exists() for p in result.files)
    assert all(set(r) == set(COLUMNS) for r in result.rows)
    text = (out / "summary.md").read_text()
    assert "## Certified verdict against the physical outcome" in text and "2 mu F0" in text


def test_qualitative_grasps_of_the_square_hold_and_their_placements_inside_too(square_run):
    _, result = square_run
    nominal = [r for r in result.rows if r["source"] == "qualitative" and r["placement"] == "nominal"
               and r["setting"] == "default"]
    # ForceGrasp finds no 3-finger grasp on a square; PairGrasp adds a third finger to an opposed pair
    assert {r["fingers"] for r in nominal} == {2, 3, 4}
    assert {r["procedure"] for r in nominal if r["fingers"] == 3} == {"pairgrasp3"}
    for r in nominal:
        assert r["certified"] and r["certified_true"] and r["held"] and r["resisted"] > 0, r
        assert r["delta_fraction"] > 0 and r["tolerance"] == "robust"
    inside = [r for r in result.rows if r["placement"] == "inside" and r["source"] == "qualitative"]
    assert len(inside) == 2 * len(nominal)
    assert all(r["held"] and 0 < r["error"] <= 1 for r in inside)
    outside = [r for r in result.rows if r["placement"] == "outside"]
    assert outside and all(1 < r["error"] <= TINY.outside_max for r in outside)


def test_summary_counts_and_the_trials_file(square_run):
    out, result = square_run
    for c in result.summary["confusion"].values():
        assert c["tp"] + c["fp"] + c["fn"] + c["tn"] == c["grasps"]
    rows = read_trials(out / "trials.csv")
    assert len(rows) == len(result.rows)
    assert [(r["grasp"], r["placement"], r["held"], r["certified"]) for r in rows] == \
        [(r["grasp"], r["placement"], r["held"], r["certified"]) for r in result.rows]
    assert summarise(rows)["placements"] == result.summary["placements"]
    fine = [r for r in result.rows if r["setting"] == "fine"]
    assert fine and all(r["placement"] == "nominal" for r in fine)


def test_explain_names_the_cause():
    base = {"executed": "contact", "certified_true": True, "fingers": 2}
    assert explain({**base, "eps_true": 1e-4}).endswith("even at the largest finger force")
    assert "at the squeeze force" in explain({**base, "eps_true": 0.006})
    assert explain({**base, "eps_true": 0.2}) == "unexplained"
    assert explain({**base, "executed": "collision"}) == "a finger started inside the true object"
    assert explain({**base, "eps_true": 0.2, "held_stiff": True}).startswith("compliance")


def _app():
    app = typer.Typer()

    @app.command("noop")
    def noop():  # a second command, so that the group keeps its command names as in the root CLI
        pass

    register(app)
    return app


@pytest.mark.parametrize("args, message", [
    (["validate"], "no images"),
    (["validate", "--builtins", "--setting", "huge"], "--setting must be one of"),
    (["validate", "--silhouettes", "100000"], "--silhouettes must be between"),
    (["validate", "--builtins", "--workers", "0"], "--workers must be between"),
    (["validate", "nowhere-folder"], "is not a folder"),
])
def test_refused_options_exit_2_with_one_line(args, message, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    result = CliRunner().invoke(_app(), args)
    assert result.exit_code == 2, result.output
    assert message in result.output and "Traceback" not in result.output


def test_output_folder_that_is_a_file_exits_2(tmp_path):
    target = tmp_path / "file"
    target.write_text("x")
    result = CliRunner().invoke(_app(), ["validate", "--builtins", "--out", str(target)])
    assert result.exit_code == 2 and "is not a folder" in result.output


def test_the_output_folder_is_never_the_input_folder(tmp_path):
    """Found by a hostile run: validate wrote its figures into its image folder, replacing an
    input image of the same name."""
    folder = tmp_path / "images"
    folder.mkdir()
    cv2.imwrite(str(folder / "physics-filmstrip.png"), render("nut"))
    before = (folder / "physics-filmstrip.png").read_bytes()
    for out in (folder, tmp_path / "link"):
        if out != folder:
            out.symlink_to(folder)
        result = CliRunner().invoke(_app(), ["validate", str(folder), "--quick", "--out", str(out)])
        assert result.exit_code == 2 and "input of this run" in result.output, result.output
    assert (folder / "physics-filmstrip.png").read_bytes() == before


def test_validate_on_a_folder_of_images(tmp_path, monkeypatch):
    """An image without known geometry: the grasps are executed on the contour it shows. The
    command's quick setting is made TINY without the re-run at FINE (which square_run covers)."""
    monkeypatch.setitem(VALIDATIONS, "quick", replace(TINY, recheck=0))
    folder = tmp_path / "images"
    folder.mkdir()
    cv2.imwrite(str(folder / "square.png"), render("square", size=256))
    out = tmp_path / "out"
    result = CliRunner().invoke(_app(), ["validate", str(folder), "--quick", "--workers", "1", "--out", str(out)],
                                terminal_width=200)
    assert result.exit_code == 0, result.output
    assert "placements inside the certified regions" in result.output
    rows = read_trials(out / "trials.csv")
    assert {r["object"] for r in rows} == {"square"}
    assert any(r["source"] == "qualitative" and r["held"] for r in rows)


def test_placements_inside_stay_on_the_certified_regions():
    """On figure3 the baseline's 2-finger grasp has a tolerance longer than the straight edge it
    sits on: a placement inside must stop at the edge's end, where its certified region stops."""
    import itertools

    from shapely.geometry import LineString, Point

    from qualgrasp.certify.regions.boundary import Boundary
    from qualgrasp.experiments.physics.study import grasps_of, placement
    from qualgrasp.experiments.study import subjects
    from qualgrasp.qualitative.synthesis.independent import outline_boundary

    subject = subjects(["figure3"])[0]
    planned, outline = grasps_of(subject, TINY)
    arc = Boundary.of(*outline_boundary(outline))
    step = arc.perimeter / len(arc.points)
    robust = [p for p in planned if p.status == "robust"]
    assert {p.source for p in robust} == {"qualitative", "baseline"}
    clipped = 0
    for plan in robust:
        t = plan.tolerance
        lines = [LineString([r.a, r.b]) if hasattr(r, "a") else LineString(r.points) for r in t.regions.regions]
        for signs in itertools.product((-1.0, 1.0), repeat=len(t.deltas)):
            shifts = placement(t.deltas, t.positions, t.limits, 1.0, signs, step)
            clipped += sum(abs(x) < d - 1e-9 for x, d in zip(shifts, t.deltas))
            for line, p, x in zip(lines, t.positions, shifts):
                assert line.distance(Point(arc.point_at(p + x))) < 1e-6
    assert clipped > 0  # some finger's tolerance reaches past its limits

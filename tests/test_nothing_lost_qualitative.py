"""Issue 23 through the qualitative and experiments commands: their outputs never replace an
input (the image, the mask, the grasp set; through symbolic and hard links), their line files are
read by certify's hardened reader, and their options bound the work they admit."""

import json
import os

import cv2
import pytest
from typer.testing import CliRunner

from qualgrasp.certify.cli.options import FOLDER_MARKER
from qualgrasp.certify.regions.boundary import TOL_FLOOR
from qualgrasp.cli import app
from qualgrasp.qualitative.objects import render
from qualgrasp.qualitative.synthesis.pipeline import synthesize


def run(*args):
    return CliRunner().invoke(app, [str(a) for a in args])


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    """A polygon image and a grasp set of two certified grasps on it."""
    folder = tmp_path_factory.mktemp("scene")
    image = folder / "obj.png"
    cv2.imwrite(str(image), render("polygon"))
    grasps = folder / "g.jsonl"
    out = run("synthesize", image, "--fingers", "2", "-o", grasps, "--no-tolerance")
    assert out.exit_code == 0, out.output
    return folder, image, grasps


@pytest.mark.parametrize("how", ["same", "symlink", "hardlink"])
def test_independent_regions_never_writes_over_its_image(scene, tmp_path, how):
    _, image, grasps = scene
    target = tmp_path / "obj.png"
    target.write_bytes(image.read_bytes())
    out = {"same": target, "symlink": tmp_path / "link.png", "hardlink": tmp_path / "hard.png"}[how]
    if how == "symlink":
        out.symlink_to(target)
    if how == "hardlink":
        os.link(target, out)
    before = target.read_bytes()
    result = run("independent-regions", target, grasps, "-o", out)
    assert result.exit_code == 2 and "never overwritten" in result.output
    assert target.read_bytes() == before


def test_independent_regions_never_writes_over_its_grasp_set_or_mask(scene, tmp_path):
    _, image, grasps = scene
    mask = tmp_path / "mask.png"
    cv2.imwrite(str(mask), (render("polygon") < 128).astype("uint8") * 255)
    for out in (grasps, mask):
        before = out.read_bytes()
        result = run("independent-regions", image, grasps, "-o", out, "--mask", mask)
        assert result.exit_code == 2 and "never overwritten" in result.output
        assert out.read_bytes() == before


def test_independent_regions_reads_grasp_lines_with_the_hardened_reader(scene, tmp_path):
    """Invalid UTF-8, deep nesting, a 5,000-digit integer and a lone surrogate in an id are error
    rows naming the problem, the good line is certified, the run goes on (exit 1)."""
    _, image, grasps = scene
    good = grasps.read_text().splitlines()[0]
    path = tmp_path / "hostile.jsonl"
    path.write_bytes(b"\n".join([
        good.encode(),
        b'{"id": "x", "contacts": \xff}',
        b"[" * 5000 + b"]" * 5000,
        ('{"id": 1, "contacts": [], "n": ' + "9" * 5000 + "}").encode(),
        '{"id": "a\\ud800", "contacts": []}'.encode(),
    ]) + b"\n")
    result = run("independent-regions", image, path, "-o", tmp_path / "out.jsonl")
    assert result.exit_code == 1, result.output
    rows = [json.loads(line) for line in (tmp_path / "out.jsonl").read_text().splitlines()]
    assert [r["line"] for r in rows] == [1, 2, 3, 4, 5]
    assert rows[0]["status"] != "error"
    assert all(r["status"] == "error" for r in rows[1:])
    assert "UTF-8" in rows[1]["error"] and "lone surrogate" in rows[4]["error"]
    assert rows[4]["id"] is None  # an id that is not valid Unicode is not carried


@pytest.mark.parametrize("source", ["/dev/zero", "fifo"])
def test_independent_regions_refuses_files_that_are_not_regular(scene, tmp_path, source):
    _, image, _ = scene
    if source == "fifo":
        source = tmp_path / "in.fifo"
        os.mkfifo(source)
    result = run("independent-regions", image, source, "-o", tmp_path / "out.jsonl")
    assert result.exit_code == 2 and "not a regular file" in result.output


@pytest.mark.parametrize("tol", ["nan", "-1", "0", "inf", "1e-300"])
def test_independent_regions_tol_is_checked_before_any_work(scene, tmp_path, tol):
    _, image, grasps = scene
    result = run("independent-regions", image, grasps, "-o", tmp_path / "out.jsonl", "--tol", tol)
    assert result.exit_code == 2 and "--tol" in result.output
    assert not (tmp_path / "out.jsonl").exists()


def test_the_bisection_tolerance_is_bounded_in_the_library_too():
    from qualgrasp.certify.errors import GraspError
    from qualgrasp.qualitative.synthesis.independent import independent_grasp
    s = synthesize(render("polygon"), fingers=2, certify=False, tolerance=False)
    with pytest.raises(GraspError, match="at least"):
        independent_grasp(s.outline, s.grasps[0], tol=TOL_FLOOR * s.outline.size / 2)


def test_synthesize_and_plots_never_write_over_the_image(scene, tmp_path):
    _, image, _ = scene
    for args in (["-o", image], ["-o", tmp_path / "g.jsonl", "--plot", image]):
        before = image.read_bytes()
        result = run("synthesize", image, "--fingers", "2", "--no-tolerance", *args)
        assert result.exit_code == 2, result.output
        assert image.read_bytes() == before


def test_figures_refuses_a_file_in_the_way_and_keeps_it(tmp_path):
    """An --out folder holding a user's FIFO under a figure's name: refused, the FIFO kept; also
    in a folder qualgrasp wrote before (its marker), where each output is checked by itself."""
    out = tmp_path / "figs"
    out.mkdir()
    os.mkfifo(out / "fig3_outline.pdf")
    result = run("figures", "--out", out)
    assert result.exit_code == 2 and "did not write" in result.output
    assert (out / "fig3_outline.pdf").is_fifo()
    (out / FOLDER_MARKER).touch()
    result = run("figures", "--out", out)
    assert result.exit_code == 2 and "FIFO" in result.output
    assert (out / "fig3_outline.pdf").is_fifo()


@pytest.mark.parametrize("command, name", [(["figures"], "fig3_outline.png"),
                                           (["compare", "--builtins"], "overall.csv"),
                                           (["silhouettes", "--n", "1", "--no-horse"], "cell-000.png")])
def test_folder_commands_never_replace_a_users_file(tmp_path, command, name):
    """A folder the command did not make, holding a user's file under one of the outputs' names
    (found by a hostile run: figures and compare replaced it): refused before any work, kept."""
    out = tmp_path / "out"
    out.mkdir()
    (out / name).write_text("mine")
    result = run(*command, "--out", out)
    assert result.exit_code == 2 and "did not write" in result.output, result.output
    assert (out / name).read_text() == "mine" and sorted(p.name for p in out.iterdir()) == [name]


def test_a_folder_qualgrasp_wrote_can_be_written_again(tmp_path):
    out = tmp_path / "sil"
    for _ in range(2):
        result = run("silhouettes", "--out", out, "--n", "1", "--no-horse")
        assert result.exit_code == 0, result.output
    assert (out / FOLDER_MARKER).exists() and any(p.suffix == ".png" for p in out.iterdir())

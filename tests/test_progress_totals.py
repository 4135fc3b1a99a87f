"""Progress that adds up (issue 28, part 5): every progress bar's count equals its total at the
end, also when the study leaves out an image it cannot read."""

import re

import cv2
from typer.testing import CliRunner

from qualgrasp.cli import app
from qualgrasp.experiments.demo import demo_steps
from qualgrasp.experiments.figures import STEMS
from qualgrasp.experiments.study import BUILTINS, workload
from qualgrasp.qualitative.synthesis import procedures
from qualgrasp.qualitative.objects import render

runner = CliRunner()


def _final_count(output: str) -> tuple[int, int]:
    """The last ``done/total`` of the progress bar's count column (rich prints the bar's final
    state when it stops)."""
    counts = re.findall(r"(\d+)/(\d+)\s+\d+:\d\d:\d\d", output)
    assert counts, output
    done, total = counts[-1]
    return int(done), int(total)


def test_compare_ends_at_its_total_when_an_image_is_left_out(tmp_path):
    folder = tmp_path / "images"
    folder.mkdir()
    cv2.imwrite(str(folder / "a-square.png"), render("square", size=160))
    (folder / "b-broken.png").write_bytes(b"not an image")  # left out by the study, with a reason
    out = runner.invoke(app, ["compare", str(folder), "--out", str(tmp_path / "out"), "--workers", "1"])
    assert out.exit_code == 0, out.output
    assert "skipped b-broken" in out.output
    done, total = _final_count(out.output)
    assert done == total == workload(1, "quick")


def test_demo_steps_count_every_message():
    """The demo's total: one message per figure, per built-in object and procedure (the new
    procedure included), the certification and its re-check, and the study's."""
    assert demo_steps() == len(STEMS) + len(BUILTINS) * len(procedures.procedures()) + 2 + workload(len(BUILTINS))

"""``qualgrasp demo`` end to end: what it writes is complete, consistent and re-checkable."""

import json
import os
import re
from pathlib import Path

import pytest
from typer.testing import CliRunner

from qualgrasp.cli import app
from qualgrasp.experiments.figures import STEMS
from qualgrasp.experiments.study import BUILTINS

runner = CliRunner()

# The whole job (figures, synthesis, certification, the quick study): `.ci/run` runs it as the
# README's demo command before the tests, and these tests read that run's output.
pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    """The demo's output folder and what it printed: with QUALGRASP_DEMO_OUTPUT and
    QUALGRASP_DEMO_LOG (set by ``.ci/run``), those of the README's demo command it has just run;
    else a run of its own."""
    given, log = os.environ.get("QUALGRASP_DEMO_OUTPUT"), os.environ.get("QUALGRASP_DEMO_LOG")
    if given and log:
        return Path(given), Path(log).read_text()
    out = tmp_path_factory.mktemp("demo") / "out"
    result = runner.invoke(app, ["demo", "--out", str(out)])
    assert result.exit_code == 0, result.output
    return out, result.output


def test_demo_writes_figures_grasps_study_and_report(demo):
    out, output = demo
    assert len(list((out / "figures").glob("fig*.png"))) == len(STEMS) == 7
    assert len(list((out / "figures").glob("fig*.pdf"))) == len(STEMS)
    assert "fig9_regions.png" in (out / "report.md").read_text()
    for name in ("overall.md", "overall.csv", "objects.csv", "robustness.csv"):
        assert (out / "study" / name).stat().st_size > 0
    report = (out / "report.md").read_text()
    for target in re.findall(r"\]\(([^)]+)\)", report):  # every link and picture exists
        assert (out / target).exists(), target
    for name in BUILTINS:
        assert f"| {name} |" in report
    assert "`/}(</{)>`" in report and "`)`" in report
    assert str(out / "report.md") in output.replace("\n", "")


def test_demo_grasps_are_certified_and_recheck(demo):
    out, _ = demo
    grasps = [json.loads(line) for line in (out / "grasps" / "grasps.jsonl").open()]
    rows = [json.loads(line) for line in (out / "grasps" / "results.jsonl").open()]
    assert [g["id"] for g in grasps] == [r["id"] for r in rows]
    pattern = re.compile(rf"^({'|'.join(BUILTINS)})-(form|force2|force3)-\d{{4}}$")
    synthesised = [r for r in rows if pattern.match(r["id"])]
    procedures = {pattern.match(r["id"]).group(2) for r in synthesised}
    assert procedures == {"form", "force2", "force3"}
    assert all(r["status"] == "closure" and r["verified"] for r in synthesised)
    mine = [g for g in grasps if pattern.match(g["id"])]
    assert all(g["delta_fraction"] is None or 0 <= g["delta_fraction"] < 1 for g in mine)
    assert sum(g["delta_fraction"] is not None and g["delta_fraction"] > 0 for g in mine) > len(mine) / 2
    assert not any(r["id"].startswith("disc-form") for r in rows)  # no form closure of a disc
    check = runner.invoke(app, ["verify", str(out / "grasps" / "results.jsonl"),
                                "--grasps", str(out / "grasps" / "grasps.jsonl")])
    assert check.exit_code == 0, check.output

"""``qualgrasp demo``: the main job on the built-in objects.

Until the vision and synthesis halves land, the demo certifies the built-in textbook grasps
(:func:`certify.samples.textbook_grasps`), writes the grasp set and the results into ``out``, and
re-verifies every certificate.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from certify.batch import Summary, certify_file, verify_file
from certify.io import write_grasps
from certify.samples import textbook_grasps

__all__ = ["DemoResult", "run_demo"]


@dataclass(frozen=True)
class DemoResult:
    """Files the demo wrote and the summaries of certification and re-verification."""

    grasps: Path
    results: Path
    certified: Summary
    verified: Summary


def run_demo(out: str | Path) -> DemoResult:
    """Certify the textbook grasps into ``out/textbook.jsonl`` and ``out/textbook-results.jsonl``."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    grasps, results = out / "textbook.jsonl", out / "textbook-results.jsonl"
    write_grasps(grasps, textbook_grasps())
    certified = certify_file(grasps, results)
    return DemoResult(grasps, results, certified, verify_file(results, grasps))

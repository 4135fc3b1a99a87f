"""``qualgrasp demo``: the main job on the built-in objects, end to end.

1. The paper's figures 3 to 8 and figure 9, certified regions
   (:func:`qualgrasp.experiments.figures.make_figures`), into ``OUT/figures``.
2. Synthesis on the built-in camera images (polygon, hexagonal nut, circular contour, figure-3
   object): FormGrasp (4 frictionless fingers) and ForceGrasp (2 and 3 fingers, ``mu = 0.5``);
   every grasp written in certify's grasp format (``OUT/grasps/grasps.jsonl``, with the
   built-in textbook grasps, planar and spatial, appended), certified by the batch engine
   (``OUT/grasps/results.jsonl``: verdicts, margins, epsilons, certificates) and every certificate
   re-checked without a solver -- the same steps as ``qualgrasp synthesize``, ``certify`` and
   ``verify``.
3. The qualitative-versus-quantitative study on the built-in objects at the ``quick`` setting
   (:func:`qualgrasp.experiments.study.compare`) into ``OUT/study``.
4. ``OUT/report.md``: the headline numbers, with links to everything written.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from qualgrasp.certify.batch import RunSummary, Summary, certify_file, textbook_grasps, verify_file
from qualgrasp.certify.files import atomic_output, write_grasps
from qualgrasp.qualitative.objects import render
from qualgrasp.qualitative.synthesis.pipeline import MU, synthesize

from ..qualitative.synthesis import procedures
from .figures import STEMS, make_figures
from .study import BUILTINS, StudyResult, compare, workload

__all__ = ["DemoResult", "SynthesisRow", "run_demo", "demo_steps"]

@dataclass(frozen=True)
class SynthesisRow:
    """One object and procedure of the demo: outline string, grasps found and certified
    (``procedure`` is the procedure's title, ``method`` its registry name)."""

    name: str
    string: str
    procedure: str
    fingers: int
    grasps: int
    certified: int
    median_margin: float | None
    median_eps_l1: float | None
    seconds: float


@dataclass(frozen=True)
class DemoResult:
    """What the demo wrote and found."""

    out: Path
    figures: tuple[Path, ...]
    grasps: Path
    results: Path
    synthesis: tuple[SynthesisRow, ...]
    certified: RunSummary
    verified: Summary
    study: StudyResult
    report: Path
    seconds: float

    @property
    def ok(self) -> bool:
        """Every certificate re-checked, no error row, every synthesised grasp certified."""
        return (not self.verified.failures and not self.certified.errors
                and all(r.certified == r.grasps for r in self.synthesis))


def demo_steps(objects: int = len(BUILTINS)) -> int:
    """Number of progress messages :func:`run_demo` sends (for a progress bar's total)."""
    return len(STEMS) + objects * len(procedures.procedures()) + 2 + workload(objects, "quick")


def _synthesise(progress: Callable[[str], None]) -> tuple[list, list[SynthesisRow]]:
    grasps, rows = [], []
    for name in BUILTINS:
        image = render(name)
        for proc in procedures.procedures():
            s = synthesize(image, procedure=proc.name, mu=MU if proc.friction else None, name=name)
            summary = s.summary()
            grasps += s.grasps
            rows.append(SynthesisRow(name, s.outline.string, proc.title, proc.fingers, len(s.grasps),
                                     summary["certified"], summary["median_margin"],
                                     summary["median_eps_l1"], s.seconds))
            progress(f"{proc.title} {proc.fingers} on {name}: {len(s.grasps)} grasps")
    return grasps, rows


def run_demo(out: str | Path = "qualgrasp-demo", *,
             progress: Callable[[str], None] | None = None) -> DemoResult:
    """Run the demo into ``out`` (created); see the module notes for what is written.

    Parameters
    ----------
    out : str or pathlib.Path
        Output folder.
    progress : callable, optional
        Called with a short message after each step (:func:`demo_steps` of them in all).

    Returns
    -------
    DemoResult
    """
    start = time.perf_counter()
    tick = progress or (lambda message: None)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    figures = tuple(make_figures(out / "figures", progress=tick))
    grasps, rows = _synthesise(tick)
    folder = out / "grasps"
    folder.mkdir(exist_ok=True)
    grasps_path, results_path = folder / "grasps.jsonl", folder / "results.jsonl"
    write_grasps(grasps_path, list(grasps) + list(textbook_grasps()))
    certified = certify_file(grasps_path, results_path, workers=1)
    tick(f"certified {certified.rows} grasps")
    verified = verify_file(results_path, grasps_path, workers=1)
    tick(f"re-checked {verified.rows} certificates, {len(verified.failures)} failed")
    study = compare(BUILTINS, out / "study", settings="quick", progress=tick)
    partial = DemoResult(out, figures, grasps_path, results_path, tuple(rows), certified, verified,
                         study, out / "report.md", time.perf_counter() - start)
    write_report(partial)
    return partial


def _fmt(value: float | None, spec: str = ".3f") -> str:
    return "-" if value is None else format(value, spec)


def _link(path: Path, out: Path) -> str:
    rel = path.relative_to(out).as_posix()
    return f"[{rel}]({rel})"


def write_report(result: DemoResult) -> Path:
    """Write ``result.report`` (Markdown): headline numbers and links to every file."""
    out = result.out
    lines = ["# qualgrasp demo", "",
             f"Built-in objects {', '.join(BUILTINS)}; {result.seconds:.0f} s in all.", "",
             "## Synthesis and certification", "",
             "Grasps synthesised on the synthetic camera images, written in certify's grasp format, "
             "certified by the batch engine and every certificate re-checked without a solver "
             f"(ForceGrasp with mu = {MU}).", "",
             "| object | outline | procedure | fingers | grasps | certified | median margin | median eps (L1) | synthesis s |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in result.synthesis:
        lines.append(f"| {r.name} | `{r.string}` | {r.procedure} | {r.fingers} | {r.grasps} | {r.certified} | "
                     f"{_fmt(r.median_margin)} | {_fmt(r.median_eps_l1)} | {r.seconds:.2f} |")
    statuses = ", ".join(f"{k} {v}" for k, v in sorted(result.certified.statuses.items()))
    lines += ["", f"Certification of {_link(result.grasps, out)} (with the textbook grasps, planar and "
              f"spatial) into {_link(result.results, out)}: {result.certified.rows} rows ({statuses}); "
              f"re-check: {len(result.verified.failures)} of {result.verified.rows} certificates failed.", "",
              "## Qualitative versus quantitative", "",
              "Quick setting of the comparison study on the built-in objects (the baseline searches "
              "densely sampled boundary contacts for the best certified epsilon; robustness: the "
              "fraction of planned grasps that still certify when executed on the true object after "
              "a perturbation of the image; certified slide: median over objects of how far, as a "
              "fraction of the object's size, every finger of the route's best grasp may slide along "
              "the outline either way with force closure still certified; below resolution: certified "
              "grasps not counted as found, by the same rule for every route, because their certified "
              "epsilon is not above the wrench change the image's uncertainty can cause).", "",
              "| route | grasps | certified | below resolution | eps median | eps best | best / baseline best "
              "| s per object | robustness | certified slide |",
              "|---|---|---|---|---|---|---|---|---|---|"]
    for r in result.study.routes:
        lines.append(f"| {r.route} | {r.grasps} | {_fmt(r.certified_fraction)} | "
                     f"{dict(r.not_counted).get('below_resolution', 0)} | {_fmt(r.eps_median)} | "
                     f"{_fmt(r.eps_best)} | {_fmt(r.ratio_best)} | {_fmt(r.seconds_median, '.2f')} | "
                     f"{_fmt(r.robustness)} | {_fmt(r.slide_median)} |")
    lines.append("")
    for path in result.study.files:
        if path.suffix == ".png":
            lines.append(f"![{path.stem}]({path.relative_to(out).as_posix()})")
    lines += ["", "## The paper's figures", ""]
    for path in result.figures:
        if path.suffix == ".png":
            lines.append(f"![{path.stem}]({path.relative_to(out).as_posix()})")
    lines += ["", "## Files", ""]
    for path in (*result.figures, result.grasps, result.results, *result.study.files):
        lines.append(f"- {_link(path, out)}")
    with atomic_output(result.report, "--out") as tmp:
        tmp.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return result.report


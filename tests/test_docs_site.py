"""The documentation site under docs/: its pages exist and are reachable, every qualgrasp name it
mentions exists, its generated references say what the package and the command say, every gallery
script runs and draws, and (slow, with the ``docs`` extra installed) the whole site builds with
warnings as errors."""

from __future__ import annotations

import importlib.util
import re
import runpy
import shutil
import subprocess
import sys
from pathlib import Path

import matplotlib
import matplotlib.pyplot as plt
import pytest
from typer.testing import CliRunner

from qualgrasp.cli import app
from qualgrasp.experiments import figures, study_plots

DOCS = Path(__file__).resolve().parents[1] / "docs"
GALLERY = DOCS / "gallery"
SCRIPTS = sorted(GALLERY.glob("plot_*.py"))
GENERATED = ("_build", "_templates", "api/generated", "auto_examples", "gallery", "sg_execution_times.rst")
# pages written by the build, and the source each comes from
BUILT = {"auto_examples/index": GALLERY / "GALLERY_HEADER.rst"}
BUILT.update({f"auto_examples/{s.stem}": s for s in SCRIPTS})


def _load_extension():
    spec = importlib.util.spec_from_file_location("qualgrasp_docs", DOCS / "_ext" / "qualgrasp_docs.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


ext = _load_extension()


def _pages() -> list[Path]:
    """The hand-written reStructuredText pages (not the generated ones)."""
    return sorted(p for p in DOCS.rglob("*.rst")
                  if not any(p.relative_to(DOCS).as_posix().startswith(g) for g in GENERATED))


def _toctree_entries(page: Path) -> list[str]:
    """Document names listed by the toctrees of ``page``, relative to the docs root."""
    names, inside = [], False
    for line in page.read_text().splitlines():
        if line.startswith(".. toctree::"):
            inside = True
            continue
        if inside:
            if line.strip() and not line.startswith(" "):
                inside = False
            elif line.strip() and not line.strip().startswith(":"):
                entry = line.strip()
                base = page.parent.relative_to(DOCS)
                names.append((base / entry).as_posix() if not entry.startswith("/") else entry[1:])
    return names


def test_every_toctree_entry_is_a_page():
    listed = {name for page in _pages() for name in _toctree_entries(page)}
    assert listed, "no toctree found"
    for name in sorted(listed):
        source = BUILT.get(name, DOCS / f"{name}.rst")
        assert source.is_file(), f"toctree names {name!r}, but {source} does not exist"


def test_every_page_is_in_a_toctree():
    listed = {name for page in _pages() for name in _toctree_entries(page)}
    for page in _pages():
        name = page.relative_to(DOCS).with_suffix("").as_posix()
        assert name == "index" or name in listed, f"{page} is in no toctree"
    assert set(BUILT) - {"auto_examples/index"} == {f"auto_examples/{s.stem}" for s in SCRIPTS}
    assert "auto_examples/index" in listed


_ROLE = re.compile(r":(?:py:)?(?:func|class|mod|data|obj|attr|meth|exc):`~?([\w.]+)(?: <([\w.]+)>)?`")
_DIRECTIVE = re.compile(r"^\.\. qualgrasp-columns:: (\S+)", re.M)


def _mentions() -> list[tuple[str, str]]:
    """``(file, qualgrasp name)`` of every name a page or gallery script refers to by role."""
    found = []
    for path in _pages() + SCRIPTS:
        text = path.read_text()
        for match in _ROLE.finditer(text):
            name = match.group(2) or match.group(1)
            if name.startswith("qualgrasp"):
                found.append((path.name, name))
        found += [(path.name, name) for name in _DIRECTIVE.findall(text)]
    return found


def test_every_name_the_pages_mention_exists():
    mentions = _mentions()
    assert len(mentions) > 50
    for where, name in mentions:
        try:
            ext.import_object(name)
        except ImportError as err:
            pytest.fail(f"{where} refers to {name}, which does not exist ({err})")


_INLINE_MATH = re.compile(r":math:`([^`]+)`")


def _math(text: str) -> list[str]:
    """The LaTeX of every ``:math:`` role and ``.. math::`` block of a page."""
    found = _INLINE_MATH.findall(text)
    lines = text.splitlines()
    for k, line in enumerate(lines):
        if line.strip() == ".. math::":
            body = []
            for nxt in lines[k + 1:]:
                if nxt.strip() and not nxt.startswith(" "):
                    break
                body.append(nxt.strip())
            found.append(" ".join(body).strip())
    return found


def test_every_formula_converts_to_mathml():
    from docutils.utils.math import latex2mathml

    formulas = [(page.name, tex) for page in _pages() for tex in _math(page.read_text())]
    assert len(formulas) > 30
    for where, tex in formulas:
        try:
            latex2mathml.tex2mathml(tex)
        except Exception as err:  # the converter's errors have no common base class
            pytest.fail(f"{where}: {tex!r} cannot be written as MathML: {err}")


def test_gallery_draws_every_figure_and_study_plot():
    stems = {s.stem.removeprefix("plot_") for s in SCRIPTS}
    assert set(figures.STEMS) <= stems, f"figures without a gallery script: {set(figures.STEMS) - stems}"
    written = set(re.findall(r"``(study-[a-z-]+)``", study_plots.__doc__))
    shown = set(re.findall(r'show\("(study-[a-z-]+)"\)', (GALLERY / "plot_study.py").read_text()))
    assert written and shown == written


def test_public_names_point_at_the_same_object():
    elsewhere = ext.public_names()
    assert elsewhere["qualgrasp.certify.core.certificates.verify"] == "qualgrasp.verify"
    assert elsewhere["qualgrasp.certify.Contact"] == "qualgrasp.Contact"
    assert "qualgrasp.verify" not in elsewhere  # the canonical name has the page
    for path, canonical in elsewhere.items():
        assert canonical not in elsewhere, f"{canonical} is not canonical"
        assert canonical.count(".") <= path.count(".")
        assert ext.import_object(path) is ext.import_object(canonical), path
    assert ext.canonical_path("qualgrasp.certify.Certificate.from_json", elsewhere) == \
        "qualgrasp.Certificate.from_json"


def test_cli_reference_has_every_command_and_option():
    import typer.main

    command = typer.main.get_command(app)
    text = "\n".join(ext.cli_lines(command, "qualgrasp"))
    runner = CliRunner()
    names = re.findall(r"^qualgrasp ([a-z0-9-]+)\n-+$", text, re.M)
    assert len(names) >= 14 and {"certify", "verify", "synthesize", "st0", "demo"} <= set(names)
    for name in names:
        result = runner.invoke(app, [name, "--help"], terminal_width=200)
        assert result.exit_code == 0, result.output
        # the options the command's own --help prints, each in the reference
        options = set(re.findall(r"(?<![\w-])(--[a-z][a-z0-9-]*)", result.output)) - {"--help"}
        section = text.split(f"qualgrasp {name}\n", 1)[1].split("\nqualgrasp ", 1)[0]
        for option in options:
            assert f"``{option}" in section or f" {option}" in section or f"/ {option}" in section, \
                f"qualgrasp {name}: {option} missing from the reference"


def test_help_markup_keeps_dashes_literal():
    assert ext.help_markup("one of --grasps and -o, hi - lo * 2") == \
        r"one of ``--grasps`` and ``-o``, hi - lo \* 2"


@pytest.mark.skipif(tuple(int(p) for p in matplotlib.__version__.split(".")[:2]) < (3, 11),
                    reason="the gallery hands figures to pyplot with plt.figure(fig), matplotlib >= 3.11")
@pytest.mark.parametrize("script", [pytest.param(s, marks=pytest.mark.slow) if s.stem == "plot_study" else s
                                    for s in SCRIPTS], ids=lambda s: s.stem)
def test_gallery_script_runs_and_draws(script, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(sys, "argv", [str(script)])
    plt.close("all")
    try:
        with matplotlib.rc_context():  # the scripts set the figures' style: keep it to them
            runpy.run_path(str(script), run_name="__main__")
            numbers = plt.get_fignums()
            assert numbers, f"{script.name} left no figure for the gallery to show"
            for number in numbers:
                assert plt.figure(number).get_axes() or plt.figure(number).images, \
                    f"{script.name}: figure {number} is empty"
    finally:
        plt.close("all")


_DOCS_TOOLS = ("sphinx", "pydata_sphinx_theme", "numpydoc", "sphinx_gallery")


@pytest.mark.slow
@pytest.mark.skipif(any(importlib.util.find_spec(m) is None for m in _DOCS_TOOLS),
                    reason='the documentation tools are not installed (pip install -e ".[docs]")')
def test_site_builds_with_warnings_as_errors(tmp_path):
    source = tmp_path / "docs"
    shutil.copytree(DOCS, source, ignore=shutil.ignore_patterns(
        "_build", "generated", "auto_examples", "sg_execution_times.rst"))
    out = tmp_path / "html"
    run = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-b", "html", "-q",
                          str(source), str(out)], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr[-4000:]
    for page in ("index.html", "getting-started.html", "cli.html", "formats.html",
                 "api/generated/qualgrasp.verify.html", "api/generated/qualgrasp.certify.html",
                 "auto_examples/plot_fig3_outline.html", "auto_examples/plot_study.html"):
        assert (out / page).is_file(), page
    cli = (out / "cli.html").read_text()
    assert "qualgrasp certify-regions" in cli and "--eps-time" in cli
    assert "<math" in (out / "concepts" / "epsilon.html").read_text()
    assert list((out / "_images").glob("sphx_glr_plot_fig9_regions_*.png"))

"""The documented public API: every function ``qualgrasp`` exports has numpydoc sections, every
Examples section in the package runs (doctests), and so does README's Python example."""

import ast
import doctest
import importlib
import inspect
import pkgutil
from pathlib import Path

import pytest

import qualgrasp

FUNCTIONS = [name for name in qualgrasp.__all__ if inspect.isfunction(getattr(qualgrasp, name))]


@pytest.mark.parametrize("name", FUNCTIONS)
def test_exported_functions_have_numpydoc_sections(name):
    doc = inspect.getdoc(getattr(qualgrasp, name)) or ""
    for section in ("Parameters", "Returns", "Examples"):
        assert f"{section}\n---" in doc, f"{name}: no {section} section"


def _modules():
    names = ["qualgrasp"]
    for info in pkgutil.walk_packages(qualgrasp.__path__, "qualgrasp."):
        names.append(info.name)
    return names


@pytest.mark.parametrize("module", _modules())
def test_examples_run(module):
    mod = importlib.import_module(module)
    finder = doctest.DocTestFinder(exclude_empty=True)
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    for test in finder.find(mod, module):
        if test.examples:
            runner.run(test)
    assert runner.failures == 0, f"{runner.failures} failing example(s) in {module}"


def _readme_block(heading: str) -> str:
    """The first ```python block after ``heading`` in README.md."""
    text = (Path(__file__).resolve().parents[1] / "README.md").read_text()
    after = text[text.index(f"\n{heading}\n"):]
    start = after.index("```python\n") + len("```python\n")
    return after[start:after.index("```", start)]


def test_readme_python_api_example_runs_as_written():
    """README's "Python API at a glance" runs as written, and its last line is True as it says."""
    code = _readme_block("## Python API at a glance")
    tree = ast.parse(code)
    last = tree.body.pop()
    assert isinstance(last, ast.Expr) and code.splitlines()[-1].rstrip().endswith("# True")
    namespace: dict = {}
    exec(compile(tree, "README.md", "exec"), namespace)
    assert eval(compile(ast.Expression(last.value), "README.md", "eval"), namespace) is True


def _readme_command(marker: str) -> str:
    lines = (Path(__file__).resolve().parents[1] / "README.md").read_text().splitlines()
    return lines[lines.index(f"<!-- {marker} -->") + 2]


@pytest.mark.parametrize("marker", ["demo-command", "test-command", "slow-test-command"])
def test_getting_started_gives_the_readme_commands(marker):
    """The documentation site's getting-started page gives the README's commands as written
    (``.ci/run`` runs the README's)."""
    page = (Path(__file__).resolve().parents[1] / "docs" / "getting-started.rst").read_text()
    assert _readme_command(marker).startswith(("python3 ", ". .venv"))
    assert f"   {_readme_command(marker)}\n" in page

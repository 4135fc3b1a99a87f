"""The documented public API: every function ``qualgrasp`` exports has numpydoc sections, and
every Examples section in the package runs (doctests)."""

import doctest
import importlib
import inspect
import pkgutil

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

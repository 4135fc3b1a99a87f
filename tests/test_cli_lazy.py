"""The command's fast first answer: ``qualgrasp --help`` and ``--version`` load no numerical library,
``import qualgrasp`` loads its names on first use, and the help's summaries are the commands' own."""

from __future__ import annotations

import inspect
import json
import subprocess
import sys

import pytest

import qualgrasp
from qualgrasp.cli import COMMANDS, registered_commands

# the numerical libraries, and click, which typer vendors and qualgrasp does not depend on
HEAVY = ("numba", "numpy", "scipy", "cvxpy", "clarabel", "matplotlib", "pyarrow", "trimesh", "cv2", "shapely",
         "click")


def _loaded_after(code: str) -> list[str]:
    probe = (f"import sys, json\n{code}\n"
             f"print(json.dumps(sorted({{m.split('.')[0] for m in sys.modules}} & set({HEAVY!r}))))")
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True).stdout
    return json.loads(out.splitlines()[-1])


@pytest.mark.parametrize("argv", [["--help"], ["--version"], []])
def test_help_and_version_load_no_numerical_library(argv):
    code = ("from qualgrasp.cli import main\n"
            f"sys.argv = ['qualgrasp', *{argv!r}]\n"
            "try:\n    main()\nexcept SystemExit:\n    pass")
    assert _loaded_after(code) == []


def test_import_loads_names_on_first_use():
    assert _loaded_after("import qualgrasp") == []
    assert "numpy" in _loaded_after("import qualgrasp; qualgrasp.Grasp")


def test_lazy_names_are_the_halves_own():
    from qualgrasp.certify import Grasp
    from qualgrasp.qualitative.synthesis import synthesize

    assert qualgrasp.Grasp is Grasp and qualgrasp.synthesize is synthesize
    assert set(qualgrasp.__all__) <= set(dir(qualgrasp))
    assert all(getattr(qualgrasp, name) is not None for name in qualgrasp.__all__)
    assert qualgrasp.certify.__name__ == "qualgrasp.certify"
    with pytest.raises(AttributeError, match="no attribute 'nothing'"):
        qualgrasp.nothing


def test_summaries_are_the_commands_first_paragraphs():
    modules = list(dict.fromkeys(module for module, _ in COMMANDS.values()))
    registered = {}
    for module in modules:
        registered.update(registered_commands(module))
    assert list(registered) == list(COMMANDS)  # every command listed once, in registration order
    for name, (module, summary) in COMMANDS.items():
        first = inspect.cleandoc(registered[name].help or "").split("\n\n")[0]
        assert " ".join(first.split()) == summary, name
        assert registered[name].callback.__module__.startswith(module), name


def test_unknown_command_is_refused(tmp_path):
    from typer.testing import CliRunner

    from qualgrasp.cli import app

    result = CliRunner().invoke(app, ["nosuch"])
    assert result.exit_code == 2 and "No such command" in result.output


def test_help_paragraphs_are_not_broken_where_the_source_breaks():
    """A command's help prints each paragraph as one text that rich wraps to the terminal, not
    with the docstring's own line breaks (the sample command's source breaks after 'With')."""
    from typer.testing import CliRunner

    from qualgrasp.cli import app

    result = CliRunner().invoke(app, ["sample", "--help"], env={"COLUMNS": "400"}, terminal_width=400)
    assert result.exit_code == 0
    assert "in closure. With --degenerate KIND, the contacts are placed" in result.output

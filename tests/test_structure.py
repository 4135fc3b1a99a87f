"""The package's structure: one top-level name, its layers (certify imports nothing of the other
halves, qualitative nothing of experiments; inside qualitative, reasoning nothing of vision or
synthesis and no domain subpackage anything of the plots), no import cycles, no private name
imported across modules and no private module imported from outside its package, imports inside
functions only for optional dependencies, and the registries. The import graph is read with ``ast``
(``import_graph.py``)."""

import ast
import pathlib
import sys
import sysconfig

import pytest

import import_graph
import qualgrasp

ROOT = pathlib.Path(qualgrasp.__file__).parent
#: Imports allowed inside functions: optional dependencies (dask.distributed, pymunk, h5py for ACRONYM
#: pose files, embreex and trimesh's embree route where embreex installs), a platform module
#: (resource), cvxpy's reference route (1.5 s to import; only ``make_solver("reference")``
#: needs it), cvxopt, which only Dex-Net's code run by ``bench --single --dexnet`` needs, and the
#: meshes' pose source in ``certify``'s command (trimesh and networkx: 0.2 s of every ``certify``
#: start-up, for runs on a mesh only).
LAZY = {"distributed", "resource", "qualgrasp.certify.solvers.reference", "h5py", "embreex",
        "trimesh.ray.ray_pyembree", "pymunk", "mujoco", "coacd", "cvxopt", "qualgrasp.certify.meshes.source",
        "scipy.optimize"}  # linprog: a benchmark's method and a fallback, 0.09 s of every certify's start-up

MODULES = import_graph.modules(ROOT)


def _imports():
    """``(module, target, names, inside a function)`` of every import of the package."""
    return import_graph.imports(MODULES)


def test_modules_are_found():
    assert {"qualgrasp.certify.core.grasp", "qualgrasp.qualitative.synthesis.pipeline", "qualgrasp.experiments.study",
            "qualgrasp.cli", "qualgrasp.certify.models.pad", "qualgrasp.qualitative.vision.outline",
            "qualgrasp.qualitative.reasoning.st0", "qualgrasp.qualitative.plots.grasp"} <= set(MODULES)


def test_no_private_name_is_imported_across_modules():
    bad = [(m, t, n) for m, t, names, _ in _imports() if t.startswith("qualgrasp")
           for n in names if n.startswith("_") and not n.startswith("__")]
    assert not bad


def test_imports_inside_functions_only_for_optional_dependencies():
    bad = [(m, t) for m, t, _, inner in _imports() if inner and t.split(".")[0] not in LAZY and t not in LAZY]
    assert not bad


def test_no_import_cycles():
    # a package's __init__ importing its own submodules is not a cycle unless a submodule imports
    # the package back
    assert not import_graph.cycles(import_graph.edges(MODULES))


def test_the_graph_checks_find_faults():
    assert import_graph.cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == [["a", "b", "c", "a"]]
    assert import_graph.longest_chain({"a": {"b"}, "b": {"c"}, "c": set()}, "") == ["a", "b", "c"]
    graph = {"q.c.regions": {"q.c.regions._branch"}, "q.c.regions.decide": {"q.c.regions._branch"},
             "q.c.batch.chunk": {"q.c.regions._branch", "q.c._kernels.lp"}, "q.x": {"q.c._kernels.lp"}}
    assert import_graph.private_imports(graph) == [("q.c.batch.chunk", "q.c.regions._branch"),
                                                   ("q.x", "q.c._kernels.lp")]


VISION, REASONING, SYNTHESIS, PLOTS = (f"qualgrasp.qualitative.{p}" for p in ("vision", "reasoning", "synthesis", "plots"))


def _under(module: str, packages: tuple[str, ...]) -> bool:
    return any(module == p or module.startswith(p + ".") for p in packages)


@pytest.mark.parametrize("half, never", [("qualgrasp.certify", ("qualgrasp.qualitative", "qualgrasp.experiments")),
                                         ("qualgrasp.qualitative", ("qualgrasp.experiments",)),
                                         (REASONING, (VISION, SYNTHESIS, PLOTS)),
                                         (VISION, (SYNTHESIS, PLOTS)),
                                         (SYNTHESIS, (PLOTS,))],
                         ids=["certify", "qualitative", "reasoning", "vision", "synthesis"])
def test_layers(half, never):
    """certify is the base layer: it imports nothing of qualitative or experiments; qualitative
    imports nothing of experiments. Inside qualitative, reasoning (RCC-8, ST0) imports nothing of
    vision, synthesis or the plots, vision nothing of synthesis or the plots, and synthesis nothing
    of the plots: the figures sit above the domain code. Inside functions neither."""
    graph = import_graph.edges(MODULES, inner=True)
    bad = sorted((m, t) for m, targets in graph.items() if _under(m, (half,))
                 for t in targets if _under(t, never))
    assert not bad


def test_private_modules_stay_in_their_package():
    """A module or package whose name starts with ``_`` (``certify/regions/_branch.py``,
    ``certify/_kernels/``) is imported only from inside the package that holds it."""
    assert not import_graph.private_imports(import_graph.edges(MODULES, inner=True))


def test_only_qualgrasp_is_installed_as_a_top_level_name():
    """The installed distribution (regular or editable) provides one importable name."""
    site = pathlib.Path(sysconfig.get_paths()["purelib"])
    infos = sorted(site.glob("qualgrasp-*.dist-info"))
    assert len(infos) == 1
    record = (infos[0] / "RECORD").read_text().splitlines()
    paths = [line.split(",")[0] for line in record]
    finder = [p for p in paths if p.startswith("__editable__") and p.endswith("_finder.py")]
    if finder:  # editable: the finder maps top-level names to folders
        tree = ast.parse((site / finder[0]).read_text())
        mapping = next(ast.literal_eval(n.value) for n in tree.body
                       if isinstance(n, ast.AnnAssign) and getattr(n.target, "id", "") == "MAPPING")
        assert set(mapping) == {"qualgrasp"}
    else:
        tops = {p.split("/")[0] for p in paths if p.endswith(".py") and not p.startswith("..")}
        assert tops == {"qualgrasp"}


@pytest.mark.parametrize("name", ["certify", "qualitative", "experiments"])
def test_halves_are_not_importable_on_their_own(name, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # away from a checkout whose folders would be found by path
    monkeypatch.setattr(sys, "path", [p for p in sys.path if p not in ("", str(ROOT), ".")])
    with pytest.raises(ModuleNotFoundError):
        __import__(name)


def _model_name_comparisons(tree: ast.AST, names: set[str]) -> list[int]:
    """Lines of ``x == "point"``, ``x != "soft"`` or ``x in ("pad", ...)`` with a model's name."""
    def named(node):
        if isinstance(node, ast.Constant):
            return node.value in names
        return isinstance(node, (ast.Tuple, ast.List, ast.Set)) and any(named(e) for e in node.elts)

    return [node.lineno for node in ast.walk(tree) if isinstance(node, ast.Compare)
            and any(named(side) for side in (node.left, *node.comparators))]


def test_only_models_branch_on_a_model_name():
    # a model owns its forms: no code of the library outside certify/models asks which model a
    # contact is by name (defaults, options and docstring examples may name one: they choose)
    from qualgrasp.certify import models

    names = set(models.names())
    bad = {m: lines for m, path in MODULES.items() if m.split(".")[1:2] in (["certify"], ["qualitative"])
           and not m.startswith("qualgrasp.certify.models")
           and (lines := _model_name_comparisons(import_graph.parse(path), names))}
    assert not bad
    assert _model_name_comparisons(ast.parse('if c.model == "pad" or m in ("x", "soft"): pass'), names) == [1, 1]

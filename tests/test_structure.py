"""The package's structure: one top-level name, no import cycles, no private name imported
across modules, imports inside functions only for optional dependencies, and the registries."""

import ast
import collections
import pathlib
import sys
import sysconfig

import pytest

import qualgrasp

ROOT = pathlib.Path(qualgrasp.__file__).parent
#: Imports allowed inside functions: optional dependencies (dask.distributed), a platform module
#: (resource), and cvxpy's reference route (1.5 s to import; only ``make_solver("reference")``
#: needs it).
LAZY = {"distributed", "resource", "qualgrasp.certify.solvers.reference"}


def _modules():
    out = {}
    for path in ROOT.rglob("*.py"):
        rel = path.relative_to(ROOT)
        if rel.parts[0] not in ("certify", "qualitative", "experiments") and len(rel.parts) > 1:
            continue
        if rel.parts[0] in ("tests", "docs") or "data" in rel.parts:
            continue
        parts = list(rel.with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(["qualgrasp"] + parts)] = path
    return out


MODULES = _modules()


def _target(module: str, node: ast.ImportFrom, is_package: bool) -> str:
    if node.level == 0:
        return node.module or ""
    base = module.split(".") if is_package else module.split(".")[:-1]
    base = base[: len(base) - (node.level - 1)]
    return ".".join(base + ([node.module] if node.module else []))


def _imports():
    """``(module, target, names, inside a function)`` of every import of the package."""
    for module, path in MODULES.items():
        tree = ast.parse(path.read_text())
        inner = {id(n) for f in ast.walk(tree) if isinstance(f, (ast.FunctionDef, ast.AsyncFunctionDef))
                 for n in ast.walk(f) if isinstance(n, (ast.Import, ast.ImportFrom))}
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom):
                target = _target(module, node, path.name == "__init__.py")
                yield module, target, [a.name for a in node.names], id(node) in inner
            elif isinstance(node, ast.Import):
                for a in node.names:
                    yield module, a.name, [], id(node) in inner


def test_modules_are_found():
    assert {"qualgrasp.certify.core.grasp", "qualgrasp.qualitative.synthesis", "qualgrasp.experiments.study",
            "qualgrasp.cli", "qualgrasp.certify.models.pad"} <= set(MODULES)


def test_no_private_name_is_imported_across_modules():
    bad = [(m, t, n) for m, t, names, _ in _imports() if t.startswith("qualgrasp")
           for n in names if n.startswith("_") and not n.startswith("__")]
    assert not bad


def test_imports_inside_functions_only_for_optional_dependencies():
    bad = [(m, t) for m, t, _, inner in _imports() if inner and t.split(".")[0] not in LAZY and t not in LAZY]
    assert not bad


def test_no_import_cycles():
    edges = collections.defaultdict(set)
    for m, t, names, inner in _imports():
        if inner or not t.startswith("qualgrasp"):
            continue
        for n in names or [None]:
            full = f"{t}.{n}" if n else t
            edges[m].add(full if full in MODULES else t)
    seen, stack, cycles = {}, [], []

    def visit(v):
        seen[v] = 1
        stack.append(v)
        for w in edges.get(v, ()):
            if w not in MODULES or w == v:
                continue
            if seen.get(w) == 1:
                cycles.append(stack[stack.index(w):] + [w])
            elif w not in seen:
                visit(w)
        stack.pop()
        seen[v] = 2

    sys.setrecursionlimit(10_000)
    for v in MODULES:
        if v not in seen:
            visit(v)
    # a package's __init__ importing its own submodules is not a cycle unless a submodule imports
    # the package back
    assert not cycles


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

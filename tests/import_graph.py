"""The package's import graph, read with ``ast`` (nothing is imported): its modules, their
imports, the longest import chain and the public names.

The structure tests (``test_structure.py``) check the graph; run as a script it prints the
figures of the package's plan::

    python tests/import_graph.py            # modules per folder, longest chain, public names
    python tests/import_graph.py --chain    # and the longest chain itself
"""

from __future__ import annotations

import ast
import collections
import functools
import pathlib
import sys
from typing import Iterator, NamedTuple

ROOT = pathlib.Path(__file__).resolve().parents[1]
HALVES = ("certify", "qualitative", "experiments")


class Import(NamedTuple):
    module: str  # the importing module
    target: str  # the module named by the import statement
    names: list[str]  # the names ``from target import ...`` takes ([] for ``import target``)
    inner: bool  # inside a function


def modules(root: pathlib.Path = ROOT) -> dict[str, pathlib.Path]:
    """``{dotted name: path}`` of every production module (not tests, docs or data)."""
    out = {}
    for path in root.rglob("*.py"):
        rel = path.relative_to(root)
        if rel.parts[0] not in HALVES and len(rel.parts) > 1:
            continue
        if rel.parts[0] in ("tests", "docs") or "data" in rel.parts:
            continue
        parts = list(rel.with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(["qualgrasp"] + parts)] = path
    return out


def _target(module: str, node: ast.ImportFrom, is_package: bool) -> str:
    if node.level == 0:
        return node.module or ""
    base = module.split(".") if is_package else module.split(".")[:-1]
    base = base[: len(base) - (node.level - 1)]
    return ".".join(base + ([node.module] if node.module else []))


@functools.lru_cache(maxsize=None)
def _parsed(path: pathlib.Path, stamp: tuple[int, int]) -> ast.Module:
    """The syntax tree of a source file, parsed once per process for its size and modification
    time ``stamp`` (several structure tests read every module). Callers must not change it."""
    return ast.parse(path.read_text())


def parse(path: pathlib.Path) -> ast.Module:
    """The syntax tree of ``path`` (shared: do not change it)."""
    st = path.stat()
    return _parsed(path, (st.st_size, st.st_mtime_ns))


@functools.lru_cache(maxsize=None)
def _file_imports(module: str, path: pathlib.Path, stamp: tuple[int, int]) -> tuple[Import, ...]:
    tree = _parsed(path, stamp)
    inner = {id(n) for f in ast.walk(tree) if isinstance(f, (ast.FunctionDef, ast.AsyncFunctionDef))
             for n in ast.walk(f) if isinstance(n, (ast.Import, ast.ImportFrom))}
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            target = _target(module, node, path.name == "__init__.py")
            out.append(Import(module, target, [a.name for a in node.names], id(node) in inner))
        elif isinstance(node, ast.Import):
            for a in node.names:
                out.append(Import(module, a.name, [], id(node) in inner))
    return tuple(out)


def imports(found: dict[str, pathlib.Path] | None = None) -> Iterator[Import]:
    """Every import statement of the package's modules."""
    found = modules() if found is None else found
    for module, path in found.items():
        st = path.stat()
        yield from _file_imports(module, path, (st.st_size, st.st_mtime_ns))


def edges(found: dict[str, pathlib.Path] | None = None, *, inner: bool = False) -> dict[str, set[str]]:
    """``{module: modules it imports}`` inside the package; ``from p import m`` names the
    submodule ``p.m`` when there is one, else ``p``. Imports inside functions only if ``inner``."""
    found = modules() if found is None else found
    out: dict[str, set[str]] = collections.defaultdict(set)
    for imp in imports(found):
        if (imp.inner and not inner) or not imp.target.startswith("qualgrasp"):
            continue
        for n in imp.names or [None]:
            full = f"{imp.target}.{n}" if n else imp.target
            hit = full if full in found else imp.target
            if hit in found and hit != imp.module:
                out[imp.module].add(hit)
    return out


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Import cycles of ``graph`` (each as a list of modules, first == last)."""
    seen: dict[str, int] = {}
    stack: list[str] = []
    out: list[list[str]] = []

    def visit(v: str) -> None:
        seen[v] = 1
        stack.append(v)
        for w in sorted(graph.get(v, ())):
            if seen.get(w) == 1:
                out.append(stack[stack.index(w):] + [w])
            elif w not in seen:
                visit(w)
        stack.pop()
        seen[v] = 2

    sys.setrecursionlimit(10_000)
    for v in sorted(graph):
        if v not in seen:
            visit(v)
    return out


def private_imports(graph: dict[str, set[str]]) -> list[tuple[str, str]]:
    """``(importer, module)`` of every import of a private module (a part of its name starts with
    ``_``) from outside the package that holds it."""
    bad = []
    for m, targets in sorted(graph.items()):
        for t in sorted(targets):
            parts = t.split(".")
            private = [k for k, p in enumerate(parts) if p.startswith("_") and not p.startswith("__")]
            if private:
                home = ".".join(parts[:private[0]])
                if not (m == home or m.startswith(home + ".")):
                    bad.append((m, t))
    return bad


def longest_chain(graph: dict[str, set[str]], within: str = "qualgrasp") -> list[str]:
    """The longest chain of imports ``a imports b imports c ...`` among modules under ``within``
    (the graph must have no cycle). A package's ``__init__`` counts as a module."""

    @functools.cache
    def chain(v: str) -> tuple[str, ...]:
        nxt = [chain(w) for w in graph.get(v, ()) if w.startswith(within)]
        return (v,) + max(nxt, key=len, default=())

    starts = [v for v in graph if v.startswith(within)]
    return list(max((chain(v) for v in starts), key=len, default=()))


def without_packages(graph: dict[str, set[str]], found: dict[str, pathlib.Path]) -> dict[str, set[str]]:
    """``graph`` with every package ``__init__`` contracted away: a module importing a package
    imports what the package's ``__init__`` imports (the floors of real modules)."""
    packages = {m for m, p in found.items() if p.name == "__init__.py"}

    @functools.cache
    def through(v: str) -> frozenset[str]:
        out = set()
        for w in graph.get(v, ()):
            out |= through(w) if w in packages else {w}
        return frozenset(out)

    return {v: set(through(v)) for v in graph if v not in packages}


def defined_public_names(found: dict[str, pathlib.Path] | None = None) -> dict[str, list[str]]:
    """``{module: names}`` of the public names each public module defines itself (functions,
    classes, assignments; not names it imports or re-exports)."""
    found = modules() if found is None else found
    out = {}
    for module, path in found.items():
        if any(p.startswith("_") for p in module.split(".")):
            continue
        names = []
        for node in parse(path).body:
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                names.append(node.name)
            elif isinstance(node, (ast.Assign, ast.AnnAssign)):
                targets = node.targets if isinstance(node, ast.Assign) else [node.target]
                names += [n.id for t in targets for n in ast.walk(t) if isinstance(n, ast.Name)]
        out[module] = sorted({n for n in names if not n.startswith("_")})
    return out


def public_names(found: dict[str, pathlib.Path] | None = None) -> dict[str, list[str]]:
    """``{module: its public names}`` of every public module (no ``_`` part in its dotted name):
    the names in ``__all__`` when the module has one, else every top-level name it binds (defines,
    assigns or imports) without a leading underscore."""
    found = modules() if found is None else found
    out = {}
    for module, path in found.items():
        if any(p.startswith("_") for p in module.split(".")):
            continue
        tree = parse(path)
        names: list[str] = []
        listed = None
        for node in tree.body:
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                names.append(node.name)
            elif isinstance(node, (ast.Assign, ast.AnnAssign)):
                targets = node.targets if isinstance(node, ast.Assign) else [node.target]
                for t in targets:
                    for n in ast.walk(t):
                        if isinstance(n, ast.Name):
                            names.append(n.id)
                            if n.id == "__all__" and node.value is not None:
                                listed = [e.value for e in node.value.elts]
            elif isinstance(node, (ast.Import, ast.ImportFrom)):
                names += [(a.asname or a.name).split(".")[0] for a in node.names]
        public = listed if listed is not None else [n for n in names if not n.startswith("_")]
        out[module] = sorted(set(public) - {"annotations"})
    return out


def report(show_chain: bool = False) -> None:
    found = modules()
    folders = collections.Counter(str(p.parent.relative_to(ROOT)) for p in found.values())
    print("modules per folder:")
    for folder, n in sorted(folders.items()):
        print(f"  {folder:24} {n}")
    print(f"  {'total':24} {len(found)}")
    graph = edges(found)
    print(f"import cycles: {len(cycles(graph))}")
    flat = without_packages(graph, found)
    for within in ("qualgrasp", "qualgrasp.certify"):
        for label, g in (("modules and package __init__s", graph), ("modules, packages contracted", flat)):
            chain = longest_chain(g, within)
            print(f"longest import chain under {within} ({label}): {len(chain)}")
            if show_chain:
                print("  " + "\n  -> ".join(chain))
    for label, names in (("public names (__all__, else every public top-level name)", public_names(found)),
                         ("public names defined (not re-exported)", defined_public_names(found))):
        certify = {m: n for m, n in names.items() if m.startswith("qualgrasp.certify")}
        print(f"{label}: {sum(map(len, names.values()))} in {len(names)} public modules; "
              f"qualgrasp.certify: {sum(map(len, certify.values()))} in {len(certify)} modules")


if __name__ == "__main__":
    report(show_chain="--chain" in sys.argv)

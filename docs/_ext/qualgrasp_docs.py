"""Sphinx extension of the qualgrasp documentation: everything the site states about commands,
columns and public names is read from the package itself, never copied by hand.

* ``.. qualgrasp-cli::`` writes the command-line reference by walking the typer application
  (:data:`qualgrasp.cli.app`, through :func:`typer.main.get_command`): every command's usage, its
  help text, and every argument and option with its help, default and whether it is required,
  exactly as ``qualgrasp COMMAND --help`` prints them (``get_help_record``).
* ``.. qualgrasp-columns:: DOTTED.NAME`` writes a table of a schema given as a sequence of
  objects with ``name``, ``type``, ``description`` and ``error`` (the results schema,
  ``qualgrasp.certify.files.results.COLUMNS``).
* Math is written as MathML (``html_math_renderer = "mathml"``), which browsers render natively:
  no MathJax from a CDN, so the pages also read right offline.
* Public names: a function or class re-exported by several modules (``qualgrasp.verify`` is
  ``qualgrasp.certify.verify`` is ``qualgrasp.certify.core.certificates.verify``) gets one API page,
  under its shortest public name. :func:`public_names` finds, for every other path, that
  canonical name; the autosummary templates list such names as links rather than pages
  (``autosummary_context['elsewhere']``), and :func:`resolve_elsewhere` resolves a reference to
  any of the paths to the one page. A reference to a ``qualgrasp`` name that does not exist at all
  is a warning (so a ``-W`` build fails when a page names a function that moved).

Only duck-typed attributes of the click-style command objects are used (``params``,
``list_commands``, ``get_command``, ``make_context``, ``get_usage``, ``get_help_record``), so the
same code works with typer's bundled command classes and with click's.
"""

from __future__ import annotations

import importlib
import inspect
import pkgutil
import re
from typing import Any, Iterator

from docutils import nodes
from docutils.parsers.rst import directives
from docutils.statemachine import StringList
from sphinx.application import Sphinx
from sphinx.util import logging
from sphinx.util.docutils import SphinxDirective
from sphinx.util.nodes import nested_parse_with_titles

logger = logging.getLogger(__name__)

PACKAGE = "qualgrasp"
# folders of the repository root (the package's own folder) that are not part of the package
_SKIP = (f"{PACKAGE}.tests", f"{PACKAGE}.docs")

# -------------------------------------------------------------------------------- helpers

_SPECIAL = re.compile(r"([\\`*_|\[\]<>:])")


def escape(text: str) -> str:
    """``text`` as literal reStructuredText (every markup character backslash-escaped)."""
    return _SPECIAL.sub(r"\\\1", text)


def import_object(path: str) -> Any:
    """The object at dotted ``path`` (a module, or an attribute of one); ImportError if none."""
    parts = path.split(".")
    for cut in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:cut]))
        except ImportError:
            continue
        try:
            for name in parts[cut:]:
                obj = getattr(obj, name)
        except AttributeError:
            raise ImportError(f"{path}: no attribute {name!r} in {'.'.join(parts[:cut])}") from None
        return obj
    raise ImportError(f"{path}: no such module")


# -------------------------------------------------------------------------------- public names

def public_modules(package: str = PACKAGE) -> Iterator[Any]:
    """Every module of ``package`` whose dotted name has no private part, the package first."""
    root = importlib.import_module(package)
    yield root
    for info in pkgutil.walk_packages(root.__path__, prefix=package + "."):
        if any(part.startswith("_") for part in info.name.split(".")):
            continue
        if info.name in _SKIP or info.name.startswith(tuple(f"{s}." for s in _SKIP)):
            continue
        yield importlib.import_module(info.name)


def public_names(package: str = PACKAGE) -> dict[str, str]:
    """``{path: canonical path}`` of every function and class of ``package`` that modules list
    in ``__all__`` under more than one path, for every path but the canonical one.

    The canonical path is the shortest (fewest dots); among equally short ones the defining
    module's, then the first in import order.
    """
    paths: dict[int, list[str]] = {}
    objects: dict[int, Any] = {}
    for module in public_modules(package):
        for name in getattr(module, "__all__", ()):
            obj = getattr(module, name, None)
            if not (inspect.isclass(obj) or inspect.isfunction(obj)):
                continue
            if not getattr(obj, "__module__", "").startswith(package + "."):
                continue
            paths.setdefault(id(obj), []).append(f"{module.__name__}.{name}")
            objects[id(obj)] = obj
    out = {}
    for key, found in paths.items():
        home = objects[key].__module__
        best = min(found, key=lambda p: (p.count("."), p.rsplit(".", 1)[0] != home))
        out.update({p: best for p in found if p != best})
    return out


def canonical_path(path: str, elsewhere: dict[str, str]) -> str | None:
    """The documented path of ``path`` when it, or the class it is a member of, is re-exported
    (``qualgrasp.certify.Certificate.from_json`` -> ``qualgrasp.Certificate.from_json``)."""
    parts = path.split(".")
    for cut in range(len(parts), 1, -1):
        head = ".".join(parts[:cut])
        if head in elsewhere:
            return ".".join([elsewhere[head], *parts[cut:]])
    return None


def resolve_elsewhere(app: Sphinx, env, node, contnode):
    """``missing-reference``: a Python reference to a re-exported path resolves to its canonical
    page; one to a ``qualgrasp`` name that cannot be imported is a warning."""
    if node.get("refdomain") != "py":
        return None
    target = node["reftarget"].lstrip("~.")
    elsewhere = app.config.autosummary_context["elsewhere"]
    module, cls = node.get("py:module"), node.get("py:class")
    candidates = [target]
    if module:
        candidates = ([f"{module}.{cls}.{target}"] if cls else []) + [f"{module}.{target}", target]
    domain = env.get_domain("py")
    for candidate in candidates:
        canonical = canonical_path(candidate, elsewhere)
        if canonical is not None:
            new = node.deepcopy()
            new["reftarget"] = canonical
            new["refspecific"] = False
            return domain.resolve_xref(env, node["refdoc"], app.builder, node["reftype"],
                                       canonical, new, contnode)
    if target.startswith(PACKAGE + "."):
        try:
            import_object(target)
        except ImportError as err:
            logger.warning("reference to a qualgrasp name that does not exist: %s", err,
                           location=node, type="qualgrasp", subtype="missing")
    return None


# -------------------------------------------------------------------------------- CLI reference

_OPTION = re.compile(r"(?<![\w-])(--?[A-Za-z][\w-]*)")


def help_markup(text: str) -> str:
    """Help text as reStructuredText: literal, with option names (``--grasps``) as code, so
    that no dash is turned into a typographic one."""
    pieces = _OPTION.split(text)
    return "".join(f"``{p}``" if k % 2 else escape(p) for k, p in enumerate(pieces))


def _paragraphs(text: str) -> list[str]:
    """Help text as paragraphs (click's ``\\b`` no-rewrap markers dropped, lines joined)."""
    text = inspect.cleandoc(text or "")
    return [" ".join(line.strip() for line in block.splitlines() if line.strip() != "\b")
            for block in re.split(r"\n\s*\n", text) if block.strip()]


def cli_lines(command, name: str, parent=None, depth: int = 0) -> list[str]:
    """reStructuredText of ``command`` and its subcommands (sections, usage, options)."""
    ctx = command.make_context(name, [], parent=parent, resilient_parsing=True)
    title = ctx.command_path
    lines = [title, "=-~^"[min(depth, 3)] * len(title), ""] if depth else []
    lines += [".. code-block:: text", "", "   " + command.get_usage(ctx).strip(), ""]
    for paragraph in _paragraphs(command.help):
        lines += [help_markup(paragraph), ""]
    records = []
    for param in command.get_params(ctx):
        if param.name == "help":  # every command has it; the page says so once
            continue
        record = param.get_help_record(ctx)
        if record is not None:
            records.append((param.param_type_name, record))
    if records:
        lines += [".. list-table::", "   :header-rows: 1", "   :widths: 30 70",
                  "   :class: qualgrasp-cli-options", "",
                  "   * - argument or option", "     - meaning"]
        for kind, (opts, help_text) in records:
            label = opts if kind == "option" else f"{opts} (argument)"
            lines += [f"   * - ``{label}``", f"     - {help_markup(' '.join(help_text.split())) or '-'}"]
        lines.append("")
    if hasattr(command, "list_commands"):
        for sub in command.list_commands(ctx):
            # the lazy application's get_command gives summaries only; load_command the command
            child = getattr(command, "load_command", command.get_command)(ctx, sub)
            if child is None or getattr(child, "hidden", False):
                continue
            lines += cli_lines(child, sub, ctx, depth + 1)
    return lines


class CliDirective(SphinxDirective):
    """``.. qualgrasp-cli:: [MODULE:APP]``: the reference of a typer application."""

    optional_arguments = 1
    option_spec = {"prog": directives.unchanged}

    def run(self) -> list[nodes.Node]:
        import typer.main

        spec = self.arguments[0] if self.arguments else "qualgrasp.cli:app"
        try:
            app = import_object(spec.replace(":", "."))
        except ImportError as err:
            raise self.error(f"qualgrasp-cli: cannot import the application {spec}: {err}") from None
        command = typer.main.get_command(app)
        lines = cli_lines(command, self.options.get("prog", PACKAGE))
        return self.parse(lines)

    def parse(self, lines: list[str]) -> list[nodes.Node]:
        node = nodes.section()
        node.document = self.state.document
        nested_parse_with_titles(self.state, StringList(lines, source="<qualgrasp-cli>"), node)
        return node.children


# -------------------------------------------------------------------------------- schemas

class ColumnsDirective(CliDirective):
    """``.. qualgrasp-columns:: DOTTED.NAME``: a table of a schema's columns."""

    required_arguments = 1
    optional_arguments = 0
    option_spec: dict = {}

    def run(self) -> list[nodes.Node]:
        try:
            columns = import_object(self.arguments[0])
        except ImportError as err:
            raise self.error(f"qualgrasp-columns: cannot import the schema: {err}") from None
        lines = [".. list-table::", "   :header-rows: 1", "   :widths: 18 20 47 15", "",
                 "   * - column", "     - type (Arrow)", "     - meaning", "     - in an error row"]
        for col in columns:
            error = "null" if col.error is None else str(col.error).lower()
            lines += [f"   * - ``{col.name}``", f"     - ``{col.type}``",
                      f"     - {escape(col.description)}", f"     - ``{error}``"]
        return self.parse(lines + [""])


# -------------------------------------------------------------------------------- math

def _mathml(translator, node, block: bool) -> None:
    """Write ``node``'s LaTeX as MathML (docutils' converter): the browser renders it, with no
    script and no network, so the pages read the same offline."""
    from docutils.utils.math import latex2mathml

    tex = node.astext()
    try:
        mathml = latex2mathml.tex2mathml(tex, as_block=block)
    except Exception as err:  # the converter's errors have no common base class
        logger.warning("cannot write %r as MathML: %s", tex, err, location=node,
                       type="qualgrasp", subtype="math")
        mathml = f"<code>{translator.encode(tex)}</code>"
    translator.body.append(f'<div class="math">{mathml}</div>' if block else mathml)
    raise nodes.SkipNode


def visit_math(translator, node) -> None:
    _mathml(translator, node, block=False)


def visit_displaymath(translator, node) -> None:
    _mathml(translator, node, block=True)


# -------------------------------------------------------------------------------- setup

def submodules(package: str = PACKAGE) -> dict[str, list[str]]:
    """``{package: [short names of its public submodules]}`` for every public package."""
    out: dict[str, list[str]] = {}
    for module in public_modules(package):
        if hasattr(module, "__path__"):
            out[module.__name__] = sorted(
                info.name for info in pkgutil.iter_modules(module.__path__)
                if not info.name.startswith("_") and f"{module.__name__}.{info.name}" not in _SKIP)
    return out


def add_public_names(app: Sphinx, config) -> None:
    """Hand the templates the re-exported paths (``elsewhere``) and the public submodules of
    every package (``submodules``: autosummary lists only those in ``__all__``)."""
    config.autosummary_context = {**config.autosummary_context, "elsewhere": public_names(),
                                  "submodules": submodules()}


def setup(app: Sphinx) -> dict[str, Any]:
    app.connect("config-inited", add_public_names)
    app.connect("missing-reference", resolve_elsewhere)
    app.add_directive("qualgrasp-cli", CliDirective)
    app.add_directive("qualgrasp-columns", ColumnsDirective)
    app.add_html_math_renderer("mathml", (visit_math, None), (visit_displaymath, None))
    return {"parallel_read_safe": True, "parallel_write_safe": True, "version": "1"}

"""Sphinx configuration of the qualgrasp documentation site.

Build (from the repository's root, with ``pip install -e ".[docs]"``)::

    sphinx-build -W --keep-going -b html docs docs/_build/html

The API reference is generated from the package by autosummary (``api/index.rst`` recurses from
``qualgrasp``), the command-line reference from the typer application and the results columns
from their schema (``_ext/qualgrasp_docs.py``), and the gallery runs ``gallery/plot_*.py``.
"""

from __future__ import annotations

import sys
from importlib import metadata
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "_ext"))

project = "qualgrasp"
author = "the qualgrasp authors"
copyright = "the qualgrasp authors, BSD-3-Clause licence"
release = version = metadata.version("qualgrasp")

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "numpydoc",
    "sphinx_gallery.gen_gallery",
    "qualgrasp_docs",  # after autosummary: it adds to autosummary_context
]

html_math_renderer = "mathml"  # qualgrasp_docs: MathML, no script from a CDN
root_doc = "index"
templates_path = ["_templates"]
exclude_patterns = ["_build", "_templates", "gallery"]  # gallery/: sources of auto_examples/
html_static_path = ["_static"]
html_css_files = ["qualgrasp.css"]

# -- API reference -------------------------------------------------------------------------------
autosummary_generate = True
autosummary_ignore_module_all = False  # a module's members are its __all__
autosummary_imported_members = False
autosummary_context: dict = {}  # qualgrasp_docs adds "elsewhere": re-exported paths
autodoc_typehints = "none"  # the numpydoc sections state every type, with units
autodoc_member_order = "bysource"
add_module_names = False
python_display_short_literal_types = True

numpydoc_show_class_members = False  # class pages document members with autodoc's :members:
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False  # type words such as "array of float" are prose, not targets
numpydoc_attributes_as_param_list = True
numpydoc_validation_checks: set = set()  # style is the test suite's business, not the build's


# -- gallery ------------------------------------------------------------------------------------
sphinx_gallery_conf = {
    "examples_dirs": "gallery",
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",  # every script runs during the build
    "image_scrapers": ("matplotlib",),
    "capture_repr": (),  # show what the scripts print, not the repr of a last expression
    "within_subsection_order": "FileNameSortKey",
    "remove_config_comments": True,
    "download_all_examples": False,
    "show_memory": False,
    "min_reported_time": 5,
}

# -- HTML ---------------------------------------------------------------------------------------
html_theme = "pydata_sphinx_theme"
html_title = f"qualgrasp {release}"
html_theme_options = {
    "navbar_align": "left",
    "show_toc_level": 2,
    "navigation_depth": 3,
    "secondary_sidebar_items": ["page-toc"],
    "footer_start": ["copyright"],
    "footer_end": ["sphinx-version", "theme-version"],
}
html_context = {"default_mode": "light"}
# single pages: no section navigation to show on the left
html_sidebars = {page: [] for page in ("index", "getting-started", "formats", "cli")}
html_show_sourcelink = False

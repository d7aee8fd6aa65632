"""Sphinx configuration of the ddg-strips manual (docs/): furo, autodoc + numpydoc, sphinx-gallery.

Build: `bash scripts/docs.sh` (html into out/docs; DDG_DOCS_GALLERY=1 also runs the examples), or
`.venv/bin/python -m sphinx -W --keep-going -b html docs out/docs`. Environment:

- DDG_DOCS_ROOT: the checkout whose sources are documented (default: the folder above docs/; a copy
  of docs/ built elsewhere, as tests/test_docs.py does, names the checkout here);
- DDG_DOCS_GALLERY: 1 runs examples/*.py inside the build (about a minute), 0 (default) shows them
  without running;
- DDG_DOCS_GALLERY_OUT: where the examples write their run folders (their --out) when run; default a
  temporary folder, removed after the build.
"""
from __future__ import annotations

import os
import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
ROOT = Path(os.environ.get("DDG_DOCS_ROOT") or DOCS.parent).resolve()
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(DOCS / "_ext"))

import ddg  # noqa: E402  (from ROOT, after the path is set)

# -- Project -----------------------------------------------------------------------------------------
project = "ddg-strips"
author = "the ddg-strips authors"
copyright = "the ddg-strips authors"
version = release = ddg.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "numpydoc",
    "sphinx_gallery.gen_gallery",
    "myst_parser",   # the findings pages (docs/findings/*.md) are Markdown, moved from the README
    "ddg_docs",   # _ext/ddg_docs.py: command-help directive, docstring fallback, gallery titles
]

root_doc = "index"
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
# MyST: "$...$" is not maths in the findings pages (they write formulas as plain text); tables, fenced code
# and {doc} roles are core; headings get anchors for links of the form page.md#heading
myst_heading_anchors = 3
exclude_patterns = ["_build", "**.ipynb_checkpoints", "auto_examples/*.ipynb", "auto_examples/*.py",
                    "auto_examples/*.zip", "auto_examples/*.md5", "auto_examples/*.pickle"]
templates_path: list[str] = []
language = "en"
nitpicky = False
# no typographic quotes or dashes: "--model" in prose stays two hyphens, as typed on the command line
smartquotes = False
# `name` in the docstrings and the examples is code (as in Markdown), not a title reference
default_role = "literal"
# Equations are numbered by the page (eq. labels), the paper's own numbers are quoted in the text.
math_number_all = False
math_eqref_format = "({number})"

# -- Mathematics -------------------------------------------------------------------------------------
# DDG_DOCS_MATHJAX=local (the default where Debian's libjs-mathjax is installed, as scripts/setup.sh's
# dolfinx brings it): MathJax 2 from /usr/share/javascript/mathjax, linked as OUT/_static/mathjax, so the
# manual renders its equations offline on this machine; =cdn: Sphinx's default MathJax 3 from a CDN
# (for a manual published elsewhere).
LOCAL_MATHJAX = Path("/usr/share/javascript/mathjax")
MATHJAX = os.environ.get("DDG_DOCS_MATHJAX") or ("local" if (LOCAL_MATHJAX / "MathJax.js").is_file() else "cdn")
if MATHJAX == "local":
    mathjax_path = "mathjax/MathJax.js?config=TeX-AMS_CHTML"
    ddg_docs_mathjax_source = str(LOCAL_MATHJAX)
    mathjax2_config = {"CommonHTML": {"linebreaks": {"automatic": True}}}

# -- HTML --------------------------------------------------------------------------------------------
html_theme = "furo"
html_title = f"ddg-strips {release}"
html_static_path: list[str] = []
html_show_sourcelink = False
html_last_updated_fmt = None   # byte-stable pages: no build date

# -- autodoc and numpydoc ----------------------------------------------------------------------------
# The FEM reference imports dolfinx and its companions lazily or at module level: mocked so that its
# modules import (and are documented) on a machine without them.
autodoc_mock_imports = ["dolfinx", "ufl", "basix", "petsc4py", "slepc4py", "mpi4py", "gmsh"]
autodoc_default_options = {
    "members": True,
    "undoc-members": False,
    "show-inheritance": True,
    "member-order": "bysource",
}
autodoc_typehints = "signature"
autodoc_typehints_format = "short"
autodoc_preserve_defaults = True
autoclass_content = "class"
autodoc_inherit_docstrings = False
# The docstrings are prose (no Parameters/Returns sections): numpydoc formats only those with numpydoc
# sections (docs/_ext/ddg_docs.py routes them; on prose it would drop text), shows no
# member tables (autodoc lists the members) and validates nothing.
numpydoc_show_class_members = False
numpydoc_show_inherited_class_members = False
numpydoc_class_members_toctree = False
numpydoc_validation_checks: set[str] = set()
numpydoc_xref_param_type = False
numpydoc_use_plots = False

# -- sphinx-gallery: examples/*.py --------------------------------------------------------------------
RUN_GALLERY = os.environ.get("DDG_DOCS_GALLERY", "0").strip().lower() in ("1", "true", "yes", "on")
# sphinx-gallery reads the Sphinx value `plot_gallery` (also `-D plot_gallery=1` on the command line).
plot_gallery = RUN_GALLERY

from ddg_docs import ExampleArguments, OutputPictures  # noqa: E402
from sphinx_gallery.sorting import FileNameSortKey  # noqa: E402

sphinx_gallery_conf = {
    "examples_dirs": os.path.relpath(ROOT / "examples", DOCS),   # "../examples" in a checkout
    "gallery_dirs": "auto_examples",
    # every script of examples/ is an example (none is named plot_*); run from the examples/ folder
    "filename_pattern": r"/[a-z][a-z0-9_]*\.py$",
    "ignore_pattern": r"__init__\.py",
    # each script takes --out DIR (its run folder): a temporary folder per example, never out/ in the
    # checkout (sphinx-gallery runs a script from examples/, where its default --out would land)
    "reset_argv": ExampleArguments(os.environ.get("DDG_DOCS_GALLERY_OUT")),
    # the pictures the examples save in their --out folder (PNG), not matplotlib's open figures
    "image_scrapers": (OutputPictures(),),
    "reset_modules": ("matplotlib",),
    "abort_on_example_error": False,
    "only_warn_on_example_error": False,
    "download_all_examples": False,
    "remove_config_comments": True,
    "min_reported_time": 0,
    "show_memory": False,
    "line_numbers": False,
    "within_subsection_order": FileNameSortKey,
    "first_notebook_cell": None,
    "capture_repr": (),
}

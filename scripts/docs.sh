#!/usr/bin/env bash
# Build the manual (docs/, Sphinx with furo, autodoc, numpydoc, sphinx-gallery) into out/docs,
# warnings as errors. From the repository root after scripts/setup.sh:
#
#   bash scripts/docs.sh                      # out/docs/index.html; the examples shown, not run (~30 s)
#   DDG_DOCS_GALLERY=1 bash scripts/docs.sh   # also run examples/*.py in the build (~1-2 min more):
#                                             # their output and pictures in the gallery pages
#   bash scripts/docs.sh -E                   # extra arguments go to sphinx (-E: rebuild from scratch)
#
# The examples run with --out in a temporary folder (DDG_DOCS_GALLERY_OUT to keep them elsewhere).
# sphinx-gallery writes the gallery's sources to docs/auto_examples/ (ignored by git, docs/.gitignore).
# Equations: MathJax 2 from Debian's libjs-mathjax, linked into out/docs/_static/mathjax (offline);
# DDG_DOCS_MATHJAX=cdn uses MathJax 3 from a CDN instead (for a manual published elsewhere).
set -euo pipefail
cd "$(dirname "$0")/.."
export DDG_DOCS_GALLERY="${DDG_DOCS_GALLERY:-0}"
exec .venv/bin/python -m sphinx -W --keep-going -b html docs out/docs "$@"

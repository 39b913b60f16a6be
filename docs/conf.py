"""Sphinx configuration of the asymslide documentation site (``make docs`` builds it into build/docs/html)."""

from __future__ import annotations

import sys
from pathlib import Path

from asymslide import __version__

# the site's own extension (docs/_ext/asymslide_docs.py): constants, the equation index, docstring check, links
sys.path.insert(0, str(Path(__file__).parent / "_ext"))

project = "asymslide"
author = "the asymslide authors"
release = version = __version__
extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "numpydoc",
    "myst_nb",
    "sphinxarg.ext",
    "asymslide_docs",
]
# a reference to an object the API does not document is a warning (an error with -W)
nitpicky = True
# the site's pages: this folder's Markdown (physics.md, design-notes.md, ...) and notebooks
exclude_patterns = ["_build", "**.ipynb_checkpoints"]
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence"]
myst_heading_anchors = 3
# notebooks are executed at build time (an error fails the build)
nb_execution_mode = "cache"
nb_execution_raise_on_error = True
nb_execution_timeout = 600
# Panel's notebook outputs (examples/jupyter.md) carry two mime types of Jupyter's HoloViews/Panel extension beside the
# HTML and JavaScript the site shows: myst-nb renders every mime type of an output before it keeps the builder's, and
# warned about those two. An output with no mime type the builder can show still fails the build (mystnb.mime_priority).
suppress_warnings = ["mystnb.unknown_mime_type"]
autodoc_member_order = "bysource"
autodoc_typehints = "none"  # the numpydoc docstrings say the types
numpydoc_show_class_members = False
numpydoc_validation_checks: set[str] = set()
html_theme = "pydata_sphinx_theme"
html_title = f"asymslide {release}"
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
}


def _literal_bars(app, what, name, obj, options, lines: list[str]) -> None:  # noqa: ARG001 (Sphinx's signature)
    """The docstrings write absolute values as |z|, |F(z)|: a bar is text, not the start of a reStructuredText
    substitution (the docstrings hold no grid tables)."""
    for i, line in enumerate(lines):
        if "|" in line:
            lines[i] = line.replace("|", r"\|")


def setup(app) -> None:
    app.connect("autodoc-process-docstring", _literal_bars, priority=400)

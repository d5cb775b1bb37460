"""Sphinx configuration of wheelrail's documentation (``make docs``; built by ``tests/test_docs.py``).

Markdown pages through myst-parser, the API from the Google-style docstrings (autodoc, napoleon, autosummary),
the examples as a sphinx-gallery gallery (shown, not run: ``tests/test_examples.py`` runs them), and the
recorded results of ``benchmarks/results/`` collected into one page (``_ext/wheelrail_docs.py``).
"""

import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(DOCS / "_ext"))

project = "wheelrail"
author = "the wheelrail authors"
copyright = "the wheelrail authors, Apache-2.0"  # noqa: A001 (Sphinx's name)

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.napoleon",
    "sphinx_gallery.gen_gallery",
    "wheelrail_docs",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "_gallery_src", "_generated", "**/.ipynb_checkpoints"]
myst_enable_extensions = ["dollarmath"]
myst_heading_anchors = 3
# Docstrings name fields that several classes share (success, message, patches): an ambiguous link is no error.
suppress_warnings = ["ref.python"]

# The API: one page per module, generated from the docstrings at build time (autosummary).
autosummary_generate = True
autosummary_imported_members = False
autodoc_default_options = {"members": True, "ignore-module-all": True}
autodoc_typehints = "none"
autodoc_member_order = "bysource"
napoleon_google_docstring = True
napoleon_numpy_docstring = False

# The examples: converted from jupytext light format into _gallery_src/ by wheelrail_docs, shown, never run.
sphinx_gallery_conf = {
    "examples_dirs": "_gallery_src",
    "gallery_dirs": "gallery",
    "plot_gallery": False,
    "filename_pattern": r"^$",
    "download_all_examples": False,
    "write_computation_times": False,
    "remove_config_comments": True,
}

html_theme = "alabaster"
html_title = "wheelrail"
html_theme_options = {"description": "railway wheelset dynamics with a verified ladder of contact models"}

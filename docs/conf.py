"""Sphinx configuration of symkin's documentation: MyST Markdown pages, autodoc for the Python
API, and the local extension (_ext/symkin_docs) that writes the generated pages. Build with

    python -m sphinx -W -b html docs docs/_build/html
"""

from __future__ import annotations

import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
sys.path[:0] = [str(DOCS.parent), str(DOCS / "_ext")]

import symkin  # noqa: E402  (after the path: the tree being documented, not an installed copy)

project = "symkin"
author = "the symkin authors"
copyright = "the symkin authors"
release = symkin.__version__
version = release

extensions = ["myst_parser", "sphinx.ext.autodoc", "sphinx.ext.napoleon", "symkin_docs"]
source_suffix = {".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "_ext", "README.md"]
myst_enable_extensions = ["colon_fence"]  # no math: the pages load nothing from the network
myst_heading_anchors = 3
# myst.header: README-derived pages jump from # to ### in places.
suppress_warnings = ["myst.header"]

autodoc_member_order = "bysource"
autodoc_typehints = "description"
autodoc_default_options = {"members": True}

html_theme = "alabaster"
html_title = f"symkin {release}"
html_static_path: list[str] = []
html_theme_options = {"description": "symbolic kinematics and dynamics of mechanisms, "
                                     "as C99 and NumPy", "fixed_sidebar": True,
                      "page_width": "1240px", "sidebar_width": "240px"}

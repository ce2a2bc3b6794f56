"""The Sphinx extension that writes symkin's generated pages before Sphinx reads the sources:
the joint, driver and force types (from the pair registry and the models), the command line
(from the argument parser) and the gallery (every example, run). They go to ``docs/auto/``,
which is not committed: the pages cannot go stale."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from sphinx.application import Sphinx
from sphinx.util import logging

from symkin_docs import cli_page, gallery, pair_pages

LOG = logging.getLogger(__name__)


def generate(app: Sphinx) -> None:
    docs = Path(app.srcdir)
    root = docs.parent
    out = docs / "auto"
    pair_pages.write_all(out / "types", root / "examples")
    cli_page.write(out)
    cache = Path(os.environ.get("SYMKIN_DOCS_CACHE", root / "docs" / "_build" / "gallery-cache"))
    for failure in gallery.write(out, root, cache):
        LOG.warning("gallery: %s", failure)


def setup(app: Sphinx) -> dict[str, Any]:
    app.connect("builder-inited", generate)
    return {"parallel_read_safe": True, "parallel_write_safe": True}

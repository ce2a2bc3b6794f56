"""Building the docs in a test: a copy of docs/ next to links to the tree's examples, package
and templates (the generated pages land in the copy, never in the working tree), built by
Sphinx in this process so that a type registered by a test is seen by the build."""

from __future__ import annotations

import contextlib
import io
import os
import shutil
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
# The quick build's gallery: two examples (the full build of .ci/run renders them all).
QUICK_GALLERY = "crank_slider,four_bar"


def sphinx_or_skip() -> None:
    """Sphinx and MyST come with the test extra; without them the docs tests cannot run."""
    pytest.importorskip("sphinx", reason="pip install '.[docs]'")
    pytest.importorskip("myst_parser", reason="pip install '.[docs]'")


def build(tree: Path, gallery_cache: Path) -> tuple[int, str, Path]:
    """Build a copy of the docs under ``tree`` with warnings as errors: (status, warnings,
    the HTML folder)."""
    from sphinx.cmd.build import build_main

    sphinx_or_skip()
    if not (tree / "docs").exists():
        shutil.copytree(DOCS, tree / "docs", ignore=shutil.ignore_patterns("_build", "auto"))
        for name in ("examples", "symkin"):
            (tree / name).symlink_to(ROOT / name)
    html = tree / "html"
    warnings = io.StringIO()
    saved = {key: os.environ.get(key) for key in ("SYMKIN_DOCS_GALLERY", "SYMKIN_DOCS_CACHE")}
    os.environ.update(SYMKIN_DOCS_GALLERY=QUICK_GALLERY, SYMKIN_DOCS_CACHE=str(gallery_cache))
    try:
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(warnings):
            status = build_main(["-W", "--keep-going", "-q", "-E", "-b", "html",
                                 str(tree / "docs"), str(html)])
    finally:
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value
    return status, warnings.getvalue(), html

"""Where the package's data lives (the jinja2 templates) and the names of generated files."""

from __future__ import annotations

import sysconfig
from pathlib import Path

_PACKAGE = Path(__file__).resolve().parent


def template_root() -> Path:
    """The templates folder: inside the installed package, or at the top of a source tree."""
    installed = _PACKAGE / "templates"
    if installed.is_dir():
        return installed
    return _PACKAGE.parent / "templates"


# The file every generated folder carries, one per mechanism (so that several mechanisms can
# share a folder): its files with their sha256 and the metadata a runtime needs. Written by
# codegen.render, read by runtime.kernel and build.index.
MANIFEST_SUFFIX = "_manifest.json"


def manifest_name(prefix: str) -> str:
    """``crank_slider`` -> ``crank_slider_manifest.json``."""
    return prefix + MANIFEST_SUFFIX


def extension_suffix() -> str:
    """The file suffix of a compiled extension module for this interpreter."""
    return sysconfig.get_config_var("EXT_SUFFIX") or ".so"

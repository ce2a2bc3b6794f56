"""Where the package's data lives (the jinja2 templates) and the suffix of compiled extensions
(the manifest's name is symkin.contract.manifest's)."""

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


def extension_suffix() -> str:
    """The file suffix of a compiled extension module for this interpreter."""
    return sysconfig.get_config_var("EXT_SUFFIX") or ".so"

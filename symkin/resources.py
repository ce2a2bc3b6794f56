"""The suffix of compiled extension modules (the manifest's name is symkin.contract.manifest's;
each backend's templates live in its own folder, ``symkin/backends/<name>/templates/``)."""

from __future__ import annotations

import sysconfig


def extension_suffix() -> str:
    """The file suffix of a compiled extension module for this interpreter."""
    return sysconfig.get_config_var("EXT_SUFFIX") or ".so"

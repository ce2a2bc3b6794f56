"""The built site, shared by the docs tests of one run."""

from __future__ import annotations

from pathlib import Path

import pytest
from docs_support import build


@pytest.fixture(scope="session")
def gallery_cache(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("gallery-cache")


@pytest.fixture(scope="session")
def site(tmp_path_factory: pytest.TempPathFactory, gallery_cache: Path) -> tuple[int, str, Path]:
    """The one Sphinx build of the run, with a pair type registered from outside the package
    (planted_pair, a module of its own): the site's tests and the planted type's page read the
    same build (a build costs a CPU-minute). The registry is restored once it is built."""
    import planted_pair

    import symkin
    from symkin import pairs

    # The public API imported first, as a program has it before it registers a type: the
    # file model's union of pair types is built at that import, from the types of the package.
    for name in symkin.__all__:
        getattr(symkin, name)
    with pytest.MonkeyPatch.context() as patch:
        patch.setitem(pairs._FAMILY, "2d", (*pairs.TYPES, planted_pair.TYPE))
        return build(tmp_path_factory.mktemp("site"), gallery_cache)

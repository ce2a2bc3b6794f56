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
    return build(tmp_path_factory.mktemp("site"), gallery_cache)

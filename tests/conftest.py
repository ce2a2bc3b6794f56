"""Shared fixtures: paths of the example mechanisms."""

from __future__ import annotations

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"


@pytest.fixture(scope="session")
def crank_slider_path() -> Path:
    return EXAMPLES / "crank_slider.yaml"


@pytest.fixture(scope="session")
def crank_slider_system(crank_slider_path: Path):
    import symkin

    return symkin.derive(crank_slider_path)

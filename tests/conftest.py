"""Shared fixtures: paths of the example mechanisms."""

from __future__ import annotations

import os
import shutil
from collections.abc import Iterator
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


def pytest_configure(config: pytest.Config) -> None:
    """One BLAS thread per test process (unless the caller chose otherwise): pytest-xdist
    already runs a process per core, and OpenBLAS's own threads, woken for every small LAPACK
    call of the NumPy driver (a 9 x 9 getrs), spin for CPU the other workers need — 1.5 ms of
    CPU per call against 3 us with one thread, measured on 2 loaded cores. Set before any test
    module imports NumPy, so this process, the xdist workers it starts and the subprocesses of
    the tests all inherit it."""
    for variable in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS"):
        os.environ.setdefault(variable, "1")


def pytest_sessionstart(session: pytest.Session) -> None:
    """Under CI, a tool it installed (SYMKIN_REQUIRE_TOOLS) must be found: the tests that need
    it would otherwise skip, and a C test that skips proves nothing."""
    required = os.environ.get("SYMKIN_REQUIRE_TOOLS", "").split()
    missing = [tool for tool in required if shutil.which(tool) is None]
    if missing:
        pytest.exit(f"required tools not found on PATH: {', '.join(missing)} (CI installed "
                    "them; their tests must run, not skip)", returncode=1)


@pytest.fixture(scope="session", autouse=True)
def shared_cache(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Path]:
    """One kernel cache for the whole run: tests never write to the user's ~/.cache/symkin.
    Under pytest-xdist the workers share it (a folder beside their own temporary folders):
    a kernel one worker built is loaded by the others, and two that build the same kernel at
    once publish it atomically (symkin.build.cache)."""
    if os.environ.get("PYTEST_XDIST_WORKER"):
        folder = tmp_path_factory.getbasetemp().parent / "symkin-cache"
        folder.mkdir(exist_ok=True)
    else:
        folder = tmp_path_factory.mktemp("symkin-cache")
    before = os.environ.get("SYMKIN_CACHE_DIR")
    os.environ["SYMKIN_CACHE_DIR"] = str(folder)
    yield folder
    if before is None:
        os.environ.pop("SYMKIN_CACHE_DIR", None)
    else:
        os.environ["SYMKIN_CACHE_DIR"] = before


@pytest.fixture(scope="session", autouse=True)
def shared_builds_folder(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Path]:
    """One folder of derived Systems and generated sources for the whole run, shared by the
    xdist workers as the kernel cache is (tests/shared_builds.py)."""
    import shared_builds

    if os.environ.get("PYTEST_XDIST_WORKER"):
        folder = tmp_path_factory.getbasetemp().parent / "symkin-shared-builds"
        folder.mkdir(exist_ok=True)
    else:
        folder = tmp_path_factory.mktemp("symkin-shared-builds")
    shared_builds.FOLDER[:] = [folder]
    yield folder
    shared_builds.FOLDER.clear()

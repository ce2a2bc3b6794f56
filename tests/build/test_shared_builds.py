"""The suite's shortcut to a kernel (codegen_support.compiled) builds what symkin.compile builds.

Tests whose point is what a kernel computes take it from goldens or from sources one worker
generated; the kernel cache names a folder by the sha256 of everything in it, so the same
folder means the same library, manifest and sources.
"""

from __future__ import annotations

from pathlib import Path

import pytest
import shared_builds
from codegen_support import ROOT, compiled, compilers, derived

import symkin


def _same_kernel(ours, theirs) -> None:
    assert type(ours) is type(theirs)
    assert Path(ours.folder) == Path(theirs.folder)


@pytest.mark.parametrize("backend", ["c", "numpy"])
def test_an_example_from_its_goldens_is_the_kernel_compile_builds(backend: str) -> None:
    if backend == "c" and not compilers():
        pytest.skip("no C compiler")
    path = ROOT / "examples" / "four_bar.yaml"
    _same_kernel(compiled(path, backend), symkin.compile(symkin.derive(path), backend))


def test_other_options_and_files_generate_the_same_sources(tmp_path: Path) -> None:
    if not compilers():
        pytest.skip("no C compiler")
    example = ROOT / "examples" / "crank_slider.yaml"
    _same_kernel(compiled(example, "c", real="float"),
                 symkin.compile(symkin.derive(example), "c", real="float"))
    mechanism = ROOT / "tests" / "mechanisms" / "five_bar.yaml"
    first = compiled(mechanism, "numpy")  # generated, then stored for the other workers
    _same_kernel(first, symkin.compile(symkin.derive(mechanism), "numpy"))
    _same_kernel(compiled(mechanism, "numpy"), first)  # loaded from the run's folder


def test_a_stored_system_is_the_derived_one() -> None:
    path = ROOT / "tests" / "mechanisms" / "five_bar.yaml"
    fresh = symkin.derive(path)
    assert derived(path) is derived(path)  # once per process, and stored for the others
    loaded = shared_builds.stored("system", shared_builds.file_key(path.resolve()),
                                  lambda: pytest.fail("the run's folder lost the System"))
    assert loaded.phi == fresh.phi and loaded.gamma == fresh.gamma
    assert loaded.pattern() == fresh.pattern()

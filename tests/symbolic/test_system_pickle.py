"""A System survives pickle: the copy generates the same bytes as the original.

The test suite keeps derived Systems on disk for its other processes (codegen_support), and a
user may send one to a worker process. SymPy's sparse matrices come back from pickle keyed by
SymPy Integers; the code generator must still see plain int row and column numbers (the
manifest is JSON).
"""

from __future__ import annotations

import functools
import pickle

import pytest
from codegen_support import ROOT

import symkin

# Planar kinematics with parameters in Phi (Phi_p), a spatial mechanism, and planar dynamics.
CASES = ("crank_slider", "cardan", "four_bar_dynamics")


@functools.cache
def _derived(name: str) -> symkin.System:
    """Derived here, once for both backends: not a copy from shared_builds, which is itself a
    pickle's."""
    return symkin.derive(ROOT / "examples" / f"{name}.yaml")


@pytest.mark.parametrize("name", CASES)
@pytest.mark.parametrize("backend", ["c", "numpy"])
def test_a_pickled_system_generates_the_same_files(name: str, backend: str, tmp_path) -> None:
    system = _derived(name)
    copy = pickle.loads(pickle.dumps(system))
    original = symkin.generate(system, backend, tmp_path / "original")
    again = symkin.generate(copy, backend, tmp_path / "copy")
    assert [path.name for path in original] == [path.name for path in again]
    for first, second in zip(original, again):
        assert first.read_bytes() == second.read_bytes(), first.name


def test_the_pattern_of_a_pickled_system_is_plain_ints() -> None:
    system = _derived("crank_slider")
    copy = pickle.loads(pickle.dumps(system))
    assert copy.pattern() == system.pattern()
    assert {type(index) for entry in copy.pattern() for index in entry} == {int}

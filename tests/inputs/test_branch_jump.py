"""Branch jumps of an input-driven run (runtime.input_driven.branch): where the crank-slider driven
by its crank angle passes its singular configuration (the rod at right angles to the slider's line)
Newton goes on along the other assembly; the rows where that happens, by the closed form of
both assemblies, are exactly the rows flagged, on both backends alike, with a warning naming
them. A smooth path along one assembly flags nothing."""

from __future__ import annotations

import shutil
import warnings
from pathlib import Path

import numpy as np
import pytest
from codegen_support import compiled, derived

import symkin
from symkin.errors import SymkinWarning

ROOT = Path(__file__).resolve().parents[2]
A, B, C = 1.0, 5.0, 4.0  # crank, rod, the height of the slider's line (the example's values)
BACKENDS = ["numpy"] + (["c"] if shutil.which("gcc") else [])


@pytest.fixture(scope="module")
def system():
    return derived(ROOT / "examples" / "crank_slider_input.yaml")


def _assembly(theta: np.ndarray, slider_x: np.ndarray) -> np.ndarray:
    """+1 or -1: which of the two closed-form assemblies, x = a cos(theta) +- sqrt(b^2 -
    (c - a sin(theta))^2), each row is on (checked to be one of them)."""
    root = np.sqrt(B**2 - (C - A * np.sin(theta)) ** 2)
    both = np.stack([A * np.cos(theta) + root, A * np.cos(theta) - root])
    distance = np.abs(both - slider_x)
    assert np.all(distance.min(axis=0) < 1e-8)
    return np.where(distance[0] <= distance[1], 1, -1)


def _run(system, backend, theta):
    kernel = compiled(ROOT / "examples" / "crank_slider_input.yaml", backend)
    t = np.arange(theta.size) * 0.05
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        trajectory = symkin.solve(kernel, t=t, inputs=theta.reshape(-1, 1))
    notes = [str(w.message) for w in caught if issubclass(w.category, SymkinWarning)]
    slider_x = trajectory.q[:, system.coordinates.index("slider.x")]
    return trajectory, _assembly(theta, slider_x), notes


@pytest.mark.parametrize("backend", BACKENDS)
def test_smooth_path_flags_nothing(system, backend):
    theta = np.linspace(np.pi / 2, np.pi / 2 + 1.0, 21)
    trajectory, assembly, notes = _run(system, backend, theta)
    assert np.all(assembly == 1)
    assert trajectory.branch_jumps is not None and not trajectory.branch_jumps.any()
    assert not any("another assembly" in note for note in notes)


def test_flags_are_the_rows_that_change_assembly(system):
    """Through the singular configuration at theta = -pi/2 (rod perpendicular to the line)."""
    theta = np.linspace(np.pi / 2, -np.pi / 2 - 1.0, 41)
    flags = []
    for backend in BACKENDS:
        trajectory, assembly, notes = _run(system, backend, theta)
        switched = np.concatenate([[False], assembly[1:] != assembly[:-1]])
        assert switched.any()  # the path does leave its assembly
        assert np.array_equal(trajectory.branch_jumps, switched)
        rows = np.flatnonzero(switched)
        note = next(note for note in notes if "another assembly" in note)
        assert all(f"row {k} (t = {trajectory.t[k]:.10g})" in note for k in rows)
        flags.append(trajectory.branch_jumps)
    assert all(np.array_equal(flags[0], other) for other in flags)


def test_time_driven_run_has_no_jump_rows(system):
    kernel = compiled(ROOT / "examples" / "crank_slider.yaml", "numpy")
    assert symkin.solve(kernel).branch_jumps is None

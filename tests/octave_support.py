"""The Octave backend's check against NumPy, shared by the Octave tests and the file that
already holds a mechanism's NumPy kernel (tests/spatial/test_stewart_fk.py for
stewart_legs_fk, whose derivation alone takes a minute: one derivation and one NumPy kernel
serve both checks)."""

from __future__ import annotations

import shutil

import numpy as np
import pytest

import symkin
from symkin.codegen import sample
from symkin.runtime.kernel import Kernel

# Without Octave the tests that run .m files skip (under CI, which installs it,
# tests/conftest.py makes its absence an error instead).
needs_octave = pytest.mark.skipif(shutil.which("octave-cli") is None,
                                  reason="GNU Octave (octave-cli) is not on PATH")


def _inputs(system: symkin.System, times: np.ndarray) -> dict[str, np.ndarray]:
    """For a file with input drivers: their nominal values moved a little each step, and
    those rates."""
    if not system.input_names:
        return {}
    start = np.array(sample.input_values(system), dtype=float)
    steps = np.arange(len(times))[:, None] + 0 * start
    return {"inputs": start + 1e-3 * steps,
            "input_rates": 1e-3 / (times[1] - times[0]) + 0 * steps,
            "input_accels": 0 * steps}


def assert_octave_equals_numpy(system: symkin.System, numpy: Kernel, name: str,
                               octave: Kernel | None = None) -> None:
    """symkin.solve with the octave kernel gives NumPy's rows to 1e-12 (the first steps of
    the file's grid: Octave evaluates each call in a running process). ``octave``: a kernel
    built from the example's committed .m goldens (test_generated proves them equal to a fresh
    generation); without one, symkin.compile generates and builds it here."""
    if octave is None:
        octave = symkin.compile(system, backend="octave")
    assert octave.backend == "octave" and numpy.backend == "numpy"
    t0, t1, dt = system.time_grid
    times = t0 + dt * np.arange(min(6, round((t1 - t0) / dt) + 1))
    runs = [symkin.solve(k, t=times, **_inputs(system, times)) for k in (octave, numpy)]
    for field in ("q", "dq", "d2q"):
        ours, theirs = (np.asarray(getattr(run, field)) for run in runs)
        assert ours.shape == theirs.shape
        assert np.isfinite(theirs).all(), (name, field)
        scale = 1 + np.max(np.abs(theirs))
        assert np.max(np.abs(ours - theirs)) <= 1e-12 * scale, (name, field)

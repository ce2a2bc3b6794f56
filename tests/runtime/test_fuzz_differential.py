"""A seeded differential fuzzer: the example mechanisms with their parameters, first guesses and
time grids mutated at random (a fixed seed, a fixed number of cases) are solved by the generated
C and the generated NumPy kernels, which must agree: both solve, with the same points flagged
and the same positions to 1e-9 (relative to the mechanism's size) wherever neither flags the
point, or both stop with the same reason near the same time. Nothing else may come out: no
other exception, no traceback, no hang (each case is bounded by its grid). The examples cover
the local and drawn layouts, higher pairs (rack, gears, a slot) and space: 3d.

Mutations: every parameter scaled by a factor in [0.5, 2] (links that no longer close, limit
positions, dead centres appear), the whole mechanism scaled by 10^k (k in -6 .. 6), q0
perturbed or zeroed, the grid shifted and refined.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest
from codegen_support import compiled

import symkin
from symkin.errors import SolveError
from symkin.runtime import driver
from symkin.runtime.solving.start import positions

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
NAMES = ("crank_slider.yaml", "four_bar.yaml", "quick_return.yaml", "custom_driver.yaml",
         "all_drivers.yaml",
         # drawn, higher pairs (rack, gears, a slot) and space: 3d
         "whitworth_drawn.yaml", "rack_linkage.yaml", "planetary.yaml", "rssr.yaml",
         "spatial_slider_crank.yaml")
# The same cases on every machine and load (a wall-time budget ran fewer cases on a busy
# machine and more CPU on an idle one); more for a longer hunt.
CASES = int(os.environ.get("SYMKIN_FUZZ_CASES", "60"))
SEED = 2029


@pytest.fixture(scope="module")
def kernels():
    """Each example's C and NumPy kernels, built from its goldens (codegen_support.compiled:
    what symkin.compile builds, with no derivation)."""
    return {name: (compiled(EXAMPLES / name, "c"), compiled(EXAMPLES / name, "numpy"))
            for name in NAMES}


def _case(rng: np.random.Generator, kernel) -> dict:
    """One mutation of the kernel's nominal inputs."""
    p = np.array(kernel.p_values, dtype=float)
    q0 = np.array(kernel.q0, dtype=float)
    t0, t1, dt = kernel.time_grid
    scale = 1.0
    kind = rng.integers(4)
    if kind == 0:  # dimensions changed one by one
        p = p * rng.uniform(0.5, 2.0, p.size)
    elif kind == 1:  # the whole mechanism in another unit (angles and speeds unchanged)
        scale = float(10.0 ** rng.integers(-6, 7))
    elif kind == 2:  # a poor first guess
        q0 = q0 + rng.normal(0.0, 0.3, q0.size)
    else:  # the chapter's start from zero, a shifted and finer grid
        q0 = np.zeros_like(q0)
        t0 = t0 + rng.uniform(0.0, 0.5) * (t1 - t0)
        dt = dt / rng.integers(1, 4)
    steps = max(1, round((t1 - t0) / dt))
    return {"p": p, "q0": q0, "t": np.linspace(t0, t0 + steps * dt, steps + 1), "scale": scale}


def _scaled_params(kernel, p: np.ndarray, scale: float) -> np.ndarray:
    """Parameters that are lengths scale with the mechanism; the examples' speeds and angles
    (named below) do not."""
    angles_or_rates = {"w", "k", "psi0", "omega", "theta0", "speed"}
    return np.array([v if name in angles_or_rates else v * scale
                     for name, v in zip(kernel.parameter_names, p)])


def _outcome(kernel, case: dict):
    try:
        return symkin.solve(kernel, t=case["t"], q0=case["q0"], params=case["p"])
    except driver.SolveFailure as failure:
        return failure


def _agree(name: str, c, numpy, case: dict) -> None:
    where = f"{name} with {case}"
    if isinstance(c, driver.SolveFailure) or isinstance(numpy, driver.SolveFailure):
        assert isinstance(c, driver.SolveFailure) and isinstance(numpy, driver.SolveFailure), \
            f"one backend solved, the other stopped: {where}: {c!s:.300} / {numpy!s:.300}"
        assert c.reason == numpy.reason, where
        step = float(np.diff(case["t"]).max(initial=0.0))
        assert abs(c.t - numpy.t) <= step + 1e-9, where
        return
    assert c.t.size == numpy.t.size, where
    # the same points flagged: the flag decision is taken alike on both backends
    assert np.array_equal(c.flagged, numpy.flagged), where
    size = max(1.0, float(np.abs(numpy.q).max(initial=0.0)))
    trusted = ~(c.flagged | numpy.flagged)
    difference = np.abs(c.q - numpy.q)[trusted]
    # Angles as they are, not modulo 2 pi: a turn apart is another branch, a disagreement.
    assert float(difference.max(initial=0.0)) <= 1e-9 * size, where


def test_c_and_numpy_agree_on_mutated_examples(kernels):
    rng = np.random.default_rng(SEED)
    for _ in range(CASES):
        name = NAMES[int(rng.integers(len(NAMES)))]
        c_kernel, numpy_kernel = kernels[name]
        case = _case(rng, numpy_kernel)
        if case["scale"] != 1.0:
            case["p"] = _scaled_params(numpy_kernel, case["p"], case["scale"])
            case["q0"] = np.where(positions(numpy_kernel), case["q0"] * case["scale"],
                                  case["q0"])
        try:
            c, numpy = _outcome(c_kernel, case), _outcome(numpy_kernel, case)
        except SolveError as error:  # a bad argument would be the fuzzer's fault: say so
            pytest.fail(f"{name}: {error}")
        _agree(name, c, numpy, case)

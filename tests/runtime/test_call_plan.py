"""A kernel called again and again answers as a fresh one: what symkin.solve keeps between calls
(runtime.solving.call_plan: the unit, the named points' vectors, the start judged regular)
never outlives a change of the parameters, q0 or t.

References: a fresh kernel of the same build (its plan made anew) solving the same call, to
the bit; and the crank-slider's closed form (textbook Example 2.5 with the slide offset c:
the slider's x = a cos phi +- sqrt(b^2 - (c - a sin phi)^2), the sign choosing the branch; a
singular start where c - a sin phi = b, the rod square to the slide)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from codegen_support import derived

import symkin
from symkin.runtime import driver

ROOT = Path(__file__).resolve().parents[2]
T = np.linspace(0.0, 1.5, 31)
FIELDS = ("t", "q", "dq", "d2q", "cond", "flagged", "point_vectors", "params")


@pytest.fixture(scope="module")
def system():
    return derived(ROOT / "examples" / "crank_slider.yaml")  # once per test run


@pytest.fixture(scope="module")
def kernel(system):
    return symkin.compile(system, backend="c")


def _fresh(system, kernel):
    """Another kernel object over the same build: nothing kept from earlier calls."""
    fresh = symkin.compile(system, backend="c")
    assert fresh is not kernel and fresh.call_plan is None
    return fresh


def _start(phi: float, a: float, b: float, c: float, sign: float = 1.0) -> np.ndarray:
    """q at crank angle phi on the branch ``sign`` (closed form): crank, rod, slider."""
    x = a * math.cos(phi) + sign * math.sqrt(b * b - (c - a * math.sin(phi)) ** 2)
    tip = (a * math.cos(phi), a * math.sin(phi))
    rod = math.atan2(c - tip[1], x - tip[0])
    return np.array([0.0, 0.0, phi, tip[0], tip[1], rod, x, c, 0.0])


def _slider_x(kernel, trajectory) -> np.ndarray:
    return trajectory.q[:, kernel.coordinates.index("slider.x")]


CALLS = [  # (label, solve's keyword arguments, parameters a, b, c, branch) in one sequence
    ("nominal", {}, (1.0, 5.0, 4.0), 1.0),
    ("b changed", {"params": {"b": 5.5}}, (1.0, 5.5, 4.0), 1.0),
    ("nominal again", {}, (1.0, 5.0, 4.0), 1.0),
    ("the other branch", {"q0": _start(math.pi / 2, 1.0, 5.0, 4.0, -1.0)}, (1.0, 5.0, 4.0),
     -1.0),
    ("nominal once more", {}, (1.0, 5.0, 4.0), 1.0),
    # From the file's q0 (zeros) as the nominal call: only the parameters tell the unit.
    ("in millimetres", {"params": {"a": 1e3, "b": 5e3, "c": 4e3}}, (1e3, 5e3, 4e3), 1.0),
    ("nominal after millimetres", {}, (1.0, 5.0, 4.0), 1.0),
]


def test_calls_in_a_row_answer_as_a_fresh_kernel(system, kernel):
    for label, arguments, (a, b, c), sign in CALLS:
        for t in (T, T[5:]):  # the same call from another t0
            got = symkin.solve(kernel, t=t, **arguments)
            expected = symkin.solve(_fresh(system, kernel), t=t, **arguments)
            for name in FIELDS:
                assert np.array_equal(getattr(got, name), getattr(expected, name)), \
                    (label, t[0], name)
            phi = t**2 + math.pi / 2  # the driver
            x = a * np.cos(phi) + sign * np.sqrt(b * b - (c - a * np.sin(phi)) ** 2)
            np.testing.assert_allclose(_slider_x(kernel, got), x, rtol=1e-9, atol=1e-9 * a,
                                       err_msg=label)
            tip = np.array([a, 0.0])  # the crank's named point at these parameters
            assert np.array_equal(got.point_vectors[0], tip), label


@pytest.mark.parametrize("gap", [1e-10, 1e-12])
def test_a_singular_start_after_regular_ones_is_still_refused(kernel, gap):
    """c = 6 - gap: at t0 the crank points up (phi = pi/2), c - a sin phi = 5 - gap, b = 5:
    the rod is all but square to the slide, where the two branches meet (singular at gap 0).
    The C solver converges there; the start check refuses it."""
    symkin.solve(kernel, t=T)
    c = 6.0 - gap
    for _ in range(2):  # and again: a refused start is not remembered as regular
        with pytest.raises(driver.SolveFailure) as caught:
            symkin.solve(kernel, t=T, params={"c": c}, q0=_start(math.pi / 2, 1.0, 5.0, c))
        assert caught.value.reason == "singular" and caught.value.t == 0.0
        assert "singular or limit configuration" in str(caught.value)
    regular = symkin.solve(kernel, t=T)
    assert not regular.flagged.any()


def test_a_result_is_its_own(kernel):
    """Arrays kept between calls are never handed out: writing into one result leaves the
    next as it was."""
    first = symkin.solve(kernel, t=T)
    kept = symkin.solve(kernel, t=T)
    first.point_vectors[:] = 99.0
    first.q[:] = 99.0
    again = symkin.solve(kernel, t=T)
    assert np.array_equal(again.point_vectors, kept.point_vectors)
    assert np.array_equal(again.q, kept.q)
    assert not np.shares_memory(again.point_vectors, kept.point_vectors)


def test_a_grid_changed_in_place_is_checked_again(kernel):
    """The same array, valid on one call, then written into: refused as any bad grid is."""
    t = T.copy()
    symkin.solve(kernel, t=t)
    t[5] = t[4]
    with pytest.raises(symkin.SolveError, match="strictly increasing"):
        symkin.solve(kernel, t=t)
    t[5] = math.nan
    with pytest.raises(symkin.SolveError, match="finite"):
        symkin.solve(kernel, t=t)
    t[5] = T[5]
    assert np.array_equal(symkin.solve(kernel, t=t).t, T)

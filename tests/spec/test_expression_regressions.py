"""Regression cases of issue 10: every expression its report listed, on both backends.

Each one once failed to build, crashed, hung or gave a silently wrong number on one backend; now
each builds and agrees with a closed form on both, or both fail the same located way.
"""

from __future__ import annotations

import copy
import math
import time
import warnings

import numpy as np
import pytest

import symkin
from symkin.errors import MechanismError
from symkin.runtime.driver import SolveFailure
from symkin.runtime.outputs.results import Trajectory

# A crank of length 1 about the origin: crank.phi = theta(t), its tip at (cos, sin).
BASE = {
    "name": "regression", "parameters": {"a": 1.0, "c": 4.0},
    "bodies": {"crank": {"q0": [0, 0, 0], "points": {"tip": ["a", 0]}}},
    "joints": [{"type": "revolute", "i": "ground", "j": "crank", "sA": [0, 0], "sB": [0, 0]}],
    "drivers": [{"type": "angle", "i": "crank", "j": "ground", "theta": "t"}],
    "time": {"t0": 0, "t1": 1, "dt": 0.25},
}
T = np.linspace(0, 1, 5)

# theta(t) text -> its values on T (NumPy, written independently of symkin)
SOLVES = {
    "pi/2 - pi/2*t": math.pi / 2 - math.pi / 2 * T,
    "log(2)*t + sqrt(2)": math.log(2) * T + math.sqrt(2),
    "Min(c, 18446744073709551617)*t": 4.0 * T,  # once 1 in C: the integer was truncated
    "Max(t, 1 - t)": np.maximum(T, 1 - T),  # once a codegen crash
    "Abs(Abs(t) - 0.5)": np.abs(np.abs(T) - 0.5),
    "sin(Piecewise((t, 1 < t), (1, True)))": np.sin(np.where(T > 1, T, 1.0)),
    "Min(t, 2, 3)": np.minimum(T, 2),  # once NameError: functools in NumPy
    "Abs(sin(Abs(sin(Abs(sin(Abs(sin(Abs(sin(Abs(sin(t)-0.5))-0.5))-0.5))-0.5))-0.5))-0.5)":
        None,  # once a hang in rewrite(Piecewise); checked between backends
    "Heaviside(t - 0.6)*t": np.where(T > 0.6, T, 0.0),
}
# theta(t) -> the time at which both backends must stop, naming a non-finite row
SINGULAR = {
    "0.01/(t - 0.5)": 0.5,
    "t**(-1)": 0.0,
    "(t - 2)**(1/3)": 0.0,  # the principal cube root of a negative number is not real
    "sqrt(t - 0.25)": 0.0,
    "sqrt(t)": 0.0,  # finite at 0, its derivative is not
}
# text -> what the refusal says (at validation, so the same for both backends)
REFUSED = {
    "Abs(t**t)": "its derivative needs",
    "sin(exp(100000000))*t": "exp of 1.0e+8 is larger than the largest double",
    "sin(cosh(500000000))*t": "cosh of 5.0e+8 is larger than the largest double",
    "Max(asin(7), t)": "the arguments of Max() must be real",
    "sin(1e20)*t": "larger than 1e+15",
}


def _mechanism(theta: str, **changes) -> symkin.System:
    data = copy.deepcopy(BASE)
    data["drivers"][0]["theta"] = theta
    data.update(changes)
    return symkin.derive(symkin.from_dict(data))


def _cranks(thetas: list[str]) -> symkin.System:
    """One crank of BASE per text, each on its own revolute and driven by its own angle:
    crank<k>.phi = thetas[k](t), the cranks independent of one another."""
    data = copy.deepcopy(BASE)
    data["bodies"] = {f"crank{k}": copy.deepcopy(BASE["bodies"]["crank"])
                      for k in range(len(thetas))}
    data["joints"] = [{**BASE["joints"][0], "j": f"crank{k}"} for k in range(len(thetas))]
    data["drivers"] = [{**BASE["drivers"][0], "i": f"crank{k}", "theta": theta}
                       for k, theta in enumerate(thetas)]
    return symkin.derive(symkin.from_dict(data))


@pytest.fixture(scope="module")
def solved() -> dict[str, Trajectory]:
    """Every SOLVES text in one mechanism, built and solved once on each backend: the cranks
    share no row, so each angle is what a mechanism of its own text alone gives, and nine
    expressions cost one derivation and two builds instead of nine and eighteen."""
    system = _cranks(sorted(SOLVES))
    results = {}
    for backend in ("c", "numpy"):
        kernel = symkin.compile(system, backend=backend)
        assert kernel.backend == backend
        results[backend] = symkin.solve(kernel)
    return results


@pytest.mark.parametrize("theta", sorted(SOLVES))
def test_expression_solves_the_same_on_both_backends(solved, theta: str) -> None:
    crank = f"crank{sorted(SOLVES).index(theta)}"
    expected = SOLVES[theta]
    states = {}
    for backend, trajectory in solved.items():
        states[backend] = trajectory.body(crank)[:2]
        angle = states[backend][0][:, 2]
        if expected is not None:
            np.testing.assert_allclose(angle, expected, rtol=0, atol=1e-12, err_msg=backend)
    np.testing.assert_allclose(states["c"][0], states["numpy"][0], rtol=0, atol=1e-13)
    np.testing.assert_allclose(states["c"][1], states["numpy"][1], rtol=0, atol=1e-12)


@pytest.mark.parametrize("theta", sorted(SINGULAR))
def test_singular_time_function_stops_both_backends_alike(theta: str) -> None:
    system = _mechanism(theta)
    messages = []
    for backend in ("c", "numpy"):
        kernel = symkin.compile(system, backend=backend)
        # NumPy's floating-point warnings stay inside symkin (the failure says it all).
        with warnings.catch_warnings(), pytest.raises(SolveFailure) as caught:
            warnings.simplefilter("error")
            symkin.solve(kernel)
        failure = caught.value
        assert failure.reason == "not finite"
        assert failure.t == SINGULAR[theta]
        assert failure.trajectory.t.size == int(round(SINGULAR[theta] / 0.25))
        assert "drivers[0] angle crank-ground" in str(failure)
        messages.append(str(failure))
    assert messages[0] == messages[1]


@pytest.mark.parametrize("theta", sorted(REFUSED))
def test_unprintable_or_unbounded_expression_is_refused_at_once(theta: str) -> None:
    began = time.perf_counter()
    with pytest.raises(MechanismError, match="at drivers\\[0\\].theta") as caught:
        _mechanism(theta)
    assert REFUSED[theta] in str(caught.value)
    assert time.perf_counter() - began < 30  # bounded work: once more than 600 s


def test_float_constant_outside_the_float_range_is_refused_when_generating() -> None:
    from symkin.errors import BuildError

    for value in (1e39, 1e-50):
        system = _mechanism("t", parameters={"a": 1.0, "c": value})
        with pytest.raises(BuildError, match="outside the range of a float"):
            symkin.compile(system, backend="c", real="float")

"""The time grid, parameters and initial guess handed to the driver."""

from __future__ import annotations

import numpy as np
import pytest
from driver_support import derive, kernel_for

from symkin.errors import SolveError, SymkinError
from symkin.runtime import driver


def test_grid_is_t0_plus_k_dt_with_the_end_point() -> None:
    times = driver.grid(0.0, 1.5, 0.05)
    assert times.size == 31 and times[-1] == 1.5
    assert np.array_equal(times[:-1], 0.05 * np.arange(30))
    fine = driver.grid(0.0, 1.5, 1.5 / 20000)
    assert fine.size == 20001 and fine[-1] == 1.5
    assert fine[12345] == 12345 * (1.5 / 20000)  # no accumulated drift


def test_grid_stops_before_t1_when_dt_does_not_divide() -> None:
    times = driver.grid(1.0, 2.0, 0.3)
    assert times.tolist() == [1.0, 1.0 + 0.3, 1.0 + 2 * 0.3, 1.0 + 3 * 0.3]


@pytest.mark.parametrize("bad", [(0, 1, 0), (0, 1, -0.1), (1, 0, 0.1)])
def test_bad_grid(bad) -> None:
    with pytest.raises(SolveError, match="time grid"):
        driver.grid(*bad)


def test_parameters_by_name_and_bad_inputs(crank_slider_system) -> None:
    kernel = kernel_for(crank_slider_system, "numpy")
    longer = driver.solve(kernel, t=[0.0], params={"b": 6.0})
    assert longer.params.tolist() == [1.0, 6.0, 4.0]
    # slider x at t = 0 (crank straight up): 0 + sqrt(b^2 - (c - a)^2)
    assert longer.q[0, 6] == pytest.approx(np.sqrt(36 - 9), abs=1e-12)
    with pytest.raises(SolveError, match="unknown parameter 'z'"):
        driver.solve(kernel, params={"z": 1.0})
    with pytest.raises(SolveError, match="q0 has 2 values"):
        driver.solve(kernel, q0=[0, 0])
    with pytest.raises(SolveError, match="increasing"):
        driver.solve(kernel, t=[0.0, 0.2, 0.1])


@pytest.mark.parametrize("argument,fragment", [
    ({"t": "abc"}, "t must be numbers"),
    ({"t": [0.0, 1j]}, "t must be real numbers, not complex"),
    ({"t": np.array([0.0, 0.5 + 1e-3j])}, "t must be real numbers, not complex"),
    ({"q0": ["x"] * 9}, "q0 must be numbers"),
    ({"params": {"a": "x"}}, "params['a'] must be numbers"),
    ({"params": {"a": [1.0, 2.0]}}, "params['a'] must be one number, not 2"),
    ({"params": np.array([1.0, 5.0, 4.0 + 1j])}, "params must be real numbers, not complex"),
])
def test_arguments_that_are_not_real_numbers_are_a_solve_error(crank_slider_system, argument,
                                                                fragment) -> None:
    # found by fuzzing the API: NumPy's ValueError or TypeError came out, or a complex array
    # lost its imaginary part without a word
    kernel = kernel_for(crank_slider_system, "numpy")
    with pytest.raises(SolveError) as caught:
        driver.solve(kernel, **argument)
    assert fragment in str(caught.value)


def test_point_lookup_and_saving_errors(tmp_path) -> None:
    trajectory = driver.solve(kernel_for(derive("point_trajectory"), "numpy"), t=[0.0, 0.1])
    r, dr, ddr = trajectory.point("rod", "tip")
    assert r.shape == dr.shape == ddr.shape == (2, 2)
    with pytest.raises(SymkinError, match="named points are: rod.tip"):
        trajectory.point("rod", "nose")
    with pytest.raises(SymkinError, match=".npz or .csv"):
        trajectory.save(tmp_path / "out.txt")


def test_runtime_imports_no_sympy() -> None:
    import subprocess
    import sys
    from pathlib import Path

    code = ("import sys, symkin.runtime.driver, symkin.runtime.outputs.results; "
            "assert 'sympy' not in sys.modules and 'jinja2' not in sys.modules")
    root = Path(__file__).resolve().parents[2]
    subprocess.run([sys.executable, "-c", code], cwd=root, check=True)


def test_generated_numpy_kernel_matches_a_lambdify_kernel(crank_slider_system) -> None:
    """The driver on a kernel lambdified straight from the System gives the same trajectory."""
    from driver_support import LambdifyKernel

    generated = driver.solve(kernel_for(crank_slider_system, "numpy"))
    lambdified = driver.solve(LambdifyKernel(crank_slider_system))
    assert np.abs(generated.q - lambdified.q).max() < 1e-12
    assert np.abs(generated.d2q - lambdified.d2q).max() < 1e-11

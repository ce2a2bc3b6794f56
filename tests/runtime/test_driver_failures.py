"""Failures users can act on: singular Phi_q named by its joints, no assembly, partial results.

The dependent equations expected at the dead centre come from statics, not from the code: with
crank and rod collinear along x, a compressive force along the line of centres is carried by the
x equations of the three revolute joints and by the slide driver (a self-stress), so exactly
those rows of Phi_q are dependent.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from driver_support import BACKENDS, derive, kernel_for

from symkin.errors import SolveError
from symkin.runtime import driver
from symkin.runtime.solving import newton

DEAD_CENTRE_ROWS = (
    "joints[0] revolute ground-crank (x)",
    "joints[1] revolute crank-rod (x)",
    "joints[2] revolute rod-slider (x)",
    "drivers[0] slide ground-slider (slide)",
)


def _failure(kernel, **kwargs) -> driver.SolveFailure:
    with pytest.raises(SolveError) as caught:
        driver.solve(kernel, **kwargs)
    assert isinstance(caught.value, driver.SolveFailure)
    return caught.value


@pytest.mark.parametrize("backend", BACKENDS)
def test_exact_dead_centre_is_singular_with_the_joints_named(backend: str) -> None:
    kernel = kernel_for(derive("dead_centre"), backend)
    at_dead_centre = [0, 0, 0, 1, 0, 0, 4, 0, 0]  # x = a + b at t = 0.5: crank and rod along x
    failure = _failure(kernel, t=[0.5, 0.6], q0=at_dead_centre)
    assert failure.reason == "singular" and failure.t == 0.5
    assert failure.rows == DEAD_CENTRE_ROWS
    assert failure.trajectory.t.size == 0
    message = str(failure)
    assert "t = 0.5" in message and "singular" in message
    assert all(row in message for row in DEAD_CENTRE_ROWS)


@pytest.mark.parametrize("backend", BACKENDS)
def test_driven_through_dead_centre_keeps_rows_solved_so_far(backend: str) -> None:
    kernel = kernel_for(derive("dead_centre"), backend)
    failure = _failure(kernel)  # slider x = 3.5 + t reaches a + b = 4 at t = 0.5
    # the slider cannot go beyond x = a + b: a limit position of the driven motion
    assert failure.reason == "limit position"
    assert set(DEAD_CENTRE_ROWS) <= set(failure.rows)
    assert failure.t == pytest.approx(0.55)
    partial = failure.trajectory
    assert partial.t.size == 11 and partial.t[-1] == 0.5
    # the rows before the dead centre are right: slider x = 3.5 + t, crank angle by cosines
    x = 3.5 + partial.t[:-1]
    theta = np.arccos((1 + x**2 - 9) / (2 * x))
    assert np.abs(partial.q[:-1, 6] - x).max() < 1e-9
    assert np.abs(partial.q[:-1, 2] - theta).max() < 1e-9
    assert "t = 0.55" in str(failure) and "limit position near t = 0.5 " in str(failure)
    assert "crank-rod" in str(failure) and "reversing the driver" in str(failure)


@pytest.mark.parametrize("backend", BACKENDS)
def test_links_too_short_cannot_assemble_at_t0(backend: str) -> None:
    kernel = kernel_for(derive("four_bar_test"), backend)
    failure = _failure(kernel, params={"d": 10.0})  # a + b + c = 6.5 < d: the loop cannot close
    assert failure.reason == "no assembly"
    assert failure.t == 0.0 and failure.trajectory.t.size == 0
    # least squares spreads the gap d - (a + b + c) = 3.5 evenly over the four joints' x rows
    assert failure.residual == pytest.approx(3.5 / 4, abs=0.01)
    assert "cannot be assembled at t = 0" in str(failure)
    assert "evidence points at the link lengths" in str(failure)


def test_newton_failure_reports_t_residual_iterations() -> None:
    kernel = kernel_for(derive("offset_crank_slider"), "numpy")
    # one huge step: the crank turns 3 rad between grid points, Newton is capped at 2 iterations
    capped = newton.Options(max_iterations=2, stop_at_singular=True)  # no step subdivision
    failure = _failure(kernel, t=[0.0, 1.0], options=capped)
    assert failure.t == 1.0 and failure.iterations == 2
    assert failure.trajectory.t.size == 1
    assert math.isfinite(failure.residual) and failure.residual > 1e-10
    assert f"{failure.residual:.3g}" in str(failure) and "2 iterations" in str(failure)


def test_assembly_from_zero_uses_levenberg_marquardt() -> None:
    """Phi_q is singular at q = 0 for the four-bar, so plain Newton cannot start there."""
    kernel = kernel_for(derive("four_bar_test"), "numpy")
    zero = np.zeros(len(kernel.coordinates))
    options = newton.Options()
    assert newton.newton(kernel, zero, 0.0, kernel.p_values, options).status != newton.OK
    trajectory = driver.solve(kernel, q0=zero)
    for k, t in enumerate(trajectory.t[::10]):
        assert np.abs(kernel.phi(trajectory.q[10 * k], t)).max() < 1e-10


def test_textbook_assembles_from_q_zero_like_the_chapter(crank_slider_system) -> None:
    kernel = kernel_for(crank_slider_system, "numpy")
    assert not np.any(kernel.q0)
    trajectory = driver.solve(kernel)
    assert trajectory.q[0] == pytest.approx([0, 0, math.pi / 2, 0, 1, math.asin(3 / 5), 4, 4, 0],
                                            abs=1e-12)


def test_too_large_step_is_subdivided_not_reported() -> None:
    """The same huge step without the old stop: the step is subdivided and t = 1 is reached,
    on the same branch as a fine grid follows it."""
    kernel = kernel_for(derive("offset_crank_slider"), "numpy")
    coarse = driver.solve(kernel, t=[0.0, 1.0], options=newton.Options(max_iterations=2))
    fine = driver.solve(kernel, t=np.linspace(0.0, 1.0, 201))
    assert np.abs(coarse.q[-1] - fine.q[-1]).max() < 1e-9
    assert np.abs(coarse.d2q[-1] - fine.d2q[-1]).max() < 1e-7
    assert not coarse.flagged.any()

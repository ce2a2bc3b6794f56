"""Limit positions told from too-large steps, and assembly from rough guesses.

References are closed forms derived here (loop closure by circle intersections, the limit of a
non-Grashof four-bar from the law of cosines), never the code under test.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from codegen_support import derived
from driver_support import BACKENDS, derive, kernel_for

from symkin.contract.dense_solvers import levenberg_marquardt
from symkin.contract.options import Options
from symkin.errors import SolveError
from symkin.runtime import driver
from symkin.runtime.solving import newton

ROOT = Path(__file__).resolve().parents[2]
T_LIMIT = math.acos(-0.25)  # non_grashof.yaml: a = b = c = 2, d = 3; cos(theta*) = -1/4


def _failure(kernel, **kwargs) -> driver.SolveFailure:
    with pytest.raises(SolveError) as caught:
        driver.solve(kernel, **kwargs)
    assert isinstance(caught.value, driver.SolveFailure)
    return caught.value


def _angle(a: np.ndarray) -> np.ndarray:
    return np.angle(np.exp(1j * np.asarray(a)))


def circles(c1: np.ndarray, r1: float, c2: np.ndarray, r2: float) -> list[np.ndarray]:
    """The intersections of two circles (none when they do not meet)."""
    d = np.linalg.norm(c2 - c1)
    along = (r1**2 - r2**2 + d**2) / (2 * d)
    if r1**2 < along**2:
        return []
    height = math.sqrt(r1**2 - along**2)
    u = (c2 - c1) / d
    n = np.array([-u[1], u[0]])
    return [c1 + along * u + height * n, c1 + along * u - height * n]


@pytest.mark.parametrize("backend", BACKENDS)
def test_non_grashof_four_bar_reaches_its_limit_position(backend: str) -> None:
    kernel = kernel_for(derive("non_grashof"), backend)
    assert kernel.backend == backend
    failure = _failure(kernel)
    assert failure.reason == "limit position"
    assert abs(failure.reached - T_LIMIT) < 1e-6
    message = str(failure)
    assert "limit position near t = 1.82347658" in message
    for joint in ("A revolute crank-coupler", "B revolute coupler-rocker",
                  "O4 revolute rocker-ground"):
        assert joint in message
    assert "O2 revolute" not in message.split("become aligned")[0]  # the crank does not move
    assert "input angle crank-ground cannot be followed" in message
    assert "reversing the driver" in message
    # every row before it is written and right: theta = t, rocker angle by the law of cosines
    partial = failure.trajectory
    assert partial.t.size == 37 and partial.t[-1] < T_LIMIT
    a_pin = 2 * np.stack([np.cos(partial.t), np.sin(partial.t)], 1)
    to_a = a_pin - np.array([3.0, 0.0])
    e = np.linalg.norm(to_a, axis=1)
    rocker = np.arctan2(to_a[:, 1], to_a[:, 0]) - np.arccos((4 + e**2 - 4) / (4 * e))
    steady = ~partial.flagged
    assert np.abs(_angle(partial.q[steady, 8] - rocker[steady])).max() < 1e-8


@pytest.mark.parametrize("backend", BACKENDS)
def test_rod_too_short_for_the_whole_turn_is_a_limit_position(backend: str) -> None:
    """The textbook crank-slider with a = 1.1, b = 3.5: the rod reaches the slide line y = c = 4
    only while a sin(phi) >= c - b, phi = t**2 + pi/2. Near that fold Phi_q is only moderately
    ill-conditioned (sigma_min shrinks like the square root of the distance), so the limit is
    told by the condition's growth as the substeps close in, not by its size."""
    system = derived(ROOT / "examples" / "crank_slider.yaml")  # once per test run
    kernel = kernel_for(system, backend)
    assert kernel.backend == backend
    failure = _failure(kernel, params={"a": 1.1, "b": 3.5})
    t_limit = math.sqrt(math.pi - math.asin(0.5 / 1.1) - math.pi / 2)
    assert failure.reason == "limit position", str(failure)
    assert abs(failure.reached - t_limit) < 1e-6
    assert "drivers[0] angle crank-ground cannot be followed" in str(failure)
    assert failure.trajectory.t[-1] < t_limit


@pytest.mark.parametrize("backend", BACKENDS)
def test_slider_driven_into_dead_centre_is_a_limit_position(backend: str) -> None:
    """dead_centre.yaml: slider x = 3.5 + t reaches a + b = 4 at t = 0.5 exactly."""
    kernel = kernel_for(derive("dead_centre"), backend)
    assert kernel.backend == backend
    failure = _failure(kernel)
    assert failure.reason == "limit position" and abs(failure.reached - 0.5) < 1e-6
    for joint in ("ground-crank", "crank-rod", "rod-slider"):
        assert joint in str(failure).split("become aligned")[0]
    partial = failure.trajectory
    x = 3.5 + partial.t
    theta = np.arccos(np.clip((1 + x**2 - 9) / (2 * x), -1, 1))
    dtheta = -(1 / np.sqrt(1 - ((1 + x[:-1]**2 - 9) / (2 * x[:-1]))**2)) * \
        (0.5 + 4 / x[:-1]**2)  # d/dt of acos((x^2 - 8) / (2x)), x' = 1
    assert np.abs(partial.q[:-1, 2] - theta[:-1]).max() < 1e-8
    assert np.abs(partial.dq[:-1, 2] - dtheta).max() < 1e-7
    # at the dead centre itself dtheta/dt is infinite: that point cannot be right, and is flagged
    assert partial.t[-1] == 0.5 and partial.flagged[-1] and not partial.flagged[:-1].any()


def six_bar_assemblies() -> list[np.ndarray]:
    """The four assemblies of watt_six_bar_rough.yaml at t = 0 (crank angle 0), by circles."""
    a_pin, o4, o6 = np.array([0.0, 1.0]), np.array([4.0, 0.0]), np.array([9.0, 0.0])
    found = []
    for b in circles(a_pin, math.sqrt(13), o4, math.sqrt(10)):
        rocker = math.atan2(*(b - o4)[::-1]) - math.atan2(3, -1)
        rot = np.array([[math.cos(rocker), -math.sin(rocker)], [math.sin(rocker), math.cos(rocker)]])
        c = o4 + rot @ np.array([2.0, 2.0])
        for d in circles(c, math.sqrt(8), o6, math.sqrt(17)):
            found.append(np.array([
                0, 0, 0,
                *a_pin, math.atan2(*(b - a_pin)[::-1]) - math.atan2(2, 3),
                *o4, rocker,
                *c, math.atan2(*(d - c)[::-1]) - math.atan2(2, 2),
                *o6, math.atan2(*(d - o6)[::-1]) - math.atan2(4, -1)]))
    return found


@pytest.mark.parametrize("backend", BACKENDS)
def test_six_bar_assembles_from_a_poor_guess(backend: str) -> None:
    kernel = kernel_for(derive("watt_six_bar_rough"), backend)
    assert kernel.backend == backend
    guess = np.zeros(15)
    guess[2::3] = math.pi  # every body at the origin, turned half a revolution
    # plain damped Newton from this guess alone stalls in a local minimum
    q, residual = levenberg_marquardt(kernel, guess, 0.0, kernel.p_values, Options())
    assert residual > 0.1
    trajectory = driver.solve(kernel, q0=guess)
    assert trajectory.t.size == 51 and not trajectory.flagged.any()
    assemblies = six_bar_assemblies()
    assert len(assemblies) >= 2
    errors = []
    for reference in assemblies:
        difference = trajectory.q[0] - reference
        difference[2::3] = _angle(difference[2::3])  # angles compared modulo 2 pi
        errors.append(np.abs(difference).max())
    assert min(errors) < 1e-10


@pytest.mark.parametrize("backend", BACKENDS)
def test_guess_singular_at_the_start_is_no_dead_centre(backend: str) -> None:
    """slide_driven.yaml with every body at the origin, unrotated: crank, rod and slider all
    lie on the slider's axis, Phi_q is singular at the guess. At t = 0 the slider is at
    x0 = 3, so the crank angle is +-acos(1/6) ((3 - cos)^2 + sin^2 = b^2 = 9)."""
    kernel = kernel_for(derive("slide_driven"), backend)
    assert kernel.backend == backend
    guess = np.zeros(9)
    at_guess = newton.newton(kernel, guess, 0.0, kernel.p_values, newton.Options())
    assert at_guess.status == newton.SINGULAR and at_guess.iterations == 0
    trajectory = driver.solve(kernel, q0=guess, t=[0.0, 0.03])
    assert abs(abs(trajectory.q[0, 2]) - math.acos(1 / 6)) < 1e-10
    assert abs(trajectory.q[0, 6] - 3.0) < 1e-10
    # links that cannot reach (x0 = 10 > a + b = 4): "cannot be assembled", never "singular"
    failure = _failure(kernel, q0=guess, params={"x0": 10.0})
    assert failure.reason == "no assembly"
    assert "cannot be assembled" in str(failure) and "link lengths" in str(failure)
    assert "dead-centre" not in str(failure)

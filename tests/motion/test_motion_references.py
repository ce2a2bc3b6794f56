"""Forward dynamics against references derived here: the pendulum's period (complete
elliptic integral), the crank-slider's minimal-coordinate equation of motion integrated by
SciPy, the energy balance, Newton-Euler per body."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import sympy as sp
from motion_support import CRANK_SLIDER, PENDULUM, shared
from motion_support import kernel as built
from scipy.integrate import solve_ivp
from scipy.special import ellipk

import symkin


def _energy(trajectory: Any) -> tuple[np.ndarray, np.ndarray]:
    out = dict(trajectory.outputs)
    total = out["kinetic_energy"] + out["potential_energy"] - out["work_nonconservative"]
    scale = np.max(np.abs(out["kinetic_energy"]) + np.abs(out["potential_energy"]))
    return total, scale


@pytest.mark.parametrize("backend", ["numpy", "c"])  # each integrates through its kernel
def test_a_pendulum_swings_with_the_period_of_the_elliptic_integral(tmp_path: Path,
                                                                    backend: str) -> None:
    amplitude = 2.0  # rad from the bottom: far from the small-angle period
    start = -math.pi / 2 + amplitude
    kernel = built(shared("p.yaml", PENDULUM.replace(
        "PHI0", repr(start))), backend)
    assert kernel.backend == backend
    period = 4 * math.sqrt(1.3 / 9.81) * ellipk(math.sin(amplitude / 2) ** 2)
    # (the small-angle period 2 pi sqrt(L/g) differs by 30 %: the test sees the difference)
    trajectory = symkin.solve(kernel, t=[0, period / 2, period, 3 * period])
    phi, rate = trajectory.q[:, 2], trajectory.dq[:, 2]
    assert phi[1] == pytest.approx(-math.pi / 2 - amplitude, abs=1e-8)
    assert phi[2] == pytest.approx(start, abs=1e-8)
    assert phi[3] == pytest.approx(start, abs=1e-8)
    assert np.abs(rate) == pytest.approx(np.zeros(4), abs=1e-7)


def _minimal_crank_slider() -> Any:
    """θ'' of the crank-slider in its crank angle θ alone, by Lagrange's equation with the
    closed-form positions of Example 2.7 (no absolute coordinates, no multipliers)."""
    th, w = sp.symbols("theta omega")
    a, b, c, m1, m2, m3, j1, j2, g, k = 1.0, 5.0, 4.0, 2.0, 3.0, 1.5, 0.2, 6.5, 9.81, 20.0
    tip = sp.Matrix([a * sp.cos(th), a * sp.sin(th)])
    phi2 = sp.asin((c - tip[1]) / b)
    rod_mid = tip + b / 2 * sp.Matrix([sp.cos(phi2), sp.sin(phi2)])
    x3 = tip[0] + b * sp.cos(phi2)
    centres = [(m1, tip / 2), (m2, rod_mid), (m3, sp.Matrix([x3, c]))]
    mass = sum(m * (r.diff(th).T * r.diff(th))[0] for m, r in centres)
    mass += j1 + j2 * phi2.diff(th) ** 2
    spring = sp.sqrt((x3 - 1.0) ** 2)  # from (1, c) to the slider, along the guide
    potential = sum(m * g * r[1] for m, r in centres) + k / 2 * (spring - 2.5) ** 2
    accel = -(mass.diff(th) * w ** 2 / 2 + potential.diff(th)) / mass
    return sp.lambdify((th, w), accel), sp.lambdify(th, x3)


@pytest.mark.parametrize("fixture", ["crank_slider", "crank_slider_c"])
def test_the_crank_slider_follows_its_minimal_coordinate_equation(
        fixture: str, request: pytest.FixtureRequest) -> None:
    trajectory = symkin.solve(request.getfixturevalue(fixture))
    accel, slider_x = _minimal_crank_slider()
    theta0, omega0 = trajectory.q[0, 2], trajectory.dq[0, 2]
    assert omega0 == pytest.approx(2.0, abs=1e-12)  # the given rate, kept exactly
    reference = solve_ivp(lambda t, y: [y[1], accel(*y)], (0, 2), [theta0, omega0],
                          method="DOP853", rtol=1e-12, atol=1e-12, t_eval=trajectory.t)
    assert trajectory.q[:, 2] == pytest.approx(reference.y[0], abs=1e-7)
    assert trajectory.dq[:, 2] == pytest.approx(reference.y[1], abs=1e-6)
    assert trajectory.q[:, 6] == pytest.approx(slider_x(reference.y[0]), abs=1e-7)


def test_every_row_satisfies_the_constraints_at_three_levels(crank_slider: Any) -> None:
    trajectory = symkin.solve(crank_slider)
    p = crank_slider.p_values
    model = crank_slider.model
    for k in range(0, trajectory.t.size, 7):
        q, dq, d2q, t = trajectory.q[k], trajectory.dq[k], trajectory.d2q[k], trajectory.t[k]
        jacobian = model.phi_q(q, t, p)
        assert np.abs(model.phi(q, t, p)).max() <= 1e-10
        assert np.abs(jacobian @ dq + model.phi_t(q, t, p)).max() <= 1e-10
        assert np.abs(jacobian @ d2q - model.gamma(q, dq, t, p)).max() <= 1e-9
    assert dict(trajectory.outputs)["constraint_residual"].max() <= 1e-10


def test_an_undamped_mechanism_keeps_its_energy_over_many_periods(tmp_path: Path) -> None:
    kernel = built(shared("p.yaml", PENDULUM.replace(
        "PHI0", "0.3")), "numpy")
    trajectory = symkin.solve(kernel, t=np.linspace(0, 60, 301))  # about 25 periods
    total, scale = _energy(trajectory)
    assert np.ptp(total) <= 1e-8 * scale
    assert dict(trajectory.outputs)["work_nonconservative"] == pytest.approx(
        np.zeros(301), abs=1e-12)


def test_a_damper_s_work_closes_the_energy_balance(tmp_path: Path) -> None:
    damped = CRANK_SLIDER.replace("SPRING", "20.0").replace("length0: 2.5}",
                                                             "length0: 2.5, damping: 3.0}")
    kernel = built(shared("d.yaml", damped), "numpy")
    trajectory = symkin.solve(kernel)
    total, scale = _energy(trajectory)
    work = dict(trajectory.outputs)["work_nonconservative"]
    assert work[-1] < -0.05 * scale  # the damper took energy out ...
    assert np.ptp(total) <= 1e-8 * scale  # ... and the balance says where it went


def _cross(r: np.ndarray, f: np.ndarray) -> np.ndarray:
    return r[..., 0] * f[..., 1] - r[..., 1] * f[..., 0]


def test_newton_euler_holds_for_every_body(crank_slider: Any) -> None:
    trajectory = symkin.solve(crank_slider)
    rows = slice(0, None, 5)
    g = np.array([0.0, -9.81])
    r0, r1, r2, r3 = (trajectory.reaction[rows, j, :2] for j in range(4))
    crank = trajectory.point("crank", "mid")
    rod = trajectory.point("rod", "mid")
    slider = trajectory.point("slider", "c")
    spring_force = -20.0 * (slider[0][rows, 0] - 1.0 - 2.5)  # along x, on the slider
    spring = np.stack([spring_force, 0 * spring_force], axis=1)
    # translation: m a_c = forces on the body (reaction j: what body i exerts on body j)
    assert 2.0 * crank[2][rows] == pytest.approx(r0 - r1 + 2.0 * g, abs=1e-7)
    assert 3.0 * rod[2][rows] == pytest.approx(r1 - r2 + 3.0 * g, abs=1e-7)
    assert 1.5 * slider[2][rows] == pytest.approx(r2 - r3 + 1.5 * g + spring, abs=1e-7)
    # rotation of the rod about its centre: J φ'' = moments of the joint forces
    tip = trajectory.point("crank", "tip")[0][rows]
    end = trajectory.point("rod", "P")[0][rows]
    moment = _cross(tip - rod[0][rows], r1) + _cross(end - rod[0][rows], -r2)
    assert 6.5 * trajectory.d2q[rows, 5] == pytest.approx(moment, abs=1e-7)


def test_a_loose_tolerance_does_not_let_the_constraints_drift(tmp_path: Path) -> None:
    # error control at 1e-5 lets the state wander by about that much per unit time; the
    # projection after every step keeps each row on Φ = 0 and Φ_q q' = -Φ_t all the same
    loose = CRANK_SLIDER.replace("SPRING", "20.0").replace("rtol: 1e-11, atol: 1e-12",
                                                            "rtol: 1e-5, atol: 1e-7")
    kernel = built(shared("l.yaml", loose), "numpy")
    trajectory = symkin.solve(kernel, t=np.linspace(0, 10, 21))
    p, model = kernel.p_values, kernel.model
    assert dict(trajectory.outputs)["constraint_residual"].max() <= 1e-10
    rates = [model.phi_q(q, t, p) @ dq for q, dq, t in
             zip(trajectory.q, trajectory.dq, trajectory.t)]
    assert np.abs(rates).max() <= 1e-10


def test_initial_velocities_take_the_parameters_the_run_is_given(tmp_path: Path) -> None:
    """A pendulum whose initial rate is the parameter w: without gravity it turns uniformly,
    phi(t) = phi0 + w t (closed form), with the w the run is given, not the file's."""
    text = PENDULUM.replace("PHI0", "0.25").replace("g: 9.81}", "g: 9.81, w: 1.0}") + \
        "initial: {velocities: {rod.phi: 2*w}}\n"
    kernel = built(shared("w.yaml", text), "numpy")
    t = np.linspace(0.0, 1.0, 5)
    phi = kernel.coordinates.index("rod.phi")
    for w in (1.0, 3.0, -0.5):
        trajectory = symkin.solve(kernel, t=t, params={"w": w, "g": 0.0})
        assert trajectory.dq[:, phi] == pytest.approx(np.full(5, 2 * w), abs=1e-9)
        assert trajectory.q[:, phi] == pytest.approx(0.25 + 2 * w * t, abs=1e-9)
    assert symkin.solve(kernel, t=t).dq[0, phi] == pytest.approx(2.0, abs=1e-12)  # nominal
    with pytest.raises(symkin.SolveError, match=r"rod\.phi"):  # not a number with these
        symkin.solve(kernel, t=t, params={"w": math.inf})

"""The start check reads the length scales a solve needs from the solver's own work: the C grid
solver measures the unit's at the first guess on its own arrays and reports the first row's in
``<prefix>_report.lever_arm``; the runtime's Newton (the NumPy backend) gives the first row's
from the Phi_q it factored there. Each value is the one a fresh computation gives, to the bit,
and the start check decides with it as before.

References: the length scale by its definition (runtime.solving.start: max |dPhi_i/dphi_j| /
max |dPhi_i/dx_k| over the length rows) evaluated here in Python from Phi_q's non-zeros, the
generated ``<prefix>_length_scales`` called on its own, and the crank-slider's closed form:
its largest lever arm is the rod's, b max(|cos theta|, |sin theta|) for the rod's angle theta
(the crank's is a = 1 < b)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from codegen_support import compiled

import symkin
from symkin.runtime import driver
from symkin.runtime.solving import start

ROOT = Path(__file__).resolve().parents[2]
T = np.linspace(0.0, 1.5, 31)
EXAMPLES = ("crank_slider", "four_bar", "rssr")


def _reference(kernel, q: np.ndarray, t: float, p: np.ndarray) -> float:
    """L at (q, t, p) from the definition, in Python: per row with a length column, the
    largest |entry| in an angle column over the largest in a length column."""
    nz = np.asarray(kernel.phi_q_nz(q, t, p), dtype=float)
    length = start.positions(kernel)[kernel.pattern_cols]
    moved = np.zeros(kernel.nq)
    turned = np.zeros(kernel.nq)
    for value, row, is_length in zip(np.abs(nz), kernel.pattern_rows, length):
        target = moved if is_length else turned
        target[row] = max(target[row], value)
    arms = [turned[i] / moved[i] for i in range(kernel.nq) if moved[i] > 0]
    return max(arms, default=0.0)


def _parameter_sets(kernel, count: int = 4) -> list[np.ndarray]:
    """The nominal set and a few moved by up to 5 %, seeded."""
    rng = np.random.default_rng(11)
    nominal = np.array(kernel.p_values, dtype=float)
    return [nominal] + [nominal * rng.uniform(0.95, 1.05, nominal.size) for _ in range(count)]


def _recorded(monkeypatch, module, name: str) -> list[tuple]:
    """The arguments of every call of ``module``'s ``name`` (the start check's tests)."""
    calls: list[tuple] = []
    original = getattr(module, name)

    def recording(*args):
        calls.append(args)
        return original(*args)

    monkeypatch.setattr(module, name, recording)
    return calls


@pytest.mark.parametrize("example", EXAMPLES)
def test_the_c_solver_reports_the_first_rows_lever_arm(example, monkeypatch):
    """The value the start check's test reads (clears', after the senses of rssr were
    checked) is the first row's."""
    kernel = compiled(ROOT / "examples" / f"{example}.yaml")
    used = _recorded(monkeypatch, start, "clears")
    for p in _parameter_sets(kernel):
        trajectory = symkin.solve(kernel, t=T, params=p)
        estimate, reported, _ = used[-1]
        first = trajectory.q[0]
        generated = float(kernel.batch_solver.length_scales(p[None, :], first, T[0])[0])
        assert reported == generated == _reference(kernel, first, T[0], p), p
        assert estimate == trajectory.cond[0]


@pytest.mark.parametrize("example", EXAMPLES)
def test_the_c_solver_measures_the_units_lever_arm_at_the_first_guess(example):
    kernel = compiled(ROOT / "examples" / f"{example}.yaml")
    options = driver.default_options(kernel)
    for p in _parameter_sets(kernel):
        solver = kernel.grid_solver(options, kernel.q0, p)
        try:
            measured = solver.start_lever_arm(T[0])
        finally:
            solver.release()
        generated = float(kernel.batch_solver.length_scales(p[None, :], kernel.q0, T[0])[0])
        assert measured == generated == _reference(kernel, kernel.q0, T[0], p), p


def test_the_crank_sliders_lever_arm_is_the_rods():
    kernel = compiled(ROOT / "examples" / "crank_slider.yaml")
    b = kernel.p_values[list(kernel.parameter_names).index("b")]
    trajectory = symkin.solve(kernel, t=T)
    theta = trajectory.q[0, kernel.coordinates.index("rod.phi")]
    solver = kernel.grid_solver(driver.default_options(kernel), trajectory.q[0],
                                kernel.p_values)
    try:
        assert solver.start_lever_arm(T[0]) == pytest.approx(
            b * max(abs(math.cos(theta)), abs(math.sin(theta))), rel=1e-14)
    finally:
        solver.release()


@pytest.mark.parametrize("example", EXAMPLES)
def test_the_runtimes_newton_gives_the_first_rows_lever_arm(example, monkeypatch):
    """The NumPy backend: the value the start check reads is start.lever_arm's."""
    kernel = compiled(ROOT / "examples" / f"{example}.yaml", backend="numpy")
    used = _recorded(monkeypatch, driver, "singular_start")
    for p in _parameter_sets(kernel, 2):
        trajectory = symkin.solve(kernel, t=T[:3], params=p)
        _, q, t0, _, _, estimate, reported = used[-1]
        assert np.array_equal(q, trajectory.q[0]) and estimate == trajectory.cond[0]
        assert reported == start.lever_arm(kernel, q, t0, p) == _reference(kernel, q, t0, p)


def test_both_backends_judge_the_start_alike(monkeypatch):
    """The same first row, parameters and lever arm on C and NumPy."""
    c = compiled(ROOT / "examples" / "four_bar.yaml")
    numpy_kernel = compiled(ROOT / "examples" / "four_bar.yaml", backend="numpy")
    checked = _recorded(monkeypatch, start, "clears")
    judged = _recorded(monkeypatch, driver, "singular_start")
    from_c = symkin.solve(c, t=T[:3])
    from_numpy = symkin.solve(numpy_kernel, t=T[:3])
    np.testing.assert_allclose(from_c.q[0], from_numpy.q[0], rtol=0, atol=1e-12)
    assert checked[-1][1] == pytest.approx(judged[-1][6], rel=1e-12)


def test_without_a_reported_lever_arm_the_start_check_works_it_out(monkeypatch):
    """A kernel built before the report had the field (first_lever_arm None) solves and
    refuses as one that has it."""
    from symkin.backends.c.csolver import GridSolver

    kernel = compiled(ROOT / "examples" / "crank_slider.yaml")
    reported = symkin.solve(kernel, t=T)
    monkeypatch.setattr(GridSolver, "first_lever_arm", property(lambda self: None))
    monkeypatch.setattr(GridSolver, "start_lever_arm", lambda self, t: None)
    kernel.call_plan = None  # nothing judged before
    unreported = symkin.solve(kernel, t=T)
    for name in ("q", "dq", "d2q", "cond", "flagged"):
        assert np.array_equal(getattr(reported, name), getattr(unreported, name)), name

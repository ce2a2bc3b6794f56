"""Newton goes on at a converged point where the error model would flag it, and the condition
estimate after those extra steps.

The lazy tongs (bench/scaling_limit.py) amplify their driver's motion along their length:
at 10 bodies the condition is only about 300, but a point accepted at Newton's tolerance
(max |Phi| <= 1e-10) is flagged by the error model at most points of a fine grid. The solver
tightens such points before it concedes a flag. The references are the tongs' closed form
(every bar at the driven angle a(t) = 0.7 + 0.2 sin t) differentiated by hand here.
"""

from __future__ import annotations

import dataclasses
import math
import sys
from pathlib import Path

import numpy as np
import pytest

import symkin
from symkin.contract.options import defaults
from symkin.contract.tuning import REESTIMATE_SHIFT, UNIT_ROUNDOFF
from symkin.runtime.solving import accuracy, linalg, newton
from symkin.spec import validate as model

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))

HALF = 1.0  # half a bar, as in scaling_limit


def closed_form(units: int, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """q, dq, ddq of the tongs: bar k's middle at ((2k-1) h cos a, h sin a), angles +a, -a."""
    a, da, dda = 0.7 + 0.2 * np.sin(t), 0.2 * np.cos(t), -0.2 * np.sin(t)
    c, s = np.cos(a), np.sin(a)
    q, dq, ddq = [], [], []
    for k in range(1, units + 1):
        m = (2 * k - 1) * HALF
        for sign in (1.0, -1.0):
            q += [m * c, HALF * s, sign * a]
            dq += [-m * s * da, HALF * c * da, sign * da]
            ddq += [-m * c * da**2 - m * s * dda, -HALF * s * da**2 + HALF * c * dda, sign * dda]
    return np.array(q).T, np.array(dq).T, np.array(ddq).T


@pytest.fixture(scope="module")
def tongs10() -> symkin.System:
    import scaling_limit  # bench/: the tongs' mechanism file

    return symkin.derive(model.from_dict(scaling_limit.tongs(5)))


@pytest.mark.parametrize("backend", ["numpy", "c"])
def test_points_the_model_would_flag_are_tightened(tongs10: symkin.System, backend: str,
                                                   tmp_path: Path) -> None:
    kernel = symkin.compile(tongs10, backend=backend)  # built once (run cache)
    assert kernel.backend == backend
    t = np.arange(301) * 0.001
    trajectory = symkin.solve(kernel, t=t)
    assert trajectory.cond.max() < 1e3  # not ill-conditioned: below tighten_cond
    # accepted at tol_phi, 2/3 of these points were flagged; Newton's extra steps clear them
    assert not trajectory.flagged.any()
    q, dq, ddq = closed_form(5, t)
    assert np.abs(trajectory.q - q).max() <= 1e-9 * np.abs(q).max()
    assert np.abs(trajectory.dq - dq).max() <= 1e-9 * np.abs(dq).max()
    assert np.abs(trajectory.d2q - ddq).max() <= 1e-9 * np.abs(ddq).max()


@pytest.mark.parametrize("backend", ["numpy", "c"])
def test_tighten_cond_inf_turns_the_extra_iterations_off(tongs10: symkin.System, backend: str,
                                                         tmp_path: Path) -> None:
    """The same work at every step, for who needs it: the points stay as Newton's tolerance
    left them (q within 1e-9 relative, not to the rounding level). The model of every
    coordinate flagged most of them; only the angles move Phi_q, and theirs are accurate
    (dq, ddq within 2e-10): none is flagged (tests/runtime/test_flag_model.py)."""
    kernel = symkin.compile(tongs10, backend=backend)  # built once (run cache)
    assert kernel.backend == backend
    t = np.arange(301) * 0.001
    options = dataclasses.replace(defaults("double"), tighten_cond=math.inf)
    trajectory = symkin.solve(kernel, t=t, options=options)
    q, dq, ddq = closed_form(5, t)
    assert 1e-12 < np.abs(trajectory.q - q).max() <= 1e-9 * np.abs(q).max()
    assert np.abs(trajectory.dq - dq).max() <= 1e-9 and np.abs(trajectory.d2q - ddq).max() <= 1e-9
    assert not trajectory.flagged.any()


def _newton_at(matrix: np.ndarray, inv_norm: float = math.nan) -> newton.Newton:
    result = newton.Newton(np.zeros(len(matrix)), 0, 0, 0.0, linalg.factor(matrix))
    result.inv_norm = inv_norm
    return result


def test_estimate_after_a_small_move_is_the_banach_bound() -> None:
    """Newton moved Phi_q from A to A + E: where theta = ||A^-1|| ||E|| is small the estimate is
    not made again; ||A^-1|| / (1 - theta) is an upper bound of the new ||(A + E)^-1||."""
    rng = np.random.default_rng(3)
    n = linalg.EXACT_INVERSE_UP_TO + 8  # an estimate, not the exact norm, at this size
    for _ in range(20):
        a = np.eye(n) * 4 + rng.normal(size=(n, n)) / n
        e = rng.normal(size=(n, n)) * 1e-6
        exact = np.abs(np.linalg.inv(a)).sum(axis=0).max()
        after = newton._estimate_again(_newton_at(a, exact), _newton_at(a + e))
        theta = exact * np.abs(e).sum(axis=0).max()
        assert theta <= REESTIMATE_SHIFT
        assert after.inv_norm == pytest.approx(exact / (1 - theta), rel=1e-12)
        assert after.inv_norm >= np.abs(np.linalg.inv(a + e)).sum(axis=0).max()
        assert after.norm_a == pytest.approx(np.abs(a + e).sum(axis=0).max(), rel=1e-12)


def test_estimate_after_a_large_move_is_made_again() -> None:
    rng = np.random.default_rng(4)
    n = linalg.EXACT_INVERSE_UP_TO + 8
    a = np.eye(n) * 4 + rng.normal(size=(n, n)) / n
    moved = a + rng.normal(size=(n, n)) * 0.1
    exact = np.abs(np.linalg.inv(a)).sum(axis=0).max()
    after = newton._estimate_again(_newton_at(a, exact), _newton_at(moved))
    assert after.inv_norm == pytest.approx(linalg.factor(moved).inverse_norm1(), rel=1e-12)


def test_c_estimate_at_tightened_points_bounds_the_exact_norm(tongs10: symkin.System,
                                                              tmp_path: Path) -> None:
    """The C solver on the tongs (Hager's estimate: their inverse is dense) with every point
    tightened (tighten_cond 0) from a loose tolerance, so that the extra steps move Phi_q
    measurably: the estimate after them is the Banach bound, at or above the exact
    ||Phi_q^-1||_1 at the new q (Hager's estimate before them is exact on these matrices) and
    at most REESTIMATE_SHIFT's few per cent above it."""
    kernel = symkin.compile(tongs10, backend="c")  # built once (run cache)
    ffi, lib, name, n = kernel.ffi, kernel.lib, kernel.name, kernel.nq
    options, state = ffi.new(f"{name}_options *"), ffi.new(f"{name}_state *")
    work, report = ffi.new(f"{name}_workspace *"), ffi.new(f"{name}_report *")
    getattr(lib, f"{name}_default_options")(options)
    options.tighten_cond = 0.0
    options.tol_phi, options.tol_dq = 1e-5, 1e-4
    p = ffi.new(f"{name}_real[]", list(kernel.p_values))
    state.q[0:n] = list(kernel.q0)
    ratios = []
    for t in np.arange(101) * 0.02:
        assert getattr(lib, f"{name}_solve_step")(options, p, t, state, work, report) == 0
        a = kernel.phi_q(np.array(ffi.unpack(state.q, n)), t)
        ratios.append(report.inv_norm / np.abs(np.linalg.inv(a)).sum(axis=0).max())
    assert min(ratios) >= 1 - 1e-12 and max(ratios) <= 1 / (1 - REESTIMATE_SHIFT)
    assert max(ratios) > 1 + 1e-6  # the bound was used, not a new estimate


T_POINT = 0.3
SHIFT = 8e-11  # within tol_phi (1e-10): Newton accepts the point at its first iterate
LAST_X = 24  # x of the last rising bar a5 (bodies a1, b1, ..., a5, b5; x, y, phi each)


def _displaced(kernel, along_worst: bool) -> tuple[np.ndarray, np.ndarray]:
    """The exact q of the 10-body tongs at T_POINT displaced so that max |Phi| is about SHIFT,
    and that displacement. Moving one bar along x by SHIFT is a correction of SHIFT; the
    column of Phi_q^-1 with the largest max entry, scaled to a residual of SHIFT, is a
    correction as large as a residual of that size can ask for."""
    q_exact = closed_form(5, np.array([T_POINT]))[0][0]
    if along_worst:
        inverse = np.linalg.inv(kernel.phi_q(q_exact, T_POINT))
        displacement = SHIFT * inverse[:, np.argmax(np.abs(inverse).max(axis=0))]
    else:
        displacement = np.zeros(q_exact.size)
        displacement[LAST_X] = SHIFT
    return q_exact + displacement, displacement


def _python_point(kernel, q0: np.ndarray) -> tuple[newton.Newton, tuple[float, float, float]]:
    q, dq, ddq = (x[0] for x in closed_form(5, np.array([T_POINT])))
    previous = tuple(float(np.abs(x).max()) for x in (q, dq, ddq))
    result = newton.newton(kernel, q0, T_POINT, np.array(kernel.p_values), defaults("double"),
                           previous=previous)
    return result, previous


@pytest.mark.parametrize("backend", ["numpy", "c"])
def test_a_small_correction_clears_a_point_without_a_step(tongs10: symkin.System, backend: str,
                                                          tmp_path: Path) -> None:
    """The residual's bound s r would flag the point; the correction Phi_q^-1 Phi, solved
    for, is SHIFT, which the targets allow: the point is kept as Newton left it (no extra
    step) and not flagged."""
    kernel = symkin.compile(tongs10, backend=backend)  # built once (run cache)
    q0, _ = _displaced(kernel, along_worst=False)
    if backend == "c":
        report, q = _c_first_point(kernel, q0)
        assert report.iterations == 0 and not report.flagged
        assert np.array_equal(q, q0)
        return
    result, previous = _python_point(kernel, q0)
    assert result.status == 0 and result.iterations == 0
    assert np.array_equal(result.q, q0)
    assert result.correction == pytest.approx(SHIFT, rel=1e-3)
    options = defaults("double")
    assert accuracy.flagged_norms(result.inv_norm, result.norm_a, result.residual, q0.size,
                                  *previous, options, UNIT_ROUNDOFF["double"])  # by s r
    point = newton.kinematics(kernel, result, T_POINT, np.array(kernel.p_values), options)
    assert point is not None and not point.flagged


@pytest.mark.parametrize("backend", ["numpy", "c"])
def test_a_large_correction_is_stepped(tongs10: symkin.System, backend: str,
                                       tmp_path: Path) -> None:
    """A residual of the same size along the worst column of Phi_q^-1: the correction is
    much larger than SHIFT, so Newton steps on and q comes to the exact one."""
    kernel = symkin.compile(tongs10, backend=backend)  # built once (run cache)
    q0, displacement = _displaced(kernel, along_worst=True)
    assert np.abs(kernel.phi(q0, T_POINT)).max() <= 1.2 * SHIFT
    q_exact = q0 - displacement
    if backend == "c":
        report, q = _c_first_point(kernel, q0)
        assert report.iterations == 0 and not report.flagged
    else:
        result, _ = _python_point(kernel, q0)
        assert result.status == 0 and result.iterations == 0
        q = result.q
    moved = np.abs(q0 - q_exact).max()
    assert moved > 5 * SHIFT
    assert np.abs(q - q_exact).max() < 1e-3 * moved


def _c_first_point(kernel, q0: np.ndarray):
    """One C solve_step from q0 as a first point (no predictor): its report and q."""
    ffi, lib, name, n = kernel.ffi, kernel.lib, kernel.name, kernel.nq
    options, state = ffi.new(f"{name}_options *"), ffi.new(f"{name}_state *")
    work, report = ffi.new(f"{name}_workspace *"), ffi.new(f"{name}_report *")
    getattr(lib, f"{name}_default_options")(options)
    p = ffi.new(f"{name}_real[]", list(kernel.p_values))
    state.q[0:n] = list(q0)
    state.started = 0
    assert getattr(lib, f"{name}_solve_step")(options, p, T_POINT, state, work, report) == 0
    return report, np.array(ffi.unpack(state.q, n))

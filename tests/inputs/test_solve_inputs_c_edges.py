"""The generated C solver of an input-driven mechanism at its edges, called as a controller
calls it (through cffi, structs kept between calls): a reading out of reach does not poison
the calls after it, a negative iteration cap still fills the report, the functions over t
read the inputs from their documented place in p[] (NPU values a set), and the C files refuse
-ffast-math, under which their NaN tests would vanish. The reference is the crank-slider's
loop closure in closed form: the slider at x = a cos(theta) + sqrt(b^2 - (c - a sin(theta))^2).
"""

from __future__ import annotations

import math
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from codegen_support import derived
from motion_support import kernel as built

import symkin

ROOT = Path(__file__).resolve().parents[2]
pytestmark = pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc is not installed")

A, B, C = 1.0, 5.0, 4.0  # examples/crank_slider_input.yaml
SLIDER_X, CRANK_ANGLE = 6, 2  # the slider's x and the crank's angle in q


def _slider_x(theta: float) -> float:
    return A * math.cos(theta) + math.sqrt(B**2 - (C - A * math.sin(theta)) ** 2)


@pytest.fixture(scope="module")
def mechanism() -> Path:
    return ROOT / "examples" / "crank_slider_input.yaml"


@pytest.fixture(scope="module")
def kernel(mechanism):
    return built(mechanism, "c")


class _Controller:
    """One set of the C structs, kept from call to call as in a servo loop."""

    def __init__(self, kernel, max_iterations: int | None = None) -> None:
        ffi, lib, name = kernel.ffi, kernel.lib, kernel.name
        self.ffi, self.lib, self.name = ffi, lib, name
        self.options = ffi.new(f"{name}_options *")
        getattr(lib, f"{name}_default_options")(self.options)
        if max_iterations is not None:
            self.options.max_iterations = max_iterations
        self.state = ffi.new(f"{name}_state *")
        self.work = ffi.new(f"{name}_workspace *")
        self.report = ffi.new(f"{name}_report *")
        self.p = ffi.new(f"{name}_real[]", [A, B, C])
        self.state.q[0:kernel.nq] = [float(v) for v in kernel.q0]
        self.state.started = 0

    def solve(self, u: float) -> int:
        return int(getattr(self.lib, f"{self.name}_solve_inputs")(
            self.options, self.p, self.ffi.new(f"{self.name}_real[]", [u]), self.ffi.NULL,
            self.ffi.NULL, self.state, self.work, self.report))

    def q(self) -> np.ndarray:
        return np.array(self.ffi.unpack(self.state.q, 9))


@pytest.mark.parametrize("reading", [1e12, 1e300])
def test_a_reading_out_of_reach_leaves_the_last_solution_and_the_next_call_recovers(
        kernel, reading: float) -> None:
    controller = _Controller(kernel)
    assert controller.solve(1.5708) == 0
    last = controller.q()
    assert controller.solve(reading) != 0  # Newton cannot follow a jump of that size
    assert np.array_equal(controller.q(), last)  # not the iterate Newton gave up at
    for theta in (1.6, 1.7, 1.5):
        assert controller.solve(theta) == 0
        assert controller.q()[CRANK_ANGLE] == pytest.approx(theta, abs=1e-14)
        assert controller.q()[SLIDER_X] == pytest.approx(_slider_x(theta), abs=1e-12)


def test_a_zero_iteration_cap_still_fills_the_report(kernel) -> None:
    """Cap 0: Phi is evaluated at the first guess and not iterated on; the report holds that
    residual (q0 lies off the assembly at theta = 1.6 by about 0.03 in the crank angle)."""
    controller = _Controller(kernel, max_iterations=0)
    controller.report.iterations = 12345  # what a caller's stale report may hold
    controller.report.residual = 777.0
    assert controller.solve(1.6) == 1  # NO_CONVERGENCE: no iteration was allowed
    assert controller.report.iterations == 0
    assert 1e-3 < controller.report.residual < 1.0


def test_a_negative_iteration_cap_is_refused_with_the_state_kept(kernel) -> None:
    controller = _Controller(kernel, max_iterations=-1)
    controller.report.iterations = 12345
    before = controller.q()
    assert controller.solve(1.6) == 4  # BAD_OPTIONS
    assert controller.report.status == 4 and controller.report.iterations == 0
    assert math.isnan(controller.report.residual) and controller.report.branch_jump == 0
    assert np.array_equal(controller.q(), before) and controller.state.started == 0


def test_the_functions_over_t_read_each_sets_inputs_after_its_parameters(kernel) -> None:
    """solve_batch with two sets of NPU = NP + 3 NU values each, the inputs held: each set's
    crank angle is its own input, its slider where the loop closure puts it."""
    ffi, lib, name = kernel.ffi, kernel.lib, kernel.name
    assert int(getattr(lib, f"{name.upper()}_NPU")) == 6
    inputs = (1.4, 1.9)
    p = ffi.new(f"{name}_real[]", [v for u in inputs for v in (A, B, C, u, 0.0, 0.0)])
    q0 = ffi.new(f"{name}_real[]", [float(v) for v in kernel.q0])
    t = ffi.new(f"{name}_real[]", [0.0])
    q_out = ffi.new(f"{name}_real[]", 2 * 9)
    options = ffi.new(f"{name}_options *")
    getattr(lib, f"{name}_default_options")(options)
    reports = ffi.new(f"{name}_batch_report[]", 2)
    solved = getattr(lib, f"{name}_solve_batch")(
        options, ffi.NULL, 2, p, q0, 0, 1, t, q_out, ffi.NULL, ffi.NULL,
        ffi.new(f"{name}_state *"), ffi.new(f"{name}_workspace *"), reports)
    assert solved == 2
    q = np.array(ffi.unpack(q_out, 18)).reshape(2, 9)
    for j, theta in enumerate(inputs):
        assert q[j, CRANK_ANGLE] == pytest.approx(theta, abs=1e-14)
        assert q[j, SLIDER_X] == pytest.approx(_slider_x(theta), abs=1e-12)


def test_the_c_files_refuse_fast_math(mechanism, tmp_path: Path) -> None:
    symkin.generate(derived(mechanism), backend="c", out_dir=tmp_path)
    for source in ("crank_slider_input_solver.c", "crank_slider_input_sparse_lu.c",
                   "crank_slider_input_dense_lu.c"):
        for flags in (["-ffast-math"], ["-ffinite-math-only"]):
            done = subprocess.run(["gcc", "-std=c99", "-O2", *flags, "-c", source, "-o",
                                   "/dev/null"], cwd=tmp_path, capture_output=True, text=True)
            assert done.returncode != 0 and "-ffast-math" in done.stderr, (source, flags)
        done = subprocess.run(["gcc", "-std=c99", "-O2", "-c", source, "-o", "/dev/null"],
                              cwd=tmp_path, capture_output=True, text=True)
        assert done.returncode == 0, done.stderr


@pytest.mark.parametrize("backend", ["c", "numpy"])
def test_an_interrupted_input_run_hands_on_the_rows_it_solved(mechanism, backend: str) -> None:
    """Ctrl-C inside the loop over the inputs (raised here from the progress callback after the
    fifth row): SolveInterrupted carries those five rows, equal to the whole run's; before,
    a bare KeyboardInterrupt lost them (and the CLI wrote no file)."""
    from symkin.runtime.driver import SolveInterrupted

    kernel = built(mechanism, backend)
    t = np.linspace(0.0, 1.0, 21)
    u = 1.5708 + 0.5 * t
    whole = symkin.solve(kernel, t=t, inputs=u)
    seen = []

    def interrupt(done: int, total: int) -> None:
        seen.append((done, total))
        if done == 5:
            raise KeyboardInterrupt

    try:
        symkin.solve(kernel, t=t, inputs=u, progress=interrupt)
    except SolveInterrupted as stop:
        caught = stop
    except KeyboardInterrupt:  # (not let through: it would end the whole test session)
        pytest.fail("the interrupt came through without the rows solved")
    else:
        pytest.fail("the run was not interrupted")
    part = caught.trajectory
    assert seen[:5] == [(k, 21) for k in range(1, 6)]
    assert part.t.size == 5 and caught.t == t[5]
    assert np.array_equal(part.q, whole.q[:5])


@pytest.mark.parametrize("backend", ["c", "numpy"])
def test_absurd_rates_give_the_same_rows_on_both_backends_and_no_numpy_warning(
        mechanism, backend: str) -> None:
    """Rates of 1e200 without accelerations: the accelerations are not evaluated (NumPy's
    Gamma overflowed, and the run failed on NumPy where C went on), and the points' arrays
    are NaN or inf where they must be, without NumPy's overflow warning (the CLI printed it
    as a note)."""
    import warnings

    kernel = built(mechanism, backend)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        run = symkin.solve(kernel, t=[0.0, 0.1], inputs=[1.5708, 1.6],
                           input_rates=[1e200, 1e200])
        r, dr, ddr = run.point_arrays()
    assert run.dq[:, CRANK_ANGLE] == pytest.approx([1e200, 1e200], rel=1e-14)
    assert np.isnan(run.d2q).all() and np.isnan(ddr).all() and np.isfinite(dr).all()
    assert np.abs(r[:, 0, 0] - A * np.cos([1.5708, 1.6])).max() <= 1e-14


def _slider_x_theta(theta: float) -> float:
    """d(slider x)/d(theta) of the closed form."""
    root = math.sqrt(B**2 - (C - A * math.sin(theta)) ** 2)
    return -A * math.sin(theta) + A * math.cos(theta) * (C - A * math.sin(theta)) / root


@pytest.mark.parametrize("backend", ["c", "numpy"])
def test_accelerations_not_given_are_not_judged_by_the_error_model(mechanism, backend: str) -> None:
    """Fast rates (1e10 rad/s) without accelerations, far from any singular configuration
    (condition about 21): the accelerations are not solved for, so the error model does not
    judge them. Before, it judged them as zeros against the growth |dq|^2 gives Gamma, flagged
    every row, and the command line blamed an ill-conditioned Phi_q. q and dq meet their
    targets (dq relative to its size): the closed form's slider velocity."""
    kernel = built(mechanism, backend)
    theta = np.array([1.5708, 1.6])
    rate = 1e10
    run = symkin.solve(kernel, t=[0.0, 0.1], inputs=theta, input_rates=[rate, rate])
    assert run.cond.max() < 30 and not run.flagged.any()
    assert np.isnan(run.d2q).all()
    expected = np.array([rate * _slider_x_theta(float(v)) for v in theta])
    assert np.abs(run.dq[:, SLIDER_X] - expected).max() <= 1e-7 * rate
    # the accelerations given (zero): solved, judged relative to their size, not flagged
    given = symkin.solve(kernel, t=[0.0, 0.1], inputs=theta, input_rates=[rate, rate],
                         input_accels=[0.0, 0.0])
    assert np.isfinite(given.d2q).all() and not given.flagged.any()

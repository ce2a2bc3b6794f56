"""The generated C solver: the same algorithm as the Python driver, in one call per grid.

Checks: C grid loop vs the Python loop on the same compiled kernel and vs the NumPy backend
(1e-12); one step at a time through <prefix>_solve_step gives the same as the whole grid; the
singular status; the generated folder compiles on its own with -Werror, also for Cortex-M;
the solver initialises its own workspace; sparse-LU fall-backs are counted up to the Trajectory.
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from driver_support import derive, kernel_for

import symkin
from symkin.runtime import driver
from symkin.runtime.solving import newton

MECHANISMS = ("four_bar_test", "offset_crank_slider", "slide_driven", "point_trajectory")
WARNINGS = ["-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror"]
EXAMPLES = Path(__file__).resolve().parents[3] / "examples"


def _agree(a, b, limit: float = 1e-12) -> None:
    assert np.array_equal(a.t, b.t)
    for name in ("q", "dq", "d2q"):
        assert np.abs(getattr(a, name) - getattr(b, name)).max() <= limit, name


def test_textbook_c_and_python_drivers_agree(crank_slider_system) -> None:
    kernel = kernel_for(crank_slider_system, "c")
    times = driver.grid(0.0, 1.5, 1.5 / 2000)
    in_c = driver.solve(kernel, t=times)
    _agree(in_c, driver.solve(kernel, t=times, use_c_solver=False))
    _agree(in_c, driver.solve(kernel_for(crank_slider_system, "numpy"), t=times))


@pytest.mark.parametrize("name", MECHANISMS)
def test_c_and_python_drivers_agree(name: str) -> None:
    system = derive(name)
    in_c = driver.solve(kernel_for(system, "c"))
    _agree(in_c, driver.solve(kernel_for(system, "numpy")))


@pytest.mark.parametrize("linalg", ["dense", "sparse"])
def test_c_solver_with_either_lu(linalg: str, crank_slider_system) -> None:
    kernel = symkin.compile(crank_slider_system, backend="c", linalg=linalg)
    _agree(driver.solve(kernel), driver.solve(kernel, use_c_solver=False))


def test_progress_chunks_give_the_same_trajectory(crank_slider_system) -> None:
    kernel = kernel_for(crank_slider_system, "c")
    calls = []
    chunked = driver.solve(kernel, t=driver.grid(0, 1.5, 0.005), progress=lambda d, n:
                           calls.append((d, n)))
    assert calls[-1] == (301, 301) and len(calls) > 10
    _agree(chunked, driver.solve(kernel, t=driver.grid(0, 1.5, 0.005)), 0.0)


def test_solve_step_by_step_matches_solve_grid(crank_slider_system) -> None:
    kernel = kernel_for(crank_slider_system, "c")
    ffi, lib, n = kernel.ffi, kernel.lib, len(kernel.coordinates)
    options, state = ffi.new("crank_slider_options *"), ffi.new("crank_slider_state *")
    work, report = ffi.new("crank_slider_workspace *"), ffi.new("crank_slider_report *")
    lib.crank_slider_default_options(options)
    p = ffi.new("crank_slider_real[]", list(kernel.p_values))
    whole = driver.solve(kernel)  # assembled from q = 0 by Newton alone, as in C
    rows = []
    for t in whole.t:
        assert lib.crank_slider_solve_step(options, p, t, state, work, report) == 0
        rows.append(ffi.unpack(state.q, n))
    assert report.status == 0 and report.residual <= options.tol_phi
    assert np.abs(np.array(rows) - whole.q).max() <= 1e-12


def test_c_reports_singular(crank_slider_system) -> None:
    kernel = kernel_for(derive("dead_centre"), "c")
    ffi, lib = kernel.ffi, kernel.lib
    options, state = ffi.new("dead_centre_options *"), ffi.new("dead_centre_state *")
    work, report = ffi.new("dead_centre_workspace *"), ffi.new("dead_centre_report *")
    lib.dead_centre_default_options(options)
    state.q[0:9] = [0, 0, 0, 1, 0, 0, 4, 0, 0]
    p = ffi.new("dead_centre_real[]", list(kernel.p_values))
    q_out = ffi.new("dead_centre_real[]", 9)
    solved = lib.dead_centre_solve_grid(options, p, 1, ffi.new("dead_centre_real[]", [0.5]),
                                        state, q_out, ffi.NULL, ffi.NULL, work, report)
    assert solved == 0 and report.status == 2 and report.t == 0.5 and report.iterations == 0


@pytest.mark.parametrize("compiler", [["gcc"], ["clang"], ["arm-none-eabi-gcc", "-mcpu=cortex-m4",
                                                             "-mthumb"]])
@pytest.mark.parametrize("linalg", ["dense", "sparse"])
def test_generated_folder_compiles_alone(compiler, linalg, tmp_path, crank_slider_system) -> None:
    if shutil.which(compiler[0]) is None:
        pytest.skip(f"{compiler[0]} is not installed")
    symkin.generate(crank_slider_system, backend="c", out_dir=tmp_path, linalg=linalg)
    for source in sorted(tmp_path.glob("*.c")):
        command = [*compiler, *WARNINGS, "-O2", "-c", str(source), "-o", str(tmp_path / "x.o")]
        result = subprocess.run(command, check=False, capture_output=True, text=True)
        assert result.returncode == 0, result.stderr


@pytest.mark.parametrize("linalg", ["dense", "sparse"])
def test_solver_objects_have_no_mutable_data_and_call_no_allocator(linalg, tmp_path,
                                                                   crank_slider_system) -> None:
    """nm on the compiled runtime: nothing in .data/.bss, no malloc/free/stdio imported."""
    if shutil.which("nm") is None or shutil.which("gcc") is None:
        pytest.skip("gcc and nm are needed")
    symkin.generate(crank_slider_system, backend="c", out_dir=tmp_path, linalg=linalg)
    lu = "crank_slider_linalg" if linalg == "dense" else "crank_slider_sparse_lu"
    for name in ("crank_slider_solver", lu, "crank_slider_dense_lu"):
        obj = tmp_path / f"{name}.o"
        subprocess.run(["gcc", *WARNINGS, "-O2", "-c", str(tmp_path / f"{name}.c"), "-o",
                        str(obj)], check=True)
        symbols = subprocess.run(["nm", str(obj)], capture_output=True, text=True,
                                 check=True).stdout.split("\n")
        kinds = {line.split()[-2]: line.split()[-1] for line in symbols if line.strip()}
        assert not set(kinds) & set("bBdDC"), symbols
        undefined = {s.split()[-1] for s in symbols if s.split()[-2:-1] == ["U"]}
        assert not undefined & {"malloc", "calloc", "realloc", "free", "printf", "fprintf",
                                "puts", "putchar"}, undefined


def test_float_kernel_runs_with_looser_tolerances(crank_slider_system) -> None:
    single = driver.solve(symkin.compile(crank_slider_system, backend="c", real="float"))
    double = driver.solve(kernel_for(crank_slider_system, "numpy"))
    assert np.abs(single.q - double.q).max() < 1e-4
    assert np.abs(single.d2q - double.d2q).max() < 1e-3


def _fresh(ffi, ctype: str, fill: bytes):
    """A cffi object whose bytes are all ``fill`` (the solver must not rely on zeroed memory)."""
    obj = ffi.new_allocator(should_clear_after_alloc=False)(ctype)
    buffer = ffi.buffer(obj)
    buffer[:] = fill * len(buffer)
    return obj


@pytest.mark.parametrize("linalg", ["dense", "sparse"])
def test_solver_initialises_its_own_workspace(linalg, crank_slider_system) -> None:
    """A workspace full of 0xFF bytes (NaN reals, huge counters) gives the very same grid as a
    zeroed one, and no phantom fall-backs: the first step calls <prefix>_lu_init."""
    kernel = symkin.compile(crank_slider_system, backend="c", linalg=linalg)
    ffi, lib = kernel.ffi, kernel.lib
    start = driver.solve(kernel, t=[0.0]).q[0]
    times = driver.grid(0.0, 1.5, 0.01)
    results = []
    for fill in (b"\x00", b"\xff"):
        options, report = ffi.new("crank_slider_options *"), ffi.new("crank_slider_report *")
        lib.crank_slider_default_options(options)
        state = ffi.new("crank_slider_state *")
        state.q[0:9] = start.tolist()
        work = _fresh(ffi, "crank_slider_workspace *", fill)
        q_out = np.empty((times.size, 9))
        solved = lib.crank_slider_solve_grid(
            options, ffi.new("crank_slider_real[]", list(kernel.p_values)), times.size,
            ffi.cast("crank_slider_real *", ffi.from_buffer(times)), state,
            ffi.cast("crank_slider_real *", ffi.from_buffer(q_out)), ffi.NULL, ffi.NULL, work,
            report)
        assert solved == times.size and report.status == 0 and report.fallbacks == 0
        results.append(q_out)
    assert np.array_equal(results[0], results[1])


def test_fallbacks_are_counted_and_reach_the_trajectory() -> None:
    """The four-bar's plan (chosen from structure) pivots on b sin(coupler.phi) with
    b cos(coupler.phi) below it. A first guess with coupler.phi near 0 makes that pivot fail
    the run-time ratio test: the first
    factorization falls back to dense LU, Newton still converges to the assembly that LAPACK's
    Newton reaches from the same guess, and the count reaches report and Trajectory."""
    system = symkin.derive(EXAMPLES / "four_bar.yaml")
    kernel = symkin.compile(system, backend="c", linalg="sparse")
    assembled = driver.solve(kernel, t=[0.0]).q[0]
    guess = assembled.copy()
    guess[5] = 1e-3  # coupler.phi: sin ~ 1e-3, cos ~ 1
    p = np.array(kernel.p_values)
    reference = newton.newton(kernel_for(system, "numpy"), guess, 0.0, p, newton.Options())
    assert reference.status == newton.OK
    times = np.array([0.0, 0.01, 0.02])
    run = driver._Run(times, *(np.empty((3, 9)) for _ in range(3)), np.full(3, np.nan),
                      np.zeros(3, dtype=bool))
    solver = kernel.grid_solver(newton.Options(), guess, p)
    result = driver._c_loop(kernel, run, solver, p, None)
    assert result.status == newton.OK and run.done == 3 and run.fallbacks >= 1
    assert np.abs(run.q[0] - reference.q).max() <= 1e-10
    assert np.abs(kernel.phi(run.q[0], 0.0)).max() <= 1e-10
    assert driver._trajectory(kernel, run, p).lu_fallbacks == run.fallbacks
    # the ordinary path, assembled first in Python, never needs the fall-back
    assert driver.solve(kernel).lu_fallbacks == 0


@pytest.mark.parametrize("scale", [0.0, 1e-300, 1e-17])
def test_dense_and_sparse_lu_agree_on_a_vanished_pivot(scale: float, crank_slider_system) -> None:
    """One dense LU serves the dense linear algebra and the sparse LU's fall-back, so both call
    the same pivot vanished: a Phi_q whose rod.phi column is (numerically) zero is singular
    (status k + 1, pivot ratio 0) for both, whether the column is 0, denormal or 1e-17. (A
    column that varies: the sparse LU folds in Phi_q's constant entries, the +-1 of crank.x's
    column, and does not read them.)"""
    verdicts = []
    for linalg in ("dense", "sparse"):
        kernel = symkin.compile(crank_slider_system, backend="c", linalg=linalg)
        assert kernel.backend == "c"
        ffi, lib = kernel.ffi, kernel.lib
        q = driver.solve(kernel, t=[0.3]).q[0]
        nz = kernel.phi_q_nz(q, 0.3)
        nz[kernel.pattern_cols == 5] *= scale  # the column of rod.phi
        lu = ffi.new("crank_slider_lu *")
        lib.crank_slider_lu_init(lu)
        status = lib.crank_slider_lu_factor(ffi.new("crank_slider_real[]", nz.tolist()), lu)
        verdicts.append((status != 0, lib.crank_slider_lu_pivot_ratio(lu) < 1e-10))
    assert verdicts == [(True, True), (True, True)]


def _solve_or_failure(kernel, progress):
    """The rows solved and the failure's (class, reason), or None when the whole grid is."""
    try:
        return driver.solve(kernel, progress=progress), None
    except driver.SolveFailure as failure:
        return failure.trajectory, (type(failure), failure.reason)


@pytest.mark.parametrize("progress", [None, lambda done, total: None])
def test_edge_treatment_of_the_last_point_ends_the_c_run(progress, tmp_path) -> None:
    """A very fast crank (quick_return, theta = t/0.001: 10 rad a step) sends grid points to
    the edge treatment in Python, the last one too; the C grid loop must then have nothing
    left to do, not be asked for points past the end of its grid. C and NumPy agree."""
    source = (EXAMPLES / "quick_return.yaml").read_text()
    assert 'theta: "w*t"' in source
    path = tmp_path / "quick_return.yaml"
    path.write_text(source.replace('theta: "w*t"', 'theta: "t/0.001"'))
    system = symkin.derive(path)
    in_c, failed_c = _solve_or_failure(kernel_for(system, "c"), progress)
    in_numpy, failed_numpy = _solve_or_failure(kernel_for(system, "numpy"), progress)
    assert failed_c == failed_numpy
    assert in_c.t.size == in_numpy.t.size == 101  # NumPy solves the whole grid
    assert np.array_equal(in_c.t, in_numpy.t)
    assert np.abs(in_c.q - in_numpy.q).max() <= 1e-9
    for name in ("dq", "d2q"):  # up to 1e3 rad/s and 1e6 rad/s^2: relative to their size
        a, b = getattr(in_c, name), getattr(in_numpy, name)
        assert np.abs(a - b).max() <= 1e-9 * max(1.0, np.abs(b).max()), name

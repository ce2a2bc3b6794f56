"""symkin.sweep: the generated batch solver against per-set symkin.solve, failures with their
reason, local processes and a real Dask LocalCluster against the in-process path, the NPZ.

References: each set's own ``symkin.solve`` (the trusted single-trajectory path, itself checked
against the chapter's closed forms elsewhere) and, for points, eq. 2.14 written out here.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import symkin
from symkin.errors import SolveError
from tests.driver_support import same_condition

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
T = np.linspace(0.0, 1.5, 31)


@pytest.fixture(scope="module")
def c_kernel(crank_slider_system):
    kernel = symkin.compile(crank_slider_system, backend="c")
    assert kernel.backend == "c"
    return kernel


def _designs(kernel, count: int, spread: float = 0.1, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return kernel.p_values * (1 + rng.uniform(-spread, spread, size=(count, 3)))


def _check_against_solve(kernel, result, designs) -> tuple[int, int]:
    solved = failed = 0
    for j, p in enumerate(designs):
        try:
            trajectory = symkin.solve(kernel, t=T, params=p)
        except SolveError as failure:
            failed += 1
            assert result.status[j] != 0
            assert result.reasons[j] == failure.reason
            # A limit the C batch stopped on is bisected in C (sweeps.stops): the same words
            # and times; the condition there is C's estimate, equal to about 1 %.
            same_condition(result.messages[j], str(failure))
            assert result.t_reached[j] == failure.t
            done = failure.trajectory.t.size
            assert result.solved[j] == done
            assert np.array_equal(result.q[j, :done], failure.trajectory.q)
            assert np.isnan(result.q[j, done:]).all()
            continue
        solved += 1
        assert result.status[j] == 0 and result.reasons[j] == ""
        for name in ("q", "dq", "d2q"):
            assert np.abs(getattr(result, name)[j] - getattr(trajectory, name)).max() <= 1e-12
    return solved, failed


def test_c_batch_equals_per_set_solve_and_marks_failures(c_kernel) -> None:
    designs = _designs(c_kernel, 120)
    result = symkin.sweep(c_kernel, designs, T, workers=1)
    assert result.q.shape == (120, T.size, 9) and result.params.shape == (120, 3)
    assert np.array_equal(result.t, T) and np.array_equal(result.params, designs)
    solved, failed = _check_against_solve(c_kernel, result, designs)
    assert solved > 50 and failed > 5  # both kinds really occur in this draw
    assert result.iterations[result.ok].min() >= T.size  # at least one Newton test per point


def test_numpy_kernel_sweeps_like_c(crank_slider_system, c_kernel) -> None:
    kernel = symkin.compile(crank_slider_system, backend="numpy")
    designs = _designs(kernel, 15, seed=3)
    result = symkin.sweep(kernel, designs, T)
    _check_against_solve(kernel, result, designs)
    in_c = symkin.sweep(c_kernel, designs, T)
    assert np.array_equal(result.status, in_c.status)
    ok = result.ok
    assert np.abs(result.q[ok] - in_c.q[ok]).max() < 1e-9


def test_a_link_too_short_is_reported_and_the_batch_goes_on(c_kernel) -> None:
    # b + a < c: the rod cannot reach the slider's line at any crank angle.
    designs = np.array([[1.0, 5.0, 4.0], [1.0, 2.0, 4.0], [1.1, 5.2, 4.0]])
    result = symkin.sweep(c_kernel, designs, T)
    assert result.status.tolist()[0] == 0 and result.status[2] == 0
    assert result.status[1] == 4 and result.reasons[1] == "no assembly"
    assert "cannot be assembled at t = 0" in result.messages[1]
    assert result.t_reached[1] == 0.0 and result.solved[1] == 0
    assert np.isnan(result.q[1]).all()
    assert result.summary() == {"sets": 3, "solved": 2, "failed": {"no assembly": 1}}


def test_parameters_by_name_and_per_set_guesses(c_kernel) -> None:
    b = np.array([4.8, 5.0, 5.3])
    by_name = symkin.sweep(c_kernel, {"b": b}, T)
    assert np.array_equal(by_name.params, np.column_stack([np.ones(3), b, np.full(3, 4.0)]))
    guesses = np.tile(symkin.solve(c_kernel, t=T).q[0], (3, 1))
    guessed = symkin.sweep(c_kernel, {"b": b}, T, q0=guesses)
    for j in range(3):
        reference = symkin.solve(c_kernel, t=T, q0=guesses[j], params={"b": b[j]})
        assert np.abs(guessed.q[j] - reference.q).max() <= 1e-12
    assert np.abs(guessed.q - by_name.q).max() < 1e-9


@pytest.mark.parametrize("params, message", [
    ({"d": [1.0]}, "unknown parameter 'd'"),
    ({"a": [1.0, 2.0], "b": [5.0]}, "same length"),
    (np.ones((4, 2)), "shape (M, 3)"),
    (np.ones(3), "shape (M, 3)"),
])
def test_bad_params_are_refused(c_kernel, params, message) -> None:
    with pytest.raises(SolveError, match=message.replace("(", r"\(").replace(")", r"\)")):
        symkin.sweep(c_kernel, params, T)


def test_points_follow_eq_2_14_per_set(c_kernel) -> None:
    designs = _designs(c_kernel, 6, spread=0.02)
    result = symkin.sweep(c_kernel, designs, T)
    r, _, _ = result.point("rod", "P")
    phi = result.q[:, :, 5]
    b = designs[:, 1, None]
    expected = np.stack([result.q[:, :, 3] + b * np.cos(phi), result.q[:, :, 4] + b * np.sin(phi)],
                        -1)
    assert np.abs(r - expected).max() < 1e-13
    assert np.abs(r[:, :, 1] - designs[:, 2, None]).max() < 1e-9  # P rides the slider line y = c
    assert set(result.points()) == {"crank.tip", "rod.P"}


def test_save_writes_the_arrays(c_kernel, tmp_path: Path) -> None:
    result = symkin.sweep(c_kernel, np.array([[1.0, 5.0, 4.0], [1.0, 2.0, 4.0]]), T)
    data = np.load(result.save(tmp_path / "sweep.npz"))
    assert data["q"].shape == (2, T.size, 9) and data["status"].tolist() == [0, 4]
    assert data["reasons"].tolist() == ["", "no assembly"]
    assert data["parameter_names"].tolist() == ["a", "b", "c"]
    assert data["r"].shape == (2, T.size, 2, 2) and data["points"].tolist() == ["crank.tip", "rod.P"]
    with pytest.raises(symkin.SymkinError, match="npz"):
        result.save(tmp_path / "sweep.csv")


def test_compressed_npz_holds_the_same_arrays_deflated(c_kernel, tmp_path: Path) -> None:
    import zipfile

    designs = np.column_stack([np.full(200, 1.0), np.linspace(4.5, 5.5, 200), np.full(200, 4.0)])
    result = symkin.sweep(c_kernel, designs, T)
    plain = result.save(tmp_path / "plain.npz")
    packed = result.save(tmp_path / "packed.npz", compress=True)
    with zipfile.ZipFile(packed) as archive:
        assert {info.compress_type for info in archive.infolist()} == {zipfile.ZIP_DEFLATED}
    assert packed.stat().st_size < plain.stat().st_size
    with np.load(plain) as a, np.load(packed) as b:
        assert sorted(a.files) == sorted(b.files)
        for name in a.files:
            np.testing.assert_array_equal(a[name], b[name])


def test_cli_compress(tmp_path: Path) -> None:
    import zipfile

    from cli_support import symkin_main

    out = tmp_path / "s.npz"
    done = symkin_main("sweep", str(EXAMPLES / "crank_slider.yaml"), "--vary", "b=4.5:5.5:5",
                       "-o", str(out), "--compress", cwd=EXAMPLES.parent)
    assert done.returncode == 0, done.stderr
    with zipfile.ZipFile(out) as archive:
        assert {info.compress_type for info in archive.infolist()} == {zipfile.ZIP_DEFLATED}


def test_local_processes_equal_this_process(c_kernel) -> None:
    designs = _designs(c_kernel, 40, seed=5)
    here = symkin.sweep(c_kernel, designs, T, workers=1)
    there = symkin.sweep(c_kernel, designs, T, workers=2)
    for name in ("q", "dq", "d2q"):
        assert np.array_equal(getattr(here, name), getattr(there, name), equal_nan=True)
    assert here.reasons == there.reasons and np.array_equal(here.status, there.status)


def test_dask_local_cluster_equals_this_process(c_kernel) -> None:
    distributed = pytest.importorskip("distributed")
    designs = _designs(c_kernel, 40, seed=7)
    here = symkin.sweep(c_kernel, designs, T, workers=1)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        remote = symkin.sweep(c_kernel, designs, T, client=client)
        pids = client.run(lambda: __import__("os").getpid())
    assert len(set(pids.values())) == 2  # two worker processes really ran
    for name in ("q", "dq", "d2q"):
        assert np.array_equal(getattr(here, name), getattr(remote, name), equal_nan=True)
    assert here.reasons == remote.reasons and np.array_equal(here.t_reached, remote.t_reached)


@pytest.mark.parametrize("backend", ["c", "numpy"])
def test_a_worker_without_the_build_builds_it_from_the_source(crank_slider_system, backend,
                                                              tmp_path: Path) -> None:
    from symkin.backends import from_sources
    from symkin.sweeps import parallel

    kernel = symkin.compile(crank_slider_system, backend=backend)
    files = parallel.payload(kernel).files
    rebuilt = from_sources(files, cache_dir=tmp_path / "elsewhere")
    assert rebuilt.backend == backend and rebuilt.folder != kernel.folder
    assert rebuilt.folder.parent == tmp_path / "elsewhere"
    designs = _designs(kernel, 5, spread=0.02)
    assert np.array_equal(symkin.sweep(rebuilt, designs, T).q, symkin.sweep(kernel, designs, T).q)
    for bad in ({**files, "../escape.c": "int x;"}, {k: v for k, v in files.items()
                                                    if not k.endswith(".h")} or files):
        if bad == files:
            continue
        with pytest.raises(symkin.BuildError, match="not one generated symkin folder"):
            from_sources(bad, cache_dir=tmp_path / "elsewhere")


def test_c_batch_reports_without_outputs_and_counts_newton(c_kernel) -> None:
    """<prefix>_solve_batch called directly: NULL outputs are allowed, each report says how its
    set ended, and a set's Newton count is the sum over its steps of one solve_grid run."""
    ffi, lib = c_kernel.ffi, c_kernel.lib
    designs = np.array([[1.0, 5.0, 4.0], [1.0, 2.0, 4.0], [1.05, 5.1, 4.1]])
    times = np.ascontiguousarray(T)
    options = ffi.new("crank_slider_options *")
    lib.crank_slider_default_options(options)
    reports = ffi.new("crank_slider_batch_report[]", 3)
    solved = lib.crank_slider_solve_batch(
        options, ffi.NULL, 3, ffi.from_buffer("double[]", designs),
        ffi.from_buffer("double[]", c_kernel.q0), 0, T.size, ffi.from_buffer("double[]", times), ffi.NULL, ffi.NULL, ffi.NULL,
        ffi.new("crank_slider_state *"), ffi.new("crank_slider_workspace *"), reports)
    assert solved == 2
    assert [reports[j].status for j in range(3)] == [0, 1, 0]  # plain Newton: no convergence
    assert reports[1].solved == 0 and reports[1].t == 0.0 and reports[1].residual > 1e-3
    assert reports[0].solved == T.size and reports[0].t == T[-1]
    for j in (0, 2):  # the same count, step by step through solve_step
        state, work = ffi.new("crank_slider_state *"), ffi.new("crank_slider_workspace *")
        report = ffi.new("crank_slider_report *")
        state.q[0:9] = c_kernel.q0.tolist()
        p = ffi.new("double[]", designs[j].tolist())
        total = 0
        for time_point in T:
            assert lib.crank_slider_solve_step(options, p, time_point, state, work, report) == 0
            total += report.iterations
        assert reports[j].iterations == total


def test_c_batch_runs_with_every_option_given(c_kernel) -> None:
    """The options reach the C batch whole: with max_cond below the condition the crank-slider
    reaches along T (21 at t = 0, about 32 later), the batch stops where it passes it, as
    singular; with the defaults it solves every point. Before, only the Newton tolerances
    were copied: the batch ran on with the default max_cond (1e7) whatever was given."""
    from symkin.backends.c import batch as c_batch
    from symkin.contract.options import Options
    from symkin.contract.status import OK, SINGULAR

    def run(options: Options) -> tuple[int, int]:
        rows = tuple(np.empty((1, T.size, c_kernel.nq)) for _ in range(3))
        status, _, solved, _, _ = c_batch.solve(
            c_kernel.ffi, c_kernel.lib, c_kernel.name, c_kernel.real,
            c_kernel.p_values[None, :], T, c_kernel.q0, options, rows, np.ones(1))
        return int(status[0]), int(solved[0])

    assert run(Options()) == (OK, T.size)
    status, solved = run(Options(max_cond=25.0, tighten_cond=25.0))
    assert status == SINGULAR and 0 < solved < T.size
    conditions = symkin.solve(c_kernel, t=T).cond
    assert conditions[:solved].max() <= 25.0 < conditions[solved]

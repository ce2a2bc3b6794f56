"""An input row exactly at a singular configuration: an encoder of 64 ticks a turn puts the
crank-slider's crank on its dead centre (theta = 3 pi / 2, the rod along the slider's normal,
where both assemblies meet). The row stands, flagged, with NaN rates and an infinite condition
and the passage recorded, as a run over t records a singular configuration it passes; the run
goes on. Before, that row stopped the run (exit 1 from the CLI), where the same motion driven
by t passed it. The reference is the loop closure: x = cos(theta) +- sqrt(25 - (4 -
sin(theta))^2) (a = 1, b = 5, c = 4), on either assembly (the dead centre lets it change)."""

from __future__ import annotations

import shutil
import warnings
from pathlib import Path

import numpy as np
import pytest
from motion_support import kernel as built

import symkin

ROOT = Path(__file__).resolve().parents[2]
TICKS = 64
DEAD = TICKS // 2  # the row at theta = 3 pi / 2


@pytest.fixture(scope="module")
def mechanism() -> Path:
    return ROOT / "examples" / "crank_slider_input.yaml"


@pytest.mark.parametrize("backend", ["c", "numpy"])
def test_a_row_on_the_dead_centre_is_flagged_and_the_run_goes_on(mechanism, backend: str) -> None:
    if backend == "c" and shutil.which("gcc") is None:
        pytest.skip("gcc is not installed")
    kernel = built(mechanism, backend)
    k = np.arange(TICKS + 1)
    theta = np.pi / 2 + k * 2 * np.pi / TICKS
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the branch warning: the assembly may change there
        run = symkin.solve(kernel, t=0.01 * k, inputs=theta,
                           input_rates=np.full(k.size, 2 * np.pi / TICKS / 0.01))
    assert run.t.size == k.size
    assert np.flatnonzero(run.flagged).tolist() == [DEAD]
    assert np.isnan(run.dq[DEAD]).all() and np.isnan(run.d2q[DEAD]).all()
    assert run.cond[DEAD] == np.inf
    assert [passage[0] for passage in run.singular] == [run.t[DEAD]]
    root = np.sqrt(np.maximum(25 - (4 - np.sin(theta)) ** 2, 0))
    error = np.minimum(np.abs(run.q[:, 6] - (np.cos(theta) + root)),
                       np.abs(run.q[:, 6] - (np.cos(theta) - root)))
    regular = k != DEAD
    assert error[regular].max() <= 1e-12
    assert error[DEAD] <= 1e-6  # Newton's residual test there: q to about its square root
    assert np.isfinite(run.dq[regular]).all()


def _both(mechanism):
    backends = ["numpy"] + (["c"] if shutil.which("gcc") else [])
    return [built(mechanism, backend) for backend in backends]


def test_consecutive_and_last_rows_on_the_dead_centre_and_progress(mechanism) -> None:
    """Inputs held on the dead centre for three rows, then again at the last row: each such
    row kept alike on both backends, the others on the loop closure, progress after every
    row (also the kept ones)."""
    dead = 3 * np.pi / 2
    theta = np.array([dead - 0.2, dead - 0.1, dead, dead, dead, dead + 0.1, dead])
    runs = []
    for kernel in _both(mechanism):
        calls: list[tuple[int, int]] = []
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            run = symkin.solve(kernel, t=0.1 * np.arange(theta.size), inputs=theta,
                               progress=lambda done, total, seen=calls: seen.append((done, total)))
        assert calls == [(k, theta.size) for k in range(1, theta.size + 1)]
        assert np.flatnonzero(run.flagged).tolist() == [2, 3, 4, 6]
        assert np.isinf(run.cond[[2, 3, 4, 6]]).all() and len(run.singular) == 4
        runs.append(run)
    if len(runs) == 2:
        assert np.abs(runs[0].q - runs[1].q).max() <= 1e-12
        assert np.array_equal(runs[0].branch_jumps, runs[1].branch_jumps)


def test_a_first_row_on_the_dead_centre_and_a_failure_alike_on_both_backends(mechanism) -> None:
    """Row 0 is the assembly's (the C solve's own estimate there put it over max_cond, where
    the assembly had 6e6); a reading out of reach fails with the same message, Newton's own
    iterate explained (the C solve leaves its state at the last solution, which explained
    nothing)."""
    from symkin.runtime.driver import SolveFailure

    dead = 3 * np.pi / 2
    firsts, messages = [], []
    for kernel in _both(mechanism):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            run = symkin.solve(kernel, t=[0.0, 0.1], inputs=[dead, dead + 0.05],
                               input_rates=[1.0, 1.0])
        firsts.append((run.q[0], run.dq[0], run.cond[0], bool(run.flagged[0])))
        with pytest.raises(SolveFailure) as caught:
            symkin.solve(kernel, t=[0.0, 0.1], inputs=[1.5708, 1e300], input_rates=[1.0, 1.0])
        messages.append(str(caught.value))
        assert "did not converge at t = 0.1" in messages[-1]
        assert "Give inputs closer together" in messages[-1]  # not dt: there is no dt
    if len(firsts) == 2:
        (q_a, dq_a, cond_a, flag_a), (q_b, dq_b, cond_b, flag_b) = firsts
        assert np.array_equal(q_a, q_b) and np.allclose(dq_a, dq_b, atol=1e-9)
        assert cond_a == pytest.approx(cond_b, rel=1e-6) and flag_a == flag_b
        assert messages[0] == messages[1]


def test_an_interrupt_while_assembling_hands_on_no_rows(mechanism, monkeypatch) -> None:
    from symkin.runtime.driver import SolveInterrupted
    from symkin.runtime.input_driven import inputs

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(inputs, "assemble", interrupted)
    for kernel in _both(mechanism):
        try:
            symkin.solve(kernel, t=[0.0, 0.1], inputs=[1.5, 1.6])
        except SolveInterrupted as stop:
            assert stop.trajectory.t.size == 0 and stop.t == 0.0
        except KeyboardInterrupt:  # (not let through: it would end the whole test session)
            pytest.fail("the interrupt came through")
        else:
            pytest.fail("the run was not interrupted")

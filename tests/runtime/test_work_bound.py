"""Newton's total work per time point is bounded (contract.tuning.EDGE_SUBSTEPS): a driver so
fast that a grid step spans thousands of turns ends promptly with a located message, the
rows solved so far kept, instead of subdividing without end."""

from __future__ import annotations

import shutil
import time
from pathlib import Path

import numpy as np
import pytest
from codegen_support import compiled, derived

import symkin
from symkin.contract.tuning import EDGE_SUBSTEPS
from symkin.runtime.driver import SolveFailure
from symkin.runtime.protocol import EDGE_STOPPED
from symkin.runtime.solving import edges

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def fast_path(tmp_path_factory):
    text = (ROOT / "examples" / "rssr.yaml").read_text()
    assert 'theta: "2*pi*t"' in text
    path = tmp_path_factory.mktemp("fast") / "fast.yaml"
    path.write_text(text.replace('"2*pi*t"', '"1e6*t"'))  # the reproducer
    return path


@pytest.fixture(scope="module")
def fast_kernel(fast_path):
    return symkin.compile(derived(fast_path), backend="numpy")  # derived once per run


def test_a_driver_turning_thousands_of_times_a_step_stops_at_the_bound(fast_kernel,
                                                                        monkeypatch):
    calls = []
    real = edges._step
    monkeypatch.setattr(edges, "_step", lambda *a: calls.append(1) or real(*a))
    start = time.process_time()
    with pytest.raises(SolveFailure) as raised:
        symkin.solve(fast_kernel, t=np.linspace(0, 1, 101))
    spent = time.process_time() - start
    failure = raised.value
    assert failure.reason == "too many substeps"
    assert failure.t == pytest.approx(0.01) and failure.trajectory.t.size == 1
    assert f"within {EDGE_SUBSTEPS} substeps" in str(failure) and "t = 0.01" in str(failure)
    # the march's substeps are bounded; the step over the blocked time adds a few (log2 64)
    assert EDGE_SUBSTEPS <= len(calls) <= EDGE_SUBSTEPS + 8
    assert spent < 30  # CPU seconds: about 3 on an idle machine


def test_an_ordinary_edge_treatment_is_far_below_the_bound(crank_slider_path):
    kernel = compiled(crank_slider_path, "numpy")  # from its goldens
    solved = symkin.solve(kernel, t=np.linspace(0, 1.5, 4))  # steps of 0.5: substeps needed
    p = kernel.p_values
    previous = edges.State(0.0, edges.Point(solved.q[0], solved.dq[0], solved.d2q[0], 1.0,
                                            False))
    found = edges.resolve(kernel, p, symkin.solve.__globals__["default_options"](kernel),
                          previous, 1.5)
    assert found.point is not None and 0 < found.substeps < EDGE_SUBSTEPS / 20


@pytest.mark.skipif(shutil.which("cc") is None and shutil.which("gcc") is None,
                    reason="no C compiler")
def test_the_generated_solve_edge_has_the_same_bound(fast_path):
    """The C edge treatment (sweeps run it) takes at most EDGE_SUBSTEPS substeps, says so in
    its report, and the sweep names the stop 'too many substeps'."""
    kernel = symkin.compile(derived(fast_path), backend="c")
    edge = kernel.edge_solver()
    assert edge is not None
    start = symkin.solve(kernel, t=np.array([0.0]))
    options = symkin.solve.__globals__["default_options"](kernel)
    _, h_min, delta = edges.substeps(0.0, 0.01)
    began = time.process_time()
    found = edge(options, kernel.p_values, (0.0, start.q[0], start.dq[0], start.d2q[0]),
                 float(start.cond[0]), 0.01, h_min, delta)
    assert time.process_time() - began < 10
    assert found.outcome == EDGE_STOPPED and found.substeps == EDGE_SUBSTEPS
    assert 0.0 < found.t < 0.01

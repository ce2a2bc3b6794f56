"""An input-driven mechanism drawn far from unit size solves as the same mechanism at unit size:
the runs in Python decide in the unit runtime.solving.units picks (as a run over t does), and the
generated C solve_inputs in its options' unit. Before, the crank-slider drawn in millimetres
could not be assembled on either backend (its condition 1.4e7 read as singular), and the C
solver ignored options.unit.
"""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import numpy as np
import pytest
from motion_support import kernel as built
from motion_support import shared

import symkin

ROOT = Path(__file__).resolve().parents[2]
MM = 1000.0
# crank x, y, angle; rod x, y, angle; slider x, y, angle: the lengths scale, the angles not
SCALE = np.array([MM, MM, 1, MM, MM, 1, MM, MM, 1])


def _in_millimetres() -> Path:
    text = (ROOT / "examples" / "crank_slider_input.yaml").read_text()
    for old, new in (("name: crank_slider_input ", "name: crank_slider_input_mm "),
                     ("a: 1.0, b: 5.0, c: 4.0", "a: 1000.0, b: 5000.0, c: 4000.0"),
                     ("q0: [0, 1, 0.6435]", "q0: [0, 1000, 0.6435]"),
                     ("q0: [4, 4, 0]", "q0: [4000, 4000, 0]")):
        assert old in text
        text = text.replace(old, new)
    return shared("crank_slider_input_mm.yaml", text)


@pytest.fixture(scope="module")
def mechanisms() -> tuple[Path, Path]:
    return ROOT / "examples" / "crank_slider_input.yaml", _in_millimetres()


@pytest.mark.parametrize("backend", ["numpy", "c"])
def test_the_run_in_millimetres_is_the_run_in_metres_scaled(mechanisms, backend: str) -> None:
    if backend == "c" and shutil.which("gcc") is None:
        pytest.skip("gcc is not installed")
    metres, millimetres = (built(m, backend) for m in mechanisms)
    t = np.linspace(0.0, 1.0, 21)
    u, du, ddu = 1.5708 + 0.4 * np.sin(t), 0.4 * np.cos(t), -0.4 * np.sin(t)
    a = symkin.solve(metres, t=t, inputs=u, input_rates=du, input_accels=ddu)
    b = symkin.solve(millimetres, t=t, inputs=u, input_rates=du, input_accels=ddu)
    for got, want in ((b.q, a.q), (b.dq, a.dq), (b.d2q, a.d2q)):
        assert np.abs(got / SCALE - want).max() <= 1e-12 * (1 + np.abs(want).max())
    # the same decisions: the condition of the same numbers, no flag in either
    assert np.allclose(b.cond, a.cond, rtol=1e-9)
    assert not a.flagged.any() and not b.flagged.any()
    # and the closed form: the slider at a cos(theta) + sqrt(b^2 - (c - a sin(theta))^2)
    slider = MM * (np.cos(u) + np.sqrt(25.0 - (4.0 - np.sin(u)) ** 2))
    assert np.abs(b.q[:, 6] - slider).max() <= 1e-12 * MM * 5


@pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc is not installed")
def test_the_generated_solve_inputs_decides_in_options_unit(mechanisms) -> None:
    kernel = built(mechanisms[1], "c")
    ffi, lib, name = kernel.ffi, kernel.lib, kernel.name
    results = {}
    for unit in (1.0, MM):
        options = ffi.new(f"{name}_options *")
        getattr(lib, f"{name}_default_options")(options)
        options.unit = unit
        state, work = ffi.new(f"{name}_state *"), ffi.new(f"{name}_workspace *")
        report = ffi.new(f"{name}_report *")
        state.q[0:9] = [float(v) for v in kernel.q0]
        state.started = 0
        p = ffi.new(f"{name}_real[]", [MM, 5 * MM, 4 * MM])
        statuses = []
        for theta in (1.5708, 1.6, 1.65):
            statuses.append(int(getattr(lib, f"{name}_solve_inputs")(
                options, p, ffi.new(f"{name}_real[]", [theta]),
                ffi.new(f"{name}_real[]", [0.5]), ffi.new(f"{name}_real[]", [0.0]), state, work,
                report)))
        results[unit] = statuses, float(report.cond), float(state.q[6]), float(state.dq[6])
    # in its own unit the condition (1.4e7) is over max_cond: singular, as documented
    assert results[1.0][0] == [2, 2, 2]
    statuses, cond, x, dx = results[MM]
    assert statuses == [0, 0, 0] and cond < 100
    theta = 1.65
    root = math.sqrt(25.0 - (4.0 - math.sin(theta)) ** 2)
    assert x == pytest.approx(MM * (math.cos(theta) + root), rel=1e-13)
    # d/dt of the closed form at theta' = 0.5
    rate = -math.sin(theta) + (4.0 - math.sin(theta)) * math.cos(theta) / root
    assert dx == pytest.approx(MM * rate * 0.5, rel=1e-12)


def test_through_the_dead_centre_in_millimetres_as_in_metres(mechanisms) -> None:
    """The rows kept on the dead centre and the branch test (made in the run's unit, as the
    generated C makes it) are the same for the drawing in millimetres."""
    import warnings

    backends = ["numpy"] + (["c"] if shutil.which("gcc") else [])
    k = np.arange(65)
    theta = np.pi / 2 + k * 2 * np.pi / 64  # row 32 on the dead centre
    for backend in backends:
        metres, millimetres = (built(m, backend) for m in mechanisms)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            a, b = (symkin.solve(kernel, t=0.01 * k, inputs=theta,
                                 input_rates=np.full(k.size, 2 * np.pi))
                    for kernel in (metres, millimetres))
        assert np.flatnonzero(a.flagged).tolist() == [32] == np.flatnonzero(b.flagged).tolist()
        assert np.array_equal(a.branch_jumps, b.branch_jumps) and a.branch_jumps.any()
        error = np.abs(b.q / SCALE - a.q).max(axis=1)
        # off the dead centre as exact as anywhere; on it q is fixed to the root of Newton's
        # residual test only
        assert np.delete(error, 32).max() <= 1e-12 and error[32] <= 1e-6

"""The generated C solve_inputs' own branch test (report.branch_jump), one call at a time, as a
controller sees it: its sign of det(Phi_q), read from the sparse LU's factors (the fixed pivot
order's parity, the run-time interchanges taken, the pivots) or from the dense LU's, equals
NumPy's determinant; and along input paths its flags are the rows where the closed form
changes assembly (the crank-slider through its singular configuration), none on a smooth
path, and the rows runtime.input_driven.branch flags after a run of large input steps (the Stewart
platform).
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
from codegen_support import compiled

import symkin
from symkin.contract.options import Options
from symkin.errors import SymkinWarning
from symkin.runtime.input_driven import branch
from tests.inputs.test_branch_jump import _assembly
from tests.spatial.test_stewart_fk import _legs, _poses

ROOT = Path(__file__).resolve().parents[2]
pytestmark = pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc is not installed")


def _kernel(name: str, linalg: str = "sparse"):
    path = ROOT / "examples" / f"{name}.yaml"  # the default from its goldens
    return compiled(path, "c") if linalg == "sparse" else compiled(path, "c", linalg=linalg)


def _factored(kernel, nz: np.ndarray) -> tuple[int, object]:
    """The status and the workspace of <prefix>_lu_factor (sparse path, or its fall-back)."""
    ffi, lib, name = kernel.ffi, kernel.lib, kernel.name
    lu = ffi.new(f"{name}_lu *")
    getattr(lib, f"{name}_lu_init")(lu)
    return getattr(lib, f"{name}_lu_factor")(ffi.new(f"{name}_real[]", nz.tolist()), lu), lu


def _dense_sign(kernel, nz: np.ndarray) -> int:
    ffi, lib, name = kernel.ffi, kernel.lib, kernel.name
    lu = ffi.new(f"{name}_dense_lu *")
    assert getattr(lib, f"{name}_dense_lu_factor")(ffi.new(f"{name}_real[]", nz.tolist()),
                                                    lu) == 0
    return int(getattr(lib, f"{name}_dense_lu_det_sign")(lu))


@pytest.mark.parametrize("name", ["crank_slider_input", "stewart_fk", "three_rrr_fk"])
def test_the_sign_of_det_phi_q_from_the_factors_is_numpys(name: str) -> None:
    """At points scattered about q0 (where the run-time interchanges are taken and both signs
    occur), sparse and dense factors alike."""
    kernel = _kernel(name)
    rng = np.random.default_rng(7)
    p = kernel.with_inputs(None, np.zeros(kernel.nu))
    q0 = np.array(kernel.q0, dtype=float)
    points = [q0 + rng.normal(scale=scale, size=q0.size)
              for scale in (0.02, 0.2, 0.6) for _ in range(40)]
    signs = {1: 0, -1: 0}
    swapped = 0
    for q in points:
        nz = kernel.phi_q_nz(q, 0.0, p)
        expected = int(np.linalg.slogdet(kernel.phi_q(q, 0.0, p))[0])
        assert expected != 0
        status, lu = _factored(kernel, nz)
        if not lu.dense:  # the sparse path's own sign (the fall-back is the dense case below)
            assert status == 0
            assert int(getattr(kernel.lib, f"{kernel.name}_lu_det_sign")(lu)) == expected
            swapped += sum(lu.swapped) if hasattr(lu, "swapped") else 0
        assert _dense_sign(kernel, nz) == expected
        signs[expected] += 1
    assert signs[1] and signs[-1]
    if name == "stewart_fk":
        assert swapped  # its plan's interchanges were taken, and counted in the sign


def _c_flags(kernel, t: np.ndarray, u: np.ndarray, q_start: np.ndarray) -> np.ndarray:
    """report.branch_jump of each solve_inputs call along the inputs u (positions only)."""
    stepper = kernel.input_stepper()
    stepper.start(Options(), q_start)
    flags = []
    for k in range(t.size):
        stepper.step(float(t[k]), kernel.with_inputs(None, u[k]), 0)
        flags.append(stepper.branch_jump)
    return np.array(flags)


@pytest.fixture(scope="module", params=["sparse", "dense"])
def crank_slider(request: pytest.FixtureRequest):
    """The C solver on the sparse LU, and on the dense one (--linalg dense: its own sign)."""
    return _kernel("crank_slider_input", request.param)


def test_c_flags_the_rows_that_change_assembly(crank_slider) -> None:
    """Through the crank-slider's singular configuration at theta = -pi/2 (the path of
    tests/inputs/test_branch_jump.py): the rows where the closed form switches assembly, the
    rows runtime.input_driven.branch flags."""
    theta = np.linspace(np.pi / 2, -np.pi / 2 - 1.0, 41)
    t = np.arange(theta.size) * 0.05
    with pytest.warns(SymkinWarning, match="another assembly"):
        run = symkin.solve(crank_slider, t=t, inputs=theta.reshape(-1, 1))
    slider_x = run.q[:, crank_slider.coordinates.index("slider.x")]
    assembly = _assembly(theta, slider_x)
    switched = np.concatenate([[False], assembly[1:] != assembly[:-1]])
    assert switched.any()
    flags = _c_flags(crank_slider, t, theta.reshape(-1, 1), run.q[0])
    assert np.array_equal(flags, switched)
    assert np.array_equal(flags, run.branch_jumps)


def test_c_flags_nothing_on_a_smooth_path(crank_slider) -> None:
    theta = np.linspace(np.pi / 2, np.pi / 2 + 1.0, 21)
    t = np.arange(theta.size) * 0.05
    run = symkin.solve(crank_slider, t=t, inputs=theta.reshape(-1, 1))
    assert not _c_flags(crank_slider, t, theta.reshape(-1, 1), run.q[0]).any()


def test_c_flags_the_rows_runtime_branch_flags_on_large_steps() -> None:
    """The Stewart platform's tilt-0.5 circle in 9 poses: steps so large that Newton wanders
    at some of them (a run warns about those rows); the C flags are the same rows."""
    kernel = _kernel("stewart_fk")
    t = np.linspace(0.0, 1.0, 9)
    legs = np.array([_legs(pose) for pose in _poses(t, 0.5)])
    with pytest.warns(SymkinWarning, match="another assembly"):
        run = symkin.solve(kernel, t=t, inputs=legs)
    rows = np.array([kernel.with_inputs(None, u) for u in legs])
    expected = branch.jump_rows(kernel, t, run.q, rows)
    assert expected.any() and not expected.all()
    assert np.array_equal(_c_flags(kernel, t, legs, run.q[0]), expected)

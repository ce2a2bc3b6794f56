"""Input drivers (a driver function written ``input``): runs driven by the caller's values
equal the time-driven runs of the same motion, on both backends (the C one through the
generated ``<prefix>_solve_inputs``), and every bad input is refused with a message.

References are independent of the input code path: the time-driven run of the same motion
(the file's formula in t), the closed forms of the driven coordinates (phi = u, phi_t = du,
phi_tt = ddu) and central differences of the input-driven positions.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from codegen_support import derived
from motion_support import kernel as built
from motion_support import shared

import symkin
from symkin.errors import MechanismError, SolveError
from symkin.runtime.scanning.scan import scan

ROOT = Path(__file__).resolve().parents[2]
BACKENDS = ("c", "numpy")
T = np.linspace(0.0, 1.0, 51)


def _close(a: np.ndarray, b: np.ndarray, tol: float = 1e-12) -> float:
    """max |a - b| relative to max(1, max |b|), the 1e-12 of the issue."""
    return float(np.max(np.abs(a - b)) / max(1.0, float(np.max(np.abs(b)))))


def _variant(source: str, name: str, swaps: dict[str, str]) -> Path:
    """The file ``source`` with ``swaps`` made, shared by the tests that build it."""
    text = (ROOT / source).read_text()
    for old, new in swaps.items():
        assert old in text, old
        text = text.replace(old, new)
    return shared(f"{name}.yaml", text)


def _five_bar() -> Path:
    return _variant("tests/mechanisms/five_bar.yaml", "five_bar_in", {
        "name: five_bar": "name: five_bar_in",
        "{type: angle, i: left,  j: ground, theta: 0.4*sin(2*pi*t)}":
            "{type: angle, name: left_encoder, i: left, j: ground, theta: input}",
        "{type: angle, i: right, j: ground, theta: -0.5*t}":
            "{type: angle, name: right_encoder, i: right, j: ground, theta: input}"})


def _trajectory() -> Path:
    return _variant("tests/mechanisms/point_trajectory.yaml", "trajectory_in", {
        "name: point_trajectory": "name: trajectory_in",
        '{type: trajectory, j: rod, sB: tip, f: ["1 + t", "0.5*sin(t)"]}':
            '{type: trajectory, name: pen, j: rod, sB: tip, f: [input, "0.5*sin(t)"]}'})


@pytest.fixture(scope="module", params=BACKENDS)
def backend(request: pytest.FixtureRequest) -> str:
    return str(request.param)


def _pair(time_file: Path, input_file: Path, backend: str):
    return built(time_file, backend), built(input_file, backend)


def test_crank_slider_inputs_equal_time_driven_run(backend: str) -> None:
    reference, driven = _pair(ROOT / "examples/crank_slider.yaml",
                              ROOT / "examples/crank_slider_input.yaml", backend)
    expected = symkin.solve(reference, t=T)
    u, du, ddu = T**2 + np.pi / 2, 2 * T, np.full(T.size, 2.0)
    got = symkin.solve(driven, t=T, q0=expected.q[0], inputs=u, input_rates=du,
                       input_accels=ddu)
    assert driven.input_names == ("crank_angle",)
    for name in ("q", "dq", "d2q"):
        assert _close(getattr(got, name), getattr(expected, name)) < 1e-12, name
    assert got.lu_fallbacks == 0 and not got.flagged.any()


def test_driven_coordinate_is_the_input_and_rates_match_differences(backend: str) -> None:
    driven = built(ROOT / "examples/crank_slider_input.yaml", backend)
    # Central differences of step h = 2.5e-4 (O(h^2) ~ 1e-7) at 60 places over 0.5 s: each
    # place solved at t - h, t, t + h, the differences taken within each triple (the rows of
    # a 2001-point grid of the same step, some 13 times fewer to solve).
    h = 0.5 / 2000
    t = (np.linspace(h, 0.5 - h, 60)[:, None] + np.array([-h, 0.0, h])).ravel()
    u, du, ddu = 1.0 + np.sin(3 * t), 3 * np.cos(3 * t), -9 * np.sin(3 * t)
    got = symkin.solve(driven, t=t, q0=[0, 0, 1, 3, 0, 0, 0, -4, 0], inputs=u,
                       input_rates=du, input_accels=ddu)
    phi = driven.coordinates.index("crank.phi")
    assert np.max(np.abs(got.q[:, phi] - u)) < 1e-12
    assert np.max(np.abs(got.dq[:, phi] - du)) < 1e-12
    assert np.max(np.abs(got.d2q[:, phi] - ddu)) < 1e-11
    q, dq, d2q = (values.reshape(60, 3, -1) for values in (got.q, got.dq, got.d2q))
    assert np.max(np.abs((q[:, 2] - q[:, 0]) / (2 * h) - dq[:, 1])) < 1e-5
    assert np.max(np.abs((dq[:, 2] - dq[:, 0]) / (2 * h) - d2q[:, 1])) < 1e-4


def test_two_inputs_by_name_on_a_drawn_five_bar(backend: str) -> None:
    reference, driven = _pair(ROOT / "tests/mechanisms/five_bar.yaml", _five_bar(),
                              backend)
    expected = symkin.solve(reference, t=T)
    w = 2 * np.pi
    given = {"left_encoder": 0.4 * np.sin(w * T), "right_encoder": -0.5 * T}
    rates = {"right_encoder": np.full(T.size, -0.5), "left_encoder": 0.4 * w * np.cos(w * T)}
    accels = {"left_encoder": -0.4 * w * w * np.sin(w * T), "right_encoder": 0 * T}
    got = symkin.solve(driven, t=T, inputs=given, input_rates=rates, input_accels=accels)
    assert driven.input_names == ("left_encoder", "right_encoder")
    for name in ("q", "dq", "d2q"):
        assert _close(getattr(got, name), getattr(expected, name)) < 1e-12, name


def test_one_component_of_a_trajectory_driver_is_an_input(backend: str) -> None:
    """f: [input, 0.5*sin(t)]: the other component stays a function of t, taken at t."""
    reference, driven = _pair(ROOT / "tests/mechanisms/point_trajectory.yaml",
                              _trajectory(), backend)
    expected = symkin.solve(reference, t=T)
    got = symkin.solve(driven, t=T, q0=expected.q[0], inputs=1 + T, input_rates=np.ones(T.size),
                       input_accels=np.zeros(T.size))
    assert driven.input_names == ("pen_x",)
    for name in ("q", "dq", "d2q"):
        assert _close(getattr(got, name), getattr(expected, name)) < 1e-12, name


def test_positions_only_and_rates_only(backend: str) -> None:
    reference, driven = _pair(ROOT / "examples/crank_slider.yaml",
                              ROOT / "examples/crank_slider_input.yaml", backend)
    expected = symkin.solve(reference, t=T)
    u = T**2 + np.pi / 2
    positions = symkin.solve(driven, t=T, q0=expected.q[0], inputs=u)
    assert _close(positions.q, expected.q) < 1e-12
    assert np.isnan(positions.dq).all() and np.isnan(positions.d2q).all()
    rates = symkin.solve(driven, t=T, q0=expected.q[0], inputs=u, input_rates=2 * T)
    assert _close(rates.dq, expected.dq) < 1e-12 and np.isnan(rates.d2q).all()


@pytest.mark.parametrize("kwargs, message", [
    ({}, "are inputs: pass their values as inputs="),
    ({"inputs": np.zeros((3, 1))}, "must have shape (51, 1)"),
    ({"inputs": {"crank": np.zeros(51)}}, "no input driver named 'crank'"),
    ({"inputs": {}}, "missing 'crank_angle'"),
    ({"inputs": np.where(T > 0.5, np.nan, T)}, "crank_angle is nan at point 26"),
    ({"inputs": T, "input_rates": np.full(51, np.inf)}, "input_rates: crank_angle is inf"),
    ({"inputs": T, "input_accels": T}, "input_accels= needs input_rates="),
    ({"inputs": ["a"] * 51}, "must be numbers"),
])
def test_bad_inputs_are_refused(kwargs: dict, message: str) -> None:
    driven = built(ROOT / "examples/crank_slider_input.yaml", "numpy")
    with pytest.raises(SolveError) as error:
        symkin.solve(driven, t=T, **kwargs)
    assert message in str(error.value)


def test_inputs_for_a_mechanism_without_input_drivers_are_refused() -> None:
    kernel = built(ROOT / "examples/crank_slider.yaml", "numpy")
    with pytest.raises(SolveError, match="no input drivers"):
        symkin.solve(kernel, inputs=np.zeros((31, 1)))
    with pytest.raises(SolveError, match="need inputs="):
        symkin.solve(kernel, input_rates=np.zeros((31, 1)))


def test_input_is_a_word_not_a_name() -> None:
    """A parameter cannot be called input; an expression using the word is refused."""
    named = _variant("examples/crank_slider.yaml", "named",
                     {"parameters: {a: 1.0,": "parameters: {input: 2.0, a: 1.0,"})
    with pytest.raises(MechanismError, match="input"):
        symkin.derive(named)
    mixed = _variant("examples/crank_slider_input.yaml", "mixed",
                     {"theta: input}": "theta: input + 1}"})
    with pytest.raises(MechanismError, match=r"drivers\[0\]\.theta"):
        symkin.derive(mixed)


def test_the_generated_c_declares_the_contract(tmp_path: Path) -> None:
    files = symkin.generate(derived(ROOT / "examples/crank_slider_input.yaml"),
                            backend="c", out_dir=tmp_path)
    header = (tmp_path / "crank_slider_input.h").read_text()
    solver = (tmp_path / "crank_slider_input_solver.h").read_text()
    assert "#define CRANK_SLIDER_INPUT_NU 1" in header
    assert "u[0] crank_angle" in header
    assert "int crank_slider_input_solve_inputs(const crank_slider_input_options *options, " \
           "const crank_slider_input_real p[]," in " ".join(solver.split())
    assert files


def test_sweep_and_scan_without_inputs_of_an_input_mechanism_are_refused() -> None:
    """A sweep runs over t alone; a scan needs the inputs' values: the generated functions
    would read inputs nobody gave."""
    kernel = built(ROOT / "examples/crank_slider_input.yaml", "c")
    with pytest.raises(SolveError, match="a sweep of a mechanism with input drivers"):
        symkin.sweep(kernel, {"a": [1.0, 1.1]})
    with pytest.raises(SolveError, match="a scan needs their values, inputs="):
        scan(kernel)


def test_sensitivities_of_an_input_run_are_refused() -> None:
    kernel = built(ROOT / "examples/crank_slider_input.yaml", "numpy")
    with pytest.raises(SolveError, match="sensitivities= is not supported"):
        symkin.solve(kernel, t=T, inputs=T + 1.5, sensitivities=True)


def test_float_c_kernel_solves_inputs_to_float_accuracy() -> None:
    reference = built(ROOT / "examples/crank_slider.yaml", "c")
    single = built(ROOT / "examples/crank_slider_input.yaml", "c", real="float")
    expected = symkin.solve(reference, t=T)
    got = symkin.solve(single, t=T, inputs=T**2 + np.pi / 2, input_rates=2 * T,
                       input_accels=np.full(T.size, 2.0))
    for name in ("q", "dq", "d2q"):
        assert _close(getattr(got, name), getattr(expected, name)) < 2e-5, name

"""A mechanism its forces move integrates through the compiled kernel of the backend asked
for (build.motion, runtime.dynamics.compiled): the generated C (cffi, compiled and run) and
the generated NumPy module evaluate Φ, Φ_q, Φ_t, Γ, M, Q - h and the loads; both give the
rows of the equations of motion lambdified straight from the System (an evaluation
independent of the generated code); Octave and float are refused with exit 2."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from motion_support import PENDULUM, write

import symkin
from symkin import backends, cli
from symkin.errors import UsageError
from symkin.runtime.dynamics.compiled import CompiledModel
from symkin.runtime.dynamics.model import MotionKernel
from symkin.symbolic import motion_numeric

KERNELS = ["crank_slider", "crank_slider_c"]


@pytest.fixture(scope="module")
def lambdified(crank_slider_system: Any) -> MotionKernel:
    """The free crank-slider with its equations of motion lambdified from SymPy."""
    return MotionKernel(motion_numeric.numeric(crank_slider_system), "lambdified")


@pytest.fixture
def pendulum(tmp_path: Path) -> Path:
    return write(tmp_path, "pendulum.yaml", PENDULUM.replace("PHI0", "0.4"))


def _counting(calls: list[str], name: str, function: Callable[..., Any]) -> Callable[..., Any]:
    def counted(*arguments: Any) -> Any:
        calls.append(name)
        return function(*arguments)
    return counted


@pytest.mark.parametrize(("fixture", "backend"), list(zip(KERNELS, ["numpy", "c"])))
def test_the_run_evaluates_the_generated_kernel(fixture: str, backend: str,
                                                request: pytest.FixtureRequest,
                                                monkeypatch: pytest.MonkeyPatch) -> None:
    kernel = request.getfixturevalue(fixture)
    inner = kernel.model.kernel
    assert kernel.backend == backend and inner.backend == backend
    functions = inner.unchecked
    calls: list[str] = []
    for name in ("mass", "applied", "phi_q_nz", "gamma"):
        monkeypatch.setattr(functions, name, _counting(calls, name, getattr(functions, name)))
    # a model over the same kernel, made after the counting began (kernel.model is its
    # own remainder: the same energy terms)
    symkin.solve(MotionKernel(CompiledModel(inner, kernel.model), backend), t=[0.0, 0.05])
    # every Runge-Kutta stage (7 a step) asks the generated code for M, Q - h, Φ_q and Γ
    assert all(calls.count(name) >= 7 for name in ("mass", "applied", "phi_q_nz", "gamma"))


@pytest.mark.parametrize("fixture", KERNELS)
def test_the_kernel_terms_equal_the_lambdified_equations(fixture: str, lambdified: Any,
                                                         request: pytest.FixtureRequest) -> None:
    model, reference = request.getfixturevalue(fixture).model, lambdified.model
    p = reference.p_values
    rng = np.random.default_rng(37)
    for _ in range(3):
        q, dq, lam, t = rng.normal(size=9), rng.normal(size=9), rng.normal(size=8), 0.3
        for name, arguments in [("phi", (q, t, p)), ("phi_q", (q, t, p)), ("phi_t", (q, t, p)),
                                ("gamma", (q, dq, t, p)), ("mass", (q, p)),
                                ("applied", (q, dq, t, p)), ("loads", (q, lam, t, p))]:
            found, expected = (getattr(m, name)(*arguments) for m in (model, reference))
            assert found.shape == expected.shape, name
            assert found == pytest.approx(expected, rel=1e-12, abs=1e-12), name


@pytest.mark.parametrize("fixture", KERNELS)
def test_each_backend_gives_the_lambdified_rows(fixture: str, lambdified: Any,
                                                request: pytest.FixtureRequest) -> None:
    found, expected = symkin.solve(request.getfixturevalue(fixture)), symkin.solve(lambdified)
    assert found.t.size == expected.t.size == 41
    # the integrator's tolerance is 1e-11: the same steps on equal numbers
    for name in ("q", "dq", "d2q"):
        assert getattr(found, name) == pytest.approx(getattr(expected, name), abs=1e-9), name
    for (name, values), (_, reference) in zip(found.outputs, expected.outputs):
        assert values == pytest.approx(reference, abs=1e-9), name
    assert found.reaction == pytest.approx(expected.reaction, abs=1e-7)


@pytest.mark.parametrize("backend", ["c", "auto"])
def test_run_says_which_backend_integrated(pendulum: Path, tmp_path: Path, backend: str,
                                           capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "out.npz"
    assert cli.main(["run", str(pendulum), "--backend", backend, "-o", str(out)]) == 0
    ran = backends.resolve(backend).name
    assert f"solved 11 time points, t = 0 to 1 (dynamics) ({ran} backend)" \
        in capsys.readouterr().out
    with np.load(out) as rows:  # released from rest at 0.4 rad, φ'' = -g cos φ / L
        assert rows["d2q"][0, 2] == pytest.approx(-9.81 * np.cos(0.4) / 1.3, rel=1e-12)


def test_the_octave_backend_is_refused_with_its_reason(
        pendulum: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(["run", str(pendulum), "--backend", "octave"]) == cli.EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert f"{pendulum}: pendulum has fewer drivers than freedoms and moves under its " \
           "forces, but the MATLAB/Octave backend generates no mass matrix" in err
    assert "--backend c or --backend numpy" in err and "Traceback" not in err
    with pytest.raises(UsageError, match="MATLAB/Octave backend generates no mass matrix"):
        symkin.compile(symkin.derive(pendulum), backend="octave")


def test_a_float_kernel_is_refused_for_the_motion(pendulum: Path) -> None:
    with pytest.raises(UsageError, match="integrated in double"):
        symkin.compile(symkin.derive(pendulum), backend="c", real="float")


INPUT_DRIVEN = """\
name: arm_input
parameters: {L: 1.0, m: 1.0, g: 9.81}
bodies:
  a: {q0: [0, 0, 0], mass: m, inertia: 0.1, com: [0.5, 0], points: {tip: [L, 0]}}
  b: {q0: [1, 0, 0], mass: m, inertia: 0.1, com: [0.5, 0]}
joints:
  - {type: revolute, i: ground, j: a, sA: [0, 0], sB: [0, 0]}
  - {type: revolute, i: a, j: b, sA: tip, sB: [0, 0]}
drivers:
  - {type: angle, i: a, j: ground, theta: input}
forces:
  - {type: gravity, g: [0, -g]}
time: {t0: 0, t1: 1, dt: 0.1}
"""


def test_an_input_driver_is_refused_before_anything_is_built(
        tmp_path: Path, capsys: pytest.CaptureFixture[str],
        monkeypatch: pytest.MonkeyPatch) -> None:
    # a double pendulum whose first arm an inputs table would drive: one freedom left free
    path = write(tmp_path, "arm.yaml", INPUT_DRIVEN)

    def no_build(*arguments: Any, **options: Any) -> None:
        raise AssertionError("built before the refusal")

    monkeypatch.setattr("symkin.build.motion.compile_system", no_build)
    assert cli.main(["run", str(path), "--backend", "c"]) == cli.EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert f"{path}:9: at drivers: a mechanism moved by its forces cannot have input " \
           "drivers yet" in err and "Traceback" not in err

"""The IFToMM benchmark mechanisms of bench/iftomm/ against references derived or published
independently of symkin, on the NumPy path and the generated C step:

- A02 N-four-bar: a parallelogram chain stays one, so every crank turns by the same angle
  theta with ((N + 1)/3 + N) m L^2 theta'' = -((N + 1)/2 + N) m g L cos(theta); the first
  second passes the singular horizontal configuration (theta = 0) once. The committed file
  (N = 10) is the script's; the motion is checked on the script's N = 2 chain, which the
  same equation governs, to keep the test short;
- A03 Andrews' squeezer: the test set's published initial accelerations and its solution at
  t = 0.03 (PSIDE at 1e-14);
- A04 Bricard: as many equations as coordinates, one of them dependent: it moves under
  gravity (one freedom), conserving its energy;
- A05 flyball governor (spatial, four freedoms, stiff damped springs between points of two
  bodies): the script's own minimal-coordinate equations (phi, s, b1, b2 by Lagrange with
  SymPy, SciPy's DOP853 at 1e-12): the slider and both balls, the kinetic energy, and the
  energy balance T + V - W that the damper's dissipation keeps.
"""

from __future__ import annotations

import importlib.util
import math
import shutil
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from codegen_support import derived
from motion_support import kernel, shared
from scipy.integrate import solve_ivp

import symkin
from symkin import backends
from symkin.backends.c.dynamics_step import DynamicsStepper
from symkin.build.compile import compile as build_compile
from symkin.contract.options import Options
from symkin.contract.status import OK

BENCH = Path(__file__).resolve().parents[2] / "bench" / "iftomm"
N, G = 2, 9.81  # the chain whose motion is checked
needs_gcc = pytest.mark.skipif(shutil.which("gcc") is None, reason="no C compiler")


def _bench_script(name: str) -> Any:
    spec = importlib.util.spec_from_file_location(name, BENCH / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.path.insert(0, str(BENCH))
    try:
        spec.loader.exec_module(module)
    finally:
        sys.path.remove(str(BENCH))
    return module


def _cranks_theta(t: np.ndarray) -> np.ndarray:
    """The N-four-bar's crank angle from its one-coordinate equation (module docstring)."""
    inertia, weight = (N + 1) / 3 + N, ((N + 1) / 2 + N) * G
    solution = solve_ivp(lambda _t, y: [y[1], -weight / inertia * math.cos(y[0])],
                         (0.0, float(t[-1])), [math.pi / 2, -1.0], method="DOP853",
                         rtol=1e-12, atol=1e-12, t_eval=t)
    return np.asarray(solution.y[0])


def a02_chain() -> Path:
    """The script's N = 2 chain, a file of the run's (motion_support.shared): this module and
    test_dynamics_singular.py derive it and build its NumPy kernel once."""
    return shared("a02_chain.yaml", _bench_script("a02_n_four_bar").mechanism(N))


@pytest.fixture(scope="module")
def a02() -> Any:
    return derived(a02_chain())


def test_a02_file_is_the_scripts() -> None:
    text = (BENCH / "a02_n_four_bar.yaml").read_text(encoding="utf-8")
    assert text == _bench_script("a02_n_four_bar").mechanism(10)


def test_a02_numpy_follows_the_cranks_equation_through_the_horizontal() -> None:
    trajectory = symkin.solve(kernel(a02_chain(), "numpy"), t=np.linspace(0.0, 1.0, 101))
    theta = _cranks_theta(trajectory.t)
    assert theta.min() < -0.5  # the horizontal (theta = 0) was passed
    cranks = [trajectory.coordinates.index(f"crank{k}.phi") for k in range(N + 1)]
    assert np.max(np.abs(trajectory.q[:, cranks] - theta[:, None])) < 1e-6
    couplers = [trajectory.coordinates.index(f"coupler{k}.phi") for k in range(N)]
    assert np.max(np.abs(trajectory.q[:, couplers])) < 1e-6  # they only translate


@needs_gcc
def test_a02_c_step_follows_the_cranks_equation_through_the_horizontal(a02: Any) -> None:
    kernel = build_compile(a02, backends.get("c"))
    q0 = np.array(a02.q0, dtype=float)
    dq0 = np.array([v for _ in range(N + 1) for v in (0.0, 0.0, -1.0)]
                   + [v for _ in range(N) for v in (1.0, 0.0, 0.0)])
    motion = DynamicsStepper(kernel.ffi, kernel.lib, kernel.name, kernel.real).run(
        Options(), np.array(a02.p_values, dtype=float), 0.0, q0, dq0, 5e-3, 200)
    assert motion.status == OK
    theta = _cranks_theta(motion.t)
    assert theta.min() < -0.5
    assert np.max(np.abs(motion.q[:, 2:3 * (N + 1):3] - theta[:, None])) < 1e-6


# The test set's andrews problem: its consistent initial accelerations of beta and Theta
# (the others are 0) and its solution at t = 0.03 (beta, Theta, gamma, Phi, delta, Omega, eps).
A03_ACCELERATIONS = (14222.4439199541138705911625887, -10666.8329399655854029433719415)
A03_AT_003 = np.array([0.1581077119629904e2, -0.1575637105984298e2, 0.4082224013073101e-1,
                       -0.5347301163226948, 0.5244099658805304, 0.5347301163226948,
                       0.1048080741042263e1])


def _relative(trajectory: Any, row: int, values: np.ndarray) -> np.ndarray:
    """symkin's absolute angles of one row as the test set's relative ones."""
    phi = [values[row, trajectory.coordinates.index(f"{body}.phi")]
           for body in ("crank", "rod", "link3", "link4", "link5", "link6", "link7")]
    beta, rod, gamma, eg, delta, eh, eps = phi
    return np.array([beta, rod - beta, gamma, eg - delta, delta, eh - eps, eps])


@pytest.fixture(scope="module")
def a03() -> tuple[Any, Any]:
    """The squeezer's file derived and its NumPy kernel, for both of its tests."""
    system = symkin.derive(BENCH / "a03_andrews_squeezer.yaml")
    return system, symkin.compile(system, backend="numpy")


def test_a03_starts_and_ends_as_the_published_solution(a03: tuple[Any, Any]) -> None:
    trajectory = symkin.solve(a03[1])
    start = _relative(trajectory, 0, trajectory.d2q)
    assert start[:2] == pytest.approx(A03_ACCELERATIONS, rel=1e-10)
    assert np.abs(start[2:]).max() < 1e-6
    assert trajectory.t[-1] == pytest.approx(0.03, abs=1e-15)
    assert np.abs(_relative(trajectory, -1, trajectory.q) - A03_AT_003).max() < 1e-8


@needs_gcc
def test_a03_c_step_ends_at_the_published_solution_without_dense_fall_back(
        a03: tuple[Any, Any]) -> None:
    """600 steps of h = 5e-5 from the assembled start: the sparse LU with its run-time
    interchanges factors every time (the order planned on the start alone took the dense
    fall-back at about 2 % of them), and the angles at 0.03 s are the test set's."""
    system, numpy_kernel = a03
    start = symkin.solve(numpy_kernel, t=np.array([0.0, 1e-4]))
    kernel = build_compile(system, backends.get("c"))
    motion = DynamicsStepper(kernel.ffi, kernel.lib, kernel.name, kernel.real).run(
        Options(), np.array(system.p_values, dtype=float), 0.0, start.q[0], start.dq[0],
        5e-5, 600)
    assert motion.status == OK and motion.t[-1] == pytest.approx(0.03, abs=1e-15)
    assert motion.fallbacks == 0
    assert np.abs(_relative(start, -1, motion.q) - A03_AT_003).max() < 1e-6


def test_a04_bricard_moves_under_gravity_keeping_its_energy() -> None:
    system = derived(BENCH / "a04_bricard.yaml")  # shared with tests/symbolic's checks of it
    assert len(system.removed) == 1  # square, one row dependent: one freedom
    trajectory = symkin.solve(symkin.compile(system, backend="numpy"),
                              t=np.linspace(0.0, 2.0, 41))
    out = dict(trajectory.outputs)
    kinetic, potential = out["kinetic_energy"], out["potential_energy"]
    assert kinetic.max() > 1.0  # it falls
    assert np.ptp(kinetic + potential) <= 1e-8 * np.abs(potential).max()
    assert np.max(out["constraint_residual"]) < 1e-9


A05_END = 0.4  # the slider rises some 0.15 m and the shaft turns 0.8 turn
A05_EVERY = np.linspace(0.0, A05_END, 41)  # every 0.01 s: the C step's rows compared


@pytest.fixture(scope="module")
def a05() -> tuple[Any, Any, Any, Any]:
    """The governor's file derived, its NumPy kernel (compiled once: some 9 s CPU), the
    bench script and its reference at every 0.01 s (the script derives its equations with
    SymPy at each call: once here for both tests)."""
    system = symkin.derive(BENCH / "a05_flyball_governor.yaml")
    script = _bench_script("a05_flyball_governor")
    return system, symkin.compile(system, backend="numpy"), script, script.reference(A05_EVERY)


def test_a05_numpy_follows_the_minimal_coordinate_equations(
        a05: tuple[Any, Any, Any, Any]) -> None:
    _, kernel, script, every = a05
    t = A05_EVERY[::2]
    trajectory = symkin.solve(kernel, t=t)
    expected = every[::2]
    points = script.symkin_points(list(trajectory.coordinates), trajectory.q)
    assert np.ptp(expected[:, 1]) > 0.1  # the slider moved
    # seen: 4e-12 m; the damping 1 % low in symkin's spring makes it 3e-7 m
    assert script.largest_distance(points, script.reference_points(expected)) < 1e-9
    out = dict(trajectory.outputs)
    mass, _ = script.equations()
    kinetic = [0.5 * y[4:] @ mass(y[:4]) @ y[4:] for y in expected]
    assert np.max(np.abs(out["kinetic_energy"] - kinetic)) < 1e-9 * max(kinetic)
    assert out["work_nonconservative"][-1] < -1e-3  # the damper dissipates (2.4e-3 J)
    balance = out["kinetic_energy"] + out["potential_energy"] - out["work_nonconservative"]
    assert np.ptp(balance) < 1e-8 * max(kinetic)


@needs_gcc
def test_a05_c_step_follows_the_minimal_coordinate_equations(
        a05: tuple[Any, Any, Any, Any]) -> None:
    system, numpy_kernel, script, reference = a05
    kernel = build_compile(system, backends.get("c"))
    start = symkin.solve(numpy_kernel, t=np.array([0.0, 0.01]))  # the consistent start
    h = 2.5e-4  # an explicit step: the damper's fastest mode (8117 1/s) bounds it
    motion = DynamicsStepper(kernel.ffi, kernel.lib, kernel.name, kernel.real).run(
        Options(), np.array(system.p_values, dtype=float), 0.0, start.q[0], start.dq[0], h,
        round(A05_END / h))
    assert motion.status == OK
    every = slice(39, None, 40)  # every 0.01 s
    assert np.allclose(motion.t[every], A05_EVERY[1:], rtol=0, atol=1e-12)
    expected = reference[1:]
    points = script.symkin_points(list(start.coordinates), motion.q[every])
    assert script.largest_distance(points, script.reference_points(expected)) < 1e-8

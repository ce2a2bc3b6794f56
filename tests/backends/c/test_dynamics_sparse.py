"""The generated dynamics step's sparse LU (codegen.dynamics_plan, backends/c/dynamics_lu.py)
and its independent rows, C compiled and run, against references derived here:

- a point-mass pendulum released from rest at 2 rad from the vertical: back where it started
  after one period, the complete elliptic integral's 4 K(sin^2(a/2)) sqrt(L/g);
- the parallelogram with an extra parallel bar and a lamp (its rows depend on each other all
  along, so the full matrix is singular) without its motors, against Lagrange's equations in
  its two angles (tests/motion/test_motion_redundant.py's reference) integrated by SciPy at
  rtol 1e-12, in double and in float; and the NumPy step, which uses the same rows;
- masses in another unit: M is scaled, so the sparse path holds and the motion is the same;
- a free box at the identity orientation, where a fixed order's pivots vanish: the order
  planned over the quarter turns, with run-time row interchanges, takes no dense fall-back,
  and the step is the NumPy step's; planned without them, the dense fall-back where a pivot
  vanishes: counted in the report, the step still the NumPy step's;
- the budget: the header's worst case at most 3 times the kinematic step's, where a file has
  both.
"""

from __future__ import annotations

import importlib.util
import math
import shutil
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from backends.c.test_dynamics_step import TUMBLING
from codegen_support import compiled, derived
from motion.test_motion_redundant import EXAMPLE, _falling, _reference
from motion_support import PENDULUM, write
from scipy.integrate import solve_ivp
from scipy.special import ellipk

import symkin
from symkin import backends
from symkin.backends.c.dynamics_step import DynamicsStepper
from symkin.build.compile import compile as build_compile
from symkin.codegen import dynamics_plan
from symkin.contract import options
from symkin.contract.options import Options
from symkin.contract.status import OK

ROOT = Path(__file__).resolve().parents[3]
AMPLITUDE = 2.0  # rad from the downward vertical
LENGTH, G = 1.3, 9.81

pytestmark = pytest.mark.skipif(shutil.which("gcc") is None, reason="no C compiler")


def _stepper(kernel: Any) -> DynamicsStepper:
    return DynamicsStepper(kernel.ffi, kernel.lib, kernel.name, kernel.real)


@pytest.fixture(scope="module")
def pendulum(tmp_path_factory: pytest.TempPathFactory) -> Any:
    start = -math.pi / 2 + AMPLITUDE  # rod.phi from +x; the mass hangs at -pi/2
    path = write(tmp_path_factory.mktemp("pendulum"), "pendulum.yaml",
                 PENDULUM.replace("PHI0", repr(start)))
    return symkin.derive(path)


@pytest.fixture(scope="module")
def pendulum_c(pendulum: Any) -> Any:
    return build_compile(pendulum, backends.get("c"))


@pytest.fixture(scope="module")
def falling(tmp_path_factory: pytest.TempPathFactory) -> Any:
    text = _falling(EXAMPLE.read_text(encoding="utf-8"))
    return symkin.derive(write(tmp_path_factory.mktemp("falling"), "falling.yaml", text))


@pytest.fixture(scope="module")
def falling_c(falling: Any) -> Any:
    return build_compile(falling, backends.get("c"))


def _pendulum_start() -> tuple[np.ndarray, np.ndarray]:
    start = -math.pi / 2 + AMPLITUDE
    return np.array([0.0, 0.0, start]), np.zeros(3)


def test_pendulum_returns_after_its_elliptic_period(pendulum_c: Any) -> None:
    """One period of 2000 steps: back at the start angle, at rest, the mass on its circle."""
    period = 4 * ellipk(math.sin(AMPLITUDE / 2) ** 2) * math.sqrt(LENGTH / G)
    q0, dq0 = _pendulum_start()
    steps = 2000
    motion = _stepper(pendulum_c).run(Options(), np.array([LENGTH, 2.0, G]), 0.0, q0, dq0,
                                      period / steps, steps)
    assert motion.status == OK and motion.t.size == steps
    assert motion.t[-1] == pytest.approx(period, rel=1e-14)
    assert abs(motion.q[-1, 2] - q0[2]) < 1e-9
    assert abs(motion.dq[-1, 2]) < 1e-8
    # half a period on: the other extreme, mirrored about the vertical
    assert abs(motion.q[steps // 2 - 1, 2] - (-math.pi / 2 - AMPLITUDE)) < 1e-9
    assert motion.residual.max() <= Options().tol_phi


def test_masses_in_any_unit_keep_the_sparse_path() -> None:
    """M is divided by its largest entry before the pivot tests: the driven four-bar with its
    masses in grams (x 1000) takes no dense fall-back, moves as before (bit for bit: the
    scaled matrix is the same) and its multipliers scale with the masses (the load of
    gravity and inertia; its spring and damper are not zero, so only to the ratio)."""
    system = derived(ROOT / "examples" / "four_bar_dynamics.yaml")
    kernel = compiled(ROOT / "examples" / "four_bar_dynamics.yaml", "c")  # from the goldens
    trajectory = symkin.solve(kernel, t=np.arange(0.0, 0.1 + 1e-12, 1e-3))
    p = np.asarray(system.p_values, float)
    heavy = p.copy()
    for name in ("m1", "m2", "m3"):
        heavy[system.parameter_names.index(name)] *= 1000.0
    stepper = _stepper(kernel)
    runs = [stepper.run(Options(), values, 0.0, trajectory.q[0], trajectory.dq[0], 1e-3, 100)
            for values in (p, heavy)]
    assert [run.status for run in runs] == [OK, OK]
    assert [run.fallbacks for run in runs] == [0, 0]
    assert np.array_equal(runs[0].q, runs[1].q)


def _box(tmp_path: Path) -> tuple[Any, Any]:
    """The free box's System and its generated NumPy module."""
    system = symkin.derive(write(tmp_path, "box.yaml", TUMBLING))
    symkin.generate(system, "numpy", tmp_path / "numpy")
    spec = importlib.util.spec_from_file_location("tumbling", tmp_path / "numpy" / "tumbling.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return system, module


def _box_steps(system: Any, module: Any, steps: int) -> tuple[int, float]:
    """(fall-backs, max |q_C - q_NumPy|) of the C step and the NumPy step
    (numpy.linalg.solve) from Euler parameters (1, 0, 0, 0), turning about x and y."""
    kernel = build_compile(system, backends.get("c"))
    p = np.asarray(system.p_values, float)
    q0, dq0 = np.array([0, 0, 0, 1.0, 0, 0, 0]), np.zeros(7)
    dq0[4], dq0[5] = 0.5, 0.05  # e1' = omega_x / 2 at e = (1, 0, 0, 0)
    motion = _stepper(kernel).run(Options(), p, 0.0, q0, dq0, 1e-2, steps)
    assert motion.status == OK and motion.t.size == steps
    state = {"t": 0.0, "q": q0, "dq": dq0, "ddq": None}
    worst = 0.0
    for k in range(steps):
        status, state, _, _ = module.dynamics_step(p, 1e-2, state)
        assert status == module.OK
        worst = max(worst, float(np.max(np.abs(state["q"] - motion.q[k]))))
    return motion.fallbacks, worst


def test_a_free_body_at_the_identity_keeps_the_sparse_path(tmp_path: Path) -> None:
    """Euler parameters (1, 0, 0, 0): the normalisation row of Phi_q is 2 (1, 0, 0, 0), so a
    pivot order chosen on orientations near the file's start fails there. The order planned
    over the quarter turns too (dynamics_plan.ALIGNED) has run-time interchanges of the rows
    that share the Euler parameters' pattern: no factorization of 100 steps goes to the dense
    fall-back, and the step is NumPy's."""
    system, module = _box(tmp_path)
    fallbacks, worst = _box_steps(system, module, 100)
    assert fallbacks == 0
    assert worst < 1e-12


def test_a_pivot_that_vanishes_takes_the_dense_fall_back(tmp_path: Path,
                                                         monkeypatch: pytest.MonkeyPatch) -> None:
    """The same box with its order planned on the seeded samples alone (no quarter turns, no
    assembled turns): its pivots on e1, e2, e3 vanish at the start, so factorizations go to
    dense LU (counted), and the step still equals the NumPy step to rounding."""
    monkeypatch.setattr(dynamics_plan, "ALIGNED", 0)
    monkeypatch.setattr(dynamics_plan, "TURNS", 0)
    system, module = _box(tmp_path)
    fallbacks, worst = _box_steps(system, module, 5)
    assert fallbacks > 0
    assert worst < 1e-12


def _lagrange(t: np.ndarray, theta_rate: float = 0.0) -> np.ndarray:
    """(theta, psi) rows of the falling parallelogram from its two-angle equations."""
    accel = _reference()
    found = solve_ivp(lambda _t, y: [y[2], y[3], *np.ravel(accel(*y))], (0.0, t[-1]),
                      [math.pi / 3, 0.0, theta_rate, 0.0], method="DOP853", rtol=1e-12,
                      atol=1e-12, t_eval=t)
    return found.y[:2].T


def _consistent_start(system: Any) -> tuple[np.ndarray, np.ndarray]:
    """The example's drawing (assembled) at rest."""
    kernel = symkin.compile(system, "numpy")
    trajectory = symkin.solve(kernel, t=np.array([0.0, 1e-3]))
    return trajectory.q[0], np.zeros(trajectory.q.shape[1])


def test_redundant_parallelogram_falls_as_by_hand(falling: Any, falling_c: Any) -> None:
    """Rank 13 of 14 rows: the dependent row is left out of the step's matrix and named in
    the header; the motion follows Lagrange's equations, every row's residual (the one left
    out too) stays at the tolerance, and the left-out row's multiplier is 0."""
    name = falling.name
    header = (Path(falling_c.folder) / f"{name}_dynamics.h").read_text(encoding="utf-8")
    assert f"#define {name.upper()}_NK 13" in header
    assert f"#define {name.upper()}_NR 14" in header
    assert "row 11: joints[5] C revolute extra-coupler (y)" in header
    q0, dq0 = _consistent_start(falling)
    motion = _stepper(falling_c).run(Options(), np.asarray(falling.p_values, float), 0.0, q0,
                                     dq0, 1e-3, 1000)
    assert motion.status == OK and motion.t.size == 1000
    reference = _lagrange(motion.t)
    crank = falling.coordinates.index("crank.phi")
    lamp = falling.coordinates.index("lamp.phi")
    # RK4 with h = 1e-3 on a lamp swinging 1.4 rad: 1.3e-9 seen
    assert np.max(np.abs(motion.q[:, crank] + math.pi / 3 - reference[:, 0])) < 1e-8
    assert np.max(np.abs(motion.q[:, lamp] - reference[:, 1])) < 1e-8
    assert motion.residual.max() <= Options().tol_phi
    assert motion.velocity_residual.max() < 1e-11
    assert np.all(motion.lam[:, 11] == 0.0)


def test_redundant_parallelogram_in_float(falling: Any) -> None:
    kernel = build_compile(falling, backends.get("c"), {"real": "float"})
    q0, dq0 = _consistent_start(falling)
    motion = _stepper(kernel).run(options.defaults("float"),
                                  np.asarray(falling.p_values, float), 0.0, q0, dq0, 1e-2, 50)
    assert motion.status == OK and motion.t.size == 50
    crank = falling.coordinates.index("crank.phi")
    reference = _lagrange(motion.t)
    assert np.max(np.abs(motion.q[:, crank] + math.pi / 3 - reference[:, 0])) < 1e-4


def test_numpy_step_uses_the_same_rows(falling: Any, falling_c: Any, tmp_path: Path) -> None:
    symkin.generate(falling, "numpy", tmp_path)
    spec = importlib.util.spec_from_file_location(falling.name,
                                                  tmp_path / f"{falling.name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    assert list(module.KEPT) == [k for k in range(14) if k != 11]
    q0, dq0 = _consistent_start(falling)
    p = np.asarray(falling.p_values, float)
    state = {"t": 0.0, "q": q0, "dq": dq0, "ddq": None}
    rows = []
    for _ in range(30):
        status, state, _, _ = module.dynamics_step(p, 1e-2, state)
        assert status == module.OK
        rows.append(state["q"])
    motion = _stepper(falling_c).run(Options(), p, 0.0, q0, dq0, 1e-2, 30)
    assert np.max(np.abs(np.array(rows) - motion.q)) < 1e-12
    # the C step's lam (the left-out row's 0) balances every coordinate's equation of motion:
    # M ddq + Phi_q^T lam = Q - h
    for k in (0, 14, 29):
        q, dq, t = motion.q[k], motion.dq[k], motion.t[k]
        jacobian = np.zeros((14, q.size))
        jacobian[module.PATTERN_ROWS, module.PATTERN_COLS] = module.phi_q_nz(q, t, p)
        balance = (module.mass(q, p) @ motion.ddq[k] + jacobian.T @ motion.lam[k]
                   - module.applied(q, dq, t, p))
        assert np.max(np.abs(balance)) < 1e-10


@pytest.mark.parametrize("example", ["four_bar_dynamics", "crank_slider_load"])
def test_worst_case_within_three_kinematic_steps(example: str, tmp_path: Path) -> None:
    """Issue 37's goal for the budget the header states: one dynamics step at most 3 times
    the kinematic step of the same mechanism (both worst cases at the default caps)."""
    symkin.generate(derived(ROOT / "examples" / f"{example}.yaml"), "c", tmp_path)
    upper = example.upper()

    def macro(file: str, name: str) -> int:
        text = (tmp_path / f"{example}_{file}.h").read_text()
        found = [line.split()[2] for line in text.splitlines()
                 if line.startswith(f"#define {upper}_{name} ")]
        return int(found[0])

    kinematic = macro("solver", "OPS_STEP_WORST")
    dynamic = macro("dynamics", "OPS_DYNAMICS_STEP_WORST")
    assert 0 < dynamic <= 3 * kinematic

"""The generated forward-dynamics step (backends/c/templates/dynamics.*.j2, the NumPy kernel's
dynamics_step), against references derived here:

- a bar pendulum hinged at one end, free (one degree of freedom): its minimal-coordinate
  equation J_O theta'' = -m g (L/2) cos(theta) integrated by SciPy at rtol 1e-12;
- the driven four-bar of examples/four_bar_dynamics.yaml (masses off their frames, gravity, a
  spring-damper, a brake): with every freedom driven the step must follow the kinematic
  solve, and its multipliers must be the inverse dynamics' of that motion;
- M and Q - h of the generated C against the symbolic ones, at a random state;
- symkin.solve's own integrator (runtime.dynamics, tight rtol) on a pushed pendulum and on a
  free tumbling box (Euler parameters), which the C step must match.
"""

from __future__ import annotations

import importlib.util
import re
import shutil
import subprocess
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from codegen_support import compiled, derived
from scipy.integrate import solve_ivp

import symkin
from symkin import backends
from symkin.backends.c import dynamics_budget
from symkin.backends.c.dynamics_step import DynamicsStepper
from symkin.build.compile import compile as build_compile
from symkin.codegen import lower
from symkin.contract import options
from symkin.contract.options import Options
from symkin.contract.status import BAD_OPTIONS, OK

ROOT = Path(__file__).resolve().parents[3]
FOUR_BAR = ROOT / "examples" / "four_bar_dynamics.yaml"
G, LENGTH, MASS = 9.81, 1.0, 1.0
PENDULUM = """\
name: pendulum
parameters: {L: 1.0, m: 1.0}
bodies:
  bar: {q0: [0.5, 0, 0], mass: m, inertia: m*L**2/12}
joints:
  - {type: revolute, name: O, i: ground, j: bar, sA: [0, 0], sB: [-L/2, 0]}
forces:
  - {type: gravity, g: [0, -9.81]}
time: {t0: 0, t1: 1, dt: 0.01}
"""

TUMBLING = """\
name: tumbling
space: 3d
parameters: {m: 2.0}
bodies:
  box: {q0: [0, 0, 0, 0.921060994, 0.233651005, 0.311534674, 0], mass: m,
        inertia: [1.0, 2.0, 2.5]}
initial: {velocities: {box.x: 0.5, box.z: -0.25, box.omega_x: 0.1, box.omega_y: 3.0,
                       box.omega_z: 0.2}}
integrator: {rtol: 1e-11, atol: 1e-12}
time: {t0: 0, t1: 6, dt: 0.1}
"""

pytestmark = pytest.mark.skipif(shutil.which("gcc") is None, reason="no C compiler")


@pytest.fixture(scope="module")
def pendulum(tmp_path_factory: pytest.TempPathFactory) -> Any:
    path = tmp_path_factory.mktemp("pendulum") / "pendulum.yaml"
    path.write_text(PENDULUM)
    return symkin.derive(path)


@pytest.fixture(scope="module")
def pendulum_c(pendulum: Any) -> Any:
    # symkin.compile answers a mechanism its forces move with its integrator's kernel; the
    # generated C is built directly
    return build_compile(pendulum, backends.get("c"))


@pytest.fixture(scope="module")
def four_bar() -> Any:
    return derived(FOUR_BAR)


@pytest.fixture(scope="module")
def four_bar_c() -> Any:
    """Its C kernel, built once from the goldens (driven: a kinematic kernel)."""
    return compiled(FOUR_BAR, "c")


def _stepper(kernel: Any) -> DynamicsStepper:
    return DynamicsStepper(kernel.ffi, kernel.lib, kernel.name, kernel.real)


def _minimal(t: np.ndarray, theta0: float, omega0: float) -> np.ndarray:
    """theta(t) of the bar pendulum from its own equation, independently of symkin."""
    inertia = MASS * LENGTH**2 / 3  # about the hinge

    def rates(_t: float, y: np.ndarray) -> list[float]:
        return [y[1], -MASS * G * LENGTH / 2 * np.cos(y[0]) / inertia]

    solution = solve_ivp(rates, (0.0, t[-1]), [theta0, omega0], method="DOP853",
                         rtol=1e-12, atol=1e-12, t_eval=t)
    return solution.y[0]


def test_pendulum_c_step_follows_its_minimal_equation(pendulum_c: Any) -> None:
    """Released horizontal with a push (bar.phi' = 2): 2 s of 1 ms steps, C in double."""
    omega0 = 2.0
    dq0 = np.array([0.0, omega0 * LENGTH / 2, omega0])  # the centre at L/2 from the hinge
    motion = _stepper(pendulum_c).run(Options(), np.array([LENGTH, MASS]), 0.0,
                                      np.array([0.5, 0.0, 0.0]), dq0, 1e-3, 2000)
    assert motion.status == OK and motion.t.size == 2000
    theta = _minimal(motion.t, 0.0, omega0)
    assert np.max(np.abs(motion.q[:, 2] - theta)) < 1e-9
    assert np.max(np.abs(motion.q[:, 0] - LENGTH / 2 * np.cos(theta))) < 1e-9
    # no drift: Phi and Phi_q dq + Phi_t at the tolerance after every step
    assert motion.residual.max() <= Options().tol_phi
    assert motion.velocity_residual.max() < 1e-12
    # Newton's law for the bar's centre: m a = hinge force + weight, the hinge force on the
    # bar being -Phi_q^T lam restricted to x, y (Phi_q = [-I | ...] there): +lam
    assert np.allclose(MASS * motion.ddq[:, :2], motion.lam + [0.0, -MASS * G], atol=1e-9)


def _numpy_module(system: Any, folder: Path) -> Any:
    """The generated NumPy module of ``system``, imported from ``folder``."""
    symkin.generate(system, "numpy", folder)
    spec = importlib.util.spec_from_file_location(system.name, folder / f"{system.name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_numpy_step_equals_the_c_step(pendulum: Any, pendulum_c: Any,
                                      tmp_path: Path) -> None:
    step = _numpy_module(pendulum, tmp_path).dynamics_step
    p = np.array([LENGTH, MASS])
    state = {"t": 0.0, "q": np.array([0.5, 0.0, 0.0]), "dq": np.zeros(3), "ddq": None}
    rows = []
    for _ in range(50):
        status, state, _, _ = step(p, 1e-2, state)
        assert status == 0
        rows.append(state["q"])
    motion = _stepper(pendulum_c).run(Options(), p, 0.0, np.array([0.5, 0.0, 0.0]),
                                      np.zeros(3), 1e-2, 50)
    assert np.max(np.abs(np.array(rows) - motion.q)) < 1e-12


def test_float_step_runs_to_its_precision(pendulum: Any) -> None:
    kernel = build_compile(pendulum, backends.get("c"), {"real": "float"})
    motion = _stepper(kernel).run(options.defaults("float"), np.array([LENGTH, MASS]), 0.0,
                                  np.array([0.5, 0.0, 0.0]), np.zeros(3), 1e-2, 100)
    assert motion.status == OK
    theta = _minimal(motion.t, 0.0, 0.0)
    assert np.max(np.abs(motion.q[:, 2] - theta)) < 1e-3


def test_bad_step_length_is_refused_and_the_state_kept(pendulum_c: Any) -> None:
    motion = _stepper(pendulum_c).run(Options(), np.array([LENGTH, MASS]), 0.0,
                                      np.array([0.5, 0.0, 0.0]), np.zeros(3), 0.0, 3)
    assert motion.status == BAD_OPTIONS and motion.t.size == 0


def test_driven_four_bar_follows_the_kinematic_solve(four_bar: Any, four_bar_c: Any,
                                                     tmp_path: Path) -> None:
    """Every freedom driven: the step's ddq comes from Phi_q ddq = Gamma, so it must track
    the kinematic solution; its lam must be the inverse dynamics' multipliers there."""
    kernel = four_bar_c
    trajectory = symkin.solve(kernel, t=np.arange(0.0, 0.5 + 1e-12, 1e-3))
    motion = _stepper(kernel).run(Options(), np.asarray(four_bar.p_values, float), 0.0,
                                  trajectory.q[0], trajectory.dq[0], 1e-3, 500)
    assert motion.status == OK
    assert np.max(np.abs(motion.q - trajectory.q[1:])) < 1e-8
    assert np.max(np.abs(motion.dq - trajectory.dq[1:])) < 1e-7
    module = _numpy_module(four_bar, tmp_path)
    p = np.asarray(four_bar.p_values, float)
    for k in (0, 249, 499):
        lam = module.multipliers(motion.q[k], motion.dq[k], motion.ddq[k], motion.t[k], p)
        assert np.allclose(motion.lam[k], lam, rtol=1e-8, atol=1e-8)


def test_mass_and_applied_are_the_symbolic_ones(four_bar: Any, four_bar_c: Any) -> None:
    kernel = four_bar_c
    rng = np.random.default_rng(37)
    q, dq, t = rng.normal(size=9), rng.normal(size=9), 0.3
    p = np.asarray(four_bar.p_values, float)
    values = {**dict(zip(four_bar.q, q)), **dict(zip(four_bar.dq, dq)),
              **dict(zip(four_bar.p, p)), four_bar.t: t}
    mass = np.array(four_bar.dynamics.mass_matrix.xreplace(values), dtype=float)
    applied = np.array((four_bar.dynamics.applied - four_bar.dynamics.velocity_terms)
                       .xreplace(values).evalf(), dtype=float).ravel()
    ffi, lib, name = kernel.ffi, kernel.lib, kernel.name
    n_m = int(getattr(lib, f"{name.upper()}_NNZ_M"))
    nz, out = ffi.new("double[]", n_m), ffi.new("double[]", 9)
    getattr(lib, f"{name}_mass")(ffi.from_buffer("double[]", q), ffi.from_buffer("double[]", p),
                                 nz)
    dense = np.zeros((9, 9))
    rows = ffi.unpack(getattr(lib, f"{name}_mass_row"), n_m)
    cols = ffi.unpack(getattr(lib, f"{name}_mass_col"), n_m)
    dense[rows, cols] = ffi.unpack(nz, n_m)
    assert np.allclose(dense, mass, rtol=1e-13, atol=1e-13)
    getattr(lib, f"{name}_applied")(ffi.from_buffer("double[]", q),
                                    ffi.from_buffer("double[]", dq), t,
                                    ffi.from_buffer("double[]", p), out)
    assert np.allclose(ffi.unpack(out, 9), applied, rtol=1e-12, atol=1e-12)


def test_header_states_the_budget(four_bar: Any, four_bar_c: Any) -> None:
    kernel = four_bar_c
    plan = dynamics_budget.budget(lower.lower(four_bar, backends.get("c")), 25)
    assert plan.step.total == kernel.lib.FOUR_BAR_DYNAMICS_OPS_DYNAMICS_STEP_WORST
    assert plan.step.total > 0


def test_files_without_masses_get_no_dynamics(tmp_path: Path) -> None:
    paths = symkin.generate(derived(ROOT / "examples" / "four_bar.yaml"), "c", tmp_path)
    assert not [p for p in paths if "dynamics" in p.name]
    assert "_mass(" not in (tmp_path / "four_bar.h").read_text()


def test_readme_program_runs(pendulum: Any, tmp_path: Path) -> None:
    """The README's forward-dynamics program, compiled with the strict flags, at rest from
    the horizontal: the bar starts to fall as theta'' = -3 g / (2 L)."""
    symkin.generate(pendulum, "c", tmp_path)
    readme = (tmp_path / "pendulum_README.md").read_text()
    blocks = re.findall(r"```c\n(.*?)```", readme, re.DOTALL)
    assert len(blocks) == 2
    (tmp_path / "main.c").write_text(blocks[1])
    sources = sorted(str(p) for p in tmp_path.glob("*.c"))
    flags = ["-std=c99", "-O2", "-Wall", "-Wextra", "-pedantic", "-Werror"]
    subprocess.run(["gcc", *flags, f"-I{tmp_path}", "-o", str(tmp_path / "main"), *sources,
                    "-lm"], check=True)
    out = subprocess.run([str(tmp_path / "main")], check=True, capture_output=True,
                         text=True).stdout
    rows = np.array([[float(v) for v in line.split()] for line in out.splitlines()])
    assert rows.shape == (10, 4)
    theta = _minimal(rows[:, 0], 0.0, 0.0)
    assert np.allclose(rows[:, 3], theta, atol=2e-9)


def test_c_step_equals_the_python_integrator(tmp_path: Path) -> None:
    """The pendulum of docs/topics/forward-dynamics.md (a push, inertia about the centre):
    symkin.solve's integrator at rtol 1e-10 against 1 ms C steps, on the file's grid."""
    path = tmp_path / "pushed.yaml"
    path.write_text(PENDULUM.replace("time:", "initial:\n  velocities: {bar.phi: 1.5}\n"
                                     "integrator: {rtol: 1e-10, atol: 1e-12}\ntime:"))
    system = symkin.derive(path)
    trajectory = symkin.solve(symkin.compile(system, "numpy"))
    kernel = build_compile(system, backends.get("c"))
    motion = _stepper(kernel).run(Options(), np.array([LENGTH, MASS]), 0.0,
                                  trajectory.q[0], trajectory.dq[0], 1e-3, 1000)
    rows = motion.q[9::10]  # t = 0.01, 0.02, ..., the file's grid after t0
    assert np.max(np.abs(rows - trajectory.q[1:rows.shape[0] + 1])) < 1e-8


def test_spatial_free_body_equals_the_python_integrator(tmp_path: Path) -> None:
    """Euler parameters (their normalization is Phi's one row): a box tumbling about an axis
    near its middle one, 6 s of 1 ms C steps against symkin.solve at rtol 1e-11."""
    path = tmp_path / "free.yaml"
    path.write_text(TUMBLING)
    system = symkin.derive(path)
    trajectory = symkin.solve(symkin.compile(system, "numpy"))
    kernel = build_compile(system, backends.get("c"))
    motion = _stepper(kernel).run(Options(), np.asarray(system.p_values, float), 0.0,
                                  trajectory.q[0], trajectory.dq[0], 1e-3, 6000)
    assert motion.status == OK
    rows = motion.q[99::100]  # the file's grid, dt = 0.1
    assert np.max(np.abs(rows - trajectory.q[1:rows.shape[0] + 1])) < 1e-9

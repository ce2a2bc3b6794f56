"""IFToMM multibody benchmark A05, the stiff flyball governor: symkin's generated C and NumPy
dynamics steps and Exudyn, CPU time to the same accuracy, side by side in one run.

    python3 bench/iftomm/a05_flyball_governor.py [--target 1e-6] [--repeat 3] [--end 10]

The problem (bench/iftomm/a05_flyball_governor.yaml): a shaft turning freely about the
vertical in a bearing, a slider on it, two rods hinged at its top carrying 5 kg balls, each
rod's middle tied to the slider by a spring-damper of K = 8e5 N/m and C = 4e4 N s/m (rest
length 0.5 m); released turning at 2 pi rad/s with the rods 30 degrees below the
horizontal; 10 s. Four freedoms; the damper makes it stiff (linearised at the start, its
fastest mode decays at 8117 1/s, the next at 1450 1/s: an explicit fourth-order step is
stable below about 2.785 / 8117 = 3.4e-4 s), and it is not conservative, so no energy
column.

Reference: the governor's own equations of motion in its four minimal coordinates (the
spin phi, the slider's height s, the rods' angles below the horizontal b1 and b2), derived
here by Lagrange's equations with SymPy (the damper as the Rayleigh function C ldot^2 / 2)
and integrated by SciPy's DOP853 at rtol 1e-12 -- none of it symkin's. (Its Radau at 1e-12
agrees within 2e-13 m over 1 s but stops on an overflow in its difference Jacobian before
10 s; DOP853 at 1e-10 agrees within 5e-12 m over the 10 s.) Accuracy: the largest
distance of the slider's centre or of either ball from the reference's, over the run,
sampled every 0.01 s.

symkin's model: 4 bodies, Euler parameters (28 coordinates, 24 rows). Exudyn's model is its
own: four rigid bodies made by CreateRigidBody (each rod with its ball as one inertia), a
revolute, a prismatic and two revolute joints, two CreateSpringDamper, generalized-alpha at
its defaults (it meets the reference within 1.4e-9 m over 1 s at its finest steps, so its
default Newton tolerance is not what limits it here).
"""

from __future__ import annotations

import argparse
import math
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import sympy as sp
from scipy.integrate import solve_ivp

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from harness import (  # noqa: E402
    Row, Run, SymkinC, SymkinNumPy, at_step, exudyn_settings, print_table, rotation,
    to_accuracy)

import symkin  # noqa: E402

FILE = Path(__file__).with_name("a05_flyball_governor.yaml")
NAME = "a05_flyball_governor"
T_END, SAMPLE = 10.0, 0.01
# The benchmark's data (the mechanism file's parameters).
A, L, W, RHO, BALL, S0, ALPHA = 0.05, 1.0, 0.01, 3000.0, 5.0, 0.5, math.pi / 6
K, C, L0, G, SPIN = 8.0e5, 4.0e4, 0.5, 9.81, 2 * math.pi
BAR = RHO * L * W ** 2                      # a shaft's or a rod's bar, 0.3 kg
CUBE = RHO * 0.1 ** 3                       # the slider, 3 kg
ROD = BAR + BALL                            # a rod with its ball
D = (BAR * L / 2 + BALL * L) / ROD          # the rod's centre from its pin
J_AXIAL = BAR * W ** 2 / 6
J_ACROSS = BAR * (L ** 2 + W ** 2) / 12 + BAR * (L / 2 - D) ** 2 + BALL * (L - D) ** 2


def equations() -> tuple[Callable[..., np.ndarray], Callable[..., np.ndarray]]:
    """M(x) and the right-hand side f(x, v) of M x'' = f in x = (phi, s, b1, b2), by Lagrange.
    Everything is written in the shaft's turning frame, then turned by phi about z."""
    x = list(sp.symbols("phi s b1 b2"))
    v = list(sp.symbols("dphi ds db1 db2"))
    phi, s, b1, b2 = x
    turn = sp.Matrix([[sp.cos(phi), -sp.sin(phi), 0], [sp.sin(phi), sp.cos(phi), 0], [0, 0, 1]])
    ez = sp.Matrix([0, 0, 1])

    def rate(point: sp.Matrix) -> sp.Matrix:
        return (turn * point).jacobian(x) * sp.Matrix(v)

    kinetic = sp.Rational(1, 2) * (BAR * W ** 2 / 6 + CUBE * 0.1 ** 2 / 6) * v[0] ** 2
    kinetic += sp.Rational(1, 2) * CUBE * v[1] ** 2
    potential = G * (BAR * L / 2 + CUBE * s)
    rayleigh = sp.Integer(0)
    for sign, beta, dbeta, side in ((1, b1, v[2], 1), (-1, b2, v[3], -1)):
        pin = sp.Matrix([side * A, 0, L])
        along = sp.Matrix([side * sp.cos(beta), 0, -sp.sin(beta)])
        centre = pin + D * along
        # the rod turns with the shaft and about the shaft's y axis; the cross-section is
        # square, so its tensor is J_ACROSS I + (J_AXIAL - J_ACROSS) u u^T
        omega = v[0] * ez + sign * dbeta * turn * sp.Matrix([0, 1, 0])
        axial = (omega.T * turn * along)[0]
        kinetic += sp.Rational(1, 2) * ROD * (rate(centre).T * rate(centre))[0]
        kinetic += sp.Rational(1, 2) * (J_ACROSS * (omega.T * omega)[0]
                                        + (J_AXIAL - J_ACROSS) * axial ** 2)
        spring = pin + L / 2 * along - sp.Matrix([side * 0.05, 0, s])
        length = sp.sqrt((spring.T * spring)[0])
        potential += G * ROD * centre[2] + sp.Rational(1, 2) * K * (length - L0) ** 2
        rayleigh += sp.Rational(1, 2) * C * (sp.Matrix([length]).jacobian(x)
                                             * sp.Matrix(v))[0] ** 2
    momenta = sp.Matrix([kinetic]).jacobian(v).T
    mass = momenta.jacobian(v)
    force = (sp.Matrix([kinetic]).jacobian(x).T - momenta.jacobian(x) * sp.Matrix(v)
             - sp.Matrix([potential]).jacobian(x).T - sp.Matrix([rayleigh]).jacobian(v).T)
    return (sp.lambdify([x], mass, "numpy", cse=True),
            sp.lambdify([x, v], force, "numpy", cse=True))


def reference(t: np.ndarray, rtol: float = 1e-12, method: str = "DOP853") -> np.ndarray:
    """(phi, s, b1, b2) and their rates (k, 8) at the times t, from the start at rest in the
    turning frame."""
    mass, force = equations()

    def rhs(_t: float, y: np.ndarray) -> np.ndarray:
        acc = np.linalg.solve(mass(y[:4]), force(y[:4], y[4:]).ravel())
        return np.concatenate([y[4:], acc])

    start = np.array([0.0, S0, ALPHA, ALPHA, SPIN, 0.0, 0.0, 0.0])
    solution = solve_ivp(rhs, (0.0, float(t[-1])), start, method=method, rtol=rtol,
                         atol=rtol, t_eval=t)
    assert solution.success, solution.message
    return np.asarray(solution.y.T)


def reference_points(x: np.ndarray) -> np.ndarray:
    """The slider's centre and the two balls (k, 3, 3) of minimal coordinates (k, 4)."""
    phi, s, b1, b2 = x[:, :4].T
    c, n = np.cos(phi), np.sin(phi)
    r1, r2 = A + L * np.cos(b1), -A - L * np.cos(b2)
    z1, z2 = L - L * np.sin(b1), L - L * np.sin(b2)
    zero = np.zeros_like(s)
    return np.stack([np.stack([zero, zero, s], axis=1),
                     np.stack([r1 * c, r1 * n, z1], axis=1),
                     np.stack([r2 * c, r2 * n, z2], axis=1)], axis=1)


def symkin_points(coordinates: list[str], q: np.ndarray) -> np.ndarray:
    """The same three points (k, 3, 3) of symkin's coordinates: a drawn body's frame starts
    parallel to the global axes at its first point (the pin, for a rod)."""
    def point(body: str, local: np.ndarray) -> np.ndarray:
        first = coordinates.index(f"{body}.x")
        return np.array([row[first:first + 3] + rotation(row[first + 3:first + 7]) @ local
                         for row in q])

    drop = np.array([math.cos(ALPHA), 0.0, -math.sin(ALPHA)]) * L
    return np.stack([point("slider", np.zeros(3)), point("rodAC", drop),
                     point("rodBD", drop * [-1, 1, 1])], axis=1)


def largest_distance(points: np.ndarray, expected: np.ndarray) -> float:
    return float(np.max(np.linalg.norm(points - expected, axis=2))) if len(points) else math.inf


def exudyn_run(h: float, repeat: int, end: float = T_END) -> Run:
    """Exudyn's own model of A05 (module docstring); q: the three points (k, 9) a sample."""
    import exudyn as exu
    from exudyn.itemInterface import SensorBody
    from exudyn.utilities import InertiaCuboid, InertiaMassPoint, RotationMatrixY

    best, points, times = math.inf, np.empty((0, 9)), np.empty(0)
    for _ in range(repeat):
        mbs = exu.SystemContainer().AddSystem()
        ground = mbs.CreateGround()
        spin = [0.0, 0.0, SPIN]
        shaft = mbs.CreateRigidBody(referencePosition=[0, 0, L / 2],
                                    inertia=InertiaCuboid(RHO, [W, W, L]),
                                    initialAngularVelocity=spin, gravity=[0, 0, -G])
        slider = mbs.CreateRigidBody(referencePosition=[0, 0, S0],
                                     inertia=InertiaCuboid(RHO, [0.1, 0.1, 0.1]),
                                     initialAngularVelocity=spin, gravity=[0, 0, -G])
        rods, sensors = [], []
        for side in (1, -1):
            # the rod along its local x (side 1) or -x (side -1), its centre of mass the
            # body's reference point, turned down by alpha about y
            whole = InertiaCuboid(RHO, [L, W, W]) + InertiaMassPoint(BALL).Translated(
                [side * L / 2, 0, 0])
            whole = whole.Translated([-side * (D - L / 2), 0, 0])
            centre = [side * (A + D * math.cos(ALPHA)), 0, L - D * math.sin(ALPHA)]
            rods.append(mbs.CreateRigidBody(
                referencePosition=centre, referenceRotationMatrix=RotationMatrixY(
                    side * ALPHA), inertia=whole, initialAngularVelocity=spin,
                initialVelocity=[0, SPIN * centre[0], 0], gravity=[0, 0, -G]))
            sensors.append(mbs.AddSensor(SensorBody(
                bodyNumber=rods[-1], localPosition=[side * (L - D), 0, 0], storeInternal=True,
                outputVariableType=exu.OutputVariableType.Position)))
        mbs.CreateRevoluteJoint(bodyNumbers=[ground, shaft], position=[0, 0, 0],
                                axis=[0, 0, 1])
        mbs.CreatePrismaticJoint(bodyNumbers=[shaft, slider], position=[0, 0, S0],
                                 axis=[0, 0, 1])
        for side, rod in zip((1, -1), rods):
            mbs.CreateRevoluteJoint(bodyNumbers=[shaft, rod], position=[side * A, 0, L],
                                    axis=[0, 1, 0])
            mbs.CreateSpringDamper(bodyNumbers=[slider, rod],
                                   localPosition0=[side * 0.05, 0, 0],
                                   localPosition1=[side * (L / 2 - D), 0, 0],
                                   referenceLength=L0, stiffness=K, damping=C)
        sensors.insert(0, mbs.AddSensor(SensorBody(
            bodyNumber=slider, storeInternal=True,
            outputVariableType=exu.OutputVariableType.Position)))
        mbs.Assemble()
        settings = exudyn_settings(exu, end, h, SAMPLE)
        start = time.process_time()
        try:
            exu.SolveDynamic(mbs, settings)
        except Exception as stop:  # Exudyn raises on a failed Newton step
            return Run(math.inf, np.empty(0), np.empty((0, 9)), np.empty((0, 0)),
                       str(stop).splitlines()[0][:60])
        best = min(best, time.process_time() - start)
        data = [mbs.GetSensorStoredData(s) for s in sensors]
        keep = data[0][:, 0] > SAMPLE / 2
        times = data[0][keep, 0]
        points = np.column_stack([d[keep, 1:4] for d in data])
    return Run(float(best), times, points, np.empty((0, 0)))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--target", type=float, default=1e-6)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--end", type=float, default=T_END, help="a shorter run, s")
    args = parser.parse_args()
    grid = np.round(np.arange(1, round(args.end / SAMPLE) + 1) * SAMPLE, 12)
    expected = reference_points(reference(np.concatenate([[0.0], grid]))[1:, :4])
    system = symkin.derive(FILE)
    start = symkin.solve(symkin.compile(system, backend="numpy"), t=np.array([0.0, SAMPLE]))
    q0, dq0, coordinates = start.q[0], start.dq[0], list(start.coordinates)

    def error(t: np.ndarray, points: np.ndarray) -> float:
        if len(t) != len(grid) or not np.allclose(t, grid, atol=1e-9):
            return math.inf
        return largest_distance(points, expected)

    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch)

        def symkin_error(run: Run) -> float:
            return error(run.t, symkin_points(coordinates, run.q))

        c_row = to_accuracy("symkin C (dynamics_step)",
                            SymkinC(system, folder / "c", NAME, (q0, dq0), args.end, SAMPLE),
                            symkin_error, args.target, args.repeat, 1e-6, first=1e-3)
        rows: list[Row] = [
            c_row,
            at_step("symkin NumPy (dynamics_step)",
                    SymkinNumPy(system, folder / "numpy", NAME, (q0, dq0), args.end, SAMPLE),
                    symkin_error, c_row.h),
            to_accuracy("Exudyn (generalized-alpha)",
                        lambda h, repeat: exudyn_run(h, repeat, args.end),
                        lambda run: error(run.t, run.q.reshape(-1, 3, 3)), args.target,
                        args.repeat, 1e-6, first=1e-3)]
    import exudyn

    print_table(f"IFToMM A05 flyball governor, {args.end:g} s, target max distance of the"
                f" slider and the balls {args.target:g} m (against the minimal-coordinate"
                f" equations, DOP853 at 1e-12) (Exudyn {exudyn.__version__})", rows)


if __name__ == "__main__":
    main()

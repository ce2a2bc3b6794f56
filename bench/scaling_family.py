"""A parametric family of planar mechanisms for scaling measurements: a chain of four-bar loops.

Loop k (k = 1..L) is a parallelogram four-bar: the rocker of loop k-1 (the crank for k = 1),
a coupler, a new rocker pinned to the ground at (k d, 0), and the ground. Each rocker is shared
with the next loop, so the mechanism has n = 1 + 2L bodies, 3 + 6L equations and one degree of
freedom, driven by the crank angle theta(t) = pi/2 + 0.5 sin(t). It stays well away from the
parallelogram's change points (theta = 0, pi), and its motion has a closed form used to check
solvers: every crank and rocker turns by theta(t), every coupler keeps its angle 0.

Usage:
    python3 bench/scaling_family.py                 # derive time for 11 .. 301 bodies
    python3 bench/scaling_family.py --lu            # + the generated sparse LU alone
    python3 bench/scaling_family.py --solver        # symkin's generated C solver
    python3 bench/scaling_family.py --loops 5 --yaml > chain.yaml
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
RADIUS = 1.0  # crank and rocker length r
SPACING = 3.0  # ground pivot spacing d, also the coupler length
THETA = "pi/2 + 0.5*sin(t)"


def theta(t: np.ndarray | float) -> np.ndarray | float:
    """The crank angle theta(t) the family's driver imposes."""
    return math.pi / 2 + 0.5 * np.sin(t)


def chain(loops: int, dt: float = 0.05, t1: float = 1.5) -> dict[str, Any]:
    """The mechanism (file structure as a dict) of a chain of ``loops`` four-bar loops."""
    if loops < 1:
        raise ValueError("a chain needs at least one loop")
    q = closed_form_body_states(loops, 0.0)
    bodies: dict[str, Any] = {"crank": {"q0": q["crank"], "points": {"tip": ["r", 0]}}}
    joints: list[dict[str, Any]] = [
        {"type": "revolute", "i": "ground", "j": "crank", "sA": [0, 0], "sB": [0, 0]}]
    previous = "crank"
    for k in range(1, loops + 1):
        coupler, rocker = f"coupler{k}", f"rocker{k}"
        bodies[coupler] = {"q0": q[coupler]}
        bodies[rocker] = {"q0": q[rocker], "points": {"tip": ["r", 0]}}
        joints += [
            {"type": "revolute", "i": previous, "j": coupler, "sA": ["r", 0], "sB": [0, 0]},
            {"type": "revolute", "i": coupler, "j": rocker, "sA": ["d", 0], "sB": ["r", 0]},
            {"type": "revolute", "i": "ground", "j": rocker, "sA": [f"{k}*d", 0],
             "sB": [0, 0]},
        ]
        previous = rocker
    return {
        "name": f"chain{loops}",
        "parameters": {"r": RADIUS, "d": SPACING},
        "bodies": bodies,
        "joints": joints,
        "drivers": [{"type": "angle", "i": "crank", "j": "ground", "theta": THETA}],
        "time": {"t0": 0, "t1": t1, "dt": dt},
    }


def closed_form_body_states(loops: int, t: float) -> dict[str, list[float]]:
    """[x, y, phi] of every body at time t (the exact motion of the chain)."""
    angle = float(theta(t))
    tip = (RADIUS * math.cos(angle), RADIUS * math.sin(angle))
    states = {"crank": [0.0, 0.0, angle]}
    for k in range(1, loops + 1):
        states[f"coupler{k}"] = [(k - 1) * SPACING + tip[0], tip[1], 0.0]
        states[f"rocker{k}"] = [k * SPACING, 0.0, angle]
    return states


def closed_form(loops: int, t: np.ndarray) -> np.ndarray:
    """q(t) for every t (rows), in the file's body order."""
    return np.array([[v for state in closed_form_body_states(loops, float(s)).values()
                      for v in state] for s in np.atleast_1d(t)])


def bodies_of(loops: int) -> int:
    return 1 + 2 * loops


def loops_for(bodies: int) -> int:
    """The number of loops whose chain has at least ``bodies`` bodies."""
    return max(1, math.ceil((bodies - 1) / 2))


def to_yaml(mechanism: dict[str, Any]) -> str:
    import yaml

    return yaml.safe_dump(mechanism, sort_keys=False, default_flow_style=None)


def measure_derive(sizes: list[int]) -> list[tuple[int, int, float]]:
    """(bodies, N, CPU seconds) of validating and deriving each chain."""
    sys.path.insert(0, str(ROOT))
    from symkin.spec import validate as model
    from symkin.symbolic import derivation

    rows = []
    for bodies in sizes:
        loops = loops_for(bodies)
        start = time.process_time()
        system = derivation.derive(model.from_dict(chain(loops)))
        rows.append((bodies_of(loops), len(system.q), time.process_time() - start))
    return rows


def measure_sparse_lu(sizes: list[int], style: str | None = None) -> list[dict[str, float]]:
    """Per size: derive, analyse (pivot order + fill), render + gcc -O2 of the sparse LU, and
    the C time of one factorization plus three solves (one Newton step's worth) at q(t0).
    All times are CPU seconds (this process, plus gcc's for the build), robust to load."""
    import resource
    import tempfile

    sys.path.insert(0, str(ROOT))
    sys.path.insert(0, str(ROOT / "tests"))
    import sympy as sp
    from sparse_lu_harness import build

    from symkin.codegen import lu_plan as sparse_lu
    from symkin.spec import validate as model
    from symkin.symbolic import derivation

    rows_out = []
    for bodies in sizes:
        loops = loops_for(bodies)
        start = time.process_time()
        system = derivation.derive(model.from_dict(chain(loops)))
        derive_s = time.process_time() - start
        pattern = system.pattern()
        rows, cols = [r for r, _ in pattern], [c for _, c in pattern]
        nz_of = sp.lambdify([system.q, system.t, system.p],
                            [system.phi_q[r, c] for r, c in pattern], "math")
        nz = np.array(nz_of(list(system.q0), 0.0, system.p_values), dtype=float)
        start = time.process_time()
        plan = sparse_lu.analyse(len(system.q), rows, cols, nz)
        analyse_s = time.process_time() - start
        with tempfile.TemporaryDirectory() as folder:
            start, children = time.process_time(), _children_cpu(resource)
            lib = build(Path(folder), system.name, len(system.q), rows, cols, plan,
                        style=style)
            build_s = time.process_time() - start + _children_cpu(resource) - children
            b = np.ones(len(system.q))
            reps = max(10, int(2e7 // (plan.flops + 3 * plan.solve_flops)))
            best = float("inf")
            for _ in range(5):
                start = time.process_time()
                lib.repeat(reps, nz, b)
                best = min(best, (time.process_time() - start) / reps)
            x, status, _, _, fallbacks = lib.solve(nz, b)
            a = np.zeros((len(system.q),) * 2)
            a[rows, cols] = nz
            residual = float(np.abs(a @ x[0] - b).max())
        rows_out.append({"bodies": bodies_of(loops), "n": len(system.q), "nnz": plan.nnz,
                         "fill": plan.n_lu - plan.nnz, "flops": plan.flops,
                         "derive_s": derive_s, "analyse_s": analyse_s, "build_s": build_s,
                         "lu_us": best * 1e6, "residual": residual, "status": int(status[0]),
                         "fallbacks": fallbacks})
    return rows_out


def measure_solver(sizes: list[int], steps: int = 2000) -> list[dict[str, float]]:
    """Per size: derive + generate + compile CPU time of symkin's C kernel with the sparse LU
    (fresh cache), and its CPU time per step of symkin.solve over t = k 1.5/steps, checked
    against the closed form."""
    import os
    import resource
    import tempfile

    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    sys.path.insert(0, str(ROOT))
    import symkin
    from symkin.spec import validate as model
    from symkin.symbolic import derivation

    out = []
    for bodies in sizes:
        loops = loops_for(bodies)
        with tempfile.TemporaryDirectory() as cache:
            start = time.process_time() + _children_cpu(resource)
            system = derivation.derive(model.from_dict(chain(loops, dt=1.5 / steps)))
            kernel = symkin.compile(system, backend="c", linalg="sparse", cache_dir=cache)
            build_s = time.process_time() + _children_cpu(resource) - start
            times = np.arange(steps + 1) * (1.5 / steps)
            best = float("inf")
            for _ in range(3):
                start = time.process_time()
                trajectory = symkin.solve(kernel, t=times)
                best = min(best, time.process_time() - start)
        error = float(np.abs(trajectory.q - closed_form(loops, times)).max())
        out.append({"bodies": bodies_of(loops), "n": len(system.q), "build_s": build_s,
                    "step_us": best / len(times) * 1e6, "q_error": error})
    return out


def report_solver(rows: list[dict[str, float]]) -> int:
    print(f"{'bodies':>6} {'N':>5} {'derive+generate+compile s':>26} {'us/step':>9} "
          f"{'max|q err|':>10}")
    for r in rows:
        print(f"{r['bodies']:6d} {r['n']:5d} {r['build_s']:26.2f} {r['step_us']:9.2f} "
              f"{r['q_error']:10.1e}")
    bodies = [r["bodies"] for r in rows]
    for key in ("build_s", "step_us"):
        print(f"log-log slope of {key}: {loglog_slope(bodies, [r[key] for r in rows]):.2f}")
    return 0


def _children_cpu(resource) -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def loglog_slope(x: list[float], y: list[float]) -> float:
    return float(np.polyfit(np.log(x), np.log(y), 1)[0])


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--loops", type=int, help="print one chain instead of measuring")
    parser.add_argument("--yaml", action="store_true", help="print it as YAML")
    parser.add_argument("--sizes", type=int, nargs="+", default=[11, 21, 41, 81, 161, 301])
    parser.add_argument("--lu", action="store_true",
                        help="also analyse, compile and time the generated sparse LU")
    parser.add_argument("--style", choices=["straight", "tables"],
                        help="force the C style of the sparse LU (default: by size)")
    parser.add_argument("--solver", action="store_true",
                        help="time symkin's generated C solver (sparse LU) instead")
    args = parser.parse_args(argv)
    if args.solver:
        return report_solver(measure_solver(args.sizes))
    if args.lu:
        return report_lu(measure_sparse_lu(args.sizes, args.style))
    if args.loops:
        mech = chain(args.loops)
        print(to_yaml(mech) if args.yaml else mech)
        return 0
    rows = measure_derive(args.sizes)
    print(f"{'bodies':>7} {'N':>5} {'derive s':>9}")
    for bodies, n, seconds in rows:
        print(f"{bodies:7d} {n:5d} {seconds:9.3f}")
    print(f"log-log slope of derive time: {loglog_slope([r[0] for r in rows], [r[2] for r in rows]):.2f}")
    return 0


def report_lu(rows: list[dict[str, float]]) -> int:
    print(f"{'bodies':>6} {'N':>5} {'nnz':>5} {'fill':>5} {'flops':>6} {'derive s':>9} "
          f"{'analyse s':>9} {'render+gcc s':>12} {'LU+3 solves us':>14} {'residual':>9}")
    for r in rows:
        print(f"{r['bodies']:6d} {r['n']:5d} {r['nnz']:5d} {r['fill']:5d} {r['flops']:6d} "
              f"{r['derive_s']:9.3f} {r['analyse_s']:9.3f} {r['build_s']:12.3f} "
              f"{r['lu_us']:14.3f} {r['residual']:9.1e}")
    bodies = [r["bodies"] for r in rows]
    for key in ("derive_s", "analyse_s", "build_s", "lu_us"):
        print(f"log-log slope of {key}: {loglog_slope(bodies, [r[key] for r in rows]):.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

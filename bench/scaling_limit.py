"""Cold build and per-step cost from 10 to 1000 bodies, with peak memory, on two families.

    python3 bench/scaling_limit.py [--family chain tongs] [--sizes 10 30 100 300 1000]
                                   [--tighten-cond C]

Families: ``chain`` (bench/scaling_family.py: four-bar loops, every rocker grounded, no
fill-in) and ``tongs`` (lazy tongs: a ladder of scissor units, grounded only at the first, so
the sparse LU has fill-in). Each size runs in a fresh child process with an empty kernel cache:
derive, generate and compile (``symkin.compile``: SymPy, codegen, gcc), then ``symkin.solve``
over grids of 401 and 2001 points (best of 3 each, after a warm-up); per step is the
difference of the two CPU times over 1600 steps (the assembly at t0 and the set-up cancel).
Times are CPU seconds of the child plus its compiler processes (robust to other load on the
machine); peak memory is the largest resident set of the child or of any compiler process
it ran (getrusage maxrss). The q of both families is checked against their closed forms
(largest error over the 2001-point grid; "flagged": the share of its points flagged).
``--tighten-cond C`` solves with that ``Options.tighten_cond`` instead of the default (``inf``:
no extra Newton iterations at all, so a step does the same work at every size).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "bench"))

HALF = 1.0  # half the length of a tongs bar
ALPHA = "0.7 + 0.2*sin(t)"


def alpha(t: np.ndarray | float) -> np.ndarray | float:
    return 0.7 + 0.2 * np.sin(t)


def tongs(units: int) -> dict[str, Any]:
    """Lazy tongs of ``units`` scissor units: bars a_k (rising) and b_k (falling) of length 2h
    pinned at their middles; a_k's right end to b_{k+1}'s left end, b_k's right end to
    a_{k+1}'s left end; a_1's left end pinned to the ground at the origin, b_1's left end in a
    vertical slot through it; the angle of a_1 driven. n = 2 units bodies, one DOF."""
    bodies: dict[str, Any] = {}
    joints: list[dict[str, Any]] = []
    states = tongs_states(units, 0.0)
    for k in range(1, units + 1):
        bodies[f"a{k}"] = {"q0": states[f"a{k}"]}
        bodies[f"b{k}"] = {"q0": states[f"b{k}"]}
        joints.append({"type": "revolute", "i": f"a{k}", "j": f"b{k}", "sA": [0, 0],
                       "sB": [0, 0]})
        if k > 1:
            joints += [
                {"type": "revolute", "i": f"a{k - 1}", "j": f"b{k}", "sA": ["h", 0],
                 "sB": ["-h", 0]},
                {"type": "revolute", "i": f"b{k - 1}", "j": f"a{k}", "sA": ["h", 0],
                 "sB": ["-h", 0]}]
    joints += [
        {"type": "revolute", "i": "ground", "j": "a1", "sA": [0, 0], "sB": ["-h", 0]},
        {"type": "pin_slot", "i": "b1", "j": "ground", "sA": ["-h", 0], "sB": [0, 0],
         "v": [1, 0]}]  # the row is the pin.x: v is the normal to the slot
    return {"name": f"tongs{units}", "parameters": {"h": HALF}, "bodies": bodies,
            "joints": joints,
            "drivers": [{"type": "angle", "i": "a1", "j": "ground", "theta": ALPHA}],
            "time": {"t0": 0, "t1": 1.5, "dt": 0.05}}


def tongs_states(units: int, t: float) -> dict[str, list[float]]:
    """[x, y, phi] of every bar at time t: a closed form of the motion."""
    a = float(alpha(t))
    c, s = math.cos(a), math.sin(a)
    out = {}
    for k in range(1, units + 1):
        centre = [(2 * k - 1) * HALF * c, HALF * s]
        out[f"a{k}"] = [*centre, a]
        out[f"b{k}"] = [*centre, -a]
    return out


def mechanism(family: str, bodies: int) -> tuple[dict[str, Any], Any]:
    """The mechanism with about ``bodies`` bodies and its closed form q(t)."""
    import scaling_family

    if family == "chain":
        loops = scaling_family.loops_for(bodies)
        return scaling_family.chain(loops), lambda t: scaling_family.closed_form(loops, t)
    units = max(1, bodies // 2)
    return tongs(units), lambda t: np.array([[v for st in tongs_states(units, float(s)).values()
                                              for v in st] for s in np.atleast_1d(t)])


def child(family: str, bodies: int, tighten_cond: float | None = None) -> dict[str, Any]:
    """One measurement, in this (fresh) process."""
    import symkin
    from symkin.contract.options import defaults
    from symkin.spec import validate as model

    data, exact = mechanism(family, bodies)
    cpu = time.process_time
    kids = lambda: resource.getrusage(resource.RUSAGE_CHILDREN)  # noqa: E731
    start = cpu()
    system = symkin.derive(model.from_dict(data))
    derive = cpu() - start
    with tempfile.TemporaryDirectory() as cache:
        before = kids()
        start = cpu()
        kernel = symkin.compile(system, backend="c", cache_dir=cache)
        own = cpu() - start
        after = kids()
        gcc = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
        assert kernel.backend == "c"
        options = (None if tighten_cond is None else
                   dataclasses.replace(defaults("double"), tighten_cond=tighten_cond))
        # first call: loading, allocation
        symkin.solve(kernel, t=np.arange(11) * 0.001, options=options)
        runs = []
        for n in (401, 2001):
            t = np.arange(n) * 0.001
            best = math.inf
            for _ in range(3):
                start = cpu()
                trajectory = symkin.solve(kernel, t=t, options=options)
                best = min(best, cpu() - start)
            runs.append(best)
        error = float(np.abs(trajectory.q - exact(t)).max())
        flagged = float(np.mean(trajectory.flagged))
    return {"family": family, "bodies": len(data["bodies"]), "nq": len(system.q),
            "derive_s": derive, "codegen_s": own, "gcc_s": gcc,
            "build_s": derive + own + gcc, "us_per_step": (runs[1] - runs[0]) / 1600 * 1e6,
            "max_q_error": error, "flagged": flagged,
            "peak_mb": max(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss,
                           resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss) / 1024}


def slope(x: list[float], y: list[float]) -> float:
    return float(np.polyfit(np.log(x), np.log(y), 1)[0])


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--family", nargs="+", default=["chain", "tongs"])
    parser.add_argument("--sizes", type=int, nargs="+", default=[10, 30, 100, 300, 1000])
    parser.add_argument("--tighten-cond", type=float, default=None)
    parser.add_argument("--child", nargs=2, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        print(json.dumps(child(args.child[0], int(args.child[1]), args.tighten_cond)))
        return 0
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
    for family in args.family:
        rows = []
        print(f"{family}: bodies  N  derive s  codegen s  gcc s  build s  us/step  "
              f"peak MB  max|q err|  flagged", flush=True)
        for bodies in args.sizes:
            tighten = [] if args.tighten_cond is None else ["--tighten-cond",
                                                            repr(args.tighten_cond)]
            done = subprocess.run([sys.executable, __file__, "--child", family, str(bodies),
                                   *tighten], capture_output=True, text=True, env=env, check=False)
            if done.returncode != 0:
                print(f"  {bodies}: failed\n{done.stderr[-2000:]}", flush=True)
                continue
            row = json.loads(done.stdout.strip().splitlines()[-1])
            rows.append(row)
            print(f"  {row['bodies']:5d} {row['nq']:5d} {row['derive_s']:8.2f} "
                  f"{row['codegen_s']:9.2f} {row['gcc_s']:6.2f} {row['build_s']:8.2f} "
                  f"{row['us_per_step']:8.2f} {row['peak_mb']:8.0f} {row['max_q_error']:9.1e}"
                  f" {row['flagged']:7.0%}",
                  flush=True)
        if len(rows) >= 2:
            n = [r["bodies"] for r in rows]
            big = [r for r in rows if r["bodies"] >= 100]
            build = slope(n, [r["build_s"] for r in rows])
            print(f"  slopes {n[0]}..{n[-1]} bodies: build {build:.2f}, "
                  f"per step {slope(n, [r['us_per_step'] for r in rows]):.2f}"
                  + (f"; from 100 on: per step "
                     f"{slope([r['bodies'] for r in big], [r['us_per_step'] for r in big]):.2f}"
                     if len(big) >= 2 else ""), flush=True)
            by = {r["bodies"]: r for r in rows}
            small = min(by, key=lambda b: abs(b - 100))
            print(f"  largest / ~100-body build: {rows[-1]['build_s'] / by[small]['build_s']:.1f}x",
                  flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""Build and run the hand-written C crank-slider (crank_slider.c) through ctypes.

Two builds of the same lean loop: with its own dense 9 x 9 LU with partial pivoting (the
baseline), and with the LU replaced by symkin's generated straight-line sparse LU
(``-DSPARSE_LU``), which isolates what the sparse factorization alone is worth.
"""

from __future__ import annotations

import ctypes
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
WARNINGS = ["-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror"]


@dataclass
class GridResult:
    q: np.ndarray
    dq: np.ndarray
    d2q: np.ndarray
    newton_iterations: int
    fallbacks: int


class Solver:
    """A compiled cs_solve_grid."""

    def __init__(self, library: Path) -> None:
        self.lib = ctypes.CDLL(str(library))
        self.lib.cs_solve_grid.restype = ctypes.c_long
        self.lib.cs_solve_grid.argtypes = [ctypes.c_long, ctypes.c_double] + [
            ctypes.c_void_p] * 5

    def solve_grid(self, steps: int, dt: float) -> GridResult:
        # np.empty, as symkin.solve does: the C loop writes every row (no zero-fill to pay).
        q, dq, d2q = (np.empty((steps + 1, 9)) for _ in range(3))
        iterations, fallbacks = ctypes.c_long(0), ctypes.c_ulong(0)
        status = self.lib.cs_solve_grid(steps, dt, q.ctypes.data, dq.ctypes.data,
                                        d2q.ctypes.data, ctypes.addressof(iterations),
                                        ctypes.addressof(fallbacks))
        if status != 0:
            raise RuntimeError(f"the hand-written C solver failed at step {status - 1}")
        return GridResult(q, dq, d2q, iterations.value, fallbacks.value)


def _gcc(sources: list[Path], library: Path, flags: list[str]) -> None:
    command = ["gcc", *WARNINGS, *flags, "-fPIC", "-shared", "-I", str(library.parent),
               *map(str, sources), "-o", str(library), "-lm"]
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(command)}\n{done.stderr}")


def build_dense(folder: Path, optimisation: str = "-O2") -> Solver:
    library = folder / f"libcs_dense{optimisation}.so"
    _gcc([HERE / "crank_slider.c"], library, [optimisation])
    return Solver(library)


def build_sparse(folder: Path, optimisation: str = "-O2") -> Solver:
    """The same loop over the generated sparse LU, planned as symkin plans it (Phi_q of the
    mechanism assembled at t0)."""
    sys.path.insert(0, str(ROOT / "tests"))

    from sparse_lu_harness import write_sources

    from symkin.codegen import lu_plan as sparse_lu
    from symkin.codegen import sample as codegen_sample
    from symkin.symbolic import derivation

    system = derivation.derive(ROOT / "examples" / "crank_slider.yaml")
    pattern = system.pattern()
    rows, cols = [r for r, _ in pattern], [c for _, c in pattern]
    assembled = codegen_sample.sample_configuration(system)
    values = {**dict(zip(system.q, assembled)), **dict(zip(system.p, system.p_values))}
    sample = [float(system.phi_q[r, c].subs(values)) for r, c in pattern]
    plan = sparse_lu.analyse(len(system.q), rows, cols, sample)
    sub = folder / f"sparse{optimisation}"
    # the numbers among Phi_q's entries folded in, as symkin's codegen does
    constants = [float(system.phi_q[r, c]) if system.phi_q[r, c].is_Number else None
                 for r, c in pattern]
    sources = write_sources(sub, "crank_slider", len(system.q), rows, cols, plan,
                            constants=constants)
    library = sub / "libcs_sparse.so"
    _gcc([*sources, HERE / "crank_slider.c"], library, [optimisation, "-DSPARSE_LU"])
    return Solver(library)

"""Test helpers for the driver: kernels for a System, and mechanism files under mechanisms/.

``LambdifyKernel`` has the Kernel interface but is built with sympy.lambdify straight from the
System, bypassing codegen: a cross-check of the generated NumPy kernel. ``kernel_for`` is
``symkin.compile``, falling back to the lambdify kernel only where symkin.build.compile is missing.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np
import pytest
import shared_builds
import sympy as sp
from codegen_support import compiled

import symkin

MECHANISMS = Path(__file__).resolve().parent / "mechanisms"
BACKENDS = ("numpy", "c")


class LambdifyKernel:
    """The Kernel interface evaluated with sympy.lambdify."""

    backend = "lambdify"
    real = "double"
    has_grid_solver = False

    def __init__(self, system) -> None:
        args = (system.q, system.t, system.p)
        self.name = system.name
        self.coordinates = system.coordinates
        self.parameter_names = system.parameter_names
        self.p_values = np.array(system.p_values, dtype=float)
        self.q0 = np.array(system.q0, dtype=float)
        self.time_grid = system.time_grid
        self.rows = tuple(str(row) for row in system.rows)
        pattern = system.pattern()
        self.pattern_rows = np.array([r for r, _ in pattern])
        self.pattern_cols = np.array([c for _, c in pattern])
        self._phi = sp.lambdify(args, system.phi, "numpy")
        self._phi_q = sp.lambdify(args, sp.Matrix(system.phi_q), "numpy")
        self._phi_t = sp.lambdify(args, system.phi_t, "numpy")
        self._gamma = sp.lambdify((system.q, system.dq, system.t, system.p), system.gamma, "numpy")
        self.points = tuple((body, name) for body, name, _ in system.points)
        vectors = [vector for _, _, vector in system.points]
        self._points = sp.lambdify((system.p,), sp.Matrix([[v[0], v[1]] for v in vectors])
                                   if vectors else sp.zeros(0, 2), "numpy")

    def _p(self, p):
        return self.p_values if p is None else np.asarray(p, dtype=float)

    def phi(self, q, t, p=None):
        return np.asarray(self._phi(q, t, self._p(p)), dtype=float).reshape(-1)

    def phi_q(self, q, t, p=None):
        return np.asarray(self._phi_q(q, t, self._p(p)), dtype=float)

    def phi_q_nz(self, q, t, p=None):
        return self.phi_q(q, t, p)[self.pattern_rows, self.pattern_cols]

    def phi_t(self, q, t, p=None):
        return np.asarray(self._phi_t(q, t, self._p(p)), dtype=float).reshape(-1)

    def gamma(self, q, dq, t, p=None):
        return np.asarray(self._gamma(q, dq, t, self._p(p)), dtype=float).reshape(-1)

    def point_vectors(self, p=None):
        return np.asarray(self._points(self._p(p)), dtype=float).reshape(-1, 2)


def kernel_for(system, backend: str):
    """symkin.compile(system, backend); the lambdify stand-in while codegen is not there."""
    try:
        import symkin.build.compile
    except ImportError:
        if backend == "numpy":
            return LambdifyKernel(system)
        pytest.skip("symkin.build.compile (the C backend) is not available yet")
    return symkin.compile(system, backend=backend)


def derive(name: str):
    """The System of tests/mechanisms/<name>.yaml."""
    return symkin.derive(MECHANISMS / f"{name}.yaml")


def mechanism_file(text: str) -> Path:
    """``text`` as a YAML mechanism file shared by the run (shared_builds.text_file): every test
    and backend that writes the same text shares one derivation and one generation of it."""
    return shared_builds.text_file(f"text-{hashlib.sha256(text.encode()).hexdigest()[:24]}.yaml",
                                   text)


def kernel_of(text: str, backend: str):
    """symkin.compile(symkin.derive(symkin.load(file of text)), backend), built once per run."""
    return compiled(mechanism_file(text), backend)



def _condition_apart(message: str) -> tuple[str, float]:
    """A failure message with its condition figure taken out, and that figure."""
    import re

    found = re.search(r"condition ([0-9.e+-]+)\)", message)
    if found is None:
        return message, 0.0
    return message.replace(found.group(1), "C"), float(found.group(1))


def same_condition(result_message: str, solve_message: str) -> None:
    """Equal messages but for the condition figure, which agrees to 1 %: a sweep's limit is
    bisected in C (sweeps.stops), whose condition estimate there may differ from the
    runtime's in the last of the 3 digits printed."""
    mine, theirs = _condition_apart(result_message), _condition_apart(solve_message)
    assert mine[0] == theirs[0]
    assert mine[1] == pytest.approx(theirs[1], rel=0.01)

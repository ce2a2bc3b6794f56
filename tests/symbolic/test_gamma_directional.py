"""Gamma of every spatial example, its convective part derived as D(D(row)) along dq
(symbolic.differentiation), equals (2.74) written out independently here,

    Gamma = -(Phi_q dq)_q dq - 2 Phi_qt dq - Phi_tt,

evaluated as -d2/ds2 Phi(q + s dq, t + s) at s = 0 (the three terms are its expansion) from
the System's own Phi by a second difference at 50 digits, at seeded random states (q off the
unit sphere, dq anywhere), to 1e-12 relative. An input driver's time derivatives live in the
Taylor polynomial the derivation removes, so for those files what is quadratic in dq is
compared, the convective part."""

from __future__ import annotations

from pathlib import Path

import mpmath
import numpy as np
import pytest
import sympy as sp
from codegen_support import EXAMPLES, ROOT, derived

from symkin.spec import constants

SPATIAL = [path for path in EXAMPLES if "space: 3d" in path.read_text(encoding="utf-8")]
FILES = [*SPATIAL, ROOT / "tests" / "trust" / "spherical_four_bar.yaml",
         ROOT / "bench" / "iftomm" / "a04_bricard.yaml"]
STATES = 3
DIGITS = 50
STEP = mpmath.mpf("1e-12")


def _path_phi(system):
    """Phi as an mpmath function of (q, dq, t, p), for the reference."""
    arguments = [list(system.q), list(system.dq), system.t, list(system.code_parameters)]
    return sp.lambdify(arguments, system.phi, modules="mpmath", cse=True)


def _reference(phi):
    """(2.74) at a state: -d2/ds2 Phi(q + s dq, t + s) at s = 0, whose expansion is the three
    terms above, by a central second difference of the System's own Phi at 50 digits (step
    1e-12: truncation about 1e-24, rounding about 1e-26). sympy.diff of every row column by
    column and its lambdify took minutes of CPU for delta and stewart."""
    def gamma(q, dq, t, p) -> np.ndarray:
        with mpmath.workdps(DIGITS):
            q, dq, p = ([mpmath.mpf(float(x)) for x in v] for v in (q, dq, p))
            t = mpmath.mpf(float(t))

            def along(s):
                value = phi([a + b * s for a, b in zip(q, dq)], dq, t + s, p)
                return [value[r, 0] for r in range(value.rows)]

            ahead, here, behind = along(STEP), along(0), along(-STEP)
            return np.array([float(-(a - 2 * b + c) / STEP**2)
                             for a, b, c in zip(ahead, here, behind)])
    return gamma


def _quadratic(function, q, dq, t, p) -> np.ndarray:
    """(f(dq) + f(-dq)) / 2 - f(0): what of Gamma is quadratic in dq."""
    def at(v):
        return np.array(function(q, v, t, p), dtype=float).ravel()
    return (at(dq) + at(-dq)) / 2 - at(np.zeros_like(dq))


@pytest.mark.parametrize("path", FILES, ids=lambda path: Path(path).stem)
def test_gamma_equals_the_column_sum_of_2_74(path: Path) -> None:
    system = derived(Path(path).resolve())
    arguments = [list(system.q), list(system.dq), system.t, list(system.code_parameters)]
    derived_gamma = constants.lambdify_floats(arguments, system.gamma)
    reference = _reference(_path_phi(system))
    generator = np.random.default_rng(38)
    p = np.array(system.code_p_values, dtype=float)
    p = p + generator.uniform(-0.1, 0.1, p.size) * np.maximum(np.abs(p), 1.0)
    whole = not system.inputs
    for _ in range(STATES):
        q = np.array(system.q0) + generator.uniform(-0.5, 0.5, len(system.q))
        dq = generator.uniform(-2.0, 2.0, len(system.q))
        t = float(generator.uniform(0.0, 1.0))
        got, want = (np.array(f(q, dq, t, p), dtype=float).ravel()
                     for f in (derived_gamma, reference))
        if not whole:  # the part quadratic in dq: the convective one
            got, want = (_quadratic(f, q, dq, t, p) for f in (derived_gamma, reference))
        scale = max(1.0, float(np.abs(want).max()))
        assert np.abs(got - want).max() <= 1e-12 * scale, (path, got - want)

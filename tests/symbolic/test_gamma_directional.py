"""Gamma of every spatial example, its convective part derived as D(D(row)) along dq
(symbolic.differentiation), equals (2.74) written out independently here,

    Gamma = -(Phi_q dq)_q dq - 2 Phi_qt dq - Phi_tt,

with sympy.diff column by column of the System's own Phi, at seeded random states (q off the
unit sphere, dq anywhere), to 1e-12 relative. An input driver's time derivatives live in the
Taylor polynomial the derivation removes, so for those files what is quadratic in dq is
compared, the convective part."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from codegen_support import EXAMPLES, ROOT, derived

from symkin.spec import constants

SPATIAL = [path for path in EXAMPLES if "space: 3d" in path.read_text(encoding="utf-8")]
FILES = [*SPATIAL, ROOT / "tests" / "trust" / "spherical_four_bar.yaml",
         ROOT / "bench" / "iftomm" / "a04_bricard.yaml"]
STATES = 3


def _reference(system) -> sp.Matrix:
    """(2.74) by sympy.diff: the velocity row Phi_q dq differentiated column by column."""
    rows = []
    for row in system.phi:
        touched = [k for k, q in enumerate(system.q) if q in row.free_symbols]
        jacobian = {k: sp.diff(row, system.q[k]) for k in touched}
        velocity = sum((jacobian[k] * system.dq[k] for k in touched), sp.S.Zero)
        convective = sum((sp.diff(velocity, system.q[k]) * system.dq[k] for k in touched),
                         sp.S.Zero)
        mixed = sum((sp.diff(jacobian[k], system.t) * system.dq[k] for k in touched),
                    sp.S.Zero)
        rows.append(-convective - 2 * mixed - sp.diff(row, system.t, 2))
    return sp.Matrix(rows)


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
    reference = constants.lambdify_floats(arguments, _reference(system))
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

"""Large routines are split into bounded parts (codegen.lower.PART_OUTPUTS), each with its own
CSE and its own C function, so that SymPy and the compiler see bounded pieces.

A small mechanism (a chain of 8 four-bar loops, 17 bodies, 51 coordinates, 131 entries of
Phi_q) is built split, in parts of at most 50 outputs (the split a 183-coordinate chain gets
at the default of 200, at a quarter of the compile), and unsplit: the numbers agree at random
states, and the split solver follows the chain's closed form. The 1000-body build is in the
slow set only (SYMKIN_SLOW=1), so that the suite stays within its time budget;
bench/scaling_limit.py measures it.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np
import pytest

import symkin
from symkin.codegen import lower
from symkin.spec import validate as model

ROOT = Path(__file__).resolve().parents[3]
sys.path.insert(0, str(ROOT / "bench"))

import scaling_family  # noqa: E402

LOOPS = 8
PART = 50  # Phi_q (131 entries) in three parts, Phi and Phi_q together (182) in four


@pytest.fixture(scope="module")
def chain():  # type: ignore[no-untyped-def]
    return symkin.derive(model.from_dict(scaling_family.chain(LOOPS)))


def test_split_and_unsplit_builds_agree(chain, tmp_path: Path,  # type: ignore[no-untyped-def]
                                        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(lower, "PART_OUTPUTS", PART)
    split = symkin.compile(chain, backend="c", cache_dir=tmp_path / "split")
    assert split.backend == "c"
    source = (split.folder / f"{chain.name}.c").read_text()
    assert f"static void {chain.name}_phi_q_1(" in source  # really split
    assert f"static void {chain.name}_phi_phi_q_2(" in source
    assert f"static void {chain.name}_phi_phi_q_3(" in source
    monkeypatch.setattr(lower, "PART_OUTPUTS", 10**9)
    whole = symkin.compile(chain, backend="c", cache_dir=tmp_path / "whole")
    assert whole.backend == "c"
    assert f"{chain.name}_phi_q_1(" not in (whole.folder / f"{chain.name}.c").read_text()
    rng = np.random.default_rng(4)
    p = np.array(chain.p_values)
    for _ in range(20):
        q, dq, t = rng.uniform(-2, 2, len(chain.q)), rng.uniform(-3, 3, len(chain.q)), 0.3
        for a, b in [(split.phi(q, t, p), whole.phi(q, t, p)),
                     (split.phi_q_nz(q, t, p), whole.phi_q_nz(q, t, p)),
                     (split.phi_t(q, t, p), whole.phi_t(q, t, p)),
                     (split.gamma(q, dq, t, p), whole.gamma(q, dq, t, p))]:
            assert np.abs(a - b).max() <= 1e-13 * max(1.0, np.abs(b).max())
    times = np.linspace(0.0, 1.5, 31)
    trajectory = symkin.solve(split, t=times)
    assert np.abs(trajectory.q - scaling_family.closed_form(LOOPS, times)).max() <= 1e-8


@pytest.mark.slow
@pytest.mark.skipif(os.environ.get("SYMKIN_SLOW") != "1",
                    reason="a 1000-body build takes minutes: set SYMKIN_SLOW=1")
def test_a_thousand_body_chain_builds_and_solves(tmp_path: Path) -> None:
    loops = 500
    derived = symkin.derive(model.from_dict(scaling_family.chain(loops)))
    assert len(derived.mechanism.bodies) == 1001
    kernel = symkin.compile(derived, backend="c", cache_dir=tmp_path)
    assert kernel.backend == "c"
    times = np.linspace(0.0, 0.5, 11)
    trajectory = symkin.solve(kernel, t=times)
    assert np.abs(trajectory.q - scaling_family.closed_form(loops, times)).max() <= 1e-8

"""Fused evaluation: one routine per Newton iterate for Phi and Phi_q, shared sines and cosines.

``<prefix>_phi_phi_q`` computes Phi, the non-zeros of Phi_q and the sines and cosines Phi_t and
Gamma also need, with one CSE; ``_phi_t_shared`` and ``_gamma_shared`` read those. They must
give the numbers of the separate entry points (which stay), on both backends, at random
states; the separate ones are checked against SymPy elsewhere (test_generated), and here once
more against SymPy directly so that both sides of the comparison are anchored.
"""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import numpy as np
import pytest
from codegen_support import ROOT, Reference, compiled, golden_folder, random_states, system

from symkin import backends
from symkin.codegen import lower
from symkin.contract.manifest import manifest_name

MECHANISMS = ["crank_slider", "all_drivers", "andrews_squeezer", "quick_return"]
TOL = 1e-14
# The states (of 40) where the fused values are also compared with SymPy at 30 digits (an
# mpmath evaluation of the whole System each): the separate entry points are anchored at
# every example's random states in test_codegen.
ANCHORED = 8


def _c_fused(kernel, nshared, q, dq, t, p):  # type: ignore[no-untyped-def]
    ffi, lib, name = kernel.ffi, kernel.lib, kernel.name
    nq, nnz = len(q), len(kernel.pattern_rows)
    nshared = max(1, nshared)
    arrays = {k: ffi.new("double[]", n) for k, n in
              (("phi", nq), ("nz", nnz), ("shared", nshared), ("phi_t", nq), ("gamma", nq))}
    q_c, dq_c, p_c = (ffi.new("double[]", list(v) or [0.0]) for v in (q, dq, p))
    getattr(lib, f"{name}_phi_phi_q")(q_c, t, p_c, arrays["phi"], arrays["nz"],
                                      arrays["shared"])
    getattr(lib, f"{name}_phi_t_shared")(q_c, t, p_c, arrays["shared"], arrays["phi_t"])
    getattr(lib, f"{name}_gamma_shared")(q_c, dq_c, t, p_c, arrays["shared"], arrays["gamma"])
    size = {"phi": nq, "nz": nnz, "phi_t": nq, "gamma": nq}
    return {k: np.array(ffi.unpack(arrays[k], n)) for k, n in size.items()}


def _scale(*arrays: np.ndarray) -> float:
    return max(1.0, *(float(np.abs(a).max(initial=0.0)) for a in arrays))


@pytest.mark.parametrize("name", MECHANISMS)
def test_c_fused_equals_separate_entry_points(name: str) -> None:
    derived = system(name)
    kernel = compiled(ROOT / "examples" / f"{name}.yaml", "c")  # the goldens' C
    assert kernel.backend == "c"
    reference = Reference(derived)
    # the golden manifest's count (test_generated proves it fresh), not a lowering of its own
    nshared = json.loads((golden_folder(name, "c") / manifest_name(name)).read_text())["nshared"]
    for k, (q, dq, t, p) in enumerate(random_states(derived, count=40, seed=11)):
        fused = _c_fused(kernel, nshared, q, dq, t, p)
        separate = {"phi": kernel.phi(q, t, p), "nz": kernel.phi_q_nz(q, t, p),
                    "phi_t": kernel.phi_t(q, t, p), "gamma": kernel.gamma(q, dq, t, p)}
        for key in separate:
            scale = _scale(separate[key])
            assert np.abs(fused[key] - separate[key]).max(initial=0.0) <= TOL * scale, key
        if k >= ANCHORED:
            continue
        # both anchored to SymPy at 30 digits
        assert np.allclose(fused["phi"], reference.phi(q, t, p), rtol=1e-12, atol=1e-12)
        assert np.allclose(fused["gamma"], reference.gamma(q, dq, t, p), rtol=1e-12,
                           atol=1e-11)


@pytest.mark.parametrize("name", MECHANISMS)
def test_numpy_fused_equals_separate_entry_points(name: str) -> None:
    derived = system(name)
    # the golden module, which test_generated proves equal to what symkin generates now
    source = golden_folder(name, "numpy") / f"{name}.py"
    spec = importlib.util.spec_from_file_location(f"fused_{name}", source)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    for q, dq, t, p in random_states(derived, count=40, seed=12):
        phi, nz, shared = module.phi_phi_q_nz(q, t, p)
        assert shared.shape == (module.NSHARED,)
        pairs = [(phi, module.phi(q, t, p)), (nz, module.phi_q_nz(q, t, p)),
                 (module.phi_t_shared(q, t, shared, p), module.phi_t(q, t, p)),
                 (module.gamma_shared(q, dq, t, shared, p), module.gamma(q, dq, t, p))]
        for fused, separate in pairs:
            assert np.abs(fused - separate).max(initial=0.0) <= TOL * _scale(separate)


def test_crank_slider_shares_its_two_angles(crank_slider_system) -> None:  # type: ignore[no-untyped-def]
    """The textbook mechanism: sin and cos of crank.phi and rod.phi, once per iterate; Gamma
    and Phi_t read them and call no trigonometric function at all."""
    code = lower.lower(crank_slider_system, backends.get("c"))
    assert sorted(code.shared) == ["cos(q[2])", "cos(q[5])", "sin(q[2])", "sin(q[5])"]
    gamma = code.routine("gamma_shared")
    text = " ".join([*gamma.outputs, *(v for _, v in gamma.temporaries)])
    assert "sin(" not in text and "cos(" not in text and "shared[" in text
    fused = code.routine("phi_phi_q")
    calls = " ".join([*fused.outputs, *(v for _, v in fused.temporaries)])
    assert calls.count("sin(") == 2 and calls.count("cos(") == 2


def test_solver_runs_on_the_fused_routine() -> None:
    """The generated solver's Newton loop calls the fused routine, not phi and phi_q (those
    serve the work off the loop: the error model at a moved q, the sweeps' lever arms)."""
    solver = (Path(__file__).resolve().parents[2] / "generated" / "crank_slider" / "c"
              / "crank_slider_solver.c").read_text()
    start = solver.index("static int crank_slider_newton(")
    newton = solver[start:solver.index("\n}\n", start)]
    assert "crank_slider_phi_phi_q(" in newton and "crank_slider_gamma_shared(" in solver
    assert "crank_slider_phi(" not in newton and "crank_slider_phi_q(" not in newton

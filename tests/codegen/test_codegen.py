"""Generated code gives the System's numbers: C vs NumPy vs SymPy/mpmath at random states,
CSE on vs off, and independent checks by finite differences."""

from __future__ import annotations

import functools
import json
import shutil
from pathlib import Path

import mpmath
import numpy as np
import pytest
import sympy as sp
from codegen_support import (
    N_STATES,
    ROOT,
    Reference,
    assert_close,
    compiled,
    compilers,
    example_ids,
    golden_folder,
    random_states,
    system,
)

import symkin
from symkin import backends
from symkin.backends.c import printer as c_printer
from symkin.backends.numpy import printer as numpy_printer
from symkin.codegen import lower as codegen
from symkin.codegen import symbol_printing
from symkin.contract.manifest import manifest_name
from symkin.errors import BuildError


@pytest.fixture
def cache(shared_cache: Path) -> Path:
    return shared_cache


@functools.cache
def _kernels(name: str, cache: Path) -> dict[str, object]:
    """Once per example for both tests here; the default kernels from the goldens, which
    test_generated proves equal to what the generator writes (codegen_support.compiled)."""
    path = ROOT / "examples" / f"{name}.yaml"
    kernels = {"numpy": compiled(path, "numpy"),
               "numpy-nocse": symkin.compile(system(name), "numpy", cse=False, cache_dir=cache)}
    # Explicit "c": without a compiler this raises (CI has one), it never runs NumPy instead.
    kernels["c"] = compiled(path, "c")
    return kernels


@pytest.mark.parametrize("name", example_ids())
def test_backends_match_sympy_at_random_states(name: str, cache: Path) -> None:
    reference = Reference(system(name))
    kernels = _kernels(name, cache)
    assert kernels["c"].backend == "c"
    states = list(random_states(system(name)))
    assert len(states) >= N_STATES
    for q, dq, t, p in states:
        expected = {"phi": reference.phi(q, t, p), "phi_q": reference.phi_q(q, t, p),
                    "phi_t": reference.phi_t(q, t, p), "gamma": reference.gamma(q, dq, t, p)}
        for label, kernel in kernels.items():
            assert_close(kernel.phi(q, t, p), expected["phi"], what=f"{label} phi")
            assert_close(kernel.phi_q(q, t, p), expected["phi_q"], what=f"{label} phi_q")
            assert_close(kernel.phi_t(q, t, p), expected["phi_t"], what=f"{label} phi_t")
            assert_close(kernel.gamma(q, dq, t, p), expected["gamma"], what=f"{label} gamma")
            assert_close(kernel.point_vectors(p), reference.points(p), what=f"{label} points")


@pytest.mark.parametrize("name", example_ids())
def test_jacobian_and_gamma_match_finite_differences(name: str, cache: Path) -> None:
    """Phi_q by central differences of Phi; Gamma = -d2/ds2 Phi(q + s dq, t + s) at s = 0,
    which holds because (2.74) is the second time derivative of Phi along a path with ddq = 0.
    Input drivers move along that path too: u + s du + s^2/2 ddu (their p[] entries)."""
    kernel = _kernels(name, cache).get("c") or _kernels(name, cache)["numpy"]
    h = 1e-4
    nu, n_params = len(system(name).inputs), len(system(name).p)

    def moved(p: np.ndarray, s: float) -> np.ndarray:
        if not nu:
            return p
        u, du, ddu = (p[n_params + k * nu:n_params + (k + 1) * nu] for k in range(3))
        return np.concatenate([p[:n_params], u + s * du + s * s / 2 * ddu, du + s * ddu, ddu])

    for q, dq, t, p in random_states(system(name), count=10, seed=11):
        columns = [(kernel.phi(q + h * e, t, p) - kernel.phi(q - h * e, t, p)) / (2 * h)
                   for e in np.eye(len(q))]
        assert_close(kernel.phi_q(q, t, p), np.array(columns).T, rtol=1e-6, what="phi_q")
        assert_close(kernel.phi_t(q, t, p),
                     (kernel.phi(q, t + h, moved(p, h)) - kernel.phi(q, t - h, moved(p, -h)))
                     / (2 * h), rtol=1e-6, what="phi_t")
        g = 1e-3
        second = (kernel.phi(q + g * dq, t + g, moved(p, g)) - 2 * kernel.phi(q, t, p)
                  + kernel.phi(q - g * dq, t - g, moved(p, -g))) / g**2
        assert_close(kernel.gamma(q, dq, t, p), -second, rtol=1e-4, what="gamma")


@pytest.mark.skipif(not compilers(), reason="no C compiler")
def test_c_without_cse_and_in_float(cache: Path) -> None:
    name = "crank_slider"
    reference = Reference(system(name))
    plain = symkin.compile(system(name), "c", cse=False, cache_dir=cache)
    single = symkin.compile(system(name), "c", real="float", cache_dir=cache)
    for q, dq, t, p in random_states(system(name), count=20):
        assert_close(plain.gamma(q, dq, t, p), reference.gamma(q, dq, t, p), what="no cse")
        # float32 carries about 7 digits; sin/cos of arguments near 2 lose a little more.
        assert_close(single.gamma(q, dq, t, p), reference.gamma(q, dq, t, p), rtol=1e-5,
                     what="float")


def test_textbook_phi_closed_form(cache: Path) -> None:
    """Example 2.5, eq. (a): row 8 is phi_crank - (t^2 + pi/2); rows 2-3 the crank tip."""
    kernel = symkin.compile(system("crank_slider"), "numpy", cache_dir=cache)
    q = np.zeros(9)
    q[2] = 0.3
    values = kernel.phi(q, 0.5)
    assert values[8] == pytest.approx(0.3 - 0.25 - np.pi / 2, abs=1e-15)
    assert values[2] == pytest.approx(np.cos(0.3), abs=1e-15)
    assert values[3] == pytest.approx(np.sin(0.3), abs=1e-15)


def test_cse_shrinks_gamma_of_every_example() -> None:
    """From the C goldens' manifests (the lowered Code's ops; test_generated proves every
    golden, manifest included, equal to a fresh generation), not by lowering them again."""
    for name in example_ids():
        manifest = json.loads((golden_folder(name, "c") / manifest_name(name)).read_text())
        assert manifest["cse"] is True, name
        assert manifest["ops"]["gamma"] <= manifest["ops_before_cse"]["gamma"], name


# ----- printers ------------------------------------------------------------------------------

def _internal(name: str) -> sp.Symbol:
    return sp.Symbol(name, real=True)


def test_c_printer_maps_symbols_and_avoids_posix_constants() -> None:
    q0, p1, t = _internal("_q0"), _internal("_p1"), _internal("_t")
    text = c_printer.CPrinter().doprint(p1 * sp.sin(q0) + sp.pi * t**2)
    assert "q[0]" in text and "p[1]" in text and "(t*t)" in text
    assert "M_PI" not in text and "3.141592653589793" in text


def test_c_printer_float_mode_has_no_double_literals_or_calls() -> None:
    q0 = _internal("_q0")
    expr = sp.sqrt(q0) + sp.Rational(1, 3) * sp.cos(q0) + sp.Float(0.25) * sp.atan2(q0, _internal("_q1")) + sp.E
    text = c_printer.CPrinter("float").doprint(expr)
    assert "sqrtf(" in text and "cosf(" in text and "atan2f(" in text
    literals = [lit for lit in __import__("re").findall(r"\d+\.\d*(?:e[-+]?\d+)?F?", text)]
    assert literals and all(lit.endswith("F") for lit in literals), text


def test_printers_refuse_what_they_cannot_print() -> None:
    q0 = _internal("_q0")
    with pytest.raises(BuildError, match="cannot generate code"):
        codegen._print(c_printer.CPrinter(), sp.besselj(0, q0))


def test_step_functions_print_their_closed_forms() -> None:
    """H(x) (H(0) = 1/2) + delta(x) + sign(x): delta is dropped, H and sign print directly
    (no Piecewise rewrite, which hangs on nested Abs); the NumPy text gives H + sign."""
    x = sp.Symbol("x", real=True)
    expr = symbol_printing.prepare(sp.Heaviside(x, sp.Rational(1, 2)) + sp.DiracDelta(x) + sp.sign(x),
                            {x: _internal("_q0")})
    assert not expr.has(sp.DiracDelta, sp.Piecewise)
    c_text = c_printer.CPrinter().doprint(expr)
    assert "? 1.0 :" in c_text and "q[0]" in c_text
    numpy_text = numpy_printer.PythonPrinter().doprint(expr)
    for value, expected in ((-2.0, -1.0), (0.0, 0.5), (3.0, 2.0)):
        q = np.array([value])
        assert eval(numpy_text, {"numpy": np, "q": q}) == expected  # generated text, not user text


def test_constants_become_correctly_rounded_literals() -> None:
    """sqrt(2), log(2), pi/2 and an integer wider than 64 bits: plain C99 literals (no POSIX
    M_ macros, no truncated integer constant), the nearest doubles of the exact values."""
    q0 = _internal("_q0")
    big = sp.Integer(18446744073709551617)
    expr = symbol_printing.prepare(sp.sqrt(2) * q0 + sp.log(2) + sp.pi / 2 + sp.Min(q0, big), {})
    for real in ("double", "float"):
        text = c_printer.CPrinter(real).doprint(expr)
        assert "M_" not in text and "18446744073709551617" not in text, text
    text = c_printer.CPrinter().doprint(expr)
    assert "1.4142135623730951" in text and "1.8446744073709552e+19" in text, text
    # log(2) + pi/2 is one constant part, folded as a whole to the nearest double.
    with mpmath.workdps(50):
        exact = float(mpmath.log(2) + mpmath.pi / 2)
    assert repr(exact) in text, text


def test_bad_options_are_refused() -> None:
    with pytest.raises(BuildError, match="backend"):
        backends.get("fortran")
    with pytest.raises(BuildError, match="real"):
        codegen.lower(system("crank_slider"), backends.get("c"), {"real": "long double"})
    with pytest.raises(BuildError, match="NumPy backend"):
        codegen.lower(system("crank_slider"), backends.get("numpy"), {"real": "float"})


def test_comments_are_sanitised() -> None:
    assert codegen.comment("a */ b\nc // d") == "a ?? b?c ?? d"


STEP_THETA = ("Piecewise((t**2, t < 1), (2*t - 1, True)) + 0.1*Heaviside(t - 0.5) + Min(t, 0.7)"
              " + Max(t, 0.2)*Abs(sin(3*t)) + pi/2")


def test_every_expression_function_reaches_c_and_numpy(cache: Path, tmp_path: Path) -> None:
    """Piecewise, Heaviside (its derivative DiracDelta), Min, Max, Abs (sign) in a driver;
    in Octave too where it is installed (its printer shares Min/Max with NumPy's through
    codegen.printing)."""
    import yaml
    from codegen_support import ROOT, STRICT_FLAGS, compile_object

    data = yaml.safe_load((ROOT / "examples" / "crank_slider.yaml").read_text())
    data["drivers"][0]["theta"] = STEP_THETA
    s = symkin.derive(symkin.from_dict(data))
    reference = Reference(s)
    kernels = [symkin.compile(s, "numpy", cache_dir=cache)]
    if compilers():
        kernels.append(symkin.compile(s, "c", cache_dir=cache))
        single = tmp_path / "float"
        symkin.generate(s, backend="c", out_dir=single, real="float")
        result = compile_object(compilers()[0], single / "crank_slider.c",
                                [*STRICT_FLAGS, "-Wdouble-promotion"], tmp_path / "k.o")
        assert result.returncode == 0, result.stderr
    if shutil.which("octave-cli"):
        kernels.append(symkin.compile(s, "octave", cache_dir=cache))
    for q, dq, t, p in random_states(s, count=50):
        for kernel in kernels:
            assert_close(kernel.phi(q, t, p), reference.phi(q, t, p), what=kernel.backend)
            assert_close(kernel.phi_t(q, t, p), reference.phi_t(q, t, p), what=kernel.backend)
            assert_close(kernel.gamma(q, dq, t, p), reference.gamma(q, dq, t, p),
                         what=kernel.backend)


def test_a_name_from_the_file_never_reaches_the_code() -> None:
    """Only argument arrays and temporaries print; a stray user symbol is an error, not text."""
    for printer in (c_printer.CPrinter(), numpy_printer.PythonPrinter()):
        with pytest.raises(BuildError, match="not an argument"):
            codegen._print(printer, sp.Symbol("crank.x", real=True) + 1)

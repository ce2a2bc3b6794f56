"""Helpers for the codegen, generated-code, build and embedded tests.

The reference for every generated function is the System itself, evaluated by SymPy with
mpmath at 30 digits: an evaluation path that shares no code with the printers under test.
"""

from __future__ import annotations

import contextlib
import functools
import itertools
import json
import os
import re
import shutil
import subprocess
from collections.abc import Callable, Iterator
from pathlib import Path

import mpmath
import numpy as np
import pytest
import shared_builds
import sympy as sp

import symkin
from symkin import backends
from symkin.build import motion
from symkin.build.cache import open_cache
from symkin.codegen import lower, render
from symkin.contract.manifest import manifest_name
from symkin.spec import expressions
from symkin.spec.motion import moves

ROOT = Path(__file__).resolve().parent.parent
ALL_EXAMPLES = sorted((ROOT / "examples").glob("*.yaml"))
# Examples whose code generation takes a minute or more each (91 coordinates; a 600-character
# cam profile). Their own tests solve them and test_generated diffs their goldens; the loops
# that take every example again (more builds, show, sensitivities) leave them to the slow set
# (SYMKIN_SLOW=1), so that the suite stays within CI's time.
HEAVY = ("cam_cycloidal", "stewart_legs", "stewart_legs_fk")
EXAMPLES = (ALL_EXAMPLES if os.environ.get("SYMKIN_SLOW") == "1"
            else [path for path in ALL_EXAMPLES if path.stem not in HEAVY])
GENERATED = ROOT / "generated"
BACKENDS = ("c", "numpy")
STRICT_FLAGS = ["-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror"]
N_STATES = 12
"""Random states per example where generated code is compared with SymPy/mpmath: each state
evaluates every output of every routine (a wrong term shows at almost any state), and each
costs a 30-digit evaluation of the whole System; twelve prove what a hundred did."""


def example_ids() -> list[str]:
    return [path.stem for path in EXAMPLES]


@functools.cache
def derived(path: Path):
    """The System of a mechanism file, derived once per test run: a System is plain data
    that compile, generate and solve only read, and the heavy examples (stewart_legs_fk's 91
    coordinates) take SymPy a minute or more each. Tests that build from an example file take
    it from here, so the files every worker runs share one derivation (shared_builds)."""
    resolved = Path(path).resolve()
    return shared_builds.stored("system", shared_builds.file_key(resolved),
                                lambda: symkin.derive(resolved))


def compiled(path: Path, backend: str = "c", **options: str):
    """symkin.compile(derived(path), backend, **options) for the tests whose point is what a
    kernel computes, not what the generator writes.

    An example with the default options is built from its goldens (generated/<name>/<backend>),
    which test_generated proves byte for byte equal to what symkin.generate writes now, the
    manifest included: the kernel cache finds the same folder symkin.compile would build, and
    no process derives or generates the example for it. Any other file or options: the sources
    are generated once per run and shared by every worker, as the System is. A file its forces
    move compiles as always."""
    resolved = Path(path).resolve()
    chosen = backends.resolve(backend)
    golden = golden_folder(resolved.stem, chosen.name)
    if not options and resolved.parent == ROOT / "examples" and golden.is_dir():
        chosen.require()
        files = {item.name: item.read_bytes().decode("utf-8")
                 for item in sorted(golden.iterdir()) if item.is_file()}
        meta = json.loads(files[manifest_name(resolved.stem)])
        if not moves(len(meta["rows"]), meta["nq"]):  # else symkin.compile's MotionKernel
            return chosen.build(files, open_cache())
    system = derived(resolved)
    if motion.moves_under_forces(system):
        return symkin.compile(system, backend, **options)
    chosen.require()
    return chosen.build(sources(resolved, chosen.name, **options), open_cache())


def sources(path: Path, backend: str, **options: str) -> dict[str, str]:
    """{file name: text} that symkin.generate(derived(path), backend, **options) writes (the
    same lower, render and manifest), generated once per run for every worker."""
    resolved = Path(path).resolve()

    def generate() -> dict[str, str]:
        return render.rendered(lower.lower(derived(resolved), backends.get(backend), options,
                                           True))

    key = (*shared_builds.file_key(resolved), backend, sorted(options.items()))
    return shared_builds.stored("sources", key, generate)


@contextlib.contextmanager
def one_cse(monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    """While it is open, sympy.cse and sympy.count_ops remember their results by their whole
    input, so that generating several backends of one System (test_generated) does the CSE once.

    Lowering eliminates common subexpressions on SymPy expressions before any printer sees them,
    and counts their operations: both are the same for every backend, and are about half of a
    lowering's CPU. A call whose input differs in anything (the expressions, an option, the
    name or assumptions of the first temporary) is computed afresh, so a backend that lowered
    other expressions would still get its own CSE; the printers, templates and everything
    after the CSE run for each backend as they always do."""
    real_cse, real_count = sp.cse, sp.count_ops
    results: dict[tuple[object, ...], tuple[list[object], list[object]]] = {}
    counts: dict[object, object] = {}

    def cse(exprs, symbols=None, **options):  # type: ignore[no-untyped-def]
        if symbols is None or not isinstance(exprs, (list, tuple)):
            return real_cse(exprs, symbols=symbols, **options)
        first = next(symbols)  # numbered afresh per call: its name and assumptions key it
        key = (tuple(exprs), first, tuple(sorted(first.assumptions0.items())),
               tuple(sorted(options.items(), key=repr)))
        if key not in results:
            results[key] = real_cse(exprs, symbols=itertools.chain([first], symbols),
                                    **options)
        temporaries, reduced = results[key]
        return list(temporaries), list(reduced)  # lower's own lists, never the cached ones

    def count_ops(expr, visual=False):  # type: ignore[no-untyped-def]
        if visual or not isinstance(expr, sp.Basic):
            return real_count(expr, visual)
        if expr not in counts:
            counts[expr] = real_count(expr)
        return counts[expr]

    with monkeypatch.context() as patched:
        patched.setattr(sp, "cse", cse)
        patched.setattr(sp, "count_ops", count_ops)
        yield


def write_sources(files: dict[str, str], folder: Path) -> Path:
    """The files of :func:`sources` written into ``folder`` (created), as generate writes."""
    folder.mkdir(parents=True, exist_ok=True)
    for name, text in files.items():
        (folder / name).write_text(text, encoding="utf-8", newline="\n")
    return folder


def system(name: str):
    return derived(ROOT / "examples" / f"{name}.yaml")


def golden_folder(name: str, backend: str) -> Path:
    return GENERATED / name / backend


def _heaviside(x, at_zero=0.5):
    return mpmath.mpf(1) if x > 0 else mpmath.mpf(0) if x < 0 else mpmath.mpf(at_zero)


# Step functions defined here, independently of the code generator's rewriting; the Dirac delta
# is zero wherever a float can land.
MPMATH = [{"DiracDelta": lambda *args: mpmath.mpf(0), "Heaviside": _heaviside,
           "sign": mpmath.sign, "Min": min, "Max": max}, "mpmath"]


class Reference:
    """Phi, Phi_q, Phi_t, Gamma and the point vectors of a System, by SymPy + mpmath."""

    def __init__(self, system) -> None:
        # p[] of the generated functions: the parameters, then any inputs' u, du, ddu.
        q, dq, t, p = system.q, system.dq, system.t, system.code_parameters
        self.nq = len(q)
        dense = sp.Matrix(system.phi_q)
        # The point vectors straight from the file's text (the parser, not codegen's own
        # point_vectors, which is under test), in file order: bodies, then their points.
        by_name = {symbol.name: symbol for symbol in system.p}
        vectors = [expressions.parse(raw, by_name) for body in system.mechanism.bodies.values()
                   for vector in body.points.values() for raw in vector]
        self._phi = sp.lambdify((q, t, p), list(system.phi), MPMATH, dummify=True)
        self._phi_q = sp.lambdify((q, t, p), list(dense), MPMATH, dummify=True)
        self._phi_t = sp.lambdify((q, t, p), list(system.phi_t), MPMATH, dummify=True)
        self._gamma = sp.lambdify((q, dq, t, p), list(system.gamma), MPMATH, dummify=True)
        self._points = sp.lambdify((p,), vectors or [sp.Integer(0)], MPMATH, dummify=True)
        self._n_points = len(vectors)
        self._point_size = 3 if system.mechanism.is_spatial else 2  # spatial: (x, y, z)

    @staticmethod
    def _floats(values) -> np.ndarray:
        return np.array([float(mpmath.re(v)) for v in values], dtype=float)

    def _call(self, function: Callable, *arrays) -> np.ndarray:
        with mpmath.workdps(30):
            arguments = [[mpmath.mpf(float(x)) for x in np.atleast_1d(a)] if np.ndim(a)
                         else mpmath.mpf(float(a)) for a in arrays]
            return self._floats(function(*arguments))

    def phi(self, q, t, p):
        return self._call(self._phi, q, t, p)

    def phi_q(self, q, t, p):
        return self._call(self._phi_q, q, t, p).reshape(self.nq, self.nq)

    def phi_t(self, q, t, p):
        return self._call(self._phi_t, q, t, p)

    def gamma(self, q, dq, t, p):
        return self._call(self._gamma, q, dq, t, p)

    def points(self, p):
        return self._call(self._points, p)[: self._n_points].reshape(-1, self._point_size)


def random_states(system, count: int = N_STATES, seed: int = 7
                  ) -> Iterator[tuple[np.ndarray, np.ndarray, float, np.ndarray]]:
    """(q, dq, t, p): coordinates in [-2, 2], velocities in [-3, 3], t on the grid's span,
    parameters within 20 % of nominal."""
    rng = np.random.default_rng(seed)
    t0, t1, _ = system.time_grid
    nominal = np.array(system.p_values, dtype=float)
    inputs = 3 * len(system.inputs)  # u, du, ddu of input drivers, after the parameters
    for _ in range(count):
        state = (rng.uniform(-2, 2, len(system.q)), rng.uniform(-3, 3, len(system.q)),
                 float(rng.uniform(t0, t1)), nominal * rng.uniform(0.8, 1.2, nominal.shape))
        if inputs:
            state = (*state[:3], np.concatenate([state[3], rng.uniform(-2, 2, inputs)]))
        yield state


def assert_close(actual, expected, rtol: float = 1e-12, what: str = "") -> None:
    """Agreement to ``rtol`` relative to the magnitude of the reference vector (at least 1)."""
    actual, expected = np.asarray(actual, dtype=float), np.asarray(expected, dtype=float)
    assert actual.shape == expected.shape, what
    scale = max(1.0, float(np.max(np.abs(expected), initial=0.0)))
    error = float(np.max(np.abs(actual - expected), initial=0.0))
    assert error <= rtol * scale, f"{what}: max error {error:.3e} > {rtol:g} x {scale:.3g}"


def compilers() -> list[str]:
    return [cc for cc in ("gcc", "clang") if shutil.which(cc)]


def compile_object(compiler: str, source: Path, flags: list[str], out: Path
                   ) -> subprocess.CompletedProcess:
    return subprocess.run([compiler, *flags, "-c", str(source), "-o", str(out)],
                          capture_output=True, text=True, check=False)


def undefined_symbols(nm: str, objects: list[Path]) -> set[str]:
    listing = subprocess.run([nm, "-u", *map(str, objects)], capture_output=True, text=True,
                             check=True).stdout
    return {line.split()[-1] for line in listing.splitlines()
            if line.strip() and not line.endswith(":")}


def code_without_comments(text: str) -> str:
    """C source with its comments removed (block and line)."""
    return re.sub(r"//[^\n]*", "", re.sub(r"/\*.*?\*/", "", text, flags=re.DOTALL))


def env_without_hash_seed(seed: str) -> dict[str, str]:
    env = dict(os.environ)
    env["PYTHONHASHSEED"] = seed
    return env


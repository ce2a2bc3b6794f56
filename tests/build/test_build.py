"""The build stage: cffi kernels, the content-hash cache, concurrent builds, failures, fall-back,
and a runtime that never imports SymPy or jinja2."""

from __future__ import annotations

import multiprocessing
import os
import shutil
import stat
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
from codegen_support import GENERATED, ROOT, compilers, system

import symkin
from symkin.backends.c import toolchain
from symkin.build import cache as build_cache
from symkin.errors import BuildError

needs_cc = pytest.mark.skipif(not compilers(), reason="no C compiler")


@pytest.fixture
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    folder = tmp_path / "cache"
    monkeypatch.setenv("SYMKIN_CACHE_DIR", str(folder))
    return folder


def _entries(cache: Path) -> list[Path]:
    return sorted(cache.iterdir()) if cache.exists() else []


def test_cache_root_follows_the_environment(monkeypatch: pytest.MonkeyPatch,
                                            tmp_path: Path) -> None:
    monkeypatch.setenv("SYMKIN_CACHE_DIR", str(tmp_path / "x"))
    assert build_cache.cache_root() == tmp_path / "x"
    monkeypatch.delenv("SYMKIN_CACHE_DIR")
    monkeypatch.delenv("XDG_CACHE_HOME", raising=False)
    monkeypatch.setenv("HOME", str(tmp_path))
    assert build_cache.cache_root() == tmp_path / ".cache" / "symkin"


@needs_cc
def test_second_compile_reuses_the_cache(cache: Path) -> None:
    first = symkin.compile(system("crank_slider"), "c")
    (entry,) = _entries(cache)
    library = next(entry.glob("*.so")) if list(entry.glob("*.so")) else next(entry.glob("*.*"))
    stamp = library.stat().st_mtime_ns
    second = symkin.compile(system("crank_slider"), "c")
    assert _entries(cache) == [entry] and library.stat().st_mtime_ns == stamp
    q = np.linspace(-1, 1, 9)
    assert np.array_equal(first.phi(q, 0.2), second.phi(q, 0.2))


@needs_cc
def test_key_covers_the_options(cache: Path, shared_cache: Path) -> None:
    # the default kernel, built once for the run, copied in: its compile here finds it
    built = symkin.compile(system("crank_slider"), "c", cache_dir=shared_cache).folder
    assert built is not None
    shutil.copytree(built, cache / built.name)
    for real in ("double", "float"):
        symkin.compile(system("crank_slider"), "c", real=real)
    symkin.compile(system("crank_slider"), "c", cse=False)
    assert len(_entries(cache)) == 3


def _build_in_child(cache: str, barrier, queue) -> None:
    barrier.wait()  # all start compiling at the same moment
    try:
        k = symkin.compile(system("crank_slider"), "c", cache_dir=cache)
        queue.put(("ok", k.phi(np.full(9, 0.5), 0.1).tolist()))
    except Exception as error:  # noqa: BLE001 -- reported to the parent, which fails the test
        queue.put(("error", repr(error)))


@pytest.mark.slow
@needs_cc
def test_three_processes_building_the_same_kernel_all_succeed(tmp_path: Path) -> None:
    """Three processes released at one barrier build one kernel into one cache: two of them
    lose the rename, as seven of eight did (each costs a C compile)."""
    system("crank_slider")  # derived once, inherited by the forked children
    context = multiprocessing.get_context("fork")
    barrier, queue = context.Barrier(3), context.Queue()
    cache = str(tmp_path / "shared")
    children = [context.Process(target=_build_in_child, args=(cache, barrier, queue))
                for _ in range(3)]
    for child in children:
        child.start()
    results = [queue.get(timeout=120) for _ in children]
    for child in children:
        child.join(timeout=60)
    assert all(status == "ok" for status, _ in results), results
    assert all(values == results[0][1] for _, values in results)
    entries = sorted(Path(cache).iterdir())
    assert len(entries) == 1 and not entries[0].name.startswith("."), entries  # no leftovers


@needs_cc
def test_compiler_failure_carries_command_and_stderr(cache: Path, tmp_path: Path,
                                                     monkeypatch: pytest.MonkeyPatch) -> None:
    fake = tmp_path / "broken-cc"
    fake.write_text("#!/bin/sh\necho 'fatal: this compiler is broken' >&2\nexit 3\n")
    fake.chmod(fake.stat().st_mode | stat.S_IEXEC)
    monkeypatch.setenv("CC", str(fake))
    with pytest.raises(BuildError) as caught:
        symkin.compile(system("crank_slider"), "c")
    assert "this compiler is broken" in str(caught.value)
    assert str(fake) in str(caught.value) and "-fPIC" in caught.value.command
    assert "broken" in caught.value.stderr
    assert not any(p.name.startswith(".") for p in _entries(cache))  # temp folder removed


@needs_cc
def test_a_real_compile_error_is_reported(tmp_path: Path) -> None:
    source = tmp_path / "bad.c"
    source.write_text("int f(void) { return undeclared; }\n")
    with pytest.raises(BuildError, match="undeclared"):
        toolchain.run([compilers()[0], "-c", str(source)], tmp_path)


def test_auto_without_a_compiler_notes_once_and_uses_numpy(
        cache: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("CC", "/nonexistent/cc")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        k = symkin.compile(system("crank_slider"))  # backend="auto"
    messages = [str(w.message) for w in caught]
    assert len(messages) == 1 and "no C compiler" in messages[0] and "CC" in messages[0]
    assert k.backend == "numpy"
    assert k.phi(np.zeros(9), 0.0)[8] == pytest.approx(-np.pi / 2)


def test_explicit_c_without_a_compiler_is_an_error_not_numpy(
        cache: Path, monkeypatch: pytest.MonkeyPatch, tmp_path: Path,
        capsys: pytest.CaptureFixture[str]) -> None:
    from symkin import cli
    from symkin.errors import NoCompilerError

    monkeypatch.setenv("CC", "/nonexistent/cc")
    with pytest.raises(NoCompilerError, match="apt install gcc"):
        symkin.compile(system("crank_slider"), "c")
    example = Path(__file__).resolve().parents[2] / "examples" / "crank_slider.yaml"
    status = cli.main(["run", str(example), "--backend", "c", "-o", str(tmp_path / "r.npz")])
    assert status == cli.EXIT_BAD_INPUT
    assert "needs a C compiler" in capsys.readouterr().err
    assert not (tmp_path / "r.npz").exists()


def test_kernel_checks_argument_shapes(cache: Path) -> None:
    k = symkin.compile(system("crank_slider"), "numpy")
    with pytest.raises(ValueError, match=r"q must have shape \(9,\)"):
        k.phi(np.zeros(8), 0.0)
    with pytest.raises(ValueError, match="parameters a, b, c"):
        k.phi(np.zeros(9), 0.0, p=[1.0])


@pytest.mark.parametrize("backend", ["numpy", "c"])
def test_kernel_metadata_and_nominal_parameters(backend: str, shared_cache: Path) -> None:
    if backend == "c" and not compilers():
        pytest.skip("no C compiler")
    s = system("crank_slider")
    k = symkin.compile(s, backend, cache_dir=shared_cache)
    assert k.backend == backend and k.coordinates == s.coordinates
    assert k.parameter_names == ("a", "b", "c") and list(k.p_values) == [1.0, 5.0, 4.0]
    assert k.time_grid == (0.0, 1.5, 0.05) and k.points == (("crank", "tip"), ("rod", "P"))
    assert k.rows[8].startswith("drivers[0] angle")
    assert list(zip(k.pattern_rows, k.pattern_cols)) == s.pattern()
    q = np.full(9, 0.3)
    assert np.array_equal(k.phi(q, 0.1), k.phi(q, 0.1, p=[1.0, 5.0, 4.0]))
    assert k.phi(q, 0.1, p=[2.0, 5.0, 4.0])[2] == pytest.approx(2 * np.cos(0.3) + 0.3 - 0.3)
    assert np.array_equal(k.point_vectors(), [[1.0, 0.0], [5.0, 0.0]])


_RUNTIME_ONLY = """
import sys
from symkin import backends
for folder in sys.argv[1:]:
    k = backends.load(folder)
    k.gamma(k.q0 + 0.1, k.q0 + 0.2, 0.3)
    k.phi_q(k.q0, 0.0)
leaked = sorted(m for m in sys.modules if m.split(".")[0] in ("sympy", "jinja2"))
assert not leaked, leaked
print("clean")
"""


def test_runtime_imports_neither_sympy_nor_jinja2(shared_cache: Path) -> None:
    folders = [str(GENERATED / "crank_slider" / "numpy")]
    if compilers():
        symkin.compile(system("crank_slider"), "c", cache_dir=shared_cache)
        # published entries only: a hidden ".<name>.<pid>..." folder is another worker's build
        # still under way (no extension yet)
        folders += [str(p) for p in _entries(shared_cache) if "crank_slider_" in p.name
                    and "_general" not in p.name and not p.name.startswith(".")]
    result = subprocess.run([sys.executable, "-c", _RUNTIME_ONLY, *folders], cwd=ROOT,
                            capture_output=True, text=True,
                            env={**os.environ, "PYTHONPATH": str(ROOT)}, check=False)
    assert result.returncode == 0 and "clean" in result.stdout, result.stderr


@needs_cc
def test_solver_symbols_reach_python_when_present(shared_cache: Path) -> None:
    k = symkin.compile(system("crank_slider"), "c", cache_dir=shared_cache)
    exported = set(dir(k.lib))
    assert {"crank_slider_phi", "crank_slider_phi_q", "crank_slider_gamma"} <= exported
    if any((ROOT / "symkin" / "backends" / "c" / "templates").glob("solver.*.j2")):
        assert "crank_slider_solve_step" in exported


@needs_cc
@pytest.mark.parametrize("linalg", ["dense", "sparse"])
def test_lu_behind_the_solver_solves_phi_q(linalg: str, shared_cache: Path) -> None:
    """The linear algebra compiled into the kernel solves Phi_q x = b like numpy does."""
    s = system("four_bar")
    k = symkin.compile(s, "c", linalg=linalg, cache_dir=shared_cache)
    ffi, lib = k.ffi, k.lib
    rng = np.random.default_rng(3)
    lu = ffi.new(f"{k.name}_lu *")
    if hasattr(lib, f"{k.name}_lu_init"):
        getattr(lib, f"{k.name}_lu_init")(lu)
    for _ in range(5):
        q, b = k.q0 + rng.normal(0, 0.1, k.nq), rng.normal(size=k.nq)
        nz = ffi.new("double[]", k.phi_q_nz(q, 0.1).tolist())
        x = ffi.new("double[]", b.tolist())
        assert getattr(lib, f"{k.name}_lu_factor")(nz, lu) == 0
        getattr(lib, f"{k.name}_lu_solve")(lu, x)
        expected = np.linalg.solve(k.phi_q(q, 0.1), b)
        assert np.allclose(np.frombuffer(ffi.buffer(x), dtype=float), expected, rtol=1e-9,
                           atol=1e-9)


def test_cdef_is_the_generated_headers(tmp_path: Path) -> None:
    """cffi reads the headers a C user compiles against: every prototype of every header is
    in the cdef, headers come after those they include, and no comment or include is left."""
    from symkin.backends.c.cdef import from_headers

    folder = GENERATED / "crank_slider" / "c"
    files = {p.name: p.read_text(encoding="utf-8") for p in folder.iterdir() if p.is_file()}
    cdef = from_headers(files)
    assert "/*" not in cdef and "#include" not in cdef and "#ifndef" not in cdef
    assert cdef.index("typedef double crank_slider_real;") < cdef.index("crank_slider_lu;")
    assert cdef.index("crank_slider_lu;") < cdef.index("crank_slider_solve_grid(")
    for name in ("crank_slider_phi(", "crank_slider_lu_factor(", "crank_slider_solve_step("):
        assert name in cdef
    import cffi

    cffi.FFI().cdef(cdef)  # parses as C declarations

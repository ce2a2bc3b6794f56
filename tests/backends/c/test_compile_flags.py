"""The flags that only save compile time change no result: the kernel's (no dead-store
elimination) give the same machine code, a large sparse LU file at -O1 gives the same numbers
to the bit as at -O2, and the cffi wrapper (glue) is built without optimisation while every
generated file keeps its own level."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

import symkin
from symkin.backends.c import cffi_build

ROOT = Path(__file__).resolve().parents[3]
pytestmark = pytest.mark.skipif(shutil.which("gcc") is None or shutil.which("objdump") is None,
                                reason="gcc and objdump are needed")


def _machine_code(source: Path, flags: list[str], folder: Path) -> str:
    target = folder / "unit.o"
    subprocess.run(["gcc", *cffi_build.C_FLAGS, *flags, f"-iquote{source.parent}", "-c",
                    str(source), "-o", str(target)], check=True)
    listing = subprocess.run(["objdump", "-d", "--no-show-raw-insn", str(target)],
                             capture_output=True, text=True, check=True).stdout
    return listing.split("Disassembly", 1)[1]


@pytest.mark.parametrize("name", ["crank_slider", "stewart_fk", "four_bar_dynamics"])
def test_the_kernel_flags_change_no_machine_code(name: str, tmp_path: Path) -> None:
    source = ROOT / "generated" / name / "c" / f"{name}.c"
    plain = _machine_code(source, list(cffi_build.KERNEL_FLAGS), tmp_path)
    chosen = _machine_code(source, list(cffi_build._unit_flags(f"{name}.c", name, True,
                                                                 len(source.read_text()))),
                           tmp_path)
    assert chosen == plain


def test_a_large_sparse_lu_at_o1_gives_the_same_numbers(tmp_path: Path,
                                                         monkeypatch: pytest.MonkeyPatch
                                                         ) -> None:
    system = symkin.derive(ROOT / "examples" / "four_bar.yaml")
    t = np.linspace(0.0, 1.0, 201)
    default = symkin.solve(symkin.compile(system, backend="c", cache_dir=tmp_path / "a"), t=t)
    seen: list[list[str]] = []
    compile_unit = cffi_build._object

    def record(compiler: list[str], flags: list[str], source: Path) -> Path:
        if source.name.endswith("_sparse_lu.c"):
            seen.append(flags)
        return compile_unit(compiler, flags, source)

    monkeypatch.setattr(cffi_build, "_object", record)
    monkeypatch.setattr(cffi_build, "LARGE_LU_BYTES", 0)  # every sparse LU file is "large"
    large = symkin.solve(symkin.compile(system, backend="c", cache_dir=tmp_path / "b"), t=t)
    assert seen and "-O1" in seen[0] and seen[0].index("-O1") > seen[0].index("-O2")
    for a, b in ((default.q, large.q), (default.dq, large.dq), (default.d2q, large.d2q)):
        assert np.array_equal(a, b)


def test_only_the_wrapper_is_built_without_optimisation(tmp_path: Path,
                                                        monkeypatch: pytest.MonkeyPatch
                                                        ) -> None:
    system = symkin.derive(ROOT / "examples" / "crank_slider.yaml")
    t = np.linspace(0.0, 1.5, 31)
    levels: dict[str, str] = {}
    compile_unit = cffi_build._object

    def record(compiler: list[str], flags: list[str], source: Path) -> Path:
        levels[source.name] = [flag for flag in flags if flag.startswith("-O")][-1]
        return compile_unit(compiler, flags, source)

    monkeypatch.setattr(cffi_build, "_object", record)
    glue = symkin.solve(symkin.compile(system, backend="c", cache_dir=tmp_path / "a"), t=t)
    wrapper = [name for name in levels if name.startswith("_symkin_crank_slider_")]
    assert len(wrapper) == 1 and levels.pop(wrapper[0]) == "-O0"
    # the solver's step and the LU run at -O2 (the kernel at -O1: the same instructions)
    assert levels == {"crank_slider.c": "-O1", "crank_slider_solver.c": "-O2",
                      "crank_slider_sparse_lu.c": "-O2", "crank_slider_dense_lu.c": "-O2"}
    monkeypatch.setattr(cffi_build, "WRAPPER_FLAGS", ("-O2", "-fPIC"))
    optimised = symkin.solve(symkin.compile(system, backend="c", cache_dir=tmp_path / "b"),
                             t=t)
    # a module of its own: the cache key covers the wrapper's flags
    assert [levels[name] for name in levels if name.startswith("_symkin_crank_slider_")
            and name != wrapper[0]] == ["-O2"]
    for a, b in ((glue.q, optimised.q), (glue.dq, optimised.dq), (glue.d2q, optimised.d2q),
                 (glue.cond, optimised.cond)):
        assert np.array_equal(a, b)

"""The generated C folders cross-compile for a Cortex-M4 and call nothing but libm.

Skipped when the ARM toolchain is missing (Debian: gcc-arm-none-eabi).
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from codegen_support import (
    ROOT,
    STRICT_FLAGS,
    compile_object,
    example_ids,
    golden_folder,
    sources,
    undefined_symbols,
    write_sources,
)

from symkin.spec.names import LIBM_NAMES

ARM_GCC, ARM_NM = shutil.which("arm-none-eabi-gcc"), shutil.which("arm-none-eabi-nm")
pytestmark = pytest.mark.skipif(not (ARM_GCC and ARM_NM),
                                reason="arm-none-eabi-gcc/nm not installed (gcc-arm-none-eabi)")

CORTEX_M4 = ["-mcpu=cortex-m4", "-mthumb", "-mfloat-abi=hard", "-mfpu=fpv4-sp-d16", "-O2"]
ALLOWED = LIBM_NAMES | {name + "f" for name in LIBM_NAMES} | {"memset", "memcpy"}


def _cross_compile(folder: Path, out: Path) -> list[Path]:
    objects = []
    for source in sorted(folder.glob("*.c")):
        target = out / f"{source.stem}.o"
        result = compile_object(ARM_GCC, source, [*STRICT_FLAGS, *CORTEX_M4], target)
        assert result.returncode == 0, f"{source.name}:\n{result.stderr}"
        objects.append(target)
    return objects


def _undefined(objects: list[Path]) -> set[str]:
    """What the folder needs from outside: link its objects into one, then ``nm -u``."""
    combined = objects[0].parent / "folder.o"
    subprocess.run([ARM_GCC, *CORTEX_M4, "-r", "-nostdlib", "-o", str(combined),
                    *map(str, objects)], check=True)
    return undefined_symbols(ARM_NM, [combined])


@pytest.mark.parametrize("name", example_ids())
def test_double_folder_needs_only_libm(name: str, tmp_path: Path) -> None:
    undefined = _undefined(_cross_compile(golden_folder(name, "c"), tmp_path))
    # The M4's FPU is single precision: double arithmetic goes through the compiler's own
    # run-time helpers (__aeabi_d*, libgcc), which are not library calls of the generated code.
    calls = {s for s in undefined if not s.startswith("__aeabi_")}
    assert calls <= ALLOWED, f"unexpected external symbols: {sorted(calls - ALLOWED)}"


@pytest.mark.parametrize("name", example_ids())
def test_float_folder_needs_only_single_precision_libm(name: str, tmp_path: Path) -> None:
    # shared with test_generated's float folder (codegen_support.sources)
    folder = write_sources(sources(ROOT / "examples" / f"{name}.yaml", "c", real="float"),
                           tmp_path / "src")
    undefined = _undefined(_cross_compile(folder, tmp_path))
    helpers = sorted(s for s in undefined if s.startswith("__aeabi_d"))
    assert not helpers, f"double-precision soft-float helpers in float mode: {helpers}"
    assert undefined <= ALLOWED, f"unexpected external symbols: {sorted(undefined - ALLOWED)}"
    double_libm = sorted(undefined & LIBM_NAMES)
    assert not double_libm, f"double-precision libm calls in float mode: {double_libm}"


# ----- the textbook solver on an ARM core, under qemu ------------------------------------------

QEMU = shutil.which("qemu-arm")
STEPS = 31

_RUN_C = """
/* Solve the textbook grid and write q, dq, ddq as raw reals to fd 1. */
#include "crank_slider_solver.h"
#define STEPS 31
long out_write(const void *buffer, unsigned long size);
static crank_slider_real out[3][STEPS * CRANK_SLIDER_NQ];
int run(void)
{
    crank_slider_options options;
    crank_slider_state state;
    crank_slider_workspace work;
    crank_slider_report report;
    crank_slider_real t[STEPS];
    int k, n;
    for (k = 0; k < STEPS; ++k) t[k] = (crank_slider_real)0.05 * (crank_slider_real)k;
    for (k = 0; k < CRANK_SLIDER_NQ; ++k) state.q[k] = crank_slider_q0[k];
    state.started = 0;
    crank_slider_default_options(&options);
    n = crank_slider_solve_grid(&options, crank_slider_p_nominal, STEPS, t, &state,
                                out[0], out[1], out[2], &work, &report);
    out_write(out, sizeof out);
    return n == STEPS ? 0 : 1;
}
"""

# No C library start-up on the ARM side: _start calls run() and two Linux system calls
# (write, exit), which qemu's user mode serves.
_ARM_START_C = """
int run(void);
long out_write(const void *buffer, unsigned long size)
{
    register long r0 __asm__("r0") = 1;
    register long r1 __asm__("r1") = (long)buffer;
    register long r2 __asm__("r2") = (long)size;
    register long r7 __asm__("r7") = 4;
    __asm__ volatile("svc 0" : "+r"(r0) : "r"(r1), "r"(r2), "r"(r7) : "memory");
    return r0;
}
void _start(void)
{
    register long r0 __asm__("r0") = run();
    register long r7 __asm__("r7") = 1;
    __asm__ volatile("svc 0" : : "r"(r0), "r"(r7) : "memory");
    for (;;) {}
}
"""

_HOST_MAIN_C = """
#include <unistd.h>
int run(void);
long out_write(const void *buffer, unsigned long size) { return write(1, buffer, size); }
int main(void) { return run(); }
"""


def _solve(command: list[str], run: list[str], tmp_path: Path, dtype: str) -> np.ndarray:
    subprocess.run(command, check=True, cwd=tmp_path)
    result = subprocess.run(run, capture_output=True, check=False, timeout=60)
    assert result.returncode == 0, "the solver did not finish the grid"
    return np.frombuffer(result.stdout, dtype=dtype).reshape(3, STEPS, -1)


@pytest.mark.skipif(QEMU is None, reason="qemu-arm not installed")
@pytest.mark.parametrize("real", ["double", "float"])
def test_textbook_solver_on_arm_matches_the_host(real: str, tmp_path: Path) -> None:
    host_cc = shutil.which("gcc") or shutil.which("clang")
    if host_cc is None:
        pytest.skip("no host C compiler")
    # The double golden (test_generated proves it is what generate writes) and the float
    # folder the tests above share: the same files symkin.generate writes, lowered once a run.
    folder = (golden_folder("crank_slider", "c") if real == "double" else
              write_sources(sources(ROOT / "examples" / "crank_slider.yaml", "c", real="float"),
                            tmp_path / "src"))
    if not (folder / "crank_slider_solver.h").exists():
        pytest.skip("the solver runtime templates are not there yet")
    (tmp_path / "run.c").write_text(_RUN_C)
    (tmp_path / "start.c").write_text(_ARM_START_C)
    (tmp_path / "host.c").write_text(_HOST_MAIN_C)
    files = ["run.c", *map(str, sorted(folder.glob("*.c")))]
    dtype = "<f4" if real == "float" else "<f8"
    arm = _solve([ARM_GCC, *CORTEX_M4, "-std=c99", f"-I{folder}", *files, "start.c",
                  "-nostartfiles", "-static", "-lm", "-lc", "-lgcc", "-o", "arm.elf"],
                 [QEMU, str(tmp_path / "arm.elf")], tmp_path, dtype)
    host = _solve([host_cc, "-O2", "-std=c99", f"-I{folder}", *files, "host.c", "-lm",
                   "-o", "host"], [str(tmp_path / "host")], tmp_path, dtype)
    scale = float(np.max(np.abs(host)))
    # Different libm (newlib vs the host's) may differ in the last bit of sin/cos.
    tolerance = 1e-4 if real == "float" else 1e-12
    assert float(np.max(np.abs(arm - host))) <= tolerance * scale
    # The slider's x at t = 0: crank at pi/2, so x = sqrt(b^2 - (c - a)^2) (closed form).
    slider_x = host[0, 0, 6]
    assert slider_x == pytest.approx(np.sqrt(5.0**2 - (4.0 - 1.0) ** 2), rel=tolerance * 10)

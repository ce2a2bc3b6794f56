"""The worst-case operation count the solver header states, checked against counts made
independently: by hand, and by running the generated C compiled as C++ with a real type that
counts every operation it takes part in (so what is counted is what executes)."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
from pathlib import Path

import pytest

import symkin
from symkin.backends import get as get_backend
from symkin.backends.c import context, op_budget
from symkin.codegen import lower
from symkin.codegen.op_count import KINDS, Flops, count

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"

# A real type that counts: each operation on it adds one to its kind. A literal's sign and an
# operation of two literals stay double arithmetic (folded by the compiler), not counted.
COUNTED = r"""
#include <cmath>
#include <cstring>
struct Ops { unsigned long add, mul, div, sqrt, call, abs, cmp; };
static Ops ops;
struct R { double v; R() = default; R(double x) : v(x) {} };
#define BIN(op, kind) inline R operator op(R a, R b) { ops.kind++; return a.v op b.v; } \
    inline R &operator op##=(R &a, R b) { ops.kind++; a.v = a.v op b.v; return a; }
BIN(+, add) BIN(-, add) BIN(*, mul) BIN(/, div)
inline R operator-(R a) { ops.add++; return -a.v; }
inline R operator+(R a) { return a; }
#define CMP(op) inline bool operator op(R a, R b) { ops.cmp++; return a.v op b.v; }
CMP(<) CMP(>) CMP(<=) CMP(>=) CMP(==) CMP(!=)
inline R fabs(R a) { ops.abs++; return std::fabs(a.v); }
inline R sqrt(R a) { ops.sqrt++; return std::sqrt(a.v); }
#define F1(f) inline R f(R a) { ops.call++; return std::f(a.v); }
F1(sin) F1(cos) F1(tan) F1(exp) F1(log) F1(asin) F1(acos) F1(atan) F1(sinh) F1(cosh)
F1(tanh)
inline R atan2(R a, R b) { ops.call++; return std::atan2(a.v, b.v); }
inline R pow(R a, R b) { ops.call++; return std::pow(a.v, b.v); }
inline R copysign(R a, R b) { ops.call++; return std::copysign(a.v, b.v); }
static void show(const char *name, Ops o)
{
    printf("{\"name\": \"%s\", \"add\": %lu, \"mul\": %lu, \"div\": %lu, \"sqrt\": %lu, "
           "\"call\": %lu, \"abs\": %lu, \"cmp\": %lu}\n", name, o.add, o.mul, o.div, o.sqrt,
           o.call, o.abs, o.cmp);
}
#define MEASURE(name, statement) \
    do { memset(&ops, 0, sizeof ops); statement; show(name, ops); } while (0)
"""

MAIN = r"""
#include <cstdio>
#include "counted.hpp"
#include "@P@.c"
#include "@P@_dense_lu.c"
#include "@P@_sparse_lu.c"
#include "@P@_solver.c"
int main()
{
    static @P@_workspace w;
    static @P@_state s;
    @P@_options o;
    @P@_report r;
    @P@_real q[@U@_NQ], dq[@U@_NQ], out[@U@_NQ], nz[@U@_NNZ], sh[@U@_NSHARED + 1];
    int k, i, n = @STEPS@;
    @P@_default_options(&o);
    for (k = 0; k < @U@_NQ; ++k) { s.q[k] = @P@_q0[k]; }
    s.started = 0;
    for (k = 0; k < n; ++k) {
        memset(&ops, 0, sizeof ops);
        if (@P@_solve_step(&o, @P@_p_nominal, k * @DT@, &s, &w, &r) != @U@_OK) return 1;
        if (k > 0) { printf("%d ", r.iterations); show("step", ops); }
    }
    for (i = 0; i < @U@_NQ; ++i) { q[i] = s.q[i]; dq[i] = s.dq[i]; }
    MEASURE("phi_phi_q", @P@_phi_phi_q(q, 0.3, @P@_p_nominal, out, nz, sh));
    MEASURE("phi_t_shared", @P@_phi_t_shared(q, 0.3, @P@_p_nominal, sh, out));
    MEASURE("gamma_shared", @P@_gamma_shared(q, dq, 0.3, @P@_p_nominal, sh, out));
    @P@_lu_init(&w.lu);
    MEASURE("factor", @P@_lu_factor(nz, &w.lu));
    MEASURE("pivot_ratio", @P@_lu_pivot_ratio(&w.lu));
    MEASURE("solve", @P@_lu_solve(&w.lu, out));
    MEASURE("solve_transposed", @P@_lu_solve_transposed(&w.lu, out));
    o.tol_phi = -1; /* never converges: Newton runs to its cap */
    o.max_iterations = @CAP@;
    MEASURE("capped", @P@_solve_step(&o, @P@_p_nominal, n * @DT@, &s, &w, &r));
    printf("%d %d\n", r.status, r.iterations);
    return 0;
}
"""


def _measure(folder: Path, prefix: str, steps: int, dt: float, cap: int) -> list[str]:
    """Compile the generated folder as one C++ unit with the counting real type; its output."""
    header = folder / f"{prefix}.h"
    text = header.read_text()
    typedef = f"typedef double {prefix}_real;"
    assert typedef in text
    header.write_text(text.replace(typedef, f"typedef R {prefix}_real;"))
    (folder / "counted.hpp").write_text(COUNTED)
    source = (MAIN.replace("@P@", prefix).replace("@U@", prefix.upper())
              .replace("@STEPS@", str(steps)).replace("@DT@", repr(dt))
              .replace("@CAP@", str(cap)))
    (folder / "main.cpp").write_text(source)
    compiler = shutil.which("g++") or shutil.which("c++")
    if compiler is None:
        pytest.skip("no C++ compiler")
    binary = folder / "counted"
    subprocess.run([compiler, "-O0", "-w", "-Drestrict=__restrict__", "-I", str(folder),
                    str(folder / "main.cpp"), "-o", str(binary), "-lm"], check=True,
                   capture_output=True, timeout=300)
    run = subprocess.run([str(binary)], check=True, capture_output=True, text=True,
                         timeout=120)
    return run.stdout.splitlines()


def _flops(record: dict[str, int]) -> Flops:
    return Flops(**{k: record[k] for k in KINDS})


def _parse(lines: list[str]) -> tuple[list[tuple[int, Flops]], dict[str, Flops], list[int]]:
    steps, named = [], {}
    for line in lines[:-1]:
        head, _, rest = line.partition("{")
        record = json.loads("{" + rest)
        if record["name"] == "step":
            steps.append((int(head), _flops(record)))
        else:
            named[record["name"]] = _flops(record)
    return steps, named, [int(x) for x in lines[-1].split()]


def _arithmetic(f: Flops) -> tuple[int, int, int, int, int]:
    """The kinds that do not depend on which arm of a max was taken."""
    return f.add, f.mul, f.div, f.sqrt, f.call


def test_counting_of_statements_by_hand():
    assert count("q[0] - q[3] + w1") == Flops(add=2)
    assert count("-q[0]") == Flops(add=1)
    assert count("-1") == Flops()
    assert count("-2*t") == Flops(mul=1)
    assert count("(1.0/2.0)*p[0]") == Flops(mul=1)
    assert count("q[2] - (t*t) - 1.5707963267948966") == Flops(add=2, mul=1)
    assert count("v[3] -= v[1] * v[2];") == Flops(add=1, mul=1)
    assert count("x[4] *= inv[4];") == Flops(mul=1)
    assert count("fabs(a) > 1e-3 ? sin(b) : -cos(b)") == Flops(abs=1, cmp=1, call=2, add=1)
    assert count("if (!(tiny < 1.0)) return 9;") == Flops(cmp=1)
    helper = {"f_amax": Flops(abs=2, cmp=1)}
    assert count("cmax = f_amax(cmax, v[5]);", helper) == Flops(abs=2, cmp=1)


def test_crank_slider_phi_by_hand():
    """Phi of the crank-slider (Example 2.5's eq. a): per revolute joint between moving
    bodies x and y rows r_i + R_i s_A - r_j (2 additions each, R_i s_A = a (cos, sin) once
    per body: 2 calls and 2 products); the ground joint's rows are a negation each, the
    prismatic pair's a subtraction, the driver q - t^2 - pi/2 a product and 2 subtractions."""
    system = symkin.derive(symkin.load(EXAMPLES / "crank_slider.yaml"))
    code = lower.lower(system, get_backend("c"))
    by_hand = Flops(add=4 * 2 + 2 + 1 + 2, mul=2 * 2 + 1, call=4)
    assert op_budget._routine(code, "phi") == by_hand


@pytest.mark.parametrize("name, steps, dt", [("crank_slider", 31, 0.05),
                                             ("four_bar", 21, 0.05)])
def test_budget_against_counted_run(tmp_path, name, steps, dt):
    """C compiled with a counting real type: each routine's count equals the one the budget
    adds up (the kinds a max's arm does not change, exactly; fabs and compares at most);
    every step of a run, and a step that runs Newton to its cap, stays within the stated
    worst case, which the capped step reaches for the iterations' part."""
    system = symkin.derive(symkin.load(EXAMPLES / f"{name}.yaml"))
    symkin.generate(system, backend="c", out_dir=tmp_path)
    code = lower.lower(system, get_backend("c"))
    extra = context.template_context(code)
    cap = 6
    lines = _measure(tmp_path, system.name, steps, dt, cap)
    run, measured, (status, iterations) = _parse(lines)
    algebra = op_budget.sparse_lu(extra["lu"], code.nq, code.nnz, code.name)
    norm = op_budget.norm1(extra["norm1"], code.nq, code.nnz)
    expected = {"phi_phi_q": op_budget._routine(code, "phi_phi_q"),
                "phi_t_shared": op_budget._routine(code, "phi_t_shared"),
                "gamma_shared": op_budget._routine(code, "gamma_shared"),
                "factor": algebra.factor, "pivot_ratio": algebra.pivot_ratio,
                "solve": algebra.solve, "solve_transposed": algebra.solve_transposed}
    for key, value in expected.items():
        assert _arithmetic(measured[key]) == _arithmetic(value), key
        assert measured[key].abs <= value.abs and measured[key].cmp <= value.cmp, key
    # The header's numbers at the default cap, and the composition at this test's cap.
    header = (tmp_path / f"{system.name}_solver.h").read_text()
    stated = int(re.search(rf"{system.name.upper()}_OPS_STEP_WORST (\d+)", header)[1])
    assert stated == extra["ops_budget"]["step"]
    parts = op_budget.pieces(code, algebra, norm, scaled=False)
    for iterations_taken, flops in run:
        worst = op_budget.step(parts, max(iterations_taken, 1))
        assert all(getattr(flops, k) <= getattr(worst, k) for k in KINDS)
        assert flops.total <= stated
    assert (status, iterations) == (1, cap)  # NO_CONVERGENCE at the cap
    capped = measured["capped"]
    newton = parts.predictor + parts.newton(cap)
    assert _arithmetic(capped) == _arithmetic(newton)
    assert capped.total <= op_budget.step(parts, cap).total

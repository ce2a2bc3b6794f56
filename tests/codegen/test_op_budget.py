"""The worst-case operation count the solver header states, checked against counts made
independently: by hand, and by running the generated C compiled as C++ with a real type that
counts every operation it takes part in (so what is counted is what executes)."""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from codegen_support import system

from symkin.backends import get as get_backend
from symkin.backends.c import context, lu_code, op_budget
from symkin.codegen import lower, render
from symkin.codegen.op_count import KINDS, Flops, count
from symkin.contract import tuning

# A real type that counts: each operation on it adds one to its kind. A literal's sign and an
# operation of two literals stay double arithmetic (folded by the compiler), not counted.
COUNTED = r"""
#include <cmath>
#include <cstring>
struct Ops { unsigned long add, mul, div, sqrt, call, abs, cmp; };
static Ops ops;
/* zero-initialised by default, as a static C double is (a static const array of R) */
struct R { double v; R() : v(0) {} R(double x) : v(x) {} };
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
#include "@LINALG@"
#include "@P@_solver.c"
static @P@_workspace w;
static @P@_state s;
static @P@_report r;
#if @INPUTS@
#define NPU (@U@_NP + 3 * @U@_NU)
#else
#define NPU @U@_NP
#endif
static @P@_real params[NPU + 1]; /* the nominal parameters, then u0 and zero rates */
static void set_params(void)
{
    int i;
#if @U@_NP > 0
    for (i = 0; i < @U@_NP; ++i) params[i] = @P@_p_nominal[i];
#endif
    for (i = @U@_NP; i < NPU; ++i) params[i] = 0;
#if @INPUTS@
    for (i = 0; i < @U@_NU; ++i) params[@U@_NP + i] = @P@_u0[i];
#endif
}
/* One step of the run: by t, or by the inputs u = u0 + k du (positions only on odd k);
 * checked: through the public function, which checks the options first. */
static int advance(const @P@_options *o, int k, int checked)
{
#if @INPUTS@
    @P@_real u[@U@_NU], du[@U@_NU], ddu[@U@_NU];
    int i;
    for (i = 0; i < @U@_NU; ++i) { /* u in double: not counted */
        du[i] = @DT@;
        ddu[i] = 0;
        u[i] = @P@_u0[i] + k * @DT@;
    }
    return (checked ? @P@_solve_inputs : @P@_inputs_step)(o, params, u, k % 2 ? NULL : du,
                                                          k % 2 ? NULL : ddu, &s, &w, &r);
#else
    return (checked ? @P@_solve_step : @P@_step)(o, params, k * @DT@, &s, &w, &r);
#endif
}
/* The run from q0, each step's count after the first (which sets up the workspace). */
static int run(const char *name, const @P@_options *o)
{
    int k;
    for (k = 0; k < @U@_NQ; ++k) { s.q[k] = @P@_q0[k]; }
    s.started = 0;
    for (k = 0; k < @STEPS@; ++k) {
        memset(&ops, 0, sizeof ops);
        if (advance(o, k, 1) != @U@_OK) return 1;
        if (k > 0) { printf("%d %d ", r.iterations, k % 2); show(name, ops); }
    }
    return 0;
}
int main()
{
    @P@_options o;
    @P@_real q[@U@_NQ], dq[@U@_NQ], out[@U@_NQ], nz[@U@_NNZ], sh[@U@_NSHARED + 1];
    int i;
    @P@_default_options(&o);
    set_params();
    if (run("step", &o)) return 1;
    for (i = 0; i < @U@_NQ; ++i) { q[i] = s.q[i]; dq[i] = s.dq[i]; }
    MEASURE("phi_phi_q", @P@_phi_phi_q(q, 0.3, params, out, nz, sh));
    MEASURE("phi_t_shared", @P@_phi_t_shared(q, 0.3, params, sh, out));
    MEASURE("gamma_shared", @P@_gamma_shared(q, dq, 0.3, params, sh, out));
    MEASURE("norm1", @P@_norm1(nz));
    @P@_lu_init(&w.lu);
    MEASURE("factor", @P@_lu_factor(nz, &w.lu));
    MEASURE("pivot_ratio", @P@_lu_pivot_ratio(&w.lu));
    MEASURE("solve", @P@_lu_solve(&w.lu, out));
    MEASURE("solve_transposed", @P@_lu_solve_transposed(&w.lu, out));
    MEASURE("hager", @P@_inverse_norm1(&w.lu));
    MEASURE("worst_column", @P@_worst_column(&w.lu, out));
    w.estimated_inv_norm = -1;
    MEASURE("estimate", @P@_estimate(&w, &r));
    w.correction = -1;
    {   /* the model at its longest: its cheap bound fails (a large max |q|: q's target is
         * max(1, |q|) times target_q, which the bound does not count on) and every target
         * is met, so both run through */
        @P@_options wide = o;
        wide.target_dq = wide.target_ddq = 1e300;
        @P@_region_for(&wide, &w); /* other targets: as a call, without the run's region */
        MEASURE("flagged", @P@_flagged(&wide, &w, &r, 1e30, 1, 1, 2));
    }
    {   /* the refined model at its longest: the norm bound flags (ddq's target 0), the
         * propagated model runs to its end, q and dq pass, ddq fails: every comparison */
        @P@_options late = o;
        @P@_real ddq[@U@_NQ];
        for (i = 0; i < @U@_NQ; ++i) ddq[i] = s.ddq[i];
        late.target_q = late.target_dq = 1e300;
        late.target_ddq = 0;
        @P@_region_for(&late, &w);
        MEASURE("refined", @P@_flagged_refined(&late, &w, &r, 1, 1, 1, q, dq, ddq, 0.3,
                                               params));
    }
#if @INPUTS@
    {   /* the simplified Newton steps from q moved off the last solution, on its factors */
        int taken;
        @P@_real predicted[@U@_NQ], first;
        for (i = 0; i < @U@_NQ; ++i) q[i] = s.q[i] + 1e-4 * (i % 3 + 1);
        memset(&ops, 0, sizeof ops);
        taken = @P@_chord(params, s.t, q, &w, predicted, &first);
        printf("%d ", taken);
        show("chord", ops);
        MEASURE("branch_jump", @P@_branch_jump(&w, q, predicted, first, 1));
    }
#else
    {   /* the extra iterations at their longest: q moved off the solution, every point
         * flagged, so Newton goes on (its step halving) for all TIGHTEN_STEPS */
        @P@_options more = o;
        more.tighten_cond = 1e300;
        more.target_q = more.target_dq = 1e300; /* the model's last test flags: all run */
        more.target_ddq = 0;
        for (i = 0; i < @U@_NQ; ++i) q[i] = s.q[i] + 0.01 * (i % 3 + 1);
        @P@_phi_phi_q(q, s.t, params, w.phi, w.nz, w.shared);
        @P@_lu_factor(w.nz, &w.lu);
        r.residual = @P@_max_abs(w.phi);
        @P@_region_for(&more, &w);
        MEASURE("converged", @P@_converged(&more, params, s.t, q, INFINITY, &w, &r));
    }
#endif
    /* every point flagged, Newton going on at every point: the checks at their most */
    o.tighten_cond = 0;
    o.target_q = o.target_dq = o.target_ddq = 1e-300; /* (0 is refused: BAD_OPTIONS) */
    if (run("flagged_step", &o)) return 1;
    o.tol_phi = -1; /* never converges: Newton runs to its cap (past the options' check) */
    o.max_iterations = @CAP@;
    MEASURE("capped", advance(&o, @STEPS@, 0));
    printf("%d %d\n", r.status, r.iterations);
    return 0;
}
"""


def _measure(folder: Path, code: lower.Code, steps: int, dt: float, cap: int) -> list[str]:
    """Compile the generated folder as one C++ unit with the counting real type; its output."""
    prefix = code.name
    header = folder / f"{prefix}.h"
    text = header.read_text()
    typedef = f"typedef double {prefix}_real;"
    assert typedef in text
    header.write_text(text.replace(typedef, f"typedef R {prefix}_real;"))
    (folder / "counted.hpp").write_text(COUNTED)
    linalg = f"{prefix}_sparse_lu.c" if code.lu_plan is not None else f"{prefix}_linalg.c"
    u0 = ", ".join(repr(float(v)) for v in code.input_values) or "0"
    source = (MAIN.replace("@P@", prefix).replace("@U@", prefix.upper())
              .replace("@STEPS@", str(steps)).replace("@DT@", repr(dt))
              .replace("@CAP@", str(cap)).replace("@LINALG@", linalg)
              .replace("@INPUTS@", "1" if code.input_names else "0"))
    source = source.replace("static " + prefix + "_workspace w;",
                            f"static const double {prefix}_u0[] = {{ {u0} }};\n"
                            f"static {prefix}_workspace w;")
    (folder / "main.cpp").write_text(source)
    compiler = _gxx()
    binary = folder / "counted"
    subprocess.run([compiler, "-O0", "-w", "-Drestrict=__restrict__", "-I", str(folder),
                    str(folder / "main.cpp"), "-o", str(binary), "-lm"], check=True,
                   capture_output=True, timeout=300)
    run = subprocess.run([str(binary)], check=True, capture_output=True, text=True,
                         timeout=120)
    return run.stdout.splitlines()


def _gxx() -> str:
    """g++, for the counting harness; without it the test skips, unless SYMKIN_REQUIRE_TOOLS
    names g++ (CI installed it: then its absence is an error)."""
    found = shutil.which("g++")
    if found is None:
        if "g++" in os.environ.get("SYMKIN_REQUIRE_TOOLS", "").split():
            pytest.fail("g++ is required (SYMKIN_REQUIRE_TOOLS) but not found")
        pytest.skip("g++ is not installed (Debian: apt install g++)")
    return found


def _flops(record: dict[str, int]) -> Flops:
    return Flops(**{k: record[k] for k in KINDS})


def _parse(lines: list[str]) -> tuple[dict[str, list[tuple[int, int, Flops]]],
                                      dict[str, Flops], dict[str, int], list[int]]:
    """(the runs' steps: iterations, odd step, count; the single calls; the steps a single
    call reported taking; status, iterations of the capped step)."""
    runs: dict[str, list[tuple[int, int, Flops]]] = {}
    named = {}
    taken = {}
    for line in lines[:-1]:
        head, _, rest = line.partition("{")
        record = json.loads("{" + rest)
        numbers = [int(x) for x in head.split()]
        if len(numbers) == 2:  # a step of a run
            runs.setdefault(record["name"], []).append((*numbers, _flops(record)))
        else:
            named[record["name"]] = _flops(record)
            if numbers:
                taken[record["name"]] = numbers[0]
    return runs, named, taken, [int(x) for x in lines[-1].split()]


def _arithmetic(f: Flops) -> tuple[int, int, int, int, int]:
    """The kinds that do not depend on which arm of a max was taken."""
    return f.add, f.mul, f.div, f.sqrt, f.call


def _within(measured: Flops, bound: Flops) -> bool:
    return all(getattr(measured, k) <= getattr(bound, k) for k in KINDS)


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
    code = lower.lower(system("crank_slider"), get_backend("c"))
    by_hand = Flops(add=4 * 2 + 2 + 1 + 2, mul=2 * 2 + 1, call=4)
    assert op_budget._routine(code, "phi") == by_hand


def _home_legs() -> tuple[float, ...]:
    """The Stewart platform's leg lengths at its home pose (examples/stewart_fk.yaml: base
    radius 1, platform radius 0.6 at height 1, a leg's two joints 110 or 10 degrees apart
    about the axis), by the law of cosines: the inputs the run starts from."""
    apart = np.radians([110, 10] * 3)
    return tuple(float(v) for v in np.sqrt(1 + 0.6**2 + 1 - 2 * 0.6 * np.cos(apart)))


@pytest.mark.parametrize("name, linalg", [("crank_slider", "sparse"), ("four_bar", "sparse"),
                                          ("crank_slider", "dense"),
                                          ("crank_slider_input", "sparse"),
                                          ("stewart_fk", "sparse"),
                                          ("four_bar", "tables")])
def test_budget_against_counted_run(tmp_path, monkeypatch, name, linalg):
    """C compiled with a counting real type: each routine's count equals the one the budget
    adds up (the kinds a max's arm does not change, exactly; fabs and compares at most);
    every step of a run (also with every point flagged and Newton going on at each) stays
    within the worst case for its iterations and within the header's number; a step that runs
    Newton to its cap does exactly the predictor and iterations the budget counts (solve_inputs:
    the iterations exactly, its simplified Newton steps, which stop on the data, within their
    count)."""
    derived = system(name)  # derived once per run (codegen_support)
    if linalg == "tables":  # the sparse LU as loops over index tables, as for a large system
        monkeypatch.setattr(lu_code, "TABLE_FLOPS", 0)
        linalg = "sparse"
    # what symkin.generate(derived, "c", tmp_path, linalg=linalg) does, from one lowering
    code = lower.lower(derived, get_backend("c"), {"linalg": linalg})
    render.write(code, tmp_path)
    extra = context.template_context(code)
    if name == "stewart_fk":  # its file's q0 is the home pose; the inputs start there
        assert np.allclose(code.input_values, _home_legs(), rtol=1e-12, atol=0)
    cap, steps = 6, 31
    dt = 0.002 if name == "stewart_fk" else 0.05  # the legs lengthen 2 mm a step
    runs, measured, taken, (status, iterations) = _parse(
        _measure(tmp_path, code, steps, dt, cap))
    n, nnz = code.nq, code.nnz
    algebra = (op_budget.sparse_lu(extra["lu"], n, nnz, code.name) if linalg == "sparse"
               else op_budget.dense_lu(n, nnz))
    norm = op_budget.norm1(extra["norm1"], n, nnz)
    exact = {"phi_phi_q": op_budget._routine(code, "phi_phi_q"),
             "phi_t_shared": op_budget._routine(code, "phi_t_shared"),
             "gamma_shared": op_budget._routine(code, "gamma_shared"),
             "norm1": norm, "flagged": op_budget.FLAGGED,
             "solve": algebra.solve, "solve_transposed": algebra.solve_transposed,
             "estimate": op_budget._estimate(algebra, norm, n, nnz)}
    at_most = {"factor": algebra.factor, "pivot_ratio": algebra.pivot_ratio,
               "hager": op_budget._hager(algebra, n),
               "worst_column": op_budget.worst_column(algebra, n)}
    if code.input_names:  # the steps stop once they reach rounding or stop contracting
        at_most["chord"] = op_budget.chord(code, algebra)
        exact["branch_jump"] = op_budget.branch_jump(n)  # after a step: both tests made
        assert 1 <= taken["chord"] <= tuning.CHORD_STEPS
    if linalg == "sparse":  # every operation runs, whatever the values
        exact.update(factor=at_most.pop("factor"), pivot_ratio=at_most.pop("pivot_ratio"))
    if algebra.exact_inverse is None:  # Hager's estimate: its ascent may stop early
        at_most["estimate"] = exact.pop("estimate")
    for key, value in exact.items():
        assert _arithmetic(measured[key]) == _arithmetic(value), key
        assert _within(measured[key], value), key
    for key, value in at_most.items():
        assert _within(measured[key], value), key
    if "converged" in measured:  # TIGHTEN_STEPS extra iterations, estimates before, after
        parts = op_budget.pieces(code, algebra, norm, scaled=False)
        converged = parts.converged(op_budget.WOULD_FLAG + op_budget.Flops(cmp=3))
        assert _within(measured["converged"], converged)
        if algebra.exact_inverse is not None:
            # where the Newton correction was solved for, the model reads it instead of
            # ||Phi_q^-1|| times the residual: one product fewer, at the first test of each
            # extra iteration
            fewer = op_budget.Flops(mul=tuning.TIGHTEN_STEPS)
            assert _arithmetic(measured["converged"] + fewer) == _arithmetic(converged)
    # the refined model: every operation but its worst column's ascent, which may stop early
    ascent = measured["worst_column"] + op_budget.worst_column(algebra, n) * -1
    refined = op_budget.refined(code, algebra, units=False) + ascent
    assert _arithmetic(measured["refined"]) == _arithmetic(refined)
    assert _within(measured["refined"], op_budget.refined(code, algebra, units=False))
    inputs = bool(code.input_names)
    header = (tmp_path / f"{derived.name}_solver.h").read_text()
    stated = int(re.search(rf"{derived.name.upper()}_OPS_STEP_WORST (\d+)", header)[1])
    budget = extra["ops_budget"]
    assert stated == budget["step"]
    for run in ("step", "flagged_step"):
        assert len(runs[run]) == steps - 1
        for iterations_taken, odd, flops in runs[run]:
            rates = not (inputs and odd)
            parts = op_budget.pieces(code, algebra, norm, scaled=False, inputs=inputs,
                                     rates=rates)
            assert _within(flops, op_budget.step(parts, max(iterations_taken, 1), rates))
            limit = stated if not inputs else budget["inputs" if rates else "positions"]
            assert flops.total <= limit
    assert status == 1  # NO_CONVERGENCE at the cap
    parts = op_budget.pieces(code, algebra, norm, scaled=False, inputs=inputs)
    newton = parts.predictor + parts.newton(cap)
    assert _within(measured["capped"], newton)
    if inputs:  # the simplified steps taken first count as iterations too
        assert cap <= iterations <= cap + tuning.CHORD_STEPS
    else:
        assert iterations == cap
    if linalg == "sparse" and not inputs:
        assert _arithmetic(measured["capped"]) == _arithmetic(newton)
    if linalg == "sparse" and inputs:  # Newton's iterations exactly, the simplified steps more
        steps_taken = measured["capped"] + parts.newton(cap) * -1
        assert min(_arithmetic(steps_taken)) >= 0 and _within(steps_taken, parts.predictor)

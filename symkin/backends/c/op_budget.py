"""The worst-case operation count of one step of the generated C solver, for its header.

An embedded engineer budgets a servo period by the most a call can cost. The straight-line
pieces (the kernel routines, the sparse LU's factor and solves, the exact inverse norm and
||Phi_q||_1) are counted from the statements the templates render (codegen.op_count); the
solver's own loops (templates/solver.c.j2 and its partials) are counted here per call,
each formula next to the name of the function it mirrors, taking every branch that adds
work (the worst case). Composition, as ``<prefix>_solve_step`` runs:

    options check + predictor + (cap + 1) x evaluation + cap x Newton update
    + convergence checks
    (condition, up to TIGHTEN_STEPS extra iterations, condition again)
    + velocity + acceleration + per-point checks (norms, error model).

The error model at its worst is the norm bound flagging the point and the propagated model
run to its end (Hager's worst column, Phi_q and Phi_t at q moved along it, Gamma, two
solves). ``<prefix>_solve_inputs`` has no predictor but up to CHORD_STEPS simplified Newton
steps on the last factors (Phi and a solve each) before Newton. The sparse factor's run-time
row interchanges are counted from their statements (a comparison of two magnitudes each).

The cap is ``options.max_iterations`` (its default here; the header gives the cost of one
iteration so that another cap can be budgeted). The unit-scaling passes count where the
mechanism is scale-free (options.unit != 1). The dense fall-back's worst case replaces every
sparse factorization by a failed sparse attempt and the dense LU, every solve by dense
substitution, and the exact inverse norm by Hager's estimate.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from symkin.codegen.op_count import ZERO, Flops, count, count_all
from symkin.contract import lengths, options, tuning


def _routine(code: Any, name: str) -> Flops:
    """One call of a kernel routine: its temporaries and outputs, every part."""
    routine = code.routine(name)
    return sum((count_all([text for _, text in part.temporaries]) for part in routine.parts),
               ZERO) + count_all(routine.outputs)


def _max_abs(n: int) -> Flops:
    """<prefix>_max_abs: |v_i|, a branch-free max and a sum per entry, the NaN test."""
    return Flops(abs=n, cmp=n + 1, add=n)


def _max_in_unit(n: int) -> Flops:
    """<prefix>_norm_if (solve_inputs): _max_abs of |v_i| / column_i (a product each)."""
    return _max_abs(n) + Flops(mul=n)


@dataclass(frozen=True)
class LinearAlgebra:
    """The cost of one call of each LU routine the solver makes."""

    factor: Flops  # lu_factor, its pivot tests included
    pivot_ratio: Flops
    solve: Flops
    solve_transposed: Flops
    exact_inverse: Flops | None  # the straight-line ||Phi_q^-1||_1, where generated


def dense_lu(n: int, nnz: int) -> LinearAlgebra:
    """templates/dense_lu.c.j2 at its worst: every row swept and updated (a full matrix)."""
    factor = Flops(abs=2 * nnz, cmp=nnz, mul=1)  # the scatter with max |a| and the tiny bound
    for k in range(n):
        r = n - k - 1  # rows below the pivot, columns right of it
        # search (|a| twice on a new best), tests, spread, 1 / pivot, used columns,
        # multipliers with their zero test, the Schur update
        factor += Flops(abs=1 + 2 * r, cmp=3 * r + 3, div=1, mul=r + r * r, add=r * r)
    factor += Flops(cmp=1, div=1)  # the pivot spread
    triangle = Flops(mul=n * (n - 1) // 2, add=n * (n - 1) // 2)
    solve = triangle * 2 + Flops(mul=n)
    return LinearAlgebra(factor=factor, pivot_ratio=ZERO, solve=solve,
                         solve_transposed=solve, exact_inverse=None)


def _amax_helpers(prefix: str) -> dict[str, Flops]:
    """The helpers the straight-line factor calls (templates/sparse_lu.c.j2)."""
    return {f"{prefix}_lu_amax": Flops(abs=2, cmp=1),  # fabs(b) > a ? fabs(b) : a
            f"{prefix}_lu_pivot_ok": Flops(abs=2, cmp=2, mul=1)}


def sparse_lu(lu: dict[str, Any], n: int, nnz: int, prefix: str) -> LinearAlgebra:
    """templates/sparse_lu.c.j2 as rendered from ``lu`` (backends.c.lu_code's context)."""
    if lu["style"] == "tables":
        return _sparse_tables(lu, n, nnz)
    helpers = _amax_helpers(prefix)
    steps = [s for part in lu["factor_parts"] for s in part["steps"]]
    load = Flops(abs=1, cmp=1, add=2) * len(lu["loaded"]) + Flops(mul=1, add=1)
    factor = load + Flops(cmp=1 if lu["tiny_check"] else 0) + count_all(
        [line for s in steps for line in s["factor"]], helpers)
    variable = len(lu["variable_pivots"])
    if variable == n:
        ratio = Flops(abs=n, cmp=2 * (n - 1))
    else:
        ratio = Flops(abs=4 * variable, cmp=2 * variable)
    ratio += Flops(cmp=1, div=1)  # high > 0 ? low / high : 0

    def lines(key: str) -> list[str]:
        return [line for part in lu[f"{key}_parts"] for s in part["steps"] for line in s[key]]

    inverse = lu.get("inverse")
    return LinearAlgebra(
        factor=factor, pivot_ratio=ratio, solve=count_all(lines("forward") + lines("backward")),
        solve_transposed=count_all(lines("upper_t") + lines("lower_t")),
        exact_inverse=_exact_inverse(inverse) if inverse else None)


def _sparse_tables(lu: dict[str, Any], n: int, nnz: int) -> LinearAlgebra:
    """The table-driven loops: every operation of the plan, no number folded in."""
    tables = lu["tables"]
    lower = len(tables["lower"]) // 2 - 1  # each table ends in one zero record
    upper = len(tables["upper"]) // 2 - 1
    updates = len(tables["update"]) // 3 - 1
    load = Flops(abs=nnz, cmp=nnz, add=2 * nnz) + Flops(mul=1, add=1)
    factor = load + Flops(abs=3 * n + 2 * lower, cmp=lower + 2 * n, mul=n + lower + updates,
                          div=n, add=updates)
    ratio = Flops(abs=n, cmp=2 * (n - 1) + 1, div=1)
    solve = Flops(mul=lower + upper + n, add=lower + upper)
    return LinearAlgebra(factor=factor, pivot_ratio=ratio, solve=solve,
                         solve_transposed=solve, exact_inverse=None)


def _exact_inverse(inverse: dict[str, Any]) -> Flops:
    """<prefix>_inverse_norm1_exact: its temporaries, then per column sum |.|, the finite
    test and the max; then the finite test of all."""
    sums = sum((count(s) + Flops(add=2, cmp=1) for s in inverse["sums"]), ZERO)
    return count_all(inverse["lines"]) + sums + Flops(cmp=1)


def norm1(context: dict[str, Any] | None, n: int, nnz: int) -> Flops:
    """<prefix>_norm1: the straight-line column sums (each with its max), or the loop."""
    if context is None:
        return Flops(abs=nnz, add=nnz, cmp=n)
    return sum((count(expression) + Flops(cmp=1) for part in context["parts"]
                for _, expression in part), ZERO)


# ----- the solver's own work (templates/solver.c.j2, _condition, _error_model, _units) -----

UNROLLED = 16
"""Coordinates up to which the solver's element-wise passes are written out
(templates/_each.j2): there a coordinate that is no length is not divided by its unit."""

# <prefix>_within_bound, the model's cheap bound: the rounding floor, e_q, x = s (u + e_q),
# max(1, |dq|), the three bounds and their four tests.
BOUND = Flops(mul=10, add=4, cmp=6)
# <prefix>_covered: whether a point lies in the region where the bound was proven (the
# correction, the norm of the inverse, the residual, two norms, the condition).
REGION = Flops(cmp=6)
# <prefix>_widen, where the bound held: the corner (the inverse's norm and two norms grown,
# each norm at least 1, s, twice them plus one), the largest residual the three targets allow
# there (the margin, its quotients, the smaller of two, the unit roundoff, halved), its tests
# and the bound at the corner.
WIDEN = (Flops(mul=3, cmp=2) + Flops(sqrt=1, div=1) + Flops(mul=2, add=2)
         + Flops(cmp=1, mul=1) + Flops(div=2, mul=4, add=2) + Flops(cmp=2, div=5, add=1)
         + Flops(cmp=6, mul=2) + BOUND)
# <prefix>_region_for: the three targets against the region's, once a call.
REGION_TARGETS = Flops(cmp=3)
# <prefix>_flagged: s = inv_norm / sqrt(NQ) and the residual's error, the region, the bound,
# then (where it fails) e_dq, e_ddq and the three comparisons with the targets; where it
# holds, a region is proven instead (WIDEN, counted with the step's checks).
FLAGGED = Flops(sqrt=1, div=1, mul=1, cmp=1) + REGION + BOUND + Flops(mul=15, add=5, cmp=8)
# <prefix>_would_flag: the residual against the rounding level, s and the residual's error,
# the bound at the widened norms (twice the last, plus one), then the model (its own bound
# again); before it, once a step, whether the region clears the point (the region's
# comparisons: counted here, at each call).
WOULD_FLAG = Flops(add=1, mul=1, cmp=1) + Flops(mul=2, add=2) + BOUND + FLAGGED + REGION
# <prefix>_position_error: s, the residual's error, the rounding floor and their max.
POSITION_ERROR = Flops(sqrt=1, div=1, mul=3, add=1, cmp=2)
# <prefix>_flagged_refined around its calls: s, e_dq, e_ddq, the three finite tests and the
# three comparisons with the targets (each with its at_least_1).
REFINED = Flops(sqrt=1, div=1, mul=7, add=5, cmp=9)
# <prefix>_check_options at the top of every solve: per field of contract.options.RULES its
# comparisons and, where it must be finite, the x - x == 0 test (max_iterations is an int).
_RULE_OPS = {"positive finite": Flops(add=1, cmp=2), "positive": Flops(cmp=1),
             "non-negative": Flops(cmp=1), "ratio": Flops(cmp=2), "count": ZERO}
OPTIONS_CHECK = sum((_RULE_OPS[rule] for rule in options.RULES.values()), ZERO)


def worst_column(algebra: LinearAlgebra, n: int) -> Flops:
    """<prefix>_worst_column with every ascent step taken: the first solve and its sum, then
    per step the sign vector, a transposed solve, the largest |z_i| (a new one at every i
    after the first), z . x (a division at the first step), a solve and its sum."""
    first = algebra.solve + Flops(abs=n, add=n)
    ascent = (algebra.solve_transposed + algebra.solve
              + Flops(add=1 + 2 * n, cmp=3 + 2 * n, abs=3 * n))
    return first + ascent * (tuning.ESTIMATOR_STEPS - 1) + Flops(div=1)


def propagated(code: Any, algebra: LinearAlgebra, units: bool) -> Flops:
    """<prefix>_propagated through to its end: the worst column and its max, q moved along
    it, Phi_q and Phi_t there times dq, a solve; dq shifted, Gamma and Phi_q ddq, a solve."""
    n, nnz = code.nq, code.nnz
    times = Flops(mul=nnz, add=nnz)  # <prefix>_jacobian_times
    scale = Flops(div=n, mul=n)  # v[i] * (a / b), or v[i] *= a / b
    from_unit = Flops(mul=n) if units else ZERO
    rows_in_unit = Flops(div=n) if units else ZERO
    # the finite-difference step: sqrt of the unit roundoff, a constant the compiler folds
    start = Flops(mul=1, add=1) + worst_column(algebra, n) + _max_abs(n)
    start += Flops(cmp=4, add=1)  # largest or size zero; both finite, size positive
    velocity = (scale + from_unit + Flops(add=n) + _routine(code, "phi_q")
                + _routine(code, "phi_t") + times + rows_in_unit + algebra.solve
                + scale + Flops(add=n) + _max_abs(n))  # rows *= -size / step
    acceleration = (scale + from_unit + Flops(add=n) + _routine(code, "gamma")
                    + Flops(add=n) + times + rows_in_unit + algebra.solve + scale
                    + _max_abs(n))
    return start + velocity + acceleration


def refined(code: Any, algebra: LinearAlgebra, units: bool) -> Flops:
    """<prefix>_flagged_refined at its longest: the norm bound flags the point, the
    propagated model runs to its end and every comparison is made."""
    return REFINED + FLAGGED + POSITION_ERROR + propagated(code, algebra, units)


def branch_jump(n: int) -> Flops:
    """<prefix>_branch_jump (solve_inputs): the sign of det(Phi_q) from the factors (per pivot
    the zero, finite and sign tests; the interchanges and the dense path's permutation are
    integers), then |q - (q_last + s)| / column and its max, the floor and the bound."""
    sign = Flops(cmp=3 * n, add=n)
    remainder = Flops(add=n, abs=n, mul=n, cmp=n)
    return sign + remainder + Flops(add=2, mul=2, cmp=3)


def chord(code: Any, algebra: LinearAlgebra, scaled: bool = False) -> Flops:
    """<prefix>_chord (solve_inputs) with all CHORD_STEPS taken: the rounding level, then per
    step Phi (its rows in the run's unit when ``scaled``), the negated solve, its max, the
    contraction test, the step back in the kernel's unit, q += step and the two stopping
    tests."""
    n = code.nq
    units = Flops(div=n, mul=n) if scaled else ZERO
    one = (_routine(code, "phi") + Flops(add=n) + algebra.solve + _max_abs(n) + units
           + Flops(mul=1, cmp=1) + Flops(add=n) + Flops(cmp=2, mul=1, div=1))
    return Flops(mul=1, add=1) + one * tuning.CHORD_STEPS


@dataclass(frozen=True)
class Pieces:
    """The cost of one call of each piece of a step (what the header lists)."""

    evaluation: Flops  # Phi and Phi_q (fused), the residual, the factorization and its tests
    update: Flops  # the Newton step: a solve and q += dq
    estimate: Flops  # the condition at the converged q
    tighten: Flops  # one extra Newton iteration at an ill-conditioned point
    velocity: Flops
    acceleration: Flops
    checks: Flops  # max |q|, |dq|, |ddq| and the error model at its worst
    predictor: Flops  # solve_step's prediction, or solve_inputs' simplified Newton steps

    def newton(self, cap: int) -> Flops:
        return self.evaluation * (cap + 1) + self.update * cap

    def converged(self, checks: Flops) -> Flops:
        """<prefix>_converged: estimate, up to TIGHTEN_STEPS extra iterations, estimate."""
        return (self.estimate * 2 + checks + self.tighten * tuning.TIGHTEN_STEPS)


def _hager(algebra: LinearAlgebra, n: int) -> Flops:
    """<prefix>_inverse_norm1 at its worst: every ascent step taken, with the full dot
    product (a non-finite entry)."""
    first = algebra.solve + Flops(abs=n, add=n)  # Higham's test vector
    ascent = algebra.solve + Flops(abs=n, add=2 * n, call=n)
    ascent += Flops(add=1, cmp=2) + algebra.solve_transposed + Flops(abs=1 + n, add=2 * n,
                                                                     cmp=2 * n)
    dot = Flops(cmp=2, mul=n, add=n)
    steps = tuning.ESTIMATOR_STEPS
    return first + ascent * steps + dot * (steps - 1) + Flops(mul=1, div=1, add=1, cmp=2)


def _estimate(algebra: LinearAlgebra, norm: Flops, n: int, nnz: int) -> Flops:
    """<prefix>_estimate: the exact norm where generated, else the reuse test and a fresh
    Hager estimate; then cond = ||Phi_q^-1||_1 ||Phi_q||_1."""
    cond = norm + Flops(mul=1)
    if algebra.exact_inverse is not None:
        return algebra.exact_inverse + cond
    # theta: <prefix>_difference_norm1 (column sums, their finite test and max), the test
    reuse = Flops(mul=1, abs=nnz, add=2 * nnz + 2 * n, cmp=n + 3)
    return reuse + _hager(algebra, n) + cond


def pieces(code: Any, algebra: LinearAlgebra, norm: Flops, scaled: bool,
           inputs: bool = False, rates: bool = True) -> Pieces:
    """The pieces of ``<prefix>_solve_step`` (``inputs``: of ``<prefix>_solve_inputs``, whose
    predictor is its simplified Newton steps; ``rates`` False: du, ddu NULL). Both decide in
    options.unit when ``scaled``."""
    n, nnz = code.nq, code.nnz
    units = scaled
    in_unit = Flops(div=n, mul=nnz) if units else ZERO
    rows_in_unit = Flops(div=n) if units else ZERO
    from_unit = Flops(mul=n) if units else ZERO
    factor = algebra.factor + algebra.pivot_ratio + Flops(cmp=1)  # factor_jacobian
    fused = _routine(code, "phi_phi_q") + in_unit + _max_abs(n)
    evaluation = fused + Flops(add=1, cmp=1) + factor + Flops(cmp=2)
    # Newton's step: Phi_q x = Phi solved in place, its max, q -= x (no negation)
    update = algebra.solve + _max_abs(n) + from_unit + Flops(add=n)
    tighten = (update + Flops(add=n) + Flops(add=1, cmp=1) + WOULD_FLAG * 2 + Flops(cmp=2, div=1)
               + fused + factor)
    estimate = _estimate(algebra, norm, n, nnz)
    solve = rows_in_unit + algebra.solve + from_unit
    velocity = _routine(code, "phi_t_shared") + solve  # negated as the solve writes it
    acceleration = _routine(code, "gamma_shared") + solve
    if inputs:  # max |q|, |dq|, |ddq| (norm_if: each when solved for), the finite tests;
        # solve_inputs' first test: no length input below zero
        norms = (_max_in_unit(n) * (1 + 2 * rates) + Flops(add=2, cmp=2) + branch_jump(n)
                 + Flops(cmp=len(getattr(code, "input_lengths", ()))))
    else:  # the norms of dq and ddq, taken by the two solves as they write them (max, sum;
        # dq negated; at most: an entry that is +-0 whatever the factors is not taken,
        # rhs_zeros), a pass over q (max, sum; written out, the lengths' largest |q_i|
        # divided by the unit once and taken into the max), q's NaN test, the finite test of
        # dq and ddq (the larger maximum, the two sums added and tested, the infinity test);
        # then whether Newton's bound cleared the point (work->clear)
        divided = 1 if any(lengths.length_columns(code.coordinates)) else 0
        if n > UNROLLED:  # the loop divides every q_i
            divided += n
        norms = (Flops(abs=3 * n, mul=divided, cmp=3 * n, add=4 * n) + Flops(cmp=1)
                 + Flops(cmp=1) + Flops(cmp=3, add=3) + Flops(cmp=2))
    prediction = Flops(add=1, mul=1, div=1) + Flops(mul=2, add=2) * n  # (2.76), h^2 / 2 once
    predictor = chord(code, algebra, units) if inputs else prediction
    return Pieces(evaluation=evaluation, update=update, estimate=estimate,
                  tighten=tighten, velocity=velocity, acceleration=acceleration,
                  checks=norms + refined(code, algebra, units) + WIDEN * 2,
                  predictor=predictor)


def step(parts: Pieces, cap: int, rates: bool = True) -> Flops:
    """The worst case of one step with Newton capped at ``cap`` iterations; ``rates`` False:
    positions only (``<prefix>_solve_inputs`` with du, ddu NULL)."""
    convergence = parts.converged(Flops(cmp=3) + WOULD_FLAG)
    kinematics = parts.velocity + parts.acceleration if rates else ZERO
    return (OPTIONS_CHECK + REGION_TARGETS + parts.predictor + parts.newton(cap) + convergence
            + kinematics + parts.checks)


@dataclass(frozen=True)
class Budget:
    """What the header states: per-iteration cost, fixed part and worst cases by kind."""

    cap: int
    iteration: Flops  # one Newton iteration: evaluation + update
    fixed: Flops  # the rest of a step: worst(cap) = fixed + cap x iteration
    step: Flops  # solve_step's worst case at the default cap
    pieces: Pieces
    positions: Flops | None  # solve_inputs with du, ddu NULL (input mechanisms only)
    inputs: Flops | None  # solve_inputs with rates and accelerations
    chord: Flops | None  # solve_inputs' simplified Newton steps, all taken (its predictor)
    dense_step: Flops  # solve_step's worst case on the dense LU (fall-back or --linalg dense)


def budget(code: Any, lu: dict[str, Any] | None, norm1_context: dict[str, Any] | None,
           scaled: bool, cap: int) -> Budget:
    """The worst-case operation counts of one step of the generated solver.

    Args:
        code: the lowered mechanism (codegen.lower.Code).
        lu: the sparse LU's template context (None: --linalg dense).
        norm1_context: the straight-line ||Phi_q||_1 (None: the loop over the non-zeros).
        scaled: whether options.unit rescales the solve (the mechanism is scale-free).
        cap: the iteration cap of the default options.
    """
    n, nnz = code.nq, code.nnz
    norm = norm1(norm1_context, n, nnz)
    dense = dense_lu(n, nnz)
    algebra = sparse_lu(lu, n, nnz, code.name) if lu else dense
    if lu:  # the fall-back: a sparse attempt that fails at its last pivot, then dense
        fallback = LinearAlgebra(factor=algebra.factor + dense.factor, pivot_ratio=ZERO,
                                 solve=dense.solve, solve_transposed=dense.solve_transposed,
                                 exact_inverse=None)
    else:
        fallback = dense
    parts = pieces(code, algebra, norm, scaled)
    worst = step(parts, cap)
    iteration = parts.evaluation + parts.update
    inputs = positions = chord_steps = None
    if code.input_names:
        inputs_parts = pieces(code, algebra, norm, scaled, inputs=True)
        inputs, chord_steps = step(inputs_parts, cap), inputs_parts.predictor
        positions = step(pieces(code, algebra, norm, scaled, inputs=True, rates=False), cap,
                         rates=False)
    return Budget(cap=cap, iteration=iteration, fixed=worst + iteration * -cap, step=worst,
                  pieces=parts, positions=positions, inputs=inputs, chord=chord_steps,
                  dense_step=step(pieces(code, fallback, norm, scaled), cap))


def header_lines(plan: Budget) -> list[str]:
    """The comment block of ``<prefix>_solver.h`` (lines without the comment markers)."""
    def kinds(f: Flops) -> str:
        return (f"{f.total} ({f.add} add/sub, {f.mul} mul, {f.div} div, {f.sqrt} sqrt, "
                f"{f.call} other calls, {f.abs} fabs, {f.cmp} compares)")

    p = plan.pieces
    lines = [
        f"One Newton iteration: {kinds(plan.iteration)}",
        f"  Phi, Phi_q, their factorization and tests: {p.evaluation.total}; "
        f"the update (a solve): {p.update.total}",
        f"Condition at the converged q: {p.estimate.total}; an extra iteration there "
        f"(at most {tuning.TIGHTEN_STEPS}): {p.tighten.total}",
        f"Velocity: {p.velocity.total}; acceleration: {p.acceleration.total}; "
        f"per-point checks: {p.checks.total}; predictor: {p.predictor.total}",
        f"Step, worst case with the default cap of {plan.cap} iterations: {kinds(plan.step)}",
        "  (another cap c: OPS_STEP_FIXED + c * OPS_ITERATION)",
    ]
    if plan.inputs is not None and plan.positions is not None and plan.chord is not None:
        lines += [f"solve_inputs, worst case: {kinds(plan.inputs)}",
                  f"  positions only (du, ddu NULL): {kinds(plan.positions)}",
                  f"  its simplified Newton steps before Newton (at most "
                  f"{tuning.CHORD_STEPS}, in place of the predictor): {plan.chord.total}"]
    lines.append(f"On the dense LU (a fall-back at every factorization, or --linalg dense), "
                 f"worst case: {plan.dense_step.total}")
    return lines

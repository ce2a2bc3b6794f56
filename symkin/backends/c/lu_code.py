"""A sparse LU plan as data for the C templates (``template_context``): index tables, or
straight-line statements with Phi_q's known entries folded in.

Many non-zeros of Phi_q are numbers, the same at every state: the -1 and 1 of every revolute
joint, the 1 of an angle driver. Where such an entry meets the elimination unchanged it is a
constant pivot (its reciprocal, its test and the multiplications by 1 are decided here, not at
run time) or a constant multiplier (``x[i] -= x[k]`` instead of a load and a multiply). The
factorization is simulated on the plan with every slot either a known number or unknown; a
statement is emitted only where an unknown value is involved, with the known operands written
as literals. The arithmetic on known numbers is IEEE double in Python, exactly what the C code
would have done with the same operands (no fused multiply-add at -O2 without -march), so the
results are the same bits as the unfolded code's.

The factorization reads only the entries of its input that vary: the others are this
Phi_q's numbers (the header says so). The workspace still holds every value for any other
reader of ``lu->v`` and ``lu->inv``: ``<prefix>_lu_init`` stores the final value of every known
slot and the reciprocal of every constant pivot once; the factorization never overwrites them.
The tests that remain at run time still catch every near-singular pivot: a
constant pivot c can only fail the tiny-pivot bound (NQ eps max |Phi_q| >= |c|, also true when
an entry is inf or NaN), tested once for the smallest constant pivot; the threshold test of a
constant pivot with unknown entries below it stays a run-time test; an unknown pivot keeps both.

A plan's run-time row interchanges (``LUPlan.swaps``, codegen.lu_interchange) become a compare
and an exchange of the two rows' slots at their step, the outcome kept in ``lu->swapped`` for
the solves. The slots of both rows are unknown from there on: the ones known until then are
stored first (an earlier exchange may have moved another value into their place).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

from symkin.backends.c import inverse_code
from symkin.backends.c.printer import literal
from symkin.codegen.lu_plan import LUPlan, Step

Value = float | None  # a known number, or unknown until run time


@dataclass
class Statements:
    """The C statements of one plan: per step, factor; per step, forward and backward solve."""

    factor: list[list[str]] = field(default_factory=list)
    forward: list[list[str]] = field(default_factory=list)
    backward: list[list[str]] = field(default_factory=list)
    upper_t: list[list[str]] = field(default_factory=list)  # U^T z = w, per step in order
    lower_t: list[list[str]] = field(default_factory=list)  # L^T v = z, per step reversed
    uses_cmax: list[bool] = field(default_factory=list)
    ratio_tests: int = 0
    uses_pivot_ok: bool = False  # the run-time threshold test of an unknown pivot
    tiny_check: tuple[int, str] | None = None  # (k + 1, |c|) of the smallest constant pivot
    init: list[tuple[int, str]] = field(default_factory=list)  # known slots' final values
    init_inv: list[tuple[int, str]] = field(default_factory=list)  # constant pivots' 1/c
    loaded: list[int] = field(default_factory=list)  # the non-zeros read at run time
    known_max: str = "0.0"  # max |c| over the known non-zeros
    inv_low: str = "0.0"  # min and max |1/c| over the constant pivots
    inv_high: str = "0.0"
    constant_pivots: int = 0
    values: list[Value] = field(default_factory=list)  # per slot, its final number if known
    swap_lines: int = 0  # statements of the run-time interchanges
    inverses: dict[int, float] = field(default_factory=dict)  # constant pivots' 1/c


class _Emitter:
    """Simulates the factorization on known/unknown values and writes the statements."""

    def __init__(self, plan: LUPlan, constants: Sequence[Value], literal: Callable[[float], str],
                 prefix: str, fabs: str) -> None:
        self.plan = plan
        self.lit = literal
        self.prefix = prefix
        self.fabs = fabs
        self.val: list[Value] = [None] * plan.n_lu
        for e, c in enumerate(constants):
            self.val[e] = c
        for e in range(plan.nnz, plan.n_lu):
            self.val[e] = 0.0  # fill-in starts at zero
        self.inv: dict[int, float] = {}
        self.out = Statements()
        self.smallest: tuple[float, int] | None = None

    def operand(self, slot: int) -> str:
        value = self.val[slot]
        return f"v[{slot}]" if value is None else f"({self.lit(value)})"

    def known(self, slot: int, value: float, lines: list[str]) -> None:
        """Slot ``slot`` now holds the number ``value`` (stored once by lu_init)."""
        if self.val[slot] is None:  # an unknown slot never becomes known again
            lines.append(f"v[{slot}] = {self.lit(value)};")
        self.val[slot] = value

    def step(self, s: Step) -> None:
        lines: list[str] = []
        self._interchanges(s.k, lines)
        pivot = self.val[s.pivot]
        uses_cmax = False
        if pivot is not None and pivot != 0.0:
            uses_cmax = self._constant_pivot(s, pivot, lines)
        else:
            uses_cmax = self._unknown_pivot(s, lines)
        self._multipliers(s, lines)
        for target, l_slot, u_slot in s.updates:
            self._update(target, l_slot, u_slot, lines)
        self.out.factor.append(lines)
        self.out.uses_cmax.append(uses_cmax)

    def _interchanges(self, k: int, lines: list[str]) -> None:
        """Step k's interchanges: row p's slots trade with row k's when p's entry in column k
        is larger in magnitude (the comparison codegen.lu_interchange.factor makes)."""
        start = len(lines)
        for index, swap in enumerate(self.plan.swaps):
            if swap.k != k:
                continue
            for slot in (slot for pair in swap.pairs for slot in pair):
                value = self.val[slot]
                if value is not None:
                    lines.append(f"v[{slot}] = {self.lit(value)};")
                    self.val[slot] = None
            mine, theirs = swap.pivots
            lines.append(f"swapped[{index}] = {self.fabs}(v[{theirs}]) > {self.fabs}(v[{mine}]);")
            lines.append(f"if (swapped[{index}]) {{ /* rows {k} and {swap.p} trade places */")
            lines += [f"    const {self.prefix}_real w{n} = v[{a}]; v[{a}] = v[{b}]; v[{b}] = w{n};"
                      for n, (a, b) in enumerate(swap.pairs)]
            lines.append("}")
        self.out.swap_lines += len(lines) - start

    def _constant_pivot(self, s: Step, pivot: float, lines: list[str]) -> bool:
        self.out.constant_pivots += 1
        inv = 1.0 / pivot
        self.inv[s.k] = inv
        if self.smallest is None or abs(pivot) < self.smallest[0]:
            self.smallest = (abs(pivot), s.k)
        below = [self.val[slot] for _, slot in s.lower]
        known_max = max([abs(pivot)] + [abs(v) for v in below if v is not None])
        unknown = [slot for (_, slot), v in zip(s.lower, below) if v is None]
        if unknown:
            self.out.ratio_tests += 1
            lines.append(f"cmax = {self.lit(known_max)};")
            lines += [f"cmax = {self.prefix}_lu_amax(cmax, v[{slot}]);" for slot in unknown]
            lines.append(f"if (!({self.lit(abs(pivot))} >= {self.prefix.upper()}_LU_TAU * cmax))"
                         f" return {s.k + 1};")
        elif abs(pivot) < self.plan.tau * known_max:
            lines.append(f"return {s.k + 1}; /* a constant pivot that always fails */")
        return bool(unknown)

    def _unknown_pivot(self, s: Step, lines: list[str]) -> bool:
        pivot = self.operand(s.pivot)
        if s.lower:
            self.out.ratio_tests += 1
            self.out.uses_pivot_ok = True
            lines.append(f"cmax = {self.fabs}({pivot});")
            lines += [f"cmax = {self.prefix}_lu_amax(cmax, {self.operand(slot)});"
                      for _, slot in s.lower]
            lines.append(f"if (!{self.prefix}_lu_pivot_ok({pivot}, cmax, tiny)) "
                         f"return {s.k + 1};")
        else:
            lines.append(f"if (!({self.fabs}({pivot}) > tiny)) return {s.k + 1};")
        lines.append(f"inv[{s.k}] = 1 / {pivot};")
        if self.val[s.pivot] is not None:  # a pivot known to be 0: kept as a run-time failure
            self.val[s.pivot] = None
        return bool(s.lower)

    def _multipliers(self, s: Step, lines: list[str]) -> None:
        inv = self.inv.get(s.k)
        for _, slot in s.lower:
            value = self.val[slot]
            if inv is not None and value is not None:
                self.known(slot, value * inv, lines)
            elif inv is not None:
                if inv == -1.0:
                    lines.append(f"v[{slot}] = -v[{slot}];")
                elif inv != 1.0:
                    lines.append(f"v[{slot}] *= {self.lit(inv)};")
            elif value is not None:
                if value != 0.0:
                    lines.append(f"v[{slot}] = {self.lit(value)} * inv[{s.k}];")
                    self.val[slot] = None
                elif self.val[slot] is not None:
                    self.known(slot, 0.0, lines)
            else:
                lines.append(f"v[{slot}] *= inv[{s.k}];")

    def _update(self, target: int, l_slot: int, u_slot: int, lines: list[str]) -> None:
        t, lv, uv = self.val[target], self.val[l_slot], self.val[u_slot]
        if lv is not None and uv is not None:
            if t is not None:
                self.known(target, t - lv * uv, lines)
            elif lv * uv != 0.0:
                lines.append(f"v[{target}] -= {self.lit(lv * uv)};")
            return
        if lv == 0.0 or uv == 0.0:
            return
        product = _product(self.operand(l_slot), lv, self.operand(u_slot), uv)
        if t is None:
            lines.append(f"v[{target}] -= {product};")
        elif t == 0.0:
            lines.append(f"v[{target}] = -({product});")
        else:
            lines.append(f"v[{target}] = {self.lit(t)} - {product};")
        self.val[target] = None

    def solves(self) -> None:
        for s in self.plan.steps:
            self.out.forward.append([
                line for i, slot in s.lower
                for line in _axpy(f"x[{i}]", self.val[slot], f"v[{slot}]", f"x[{s.k}]",
                                  self.lit)])
        for s in reversed(self.plan.steps):
            lines = [line for j, slot in s.upper
                     for line in _axpy(f"x[{s.k}]", self.val[slot], f"v[{slot}]", f"x[{j}]",
                                       self.lit)]
            self.out.backward.append(lines + self._divide(s.k))
        self._transposed()

    def _divide(self, k: int) -> list[str]:
        """``x[k] /= u_kk`` as a multiplication by the reciprocal (known: -1 and 1 folded)."""
        inv = self.inv.get(k)
        if inv is None:
            return [f"x[{k}] *= inv[{k}];"]
        if inv == -1.0:
            return [f"x[{k}] = -x[{k}];"]
        return [] if inv == 1.0 else [f"x[{k}] *= {self.lit(inv)};"]

    def _transposed(self) -> None:
        """A^T x = b as U^T z = Pc^T b, L^T v = z: the same operations, in the same order, as
        the table-driven loops (so the same bits), with the known entries folded."""
        for s in self.plan.steps:
            self.out.upper_t.append(self._divide(s.k) + [
                line for j, slot in s.upper
                for line in _axpy(f"x[{j}]", self.val[slot], f"v[{slot}]", f"x[{s.k}]",
                                  self.lit)])
        for s in reversed(self.plan.steps):
            self.out.lower_t.append([
                line for i, slot in s.lower
                for line in _axpy(f"x[{s.k}]", self.val[slot], f"v[{slot}]", f"x[{i}]",
                                  self.lit)])


def _product(left: str, left_value: Value, right: str, right_value: Value) -> str:
    """``left * right``, without a multiplication by a literal 1."""
    if left_value == 1.0:
        return right
    if right_value == 1.0:
        return left
    return f"{left} * {right}"


def _axpy(target: str, value: Value, slot: str, x: str, lit: Callable[[float], str]
          ) -> list[str]:
    """``target -= value * x`` with value from ``slot`` unless known (0, 1, -1 folded)."""
    if value is None:
        return [f"{target} -= {slot} * {x};"]
    if value == 0.0:
        return []
    if value == 1.0:
        return [f"{target} -= {x};"]
    if value == -1.0:
        return [f"{target} += {x};"]
    return [f"{target} -= ({lit(value)}) * {x};"]


def statements(plan: LUPlan, constants: Sequence[Value] | None, literal: Callable[[float], str],
               prefix: str, fabs: str) -> Statements:
    """The straight-line statements of ``plan``; ``constants`` gives, per non-zero of Phi_q,
    its value when it is a number at every state (None: none known)."""
    emitter = _Emitter(plan, constants or [None] * plan.nnz, literal, prefix, fabs)
    for s in plan.steps:
        emitter.step(s)
    emitter.solves()
    if emitter.smallest is not None:
        emitter.out.tiny_check = (emitter.smallest[1] + 1, literal(emitter.smallest[0]))
    out = emitter.out
    out.init = [(e, literal(c)) for e, c in enumerate(emitter.val) if c is not None and c != 0.0]
    out.init_inv = [(k, literal(c)) for k, c in sorted(emitter.inv.items())]
    out.values, out.inverses = list(emitter.val), dict(emitter.inv)
    if emitter.inv:
        out.inv_low = literal(min(abs(c) for c in emitter.inv.values()))
        out.inv_high = literal(max(abs(c) for c in emitter.inv.values()))
    known = [e for e, c in enumerate(constants or []) if c is not None]
    out.loaded = sorted(set(range(plan.nnz)) - set(known))
    out.known_max = literal(max((abs(c) for c in constants or [] if c is not None), default=0.0))
    return out


def step_context(out: Statements) -> list[dict[str, Any]]:
    """Per step (pivot order) its factor statements and whether it needs ``cmax``."""
    return [{"factor": lines, "cmax": cmax} for lines, cmax in zip(out.factor, out.uses_cmax)]


PART_OPS = 250
"""Statements per generated C function: gcc's optimiser is superlinear in function size, so
the straight-line factor and solve are split into parts of about this many operations."""


TABLE_FLOPS = 40000
"""Above this many factor + solve operations the C code walks index tables in loops instead of
being straight-line: constant code size and compile time. The straight-line code folds Phi_q's
numbers in and runs about one instruction per operation, the tables two to three (they load an
index for every operand and do every operation); its parts keep the compiler's time linear, so
this limit only bounds one file's compile. Lazy tongs of 1000 bodies (N = 3000, 31,942
operations, fill-in): straight-line, the file is 1.6 MB, 24 s of gcc -O2 and 334 MB, and the
solver's 2.75 M instructions per step are linear in N; with the tables 6.60 M (callgrind). At
the limit, extrapolated: about 2 MB, 30 s and 420 MB."""


def template_context(plan: LUPlan, part_ops: int = PART_OPS,
                     style: str | None = None, constants: Sequence[float | None] | None = None,
                     real: str = "double", *, prefix: str) -> dict[str, object]:
    """The plan as plain data for ``templates/sparse_lu.*.j2`` (key ``lu``).

    Args:
        plan: the analysed factorization.
        part_ops: operations per generated function in the straight-line style.
        style: "straight" (one C statement per operation) or "tables" (loops over static
            index arrays); by default straight-line up to TABLE_FLOPS operations.
        constants: per non-zero of Phi_q (pattern order), its value when it is a number at
            every state; the straight-line code folds them in (statements above). Used in
            double precision only (a float build would round literals differently).
        real: the C real type.
        prefix: the C prefix of the generated functions.
    """
    if style is None:
        style = ("straight" if plan.flops + plan.solve_flops <= TABLE_FLOPS or plan.swaps
                 else "tables")
    if style not in ("straight", "tables"):
        raise ValueError(f"unknown sparse LU style {style!r}: use 'straight' or 'tables'")
    if style == "tables" and plan.swaps:
        # interchanges are planned only on sampled mechanisms, far below TABLE_FLOPS
        raise ValueError("the table-driven sparse LU has no run-time row interchanges: use "
                         "the straight-line style for a plan with swaps")
    fabs = "fabsf" if real == "float" else "fabs"
    code = statements(plan, constants if real == "double" else None, literal(real), prefix, fabs)
    steps = step_dicts(plan, code)
    backward = list(reversed(steps))
    return {
        "n_lu": plan.n_lu,
        "n_fill": plan.n_lu - plan.nnz,
        "tau": repr(float(plan.tau)),
        "flops": plan.flops,
        "solve_flops": plan.solve_flops,
        "row_perm": list(plan.row_perm),
        "col_perm": list(plan.col_perm),
        # the fixed order's share of det(Phi_q)'s sign: sign(P) sign(Q) is -1
        "order_negative": _odd(plan.row_perm) != _odd(plan.col_perm),
        "fill_slots": list(range(plan.nnz, plan.n_lu)),
        "unchecked": list(plan.unchecked),
        # run-time interchanges (k, p) in plan order: each a compare, then an exchange of
        # len(pairs) slot values when it is taken (and of x[k], x[p] in every solve)
        "swaps": [[s.k, s.p] for s in plan.swaps],
        "swap_pairs": [len(s.pairs) for s in plan.swaps],
        "ratio_tests": (code.ratio_tests if style == "straight"
                        else sum(1 for s in plan.steps if s.lower)),
        "tiny_check": code.tiny_check if style == "straight" else None,
        "init": code.init if style == "straight" else [],
        "init_inv": code.init_inv if style == "straight" else [],
        "loaded": code.loaded,
        "known_max": code.known_max,
        "inv_low": code.inv_low,
        "inv_high": code.inv_high,
        "variable_pivots": [k for k in range(plan.n)
                            if style == "tables" or k not in dict(code.init_inv)],
        # Beyond one part's worth, per-entry code becomes loops over static tables: a
        # function thousands of lines long costs the compiler far more than the loop costs.
        "perm_tables": style == "tables" or plan.n > part_ops,
        "init_tables": style == "straight" and len(code.init) + len(code.init_inv) > part_ops,
        "loop_tables": style == "straight" and (len(code.loaded) > part_ops
                                                or plan.n > part_ops),
        "pivot_ok": code.uses_pivot_ok or style == "tables",
        "constant_pivots": code.constant_pivots if style == "straight" else 0,
        "factor_parts": split_parts(steps, lambda s: len(s["factor"]), part_ops),
        "forward_parts": split_parts([s for s in steps if s["forward"]],
                                     lambda s: len(s["forward"]), part_ops),
        "backward_parts": split_parts([s for s in backward if s["backward"]],
                                      lambda s: len(s["backward"]), part_ops),
        "upper_t_parts": split_parts([s for s in steps if s["upper_t"]],
                                     lambda s: len(s["upper_t"]), part_ops),
        "lower_t_parts": split_parts([s for s in backward if s["lower_t"]],
                                     lambda s: len(s["lower_t"]), part_ops),
        "style": style,
        "tables": _tables(plan),
        # ||Phi_q^-1||_1 exactly, where the straight-line code for it is short
        "inverse": (inverse_code.exact_context(plan, code.values, code.inverses, literal(real),
                                               f"{prefix}_real", fabs)
                    if style == "straight" else None),
    }


def step_dicts(plan: LUPlan, code: Statements) -> list[dict[str, Any]]:
    """Per step (pivot order) its plan entries and its statements in every routine."""
    return [{"k": s.k, "row": s.row, "col": s.col, "pivot": s.pivot,
             "lower": [list(x) for x in s.lower], "upper": [list(x) for x in s.upper],
             "updates": [list(x) for x in s.updates], "factor": code.factor[s.k],
             "cmax": code.uses_cmax[s.k], "forward": code.forward[s.k],
             "backward": code.backward[plan.n - 1 - s.k], "upper_t": code.upper_t[s.k],
             "lower_t": code.lower_t[plan.n - 1 - s.k]} for s in plan.steps]


def _odd(perm: Sequence[int]) -> bool:
    """Whether a permutation is odd: the parity of n minus its number of cycles."""
    seen, cycles = [False] * len(perm), 0
    for start in range(len(perm)):
        if not seen[start]:
            cycles += 1
            k = start
            while not seen[k]:
                seen[k] = True
                k = perm[k]
    return (len(perm) - cycles) % 2 == 1


def _tables(plan: LUPlan) -> dict[str, list[int]]:
    """The plan as compressed index arrays (offsets per pivot), each ending in one zero record
    so that no C array is empty (C99 forbids it) even when a plan has no such entry."""
    tables: dict[str, list[int]] = {"pivot": [s.pivot for s in plan.steps]}
    records: tuple[tuple[str, int, Callable[[Step], Any]], ...] = (
        ("lower", 2, lambda s: s.lower), ("upper", 2, lambda s: s.upper),
        ("update", 3, lambda s: s.updates))
    for name, width, pick in records:
        start, flat = [0], []
        for step in plan.steps:
            for entry in pick(step):
                flat.extend(entry)
            start.append(start[-1] + len(pick(step)))
        tables[f"{name}_start"] = start
        tables[name] = flat + [0] * width
    return tables


def split_parts(steps: list[dict[str, Any]], size: Callable[[dict[str, Any]], int],
                limit: int) -> list[dict[str, Any]]:
    """Consecutive runs of steps of at most ``limit`` operations each (at least one step);
    ``checks`` says whether a run has a ratio test (and so needs its column maximum)."""
    runs: list[list[dict[str, Any]]] = []
    total = 0
    for step in steps:
        ops = size(step)
        if not runs or (runs[-1] and total + ops > limit):
            runs.append([])
            total = 0
        runs[-1].append(step)
        total += ops
    return [{"steps": run, "checks": any(s["cmax"] for s in run)} for run in runs]

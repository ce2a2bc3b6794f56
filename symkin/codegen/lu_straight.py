"""The straight-line C statements of a sparse LU plan, with known entries folded in.

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
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

from symkin.codegen.lu_plan import LUPlan, Step

Value = float | None  # a known number, or unknown until run time


@dataclass
class Statements:
    """The C statements of one plan: per step, factor; per step, forward and backward solve."""

    factor: list[list[str]] = field(default_factory=list)
    forward: list[list[str]] = field(default_factory=list)
    backward: list[list[str]] = field(default_factory=list)
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
            inv = self.inv.get(s.k)
            if inv is None:
                lines.append(f"x[{s.k}] *= inv[{s.k}];")
            elif inv == -1.0:
                lines.append(f"x[{s.k}] = -x[{s.k}];")
            elif inv != 1.0:
                lines.append(f"x[{s.k}] *= {self.lit(inv)};")
            self.out.backward.append(lines)


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

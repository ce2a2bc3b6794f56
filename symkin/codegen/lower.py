"""Stage 3 — codegen: common subexpressions and printing, from a System to plain strings.

Everything after this module works on plain data (strings, index lists, op counts): the
templates never see a SymPy object. A backend is a printer subclass of one of SymPy's code
printers; the printers map the mechanism's symbols to the argument arrays of the generated
functions (``q[i]``, ``dq[i]``, ``p[k]``, ``t``) in ``_print_Symbol``, never by editing printed
text. Names from the mechanism file are first replaced by internal symbols (``_q3``...), so a
user's name can never collide with a temporary (``w0``...) or reach the generated code.
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import sympy as sp
from sympy.printing.codeprinter import CodePrinter

from symkin.codegen import dynamics_plan, fusion, neutral, sample, symbol_printing
from symkin.codegen.cse_tidy import _ops_before_cse
from symkin.codegen.lu_plan import LUPlan
from symkin.codegen.symbol_printing import symbol_text
from symkin.codegen.system_facts import (
    mass_pattern,
    nonlinear_coordinates,
    parameter_pattern,
    point_names,
    routine_expressions,
)
from symkin.codegen.target import Target, chosen_options
from symkin.errors import BuildError
from symkin.symbolic.derivation import System
from symkin.symbolic.ranges import Range, coordinate_ranges

# The routines every backend emits, in output order, and the arguments each one takes.
ROUTINE_ARGUMENTS: dict[str, tuple[str, ...]] = {
    "phi": ("q", "t", "p"),
    "phi_q": ("q", "t", "p"),
    "phi_t": ("q", "t", "p"),
    "gamma": ("q", "dq", "t", "p"),
    "points": ("p",),
    "phi_p": ("q", "t", "p"),
    # Only when there are some: System.removed (checked along the motion), System.senses.
    "removed": ("q", "t", "p"),
    "senses": ("q", "t", "p"),
    # Fused evaluation (see codegen.fusion): one call per Newton iterate evaluates Phi, the
    # non-zeros of Phi_q and the shared sines and cosines; Phi_t and Gamma at the converged q
    # read those instead of evaluating them again.
    "phi_phi_q": ("q", "t", "p"),
    "phi_t_shared": ("q", "t", "p", "shared"),
    "gamma_shared": ("q", "dq", "t", "p", "shared"),
    # Inverse dynamics, only for a file with masses or forces (symbolic.dynamics): the
    # right-hand side Q - M ddq - h of Phi_q^T lam = rhs, and the efforts and reactions of lam.
    "dynamics_rhs": ("q", "dq", "ddq", "t", "p"),
    "loads": ("q", "lam", "t", "p"),
    # the same from the fused routine's sines and cosines, at the q of the last step
    "dynamics_rhs_shared": ("q", "dq", "ddq", "t", "p", "shared"),
    "loads_shared": ("q", "lam", "t", "p", "shared"),
    # Dynamics with removed rows: their Jacobian (dense) and the loads of lam of every row
    # (kept, then removed), for the runtime's minimum-norm loads (runtime.loads.indeterminate).
    "removed_q": ("q", "t", "p"),
    "loads_full": ("q", "lam", "t", "p"),
    # Forward dynamics, only for a file with masses: the non-zeros of M(q) (mass_rows/_cols
    # order) and the applied forces less the velocity terms, Q - h(q, dq, t).
    "mass": ("q", "p"),
    "applied": ("q", "dq", "t", "p"),
    # M, Phi_q, Q - h and Gamma at one (q, dq, t) with one CSE (the dynamics step's stages)
    "motion": ("q", "dq", "t", "p"),
}
DYNAMICS = ("dynamics_rhs", "loads")
FUSED = ("phi_phi_q", "phi_t_shared", "gamma_shared")

# Characters allowed in a comment of generated code; anything else becomes '?'.
_COMMENT_UNSAFE = re.compile(r"[^A-Za-z0-9_.,:;()\[\] +=-]")


PART_OUTPUTS = 200
"""Outputs per generated function: a larger routine is split into parts of this many outputs,
each with its own CSE, so that neither SymPy's CSE nor a compiler (both superlinear in
the size of one function) sees more than a bounded piece; the parts are consecutive outputs
(rows of a chain stay together, so little sharing is lost between parts)."""


@dataclass(frozen=True)
class Part:
    """A bounded piece of a routine: its temporaries and the output positions it writes."""

    temporaries: tuple[tuple[str, str], ...]
    slots: tuple[int, ...]
    unused: tuple[str, ...]


@dataclass(frozen=True)
class Routine:
    """One generated function as plain text.

    Attributes:
        name: ``phi``, ``phi_q`` (the non-zeros in pattern order), ``phi_t``, ``gamma``,
            ``points``.
        arguments: the argument names, in order.
        unused: the arguments its body does not read (a backend may have to mark them).
        temporaries: ``(name, expression)`` pairs, in evaluation order.
        outputs: one expression per output slot.
        ops: operation count after CSE (SymPy's ``count_ops``).
        sizes: how the outputs split among several output arrays, in order (the fused
            ``phi_phi_q``: Phi, the non-zeros of Phi_q, the shared values); empty for one.
        parts: the routine in pieces of at most PART_OUTPUTS outputs (one part when small);
            ``temporaries`` is then the first part's.
    """

    name: str
    arguments: tuple[str, ...]
    unused: tuple[str, ...]
    temporaries: tuple[tuple[str, str], ...]
    outputs: tuple[str, ...]
    ops: int
    sizes: tuple[int, ...] = ()
    parts: tuple[Part, ...] = ()


@dataclass(frozen=True)
class Code:
    """Everything the templates of one backend need, as plain data."""

    backend: Target
    options: Mapping[str, str]
    """The backend's options, checked and completed (codegen.target.chosen_options); only
    the backend reads them."""
    cse: bool
    name: str
    spec_sha256: str
    nq: int
    n_params: int
    coordinates: tuple[str, ...]
    parameter_names: tuple[str, ...]
    p_values: tuple[float, ...]
    q0: tuple[float, ...]
    time_grid: tuple[float, float, float]
    rows: tuple[str, ...]
    pattern_rows: tuple[int, ...]
    pattern_cols: tuple[int, ...]
    points: tuple[tuple[str, str], ...]
    routines: tuple[Routine, ...]
    ops_before_cse: dict[str, int]
    lu_plan: LUPlan | None = None
    """The sparse LU's pivot order and steps (for a backend that plans_lu, and a mechanism
    with a kinematic solve)."""
    phi_p_rows: tuple[int, ...] = ()
    phi_p_cols: tuple[int, ...] = ()
    """The structural non-zeros of Phi_p (row, parameter), row-major."""
    shared: tuple[str, ...] = ()
    """The sines and cosines the fused routine passes to Phi_t and Gamma (printed, in order)."""
    constant_nz: tuple[float | None, ...] = ()
    """Per non-zero of Phi_q: its value when it is a number (the same at every state)."""
    removed: tuple[str, ...] = ()
    """The labels of the rows removed as dependent at t0 (the ``removed`` routine's outputs)."""
    senses: tuple[str, ...] = ()  # the labels of the ``senses`` routine's outputs
    ranges: tuple[Range, ...] = ()
    """The ranges the file gives the pairs' own coordinates (symbolic.ranges)."""
    space: str = "2d"
    """``3d`` for a spatial mechanism (its points have three components)."""

    @property
    def point_axes(self) -> str:
        """The components of a point vector, in order."""
        return "xyz" if self.space == "3d" else "xy"

    driver_names: tuple[str, ...] = ()
    joint_names: tuple[str, ...] = ()
    """Inverse dynamics (``dynamics_rhs`` and ``loads`` routines present): the labels of the
    efforts (one per driver row) and of the joints' reactions."""

    @property
    def dynamics(self) -> bool:
        return any(routine.name == "loads" for routine in self.routines)

    input_names: tuple[str, ...] = ()
    """The input drivers (System.inputs): their u, du, ddu follow the parameters in p[]."""
    input_values: tuple[float, ...] = ()
    """The inputs' values in the file's q0 (codegen.sample.input_values)."""
    input_places: tuple[str, ...] = ()
    """Where each input is in the file (System.input_places)."""
    input_lengths: tuple[int, ...] = ()
    """The inputs (indices into u[]) that are lengths, never negative (System.input_lengths)."""
    nonlinear: tuple[int, ...] = ()
    """The coordinates that enter Phi_q or Phi_t (angles, Euler parameters, the positions of
    a prismatic pair's bodies): only their errors move Phi_q (runtime.solving.accuracy)."""
    mass_rows: tuple[int, ...] = ()
    mass_cols: tuple[int, ...] = ()
    """Forward dynamics (a file with masses): the structural non-zeros of M, row-major."""
    augmented: dynamics_plan.AugmentedPlan | None = None
    """Forward dynamics: the rows and the sparse LU of the step's matrix (codegen.dynamics_plan)."""

    @property
    def forward_dynamics(self) -> bool:
        """The ``mass`` and ``applied`` routines and the dynamics step are generated."""
        return bool(self.mass_rows)

    @property
    def nrows(self) -> int:
        """The rows of Phi (fewer than NQ where drivers leave freedoms to the dynamics)."""
        return len(self.rows)

    @property
    def nnz(self) -> int:
        return len(self.pattern_rows)

    @property
    def nnz_p(self) -> int:
        return len(self.phi_p_rows)

    @property
    def npoints(self) -> int:
        return len(self.points)

    @property
    def ops(self) -> dict[str, int]:
        """Operation count of each routine after CSE (when enabled)."""
        return {routine.name: routine.ops for routine in self.routines}

    def routine(self, name: str) -> Routine:
        return next(routine for routine in self.routines if routine.name == name)


# ----- lowering ------------------------------------------------------------------------------

def lower(system: System, backend: Target, options: Mapping[str, str] | None = None,
          cse: bool = True) -> Code:
    """Turn a System into the plain data the templates of ``backend`` render.

    Args:
        system: the derived kinematics.
        backend: the target (``symkin.backends.get`` finds one by name).
        options: the backend's options (``backend.options`` declares them; defaults for the
            rest).
        cse: eliminate common subexpressions within each routine.

    Raises:
        BuildError: an option the backend does not take, or an expression the printer cannot
            print, or a mechanism with fewer driving equations than freedoms and no masses.
    """
    chosen = chosen_options(backend, options)
    # A mechanism its forces move (fewer rows than coordinates) has no kinematic solve: its
    # code is the kernel and the dynamics step; the solver's Phi_q has no LU plan then.
    free = system.phi_q.shape[0] < len(system.q)
    if free and not mass_pattern(system):
        raise BuildError("the mechanism has fewer driving equations than freedoms and no "
                         "masses: its motion is not determined; give its bodies masses")
    pattern = system.pattern()
    p_pattern = parameter_pattern(system)
    m_pattern = mass_pattern(system)
    kept = neutral.of(system, lambda: _neutral(system, pattern, p_pattern, m_pattern))
    expressions, prepared, fused, shared = kept.expressions, kept.prepared, kept.fused, kept.shared
    fused = dict(fused)  # "motion" is added below
    printer: CodePrinter = backend.printer(chosen)
    # Phi's rows: as many as coordinates, or fewer where the dynamics moves the rest
    nphi = len(system.phi)
    sizes = {"phi_phi_q": (nphi, len(pattern), len(shared))}
    orders = {"phi_phi_q": fusion.fused_order(prepared, pattern, shared)}
    # Phi and Phi_q alone are the fused routine's pieces: its CSE and printing serve all three.
    count = kept.count
    fused_parts = _lowered_parts("phi_phi_q", fused["phi_phi_q"], printer, kept, cse,
                                 orders["phi_phi_q"])
    nnz = len(pattern)
    own = {"phi": _select("phi", fused_parts, {k: k for k in range(nphi)}, nphi),
           "phi_q": _select("phi_q", fused_parts, {nphi + e: e for e in range(nnz)}, nnz),
           "phi_phi_q": _assemble("phi_phi_q", fused_parts, len(fused["phi_phi_q"]),
                                  sizes["phi_phi_q"])}
    if m_pattern:  # the dynamics step's stages: each sine and cosine once for all four
        fused["motion"] = [e for name in ("mass", "phi_q", "applied", "gamma")
                           for e in prepared[name]]
        own["motion"] = _assemble("motion", _lowered_parts("motion", fused["motion"], printer,
                                                           kept, cse), len(fused["motion"]),
                                  (len(m_pattern), nnz, len(system.q), nphi))
    routines = tuple(
        own[name] if name in own else
        _assemble(name, _lowered_parts(name, exprs, printer, kept, cse), len(exprs))
        for name, exprs in {**prepared, **fused}.items())
    return Code(
        backend=backend, options=chosen, cse=cse, name=system.name,
        space="3d" if system.mechanism.is_spatial else "2d",
        spec_sha256=system.mechanism.spec_hash(), nq=len(system.q), n_params=len(system.p),
        coordinates=system.coordinates, parameter_names=system.parameter_names,
        p_values=tuple(float(v) for v in system.p_values), q0=tuple(system.q0),
        time_grid=system.time_grid, rows=tuple(str(row) for row in system.rows),
        pattern_rows=tuple(r for r, _ in pattern), pattern_cols=tuple(c for _, c in pattern),
        points=point_names(system), routines=routines,
        ops_before_cse=_ops_before_cse(expressions, fused, shared, count),
        phi_p_rows=tuple(r for r, _ in p_pattern), phi_p_cols=tuple(c for _, c in p_pattern),
        lu_plan=(sample.sparse_lu_plan(system, pattern, (prepared["phi"], prepared["phi_q"]))
                 if backend.plans_lu(chosen) and not free else None),
        shared=tuple(_print(printer, f) for f in shared),
        constant_nz=tuple(float(e) if e.is_Number else None for e in prepared["phi_q"]),
        removed=tuple(str(removed) for removed in system.removed),
        ranges=coordinate_ranges(system), senses=tuple(label for label, _ in system.senses),
        driver_names=system.dynamics.driver_names if system.dynamics else (),
        joint_names=system.dynamics.joint_names if system.dynamics else (),
        input_names=system.input_names, input_values=sample.input_values(system),
        input_places=system.input_places, input_lengths=system.input_lengths,
        nonlinear=nonlinear_coordinates(system),
        mass_rows=tuple(r for r, _ in m_pattern), mass_cols=tuple(c for _, c in m_pattern),
        augmented=dynamics_plan.analyse(system, pattern, m_pattern) if m_pattern else None,
    )


@dataclass
class _Lowered:
    """One part of a routine before it becomes text-only: what each temporary and output
    needs (the symbols it reads), so that a routine can be a selection of another's parts."""

    temporaries: list[tuple[str, str, frozenset[str], int]]  # name, text, reads, ops
    slots: list[int]  # output positions
    outputs: list[tuple[str, frozenset[str], int]]  # text, reads, ops


def _reads(expr: sp.Expr) -> frozenset[str]:
    return frozenset(s.name for s in expr.free_symbols)


def _neutral(system: System, pattern: Sequence[tuple[int, int]],
             p_pattern: Sequence[tuple[int, int]], m_pattern: Sequence[tuple[int, int]]
             ) -> neutral.Neutral:
    """The routines' expressions, prepared and fused: the same for every backend."""
    expressions = routine_expressions(system, pattern, p_pattern, m_pattern)
    prepare = symbol_printing.Preparer(symbol_printing.internal_symbols(system))
    prepared = {name: [prepare(e) for e in exprs] for name, exprs in expressions.items()}
    fused, shared = fusion.fused_expressions(prepared, DYNAMICS)
    return neutral.Neutral(expressions, prepared, fused, shared)


def _lowered_parts(name: str, exprs: list[sp.Expr], printer: Any, kept: neutral.Neutral,
                   cse: bool, order: Sequence[int] | None = None) -> list[_Lowered]:
    """CSE (``kept``'s, made once for every backend) and print ``exprs`` in parts of at most
    PART_OUTPUTS outputs (in ``order``), each temporary and output with its operations."""
    positions = list(order) if order is not None else list(range(len(exprs)))
    chunks = [positions[i:i + PART_OUTPUTS] for i in range(0, len(positions), PART_OUTPUTS)]
    parts, count = [], kept.count
    for chunk in chunks or [[]]:
        temporaries, values = kept.part(name, chunk, [exprs[k] for k in chunk], cse)
        parts.append(_Lowered(
            temporaries=[(str(t), _print(printer, v), _reads(v), count(v))
                         for t, v in temporaries],
            slots=list(chunk),
            outputs=[(_print(printer, v), _reads(v), count(v)) for v in values]))
    return parts


def _argument_names(reads: set[str]) -> set[str]:
    return {symbol_text(r).split("[")[0] for r in reads if not r.startswith("w")}


def _assemble(name: str, parts: list[_Lowered], n_outputs: int,
              sizes: tuple[int, ...] = ()) -> Routine:
    """A Routine (plain text) from lowered parts."""
    outputs = [""] * n_outputs
    done, ops, used_names = [], 0, set()
    for part in parts:
        reads: set[str] = set()
        for _, _, r, count in part.temporaries:
            reads |= r
            ops += count
        for k, (text, r, count) in zip(part.slots, part.outputs):
            outputs[k] = text
            reads |= r
            ops += count
        names = _argument_names(reads)
        used_names |= names
        done.append(Part(temporaries=tuple((n, t) for n, t, _, _ in part.temporaries),
                         slots=tuple(part.slots),
                         unused=tuple(a for a in ROUTINE_ARGUMENTS[name] if a not in names)))
    return Routine(
        name=name, arguments=ROUTINE_ARGUMENTS[name],
        unused=tuple(a for a in ROUTINE_ARGUMENTS[name] if a not in used_names),
        temporaries=done[0].temporaries, outputs=tuple(outputs), ops=ops, sizes=sizes,
        parts=tuple(done))


def _select(name: str, parts: list[_Lowered], positions: dict[int, int], n_outputs: int
            ) -> Routine:
    """The routine made of some outputs of another's parts (``positions``: theirs -> its),
    each part with the temporaries its selected outputs need, in their order."""
    selected = []
    for part in parts:
        keep = [(positions[k], out) for k, out in zip(part.slots, part.outputs)
                if k in positions]
        needed = set().union(*(r for _, (_, r, _) in keep)) if keep else set()
        temporaries = []
        for temporary in reversed(part.temporaries):
            if temporary[0] in needed:
                needed |= temporary[2]
                temporaries.append(temporary)
        if keep:
            selected.append(_Lowered(temporaries=temporaries[::-1], slots=[k for k, _ in keep],
                                     outputs=[out for _, out in keep]))
    return _assemble(name, selected or [_Lowered([], [], [])], n_outputs)


def _print(printer: Any, expr: sp.Expr) -> str:
    try:
        return str(printer.doprint(expr))
    except (TypeError, ValueError, NotImplementedError) as error:
        raise BuildError(f"cannot generate code for the expression {expr}: {error}") from None


def comment(text: str) -> str:
    """Text from a mechanism file made safe for a comment of every backend's language (one
    line, none of the characters that could end a comment, such as ``*/``)."""
    return _COMMENT_UNSAFE.sub("?", text)[:120]

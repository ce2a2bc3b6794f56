"""Verification — does a hand derivation of Phi, Phi_q, Phi_t or Gamma agree with the System?

Two routes:

* numeric (:func:`verify`): a user's NumPy functions ``phi(q, t, p)``, ``phi_q(q, t, p)``,
  ``phi_t(q, t, p)`` and ``gamma(q, dq, t, p)`` — in the coordinate, parameter and row order
  ``symkin show`` prints — are evaluated next to the derived expressions (``sympy.lambdify``)
  at many random states (q, dq, t) *and* random parameter values around the nominal design, so
  a slip multiplied by a zero dimension or a zero speed at the nominal design is still caught.
  Every entry that differs is reported with the row's owner (joint or driver, type, bodies),
  the column's coordinate, the derived expression, both values and the worst relative error.
* symbolic (:func:`compare`): SymPy expressions or matrices, equal per entry when their
  difference simplifies to zero, with a numeric fallback where simplification gives up.

A hand module is the user's own Python file: loading it runs it, as pytest runs a test file. It
is loaded by path (nothing is added to ``sys.path``) and every exception it raises is turned into
a :class:`HandModuleError` that names the function and the line.
"""

from __future__ import annotations

import importlib.util
import math
import sys
import traceback
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np
import sympy as sp

from symkin.derivation import System, derive
from symkin.errors import SymkinError
from symkin.model import Mechanism

FUNCTIONS = ("phi", "phi_q", "phi_t", "gamma")
SIGNATURES = {"phi": "phi(q, t, p)", "phi_q": "phi_q(q, t, p)", "phi_t": "phi_t(q, t, p)",
              "gamma": "gamma(q, dq, t, p)"}
DEFAULT_SAMPLES = 50
DEFAULT_SPREAD = 0.3
DEFAULT_TOLERANCE = 1e-8
# Entries smaller than this fraction of a function's largest value are compared on that
# absolute scale, so rounding in a near-zero entry is not mistaken for a relative error; and
# below this fraction of the length scale when the derived function is zero everywhere.
FLOOR_FRACTION = 1e-3
FLOOR_OF_LENGTH = 1e-6


class HandModuleError(SymkinError):
    """A hand-derivation module is missing, cannot be loaded, raises or returns wrong shapes."""


# ----- the derived side, as NumPy functions ---------------------------------------------------

@dataclass(frozen=True)
class Derived:
    """The System's four functions, lambdified once, plus what a report needs to label entries.

    Build it with :func:`derived_functions`; pass it to :func:`verify` to verify many hand
    modules (or seeds) without lambdifying again.
    """

    system: System
    phi: Callable[..., Any]
    phi_t: Callable[..., Any]
    gamma: Callable[..., Any]
    phi_q_nz: Callable[..., Any]
    pattern: tuple[tuple[int, int], ...]

    @property
    def size(self) -> int:
        return len(self.system.q)

    def evaluate(self, name: str, state: State) -> np.ndarray:
        """The derived value of one function at one state, with the hand function's shape."""
        args = (state.q, state.dq, state.t, state.p)
        if name == "phi_q":
            matrix = np.zeros((len(self.system.rows), self.size))
            if self.pattern:
                rows, cols = zip(*self.pattern)
                matrix[rows, cols] = _flat(self.phi_q_nz(*args))
            return matrix
        return _flat(getattr(self, name)(*args))

    def expression(self, name: str, row: int, column: int | None) -> sp.Expr:
        if name == "phi_q":
            return self.system.phi_q[row, column]
        return getattr(self.system, name)[row]


def _flat(value: Any) -> np.ndarray:
    return np.asarray(value, dtype=float).reshape(-1)


def derived_functions(system: System) -> Derived:
    """Lambdify Phi, Phi_t, Gamma and the non-zeros of Phi_q of a System (once)."""
    q = sp.symbols(f"q0:{len(system.q)}")
    dq = sp.symbols(f"dq0:{len(system.dq)}")
    p = sp.symbols(f"p0:{len(system.p)}")
    t = sp.Symbol("t")
    # Safe argument names: coordinates are named "crank.x", which is no Python identifier.
    rename = dict(zip(system.q, q)) | dict(zip(system.dq, dq)) | dict(zip(system.p, p))
    rename[system.t] = t

    def make(values: Iterable[sp.Expr]) -> Callable[..., Any]:
        column = [sp.sympify(value).xreplace(rename) for value in values]
        return sp.lambdify([q, dq, t, p], column, modules="numpy")

    pattern = tuple(system.pattern())
    return Derived(system=system, phi=make(system.phi), phi_t=make(system.phi_t),
                   gamma=make(system.gamma),
                   phi_q_nz=make(system.phi_q[r, k] for r, k in pattern), pattern=pattern)


# ----- sampling -------------------------------------------------------------------------------

@dataclass(frozen=True)
class State:
    """One sample point: coordinates, velocities, time and parameter values."""

    q: np.ndarray
    dq: np.ndarray
    t: float
    p: np.ndarray


def length_scale(system: System) -> float:
    """A typical size of the mechanism: the median non-zero nominal parameter, else 1."""
    sizes = [abs(v) for v in system.p_values if v != 0 and math.isfinite(v)]
    return float(np.median(sizes)) if sizes else 1.0


def sample_states(system: System, samples: int, seed: int, spread: float) -> list[State]:
    """Random states, and parameters within ``spread`` of the nominal design.

    A non-zero parameter p becomes p (1 + spread u); a zero one becomes spread L u, with u
    uniform in [-1, 1] and L the mechanism's length scale — so zero dimensions are varied too.
    Positions are uniform in [-2L, 2L], angles in [-pi, pi], rates in [-L, L] and [-2, 2],
    t in the file's time grid. The states need not satisfy Phi = 0: every function is compared
    as an identity in q, dq, t and p.
    """
    rng = np.random.default_rng(seed)
    size = len(system.q)
    scale = length_scale(system)
    angle = np.array([name.endswith(".phi") for name in system.coordinates])
    nominal = np.array(system.p_values, dtype=float)
    t0, t1, _ = system.time_grid
    states = []
    for _ in range(samples):
        q = np.where(angle, rng.uniform(-np.pi, np.pi, size), rng.uniform(-2, 2, size) * scale)
        dq = np.where(angle, rng.uniform(-2, 2, size), rng.uniform(-1, 1, size) * scale)
        u = rng.uniform(-1, 1, len(nominal))
        p = np.where(nominal != 0, nominal * (1 + spread * u), spread * scale * u)
        states.append(State(q, dq, float(rng.uniform(t0, t1)), p))
    return states


# ----- the hand side --------------------------------------------------------------------------

def load_hand_module(path: str | Path) -> ModuleType:
    """Run a hand-derivation file and return it as a module (loaded by path, not via sys.path)."""
    path = Path(path)
    if not path.is_file():
        what = "is a folder" if path.is_dir() else \
            "is not a regular file" if path.exists() else "does not exist"
        raise HandModuleError(f"{path} {what}; give the Python file that defines "
                              f"{', '.join(SIGNATURES.values())}")
    name = f"_symkin_hand_{abs(hash(str(path.resolve())))}"
    spec = importlib.util.spec_from_file_location(name, path)
    if spec is None or spec.loader is None:
        raise HandModuleError(f"{path} cannot be loaded as a Python module; use a .py file")
    module = importlib.util.module_from_spec(spec)
    # Registered only while it runs: decorators such as @dataclass look their module up.
    sys.modules[name] = module
    try:
        spec.loader.exec_module(module)
    except BaseException as error:  # any failure of the user's file (SystemExit too) is bad input
        if isinstance(error, KeyboardInterrupt):
            raise
        raise HandModuleError(f"{path}: running the file failed: {describe(error, path)}"
                              ) from error
    finally:
        sys.modules.pop(name, None)
    return module


def describe(error: BaseException, path: str | Path | None = None) -> str:
    """``IndexError: index 9 is out of bounds (line 42)`` — the error and where in the file."""
    text = f"{type(error).__name__}: {error}".rstrip(": ")
    if isinstance(error, SyntaxError) and error.lineno:
        return f"{type(error).__name__}: {error.msg} (line {error.lineno})"
    frames: list[traceback.FrameSummary] = list(traceback.extract_tb(error.__traceback__))
    if path is not None:
        target = str(Path(path).resolve())
        frames = [f for f in frames if str(Path(f.filename).resolve()) == target] or frames
    if frames:
        last = frames[-1]
        return f"{text} (line {last.lineno}: {(last.line or '').strip()})"
    return text


def _hand_functions(hand: Any, origin: str) -> dict[str, Callable[..., Any]]:
    found = {}
    for name in FUNCTIONS:
        function = getattr(hand, name, None)
        if function is None:
            continue
        if not callable(function):
            raise HandModuleError(f"{origin}: {name} is a {type(function).__name__}, not a "
                                  f"function; define {SIGNATURES[name]}")
        found[name] = function
    if not found:
        raise HandModuleError(f"{origin} defines none of {', '.join(SIGNATURES.values())}; "
                              "define at least one")
    return found


def _check_order(hand: Any, origin: str, attribute: str, expected: Sequence[str]) -> None:
    """A hand module may declare COORDINATES or PARAMETERS; then they must be symkin's order."""
    declared = getattr(hand, attribute, None)
    if declared is None:
        return
    if [str(item) for item in declared] != list(expected):
        raise HandModuleError(
            f"{origin}: it declares {attribute} = {', '.join(map(str, declared))}, but the "
            f"mechanism's {attribute.lower()} are {', '.join(expected) or 'none'} (in the order "
            f"`symkin show` prints); was it written for another mechanism file?")


def _call_hand(name: str, function: Callable[..., Any], state: State, origin: str,
               shape: tuple[int, ...]) -> np.ndarray:
    args: tuple[Any, ...] = (state.q.copy(), state.t, state.p.copy())
    if name == "gamma":
        args = (state.q.copy(), state.dq.copy(), state.t, state.p.copy())
    try:
        value = function(*args)
    except (Exception, SystemExit) as error:  # the user's code: report it, do not crash
        code = getattr(function, "__code__", None)
        where = describe(error, code.co_filename if code else None)
        raise HandModuleError(f"{origin}: {SIGNATURES[name]} raised {where}") from error
    return _as_array(name, value, origin, shape)


def _as_array(name: str, value: Any, origin: str, shape: tuple[int, ...]) -> np.ndarray:
    if hasattr(value, "toarray"):  # a SciPy sparse matrix
        value = value.toarray()
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as error:
        raise HandModuleError(f"{origin}: {SIGNATURES[name]} returned {type(value).__name__}, "
                              f"not numbers ({error})") from None
    if len(shape) == 1 and array.shape in ((shape[0], 1), (1, shape[0])):
        array = array.reshape(shape)
    if array.shape != shape:
        want = " x ".join(map(str, shape))
        raise HandModuleError(f"{origin}: {SIGNATURES[name]} returned shape {array.shape}, "
                              f"expected {want} (rows and coordinates in the order "
                              f"`symkin show` prints)")
    return array


# ----- the comparison -------------------------------------------------------------------------

@dataclass(frozen=True)
class Mismatch:
    """One entry of one function where the hand derivation differs from the derived one."""

    function: str
    row: int
    column: int | None
    owner: str  # the row's joint or driver, e.g. "joints[2] revolute rod-slider (x)"
    coordinate: str | None  # the column's coordinate (Phi_q only)
    derived: str  # the derived expression, as `symkin show` prints it
    derived_value: float
    hand_value: float
    error: float  # the worst relative error over the samples
    sample: int  # the sample where it is worst
    failing: int  # in how many samples the entry differs
    state: State | None = None  # the state of that sample

    @property
    def entry(self) -> str:
        where = f"{self.row}, {self.column}" if self.column is not None else f"{self.row}"
        return f"{self.function}[{where}]"


@dataclass(frozen=True)
class FunctionResult:
    name: str
    entries: int
    mismatches: tuple[Mismatch, ...]


@dataclass(frozen=True)
class Report:
    """The outcome of :func:`verify`; ``ok`` when every compared entry matches."""

    mechanism: str
    origin: str
    samples: int
    seed: int
    spread: float
    tolerance: float
    results: tuple[FunctionResult, ...]
    skipped: tuple[str, ...] = field(default=())
    scale: float = 1.0  # the length scale L used for zero parameters and positions

    @property
    def ok(self) -> bool:
        return not self.mismatches

    @property
    def mismatches(self) -> tuple[Mismatch, ...]:
        return tuple(m for result in self.results for m in result.mismatches)

    def text(self) -> str:
        """The report as ``symkin verify`` prints it."""
        return format_report(self)


def verify(target: Mechanism | System | Derived | str | Path, hand: Any, *,
           samples: int = DEFAULT_SAMPLES, seed: int = 0, spread: float = DEFAULT_SPREAD,
           tolerance: float = DEFAULT_TOLERANCE) -> Report:
    """Compare a hand derivation with the derived one at random states and parameters.

    Args:
        target: the mechanism (file path, Mechanism, System, or :func:`derived_functions`).
        hand: a module, any object with some of the attributes ``phi``, ``phi_q``, ``phi_t``,
            ``gamma``, or the path of a Python file defining them.
        samples: how many random (q, dq, t, p) to try.
        seed: seed of the random states; the same seed gives the same report.
        spread: relative spread of the parameters around the nominal design (0 keeps them
            nominal).
        tolerance: largest accepted relative error of an entry.

    Raises:
        HandModuleError: the hand file is missing or broken, a function raises or returns the
            wrong shape.
    """
    derived = target if isinstance(target, Derived) else derived_functions(
        target if isinstance(target, System) else derive(target))
    origin = str(hand)
    if isinstance(hand, (str, Path)):
        hand = load_hand_module(hand)
    else:
        origin = getattr(hand, "__file__", None) or getattr(hand, "__name__", None) or \
            type(hand).__name__
    system = derived.system
    _check_order(hand, origin, "COORDINATES", system.coordinates)
    _check_order(hand, origin, "PARAMETERS", system.parameter_names)
    functions = _hand_functions(hand, origin)
    states = sample_states(system, samples, seed, spread)
    results = tuple(_compare_function(derived, name, function, states, origin, tolerance)
                    for name, function in functions.items())
    return Report(system.name, origin, samples, seed, spread, tolerance, results,
                  tuple(name for name in FUNCTIONS if name not in functions),
                  length_scale(system))


def _compare_function(derived: Derived, name: str, function: Callable[..., Any],
                      states: list[State], origin: str, tolerance: float) -> FunctionResult:
    rows = len(derived.system.rows)
    shape = (rows, derived.size) if name == "phi_q" else (rows,)
    hand = np.array([_call_hand(name, function, s, origin, shape) for s in states])
    ours = np.array([derived.evaluate(name, s).reshape(shape) for s in states])
    errors = relative_errors(ours, hand, FLOOR_OF_LENGTH * length_scale(derived.system))
    bad = errors > tolerance
    mismatches = []
    for index in zip(*np.nonzero(bad.any(axis=0))):
        worst = int(np.argmax(errors[(slice(None), *index)]))
        row, column = int(index[0]), (int(index[1]) if len(index) > 1 else None)
        mismatches.append(Mismatch(
            function=name, row=row, column=column, owner=str(derived.system.rows[row]),
            coordinate=derived.system.coordinates[column] if column is not None else None,
            derived=show_expression(derived.system, derived.expression(name, row, column)),
            derived_value=float(ours[(worst, *index)]), hand_value=float(hand[(worst, *index)]),
            error=float(errors[(worst, *index)]), sample=worst,
            failing=int(bad[(slice(None), *index)].sum()), state=states[worst]))
    return FunctionResult(name, int(np.prod(shape)), tuple(mismatches))


def relative_errors(derived: np.ndarray, hand: np.ndarray, least: float = 0.0) -> np.ndarray:
    """|hand - derived| / max(|hand|, |derived|, floor), per sample and entry.

    The floor is FLOOR_FRACTION of the function's largest derived value over all samples, and
    at least ``least``; a non-finite hand value where the derived one is finite counts as an
    infinite error, and samples where the derived value itself is not finite are not judged.
    """
    finite = np.isfinite(derived)
    magnitude = np.abs(np.where(finite, derived, 0.0))
    floor = max(FLOOR_FRACTION * magnitude.max(initial=0.0), least)
    with np.errstate(invalid="ignore", over="ignore"):
        scale = np.maximum(np.maximum(magnitude, np.abs(hand)), floor)
        difference = np.abs(hand - derived)
        errors = np.where(difference == 0, 0.0,
                          difference / np.where(scale > 0, scale, 1.0))
    errors = np.where(np.isfinite(hand), errors, np.inf)
    return np.where(finite, errors, 0.0)


def show_expression(system: System, expr: sp.Expr) -> str:
    """An expression as ``symkin show`` prints it: rates of coordinates as ``crank.phi'``."""
    rates = {dq: sp.Symbol(f"{name}'") for dq, name in zip(system.dq, system.coordinates)}
    return sp.sstr(sp.sympify(expr).xreplace(rates))


# ----- the text report ------------------------------------------------------------------------

def format_report(report: Report) -> str:
    lines = [f"verify {report.mechanism} against {report.origin}",
             f"  {report.samples} random states (q, dq, t), parameters "
             + (f"within ±{report.spread:.0%} of the nominal design (zero ones within "
                f"±{report.spread * report.scale:g})" if report.spread
                else "at the nominal design")
             + f", seed {report.seed}, tolerance {report.tolerance:g}"]
    for result in report.results:
        count = len(result.mismatches)
        verdict = "all match" if not count else f"{count} mismatching entr" + \
            ("y" if count == 1 else "ies")
        lines.append(f"  {result.name:<6} {result.entries:>5} entries  {verdict}")
    lines += [f"  {name:<6} not defined, skipped" for name in report.skipped]
    for m in report.mismatches:
        lines += ["", *_format_mismatch(m, report.samples)]
    owners: dict[str, list[str]] = {}
    for m in report.mismatches:
        owners.setdefault(m.owner.rsplit(" (", 1)[0], []).append(m.entry)
    if owners:
        lines += ["", "where:"]
        lines += [f"  {owner}: {', '.join(entries)}" for owner, entries in owners.items()]
    lines += ["", "OK: the hand derivation matches" if report.ok else
              f"MISMATCH: {len(report.mismatches)} entr"
              f"{'y differs' if len(report.mismatches) == 1 else 'ies differ'}"]
    return "\n".join(lines) + "\n"


def _format_mismatch(m: Mismatch, samples: int) -> list[str]:
    column = f", column {m.column} (d/d {m.coordinate})" if m.column is not None else ""
    return [f"{m.entry}: row {m.row} {m.owner}{column}",
            f"  derived:  {m.derived}",
            (f"  values:   derived {m.derived_value:.12g}, hand {m.hand_value:.12g} "
             f"(sample {m.sample})"),
            f"  worst relative error {m.error:.3g}; differs in {m.failing} of {samples} samples"]


# ----- the command ----------------------------------------------------------------------------

def command(mechanism: str | Path, against: str | Path, *, samples: int = DEFAULT_SAMPLES,
            seed: int = 0, spread: float = DEFAULT_SPREAD,
            tolerance: float = DEFAULT_TOLERANCE) -> int:
    """``symkin verify MECH --against HAND.py``: print the report, return the exit status.

    0 when every entry matches, 1 when some differ, 2 for bad input (the hand file is missing,
    fails to run, raises, or returns the wrong shape; bad options). Errors in the mechanism
    file are raised as MechanismError for the CLI to report.
    """
    problem = _option_problem(samples, spread, tolerance)
    if problem:
        print(f"symkin verify: error: {problem}", file=sys.stderr)
        return 2
    system = derive(mechanism)
    try:
        report = verify(system, against, samples=samples, seed=seed, spread=spread,
                        tolerance=tolerance)
    except HandModuleError as error:
        print(f"symkin verify: error: {error}", file=sys.stderr)
        return 2
    print(report.text(), end="")
    return 0 if report.ok else 1


def _option_problem(samples: int, spread: float, tolerance: float) -> str | None:
    if samples < 1:
        return f"--samples {samples}: give at least 1"
    if not (math.isfinite(spread) and spread >= 0):
        return f"--spread {spread}: give a number >= 0, e.g. 0.3"
    if not (math.isfinite(tolerance) and tolerance > 0):
        return f"--tolerance {tolerance}: give a positive number, e.g. 1e-8"
    return None


# ----- the symbolic route ---------------------------------------------------------------------

@dataclass(frozen=True)
class EntryComparison:
    """The verdict on one entry: equal (and how it was decided) or different (and where)."""

    row: int
    column: int
    derived: sp.Expr
    hand: sp.Expr
    equal: bool | None  # None: neither simplification nor sampling could decide
    method: str  # "identical", "simplification", "numeric" or "counterexample"
    point: dict[sp.Symbol, float] | None = None  # a point where they differ
    derived_value: complex | None = None
    hand_value: complex | None = None


@dataclass(frozen=True)
class Comparison:
    """The outcome of :func:`compare`, entry by entry."""

    shape: tuple[int, int]
    entries: tuple[EntryComparison, ...]
    row_labels: tuple[str, ...] | None = None  # the owners of the rows, given a System
    column_labels: tuple[str, ...] | None = None  # the coordinates of the columns

    @property
    def equal(self) -> bool:
        return all(entry.equal for entry in self.entries)

    @property
    def differences(self) -> tuple[EntryComparison, ...]:
        return tuple(entry for entry in self.entries if not entry.equal)

    def __bool__(self) -> bool:
        return self.equal

    def text(self) -> str:
        if self.equal:
            return f"all {len(self.entries)} entries are equal\n"
        lines = []
        for e in self.differences:
            where = f"[{e.row}]" if self.shape[1] == 1 else f"[{e.row}, {e.column}]"
            if self.row_labels:
                where += f" {self.row_labels[e.row]}"
            if self.column_labels and self.shape[1] > 1:
                where += f", d/d {self.column_labels[e.column]}"
            if e.equal is None:
                lines.append(f"{where}: undecided: {sp.sstr(e.derived)} vs {sp.sstr(e.hand)}")
                continue
            point = ", ".join(f"{s}={v:.6g}" for s, v in (e.point or {}).items())
            lines.append(f"{where}: derived {sp.sstr(e.derived)} = {_num(e.derived_value)}, "
                         f"hand {sp.sstr(e.hand)} = {_num(e.hand_value)} at {point}")
        return "\n".join(lines) + "\n"


def _num(value: complex | None) -> str:
    if value is None:
        return "?"
    return f"{value.real:.12g}" if value.imag == 0 else f"{value:.6g}"


def compare(derived: Any, hand: Any, *, system: System | None = None, samples: int = 8,
            seed: int = 0, tolerance: float = 1e-12) -> Comparison:
    """Compare two SymPy expressions or matrices entry by entry.

    An entry is equal when the difference is identically zero or simplifies to zero; when
    simplification does not get there, it is evaluated at ``samples`` random points (30 digits):
    a point where the two differ by more than ``tolerance`` (relative) proves them different,
    agreement at every point counts as equal ("numeric"). Symbols of ``hand`` that have the
    name of a symbol of ``derived`` but other assumptions (``Symbol("a")`` against
    ``Symbol("a", real=True)``) are taken to be that symbol. Given the ``system`` the
    matrices come from, differences are labelled with the row's joint or driver and the
    column's coordinate.

    Raises:
        SymkinError: the shapes differ or an argument is not a SymPy expression or matrix.
    """
    left, right = _as_matrix(derived, "derived"), _as_matrix(hand, "hand")
    if left.shape != right.shape:
        raise SymkinError(f"the derived matrix is {left.shape[0]} x {left.shape[1]} but the "
                          f"hand one is {right.shape[0]} x {right.shape[1]}")
    right = right.xreplace(_same_names(left, right))
    rng = np.random.default_rng(seed)
    entries = tuple(_compare_entry(r, k, left[r, k], right[r, k], rng, samples, tolerance)
                    for r in range(left.rows) for k in range(left.cols))
    rows = columns = None
    if system is not None and left.rows == len(system.rows):
        rows = tuple(str(row) for row in system.rows)
        columns = system.coordinates if left.cols == len(system.q) else None
    return Comparison(left.shape, entries, rows, columns)


def _as_matrix(value: Any, which: str) -> sp.ImmutableMatrix:
    if isinstance(value, sp.MatrixBase):
        return sp.ImmutableMatrix(value)
    if isinstance(value, (sp.Basic, int, float)):
        return sp.ImmutableMatrix([[sp.sympify(value)]])
    raise SymkinError(f"the {which} argument is a {type(value).__name__}; give a SymPy "
                      "expression or matrix")


def _same_names(left: sp.MatrixBase, right: sp.MatrixBase) -> dict[sp.Symbol, sp.Symbol]:
    ours = {s.name: s for s in left.free_symbols if isinstance(s, sp.Symbol)}
    return {s: ours[s.name] for s in right.free_symbols
            if isinstance(s, sp.Symbol) and s.name in ours and ours[s.name] != s}


def _compare_entry(row: int, column: int, d: sp.Expr, h: sp.Expr, rng: np.random.Generator,
                   samples: int, tolerance: float) -> EntryComparison:
    def entry(equal: bool | None, method: str, **found: Any) -> EntryComparison:
        return EntryComparison(row, column, d, h, equal, method, **found)

    difference = sp.sympify(d - h)
    if difference == 0:
        return entry(True, "identical")
    evidence = _counterexample(d, h, rng, samples, tolerance)
    if evidence is not None and evidence[0] is not None:
        point, dv, hv = evidence
        return entry(False, "counterexample", point=point, derived_value=dv, hand_value=hv)
    if sp.simplify(difference) == 0:
        return entry(True, "simplification")
    # Every sampled point agreed (or none could be evaluated): a numeric verdict.
    return entry(True if evidence is not None else None, "numeric")


def _counterexample(d: sp.Expr, h: sp.Expr, rng: np.random.Generator, samples: int,
                    tolerance: float) -> tuple[Any, Any, Any] | None:
    """(point, derived value, hand value) where they differ; (None,)*3 if all agree; None if
    no sample could be evaluated."""
    symbols = sorted((d - h).free_symbols | d.free_symbols | h.free_symbols, key=str)
    evaluated = 0
    for _ in range(samples):
        point = {s: _random_value(s, rng) for s in symbols}
        exact = {s: sp.Float(v, 30) for s, v in point.items()}
        try:
            dv = complex(sp.sympify(d).evalf(30, subs=exact))
            hv = complex(sp.sympify(h).evalf(30, subs=exact))
        except (TypeError, ValueError, ZeroDivisionError):
            continue
        if not (np.isfinite(dv) and np.isfinite(hv)):
            continue
        evaluated += 1
        if abs(dv - hv) > tolerance * max(abs(dv), abs(hv), 1.0):
            return point, dv, hv
    return (None, None, None) if evaluated else None


def _random_value(symbol: sp.Symbol, rng: np.random.Generator) -> float:
    if symbol.is_integer:
        return float(rng.integers(1, 5))
    if symbol.is_positive or symbol.is_nonnegative:
        return float(rng.uniform(0.2, 2.0))
    if symbol.is_negative or symbol.is_nonpositive:
        return float(-rng.uniform(0.2, 2.0))
    return float(rng.uniform(-2.0, 2.0))

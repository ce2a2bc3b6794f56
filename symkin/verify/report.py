"""The outcome of a numeric verification and its text report."""

from __future__ import annotations

from dataclasses import dataclass, field

from symkin.verify.sampling import State


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
    base: int = 0  # 1 for a MATLAB hand file: its rows and columns counted from 1, as in it

    @property
    def entry(self) -> str:
        row, column = self.row + self.base, (self.column or 0) + self.base
        where = f"{row}, {column}" if self.column is not None else f"{row}"
        return f"{self.function}({where})" if self.base else f"{self.function}[{where}]"


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
    states: str = ""  # what the samples were, when not random states (a MATLAB hand file's)

    @property
    def ok(self) -> bool:
        return not self.mismatches

    @property
    def mismatches(self) -> tuple[Mismatch, ...]:
        return tuple(m for result in self.results for m in result.mismatches)

    def text(self) -> str:
        """The report as ``symkin verify`` prints it."""
        return format_report(self)




# ----- the text report ------------------------------------------------------------------------

def format_report(report: Report) -> str:
    lines = [f"verify {report.mechanism} against {report.origin}",
             f"  {report.samples} "
             + (report.states or "random states (q, dq, t)") + ", parameters "
             + (f"within ±{report.spread:.0%} of the nominal design (zero ones within "
                f"±{report.spread * report.scale:g})" if report.spread
                else "at the nominal design")
             + f", seed {report.seed}, tolerance {report.tolerance:g}"]
    width = max([6, *(len(r.name) for r in report.results)])
    for result in report.results:
        count = len(result.mismatches)
        verdict = "all match" if not count else f"{count} mismatching entr" + \
            ("y" if count == 1 else "ies")
        lines.append(f"  {result.name:<{width}} {result.entries:>5} entries  {verdict}")
    lines += [f"  {name:<{width}} not defined, skipped" for name in report.skipped]
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
    column = (f", column {m.column + m.base} (d/d {m.coordinate})" if m.column is not None
              else "")
    return [f"{m.entry}: row {m.row + m.base} {m.owner}{column}",
            f"  derived:  {m.derived}",
            (f"  values:   derived {m.derived_value:.12g}, hand {m.hand_value:.12g} "
             f"(sample {m.sample})"),
            f"  worst relative error {m.error:.3g}; differs in {m.failing} of {samples} samples"]

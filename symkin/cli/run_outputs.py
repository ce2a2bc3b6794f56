"""What ``symkin run`` writes and prints: results files, figures, the report, the animation,
one configuration (``--at``), progress bars, and notes that say whether an event matters.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import os
import sys
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, NamedTuple, TextIO

from symkin.limits import listed, listed_groups

# NumPy and the figures' series are imported where used: `symkin --help` builds this command's
# parser and must not pay for them.
if TYPE_CHECKING:
    from symkin.present.series import Units
    from symkin.runtime.solving.start import Moved


class CannotWrite(Exception):
    """An output file could not be written (a bad path, not a failed solve)."""


class Pictures(NamedTuple):  # not a dataclass: `symkin --help` then imports no `inspect`
    """What the figures show: the selection (None: the default), units and title."""

    select: list[str] | None
    units: Units
    title: str

    @classmethod
    def of(cls, args: argparse.Namespace, kernel: Any) -> Pictures:
        """From the command line and the kernel; an unknown ``--select`` name is a UsageError
        listing the valid ones (raised before anything is solved)."""
        from symkin.present import series

        select = None
        if args.select is not None:
            select = series.check_selection(series.parse_selection(args.select),
                                            kernel.coordinates, kernel.points)
        # The file is read again only for pictures: a plain warm run stays free of YAML.
        wanted = args.plot is not None or args.html is not None
        return cls(select, units_of(args.mechanism) if wanted else series.Units(), kernel.name)


def units_of(mechanism: Path) -> Units:
    """The file's ``units`` (validated with the file: on a warm run it was valid before)."""
    from symkin.errors import SymkinError
    from symkin.present.series import Units
    from symkin.spec import loader

    try:
        data = loader.read(mechanism).data
    except (SymkinError, OSError):  # validated by the run; a file changed since loses labels
        return Units()
    return Units.of(data.get("units") if isinstance(data, dict) else None)


def write(trajectory: Any, args: argparse.Namespace, outlines: Any,
          picture: Pictures) -> list[Path]:
    """Write every file asked for; returns their paths. OSError goes to the caller."""
    written = []
    if args.output:
        written.append(trajectory.save(args.output))
    if trajectory.t.size == 0:
        return written
    if args.plot:
        from symkin.present import plots

        written.append(plots.plot(trajectory, args.plot, picture.select, picture.units,
                                  picture.title))
        if trajectory.forces is not None:  # efforts and reactions: a figure of their own
            from symkin.present import force_plots

            written.append(force_plots.plot_forces(
                trajectory, force_plots.forces_path(args.plot), picture.title, picture.units))
    if args.html:
        from symkin.present import html

        written.append(html.report(trajectory, args.html, outlines or {}, picture.select,
                                   picture.units, picture.title))
    if args.animate:
        from symkin.present import animation

        bar = ProgressBar(sys.stderr, "drawing", "frame") if sys.stderr.isatty() else None
        try:
            written.append(animation.animate(trajectory, args.animate, outlines or {},
                                             fps=args.fps, size=animation.parse_size(args.size),
                                             progress=bar))
        finally:
            if bar:
                bar.finish()
    return written


def configuration(trajectory: Any, name: str, origin: str) -> str:
    """One solved instant as text: every coordinate with its first and second derivative, then
    every named point's position, velocity and acceleration (2.14-2.16)."""
    import numpy as np

    t = float(trajectory.t[0])
    lines = [f"{name} at t = {t:.10g} ({origin})", "",
             f"{'coordinate':<24}{'q':>20}{'dq/dt':>20}{'d2q/dt2':>20}"]
    # "+ 0.0" below prints a negative zero as 0. Each number has a space before it: the
    # longest, -1.23456789012e-100, still fills its field without running into the next.
    for k, coordinate in enumerate(trajectory.coordinates):
        lines.append(f"{coordinate:<24}" + "".join(
            f" {float(values[0, k]) + 0.0:>19.12g}" for values in (trajectory.q, trajectory.dq,
                                                            trajectory.d2q)))
    if trajectory.points:
        lines += ["", f"{'point':<24}" + "".join(f"{h:>18}" for h in
                                                  ("x", "y", "vx", "vy", "ax", "ay"))]
        for body, point in trajectory.points:
            r, dr, ddr = trajectory.point(body, point)
            numbers = np.concatenate([r[0], dr[0], ddr[0]])
            lines.append(f"{body + '.' + point:<24}"
                         + "".join(f" {float(v) + 0.0:>17.10g}" for v in numbers))
    return "\n".join(lines) + "\n"


@contextlib.contextmanager
def interrupts_held() -> Iterator[None]:
    """Ctrl-C (SIGINT) ignored while the rows solved so far are written after an interrupt:
    a second Ctrl-C would otherwise leave no file, or half of one. Only in the main thread
    (where Python handles signals); elsewhere nothing changes."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


class Deferred:
    """Whether a Ctrl-C came while interrupts were deferred (``interrupts_deferred``)."""

    def __init__(self) -> None:
        self.interrupted = False

    def __call__(self, signum: int, frame: Any) -> None:
        self.interrupted = True


@contextlib.contextmanager
def interrupts_deferred() -> Iterator[Deferred]:
    """Ctrl-C (SIGINT) noted, not raised, while a solved run's outputs are prepared and
    written: the files are finished whole with every row solved, and the caller then says
    it was interrupted. Only in the main thread; elsewhere nothing is deferred."""
    import signal  # here, not at the top: symkin --help stays light
    import threading

    deferred = Deferred()
    if threading.current_thread() is not threading.main_thread():
        yield deferred
        return
    previous = signal.signal(signal.SIGINT, deferred)
    try:
        yield deferred
    finally:
        signal.signal(signal.SIGINT, previous)


def fallback_note(count: int, points: int, verbose: bool = False) -> str:
    """A line on sparse-LU fall-backs, which cost time, not accuracy; ``verbose`` says why."""
    which = "factorization" if count == 1 else "factorizations"
    short = (f"{count} pivot fall-back{'s' if count != 1 else ''} to dense LU over {points} "
             "time points (time, not accuracy")
    if not verbose:
        return short + "; -v says why)"
    return (short + f"): {count} {which} of the generated sparse LU met a pivot below its "
            "threshold and were redone with dense LU and partial pivoting; every pivot is "
            "checked, and no result comes from a rejected one")


def far_start_note(moved: Sequence[Moved], scale: float) -> str:
    """A line on bodies assembled far from their q0 (runtime.solving.start.far_from_guess)."""
    said = listed(f"{m.body} (moved {m.distance:.3g}, turned {m.turn:.3g} rad)"
                  for m in moved)
    return (f"the assembled start is far from q0 (the mechanism's length scale is "
            f"{scale:.3g}): {said}. The motion is that of the mechanism the joints describe; "
            "if it is not the one you meant, check q0, and that each prismatic or pin_slot "
            "`v` is the slide's normal, not its direction (in the drawn layout `axis` is the "
            "direction)")


class ProgressBar:
    """A progress bar on a terminal (tqdm: count, rate and time left), for any loop that
    reports ``(done, total)``: the solver's grid, in C or in Python, or animation frames."""

    def __init__(self, stream: TextIO, label: str = "solving", unit: str = "point") -> None:
        self.stream = stream
        self.label = label
        self.unit = unit
        self._bar: Any = None

    def __call__(self, done: int, total: int) -> None:
        if self._bar is None:
            from tqdm import tqdm

            # A terminal that reports its size as 0 x 0 (some pseudo-terminals) would get no
            # bar at all from tqdm: give it the usual 80 x 24 then.
            try:
                size = os.get_terminal_size(self.stream.fileno())
            except (OSError, ValueError, io.UnsupportedOperation):
                size = os.terminal_size((0, 0))
            known = size.columns > 0 and size.lines > 0
            self._bar = tqdm(total=total, file=self.stream, desc=self.label, unit=self.unit,
                             mininterval=0.1, dynamic_ncols=known, leave=True,
                             ncols=None if known else 80, nrows=None if known else 24)
        self._bar.update(done - self._bar.n)

    def finish(self) -> None:
        if self._bar is not None:
            self._bar.close()
            self._bar = None


def flag_warnings(trajectory: Any) -> list[str]:
    """``warning: ... at t = ...`` for each stretch of flagged points: where, Phi_q's worst
    condition there (which need not be the cause: fast rates amplify a small error too), and
    the singular configuration passed there with its dependent rows."""
    from symkin.contract.options import Options

    targets = Options()
    flagged = list(trajectory.flagged)
    lines = []
    k = 0
    while k < len(flagged):
        if not flagged[k]:
            k += 1
            continue
        end = k
        while end + 1 < len(flagged) and flagged[end + 1]:
            end += 1
        t0, t1 = float(trajectory.t[k]), float(trajectory.t[end])
        where = f"t = {t0:.10g}" if k == end else f"t = {t0:.10g} .. {t1:.10g}"
        count = end - k + 1
        worst = max(float(c) for c in trajectory.cond[k:end + 1])
        passed = [s for s in trajectory.singular
                  if t0 - _step(trajectory, k) <= s[0] <= t1 + _step(trajectory, end + 1)]
        broken = _broken_removed(trajectory, k, end, targets.target_q)
        loads = _not_finite_loads(trajectory, k, end)
        if loads:
            lines.append(f"warning: {count} point{'s' if count > 1 else ''} flagged at {where}: "
                         f"efforts or reactions are not finite there ({loads}): a load of the "
                         "file is infinite or undefined at that time (a force such as "
                         "1/(t - 0.5) at its pole), or Phi_q is singular; they are written as "
                         "inf or nan (column 'flagged')")
            if not (passed or broken):  # flagged for its loads: no word of accuracy
                k = end + 1
                continue
        if broken:
            lines.append(f"warning: {count} point{'s' if count > 1 else ''} flagged at {where}: "
                         f"the equation(s) removed as redundant at t0 do not hold there "
                         f"({broken}), so the file's joints contradict each other along the "
                         "motion and q, dq, ddq satisfy only the kept equations (column "
                         "'flagged'); check the dimensions of the joints named")
            k = end + 1
            continue
        if passed and _moves_under_forces(trajectory):
            lines.append(_dynamics_passage(count, where, worst, passed))
            k = end + 1
            continue
        detail = "".join(
            f"; a singular configuration is passed at t = {t:.10g} (Phi_q loses rank {rank}; "
            f"dependent rows: {listed_groups(groups)}), its "
            "point(s) interpolated from both sides" for t, rank, groups in passed)
        lines.append(f"warning: {count} point{'s' if count > 1 else ''} flagged at {where}: "
                     f"the error model says q, dq, ddq may miss {targets.target_q:g}, "
                     f"{targets.target_dq:g}, {targets.target_ddq:g} there (Phi_q's condition "
                     f"up to {worst:.3g}; column 'flagged'){detail}")
        k = end + 1
    return lines


def _moves_under_forces(trajectory: Any) -> bool:
    """A forward-dynamics run (its energy outputs), whose rows are integrated, not solved
    point by point."""
    return any(name == "kinetic_energy" for name, _ in trajectory.outputs)


def _dynamics_passage(count: int, where: str, worst: float, passed: list[Any]) -> str:
    """The warning of a forward-dynamics run that went through a singular configuration:
    the motion is determinate there (its rows are integrated), only Phi_q is singular."""
    detail = "; ".join(
        f"t = {t:.10g} (Phi_q loses rank {rank}; dependent rows: "
        f"{listed_groups(groups)})" for t, rank, groups in passed)
    return (f"warning: {count} point{'s' if count > 1 else ''} flagged at {where}: the motion "
            f"passes a singular configuration at {detail}; it went on through it on its "
            "branch, the rows integrated as any other (the equations of motion's condition "
            f"up to {worst:.3g}; column 'flagged'); --stop-at-singular stops there")


def removed_note(trajectory: Any) -> str:
    """The note of a run whose file had rows removed as redundant at t0."""
    count = len(trajectory.removed)
    return (f"{count} equation{'s' if count > 1 else ''} removed as redundant (dependent on "
            f"the others at the assembled t0) and checked along the motion: "
            + listed(trajectory.removed, "; "))


def indeterminate_note(trajectory: Any) -> str:
    """The note naming the efforts and reactions that the removed rows leave indeterminate
    (empty when there is none, or no forces)."""
    forces = getattr(trajectory, "forces", None)
    names = forces.indeterminate() if forces is not None else []
    if not names:
        return ""
    return ("with equations removed as redundant these reactions are not unique (the rows "
            "can share the load in any proportion); their values are the minimum-norm "
            "solution (NPZ effort_determinate, reaction_determinate): " + listed(names))


def _broken_removed(trajectory: Any, k: int, end: int, target: float) -> str:
    """The removed rows that miss the target between points k and end, with their largest
    |Phi| there ('' when none does)."""
    residual = getattr(trajectory, "removed_residual", None)
    if residual is None or not trajectory.removed:
        return ""
    from symkin.runtime.outputs import redundant

    stretch = residual[k:end + 1]
    broken: Any = redundant.exceeded(stretch, trajectory.q[k:end + 1], target).any(axis=0)
    return listed((f"{label}: |Phi| up to {float(abs(stretch[:, r]).max()):.3g}"
                   for r, label in enumerate(trajectory.removed) if broken[r]), "; ")


def _not_finite_loads(trajectory: Any, k: int, end: int) -> str:
    """The efforts and reactions that are inf or NaN between points k and end, at most ten
    named ('' when every one is finite)."""
    import numpy as np  # here, not at the top: symkin --help stays light

    found = getattr(trajectory, "forces", None)
    if found is None:
        return ""
    rows = np.zeros(trajectory.t.size, dtype=bool)
    rows[k:end + 1] = True
    return listed(found.not_finite_columns(rows))


def _step(trajectory: Any, k: int) -> float:
    """The grid step before point k (0 at the ends)."""
    return float(trajectory.t[k] - trajectory.t[k - 1]) if 0 < k < trajectory.t.size else 0.0

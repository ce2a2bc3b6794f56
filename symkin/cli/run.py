"""``symkin run``: solve a mechanism over its time grid and write the results.

A thin layer over symkin.derive -> symkin.compile -> symkin.solve -> Trajectory.save / plots.
The kernel comes through the index of symkin/cache.py: a second run of an unchanged file loads
the cached kernel and its metadata directly, and never imports SymPy, pydantic or jinja2.
Exit status 0 on success; 1 when the solve fails (the rows solved so far are still written);
2 for bad input (a message, never a traceback).
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path
from typing import Any, TextIO

from symkin import limits
from symkin.cli import messages
from symkin.cli.exits import EXIT_BAD_INPUT, EXIT_FAILED, EXIT_INTERRUPTED, EXIT_OK

SUFFIXES = {"output": (".npz", ".csv"), "plot": (".png",), "animate": (".gif",)}


def add_parser(commands: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add the ``run`` subcommand."""
    run = commands.add_parser(
        "run", help="solve positions, velocities and accelerations over the time grid")
    run.add_argument("mechanism", type=Path, help="mechanism file (.yaml or .toml)")
    run.add_argument("--backend", choices=("auto", "c", "numpy"), default="auto",
                     help="kernel to run (default auto: the generated C when a C compiler is "
                          "found, else NumPy; c without a compiler is an error)")
    run.add_argument("--t0", type=float, help="first time (default: the file's)")
    run.add_argument("--t1", type=float, help="last time, included (default: the file's)")
    run.add_argument("--dt", type=float, help="time step (default: the file's)")
    run.add_argument("-o", "--output", type=Path, help="results file, .npz or .csv")
    run.add_argument("--plot", type=Path, help="PNG of coordinates and point paths against t")
    run.add_argument("--animate", type=Path, help="GIF of the mechanism moving")
    run.add_argument("--stop-at-singular", action="store_true",
                     help="stop at the first singular or ill-conditioned point instead of "
                          "passing through it (and do not subdivide a failed step)")
    run.set_defaults(handler=handle)


def _bad_usage(args: argparse.Namespace) -> str | None:
    """What is wrong with the command line, before any work is done."""
    for option, suffixes in SUFFIXES.items():
        path = getattr(args, option)
        if path is not None and path.suffix.lower() not in suffixes:
            return (f"--{option} {path}: the file must end in {' or '.join(suffixes)}")
    for option in ("t0", "t1", "dt"):
        value = getattr(args, option)
        if value is not None and not math.isfinite(value):
            return f"--{option} {value}: give a finite number"
    if args.dt is not None and not args.dt > 0:
        return f"--dt {args.dt}: the time step must be positive"
    return None


def _times(kernel: Any, args: argparse.Namespace) -> tuple[Any, str | None]:
    """The grid of the file, with the command line's overrides, or what is wrong with it: the
    same checks as the file's own grid, and the memory its results would need."""
    from symkin.runtime import driver

    t0, t1, dt = kernel.time_grid
    t0 = t0 if args.t0 is None else args.t0
    t1 = t1 if args.t1 is None else args.t1
    dt = dt if args.dt is None else args.dt
    if t1 < t0:
        return None, (f"the time grid ends (t1 = {t1:g}) before it starts (t0 = {t0:g}); "
                      "change --t0/--t1")
    points = limits.grid_points(t0, t1, dt)
    if points > limits.MAX_GRID_POINTS:
        need = limits.result_bytes(points, len(kernel.coordinates))
        return None, (f"the grid t0 = {t0:g} to t1 = {t1:g} by dt = {dt:g} has {points:.3g} "
                      f"points, more than the {limits.MAX_GRID_POINTS:,} allowed (its results "
                      f"would need {_size(need)}); use a larger --dt or a shorter interval")
    return driver.grid(t0, t1, dt), None


def _size(count: float) -> str:
    """Bytes in the unit a person reads: 21.6 GB, 350 MB."""
    for unit, scale in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6)):
        if count >= scale:
            return f"{count / scale:.3g} {unit}" if count < 1e15 else f"{count:.3g} bytes"
    return f"{count / 1e3:.3g} kB"


def handle(args: argparse.Namespace) -> int:
    """Run the subcommand; returns the exit status."""
    problem = _bad_usage(args)
    if problem:
        return _error(problem, EXIT_BAD_INPUT)
    try:
        return _solve_and_write(args)
    except CannotWrite as error:
        return _error(str(error), EXIT_BAD_INPUT)
    except OSError as error:  # e.g. a cache folder that cannot be used at all
        return _error(f"{error.strerror or error}: {error.filename or ''}", EXIT_FAILED)


def _solve_and_write(args: argparse.Namespace) -> int:
    from symkin.build import index as cache
    from symkin.build.toolchain import resolve_backend
    from symkin.runtime import driver

    prepared = cache.prepare(args.mechanism, cache.Options(backend=resolve_backend(args.backend)),
                             outlines=args.animate is not None)
    kernel = prepared.kernel
    times, problem = _times(kernel, args)
    if problem:
        return _error(f"{args.mechanism}: {problem}", EXIT_BAD_INPUT)
    progress = ProgressBar(sys.stderr) if sys.stderr.isatty() else None
    try:
        trajectory = driver.solve(kernel, t=times, progress=progress,
                                  stop_at_singular=args.stop_at_singular)
    except driver.SolveInterrupted as interrupted:
        if progress:
            progress.finish()
        return _stopped(args, prepared, interrupted, times.size, "interrupted",
                        EXIT_INTERRUPTED)
    except driver.SolveFailure as failure:
        if progress:
            progress.finish()
        return _stopped(args, prepared, failure, times.size, str(failure), EXIT_FAILED)
    if progress:
        progress.finish()
    _warn_flagged(trajectory)
    written = _write(trajectory, args, prepared.outlines)
    origin = ", cached kernel" if prepared.hit else ""
    print(f"solved {trajectory.t.size} time points, t = {trajectory.t[0]:g} to "
          f"{trajectory.t[-1]:g} ({kernel.backend} backend{origin})"
          + _fallback_note(trajectory.lu_fallbacks)
          + "".join(f"; wrote {path}" for path in written))
    return EXIT_OK


def _stopped(args: argparse.Namespace, prepared: Any, stop: Any, total: int, why: str,
             status: int) -> int:
    """A run that ended early: say why first (even if writing then fails), then write the
    rows solved so far and say where they went."""
    solved = stop.trajectory.t.size
    _warn_flagged(stop.trajectory)
    message = f"{args.mechanism}: {why}"
    if status == EXIT_INTERRUPTED:
        message += f" at t = {stop.t:g}."
    _error(f"{message} Solved {solved} of {total} time points.", status)
    try:
        written = _write(stop.trajectory, args, prepared.outlines)
    except CannotWrite as error:
        _error(str(error), EXIT_BAD_INPUT)
        return status
    if written:
        messages.note("the solved rows are written to " + ", ".join(map(str, written)))
    return status


def _warn_flagged(trajectory: Any) -> None:
    """One warning line per stretch of consecutive flagged points (the run still succeeds)."""
    for line in flag_warnings(trajectory):
        messages.note(line)


def flag_warnings(trajectory: Any) -> list[str]:
    """``warning: ... at t = ...`` for each stretch of flagged points: where, how
    ill-conditioned, and the singular configuration passed there with its dependent rows."""
    from symkin.runtime.options import Options

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
        detail = "".join(
            f"; a singular configuration is passed at t = {t:.10g} (Phi_q loses rank {rank}; "
            f"dependent rows: {'; '.join('{' + ', '.join(g) + '}' for g in groups)}), its "
            "point(s) interpolated from both sides" for t, rank, groups in passed)
        lines.append(f"warning: {count} point{'s' if count > 1 else ''} flagged at {where}: "
                     f"Phi_q is ill-conditioned there (condition up to {worst:.3g}), so q, dq, "
                     f"ddq may miss {targets.target_q:g}, {targets.target_dq:g}, "
                     f"{targets.target_ddq:g} (column 'flagged'){detail}")
        k = end + 1
    return lines


def _step(trajectory: Any, k: int) -> float:
    """The grid step before point k (0 at the ends)."""
    return float(trajectory.t[k] - trajectory.t[k - 1]) if 0 < k < trajectory.t.size else 0.0


def _fallback_note(count: int) -> str:
    """How often the generated sparse LU left its fixed pivot order (results stay exact)."""
    if not count:
        return ""
    return f"; {count} pivot fall-back{'s' if count != 1 else ''} to dense LU"


def _write(trajectory: Any, args: argparse.Namespace, outlines: Any) -> list[Path]:
    """Save the results, plot and animation asked for (a partial trajectory too)."""
    try:
        return _write_files(trajectory, args, outlines)
    except OSError as error:
        raise CannotWrite(f"cannot write {error.filename or 'the output'}: "
                          f"{error.strerror or error}; check the path and its permissions"
                          ) from None


def _write_files(trajectory: Any, args: argparse.Namespace, outlines: Any) -> list[Path]:
    from symkin.present import plots

    written = []
    if args.output:
        written.append(trajectory.save(args.output))
    if trajectory.t.size == 0:
        return written
    if args.plot:
        written.append(plots.plot(trajectory, args.plot))
    if args.animate:
        written.append(plots.animate(trajectory, args.animate, outlines))
    return written


def _error(message: str, status: int) -> int:
    return messages.error(message, status)


class CannotWrite(Exception):
    """An output file could not be written (a bad path, not a failed solve)."""


class ProgressBar:
    """A one-line progress bar on a terminal, redrawn at most ten times a second."""

    def __init__(self, stream: TextIO, width: int = 40) -> None:
        self.stream = stream
        self.width = width
        self.last = 0.0
        self.drawn = False

    def __call__(self, done: int, total: int) -> None:
        now = time.monotonic()
        if done < total and now - self.last < 0.1:
            return
        self.last = now
        filled = self.width * done // max(total, 1)
        self.stream.write(f"\r[{'#' * filled}{'.' * (self.width - filled)}] {done}/{total}")
        self.stream.flush()
        self.drawn = True

    def finish(self) -> None:
        if self.drawn:
            self.stream.write("\n")
            self.stream.flush()

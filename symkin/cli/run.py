"""``symkin run``: solve a mechanism over its time grid and write the results.

A thin layer over symkin.derive -> symkin.compile -> symkin.solve -> Trajectory.save / plots.
The kernel comes through the warm-run index (symkin/build/index.py): a second run of an
unchanged file loads the cached kernel and its metadata directly, and never imports SymPy,
pydantic or jinja2.
Exit status 0 on success; 1 when the solve fails (the rows solved so far are still written);
2 for bad input (a message, never a traceback). ``--at T`` solves one configuration (the
chapter's single-instant problem) and prints it; the files a run writes are in
:mod:`symkin.cli.run_outputs`.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import Any

from symkin import backends, limits, outfiles
from symkin.cli import messages, overrides, run_outputs
from symkin.cli.exits import EXIT_BAD_INPUT, EXIT_FAILED, EXIT_INTERRUPTED, EXIT_OK
from symkin.cli.run_outputs import CannotWrite, ProgressBar
from symkin.errors import BackendRefused

SUFFIXES = {"output": (".npz", ".csv"), "plot": (".png", ".svg", ".pdf"), "animate": (".gif",),
            "html": (".html", ".htm")}
GRID_ONLY = ("t0", "t1", "dt", "plot", "animate", "html")


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
    if args.at is not None:
        if not math.isfinite(args.at):
            return f"--at {args.at}: give a finite time"
        clash = [f"--{option}" for option in GRID_ONLY if getattr(args, option) is not None]
        if clash:
            return (f"--at solves one configuration; {', '.join(clash)} need a time grid. "
                    "Leave out --at, or those options")
    if args.inputs is not None:
        clash = [f"--{option}" for option in ("t0", "t1", "dt", "at")
                 if getattr(args, option) is not None]
        if clash:
            return (f"--inputs {args.inputs}: its column t is the time grid; leave out "
                    f"{', '.join(clash)}")
    overwrite = outfiles.clash(output_paths(args), [("the mechanism file", args.mechanism),
                                                    ("the --inputs table", args.inputs)])
    if overwrite:
        return overwrite
    if not 1 <= args.fps <= 100:
        return f"--fps {args.fps}: give 1 to 100 frames per second"
    if args.html is not None:
        from symkin.present import html

        if not html.available():
            return ("--html needs the plotly package, which draws the report: "
                    "pip install 'symkin[html]' (or pip install plotly)")
    return None


def output_paths(args: argparse.Namespace) -> list[tuple[str, Path | None]]:
    """Every file the run may write, as the command line names it: the forces' figure goes
    next to --plot's as NAME_forces.SUFFIX."""
    paths: list[tuple[str, Path | None]] = [
        ("-o" if option == "output" else f"--{option}", getattr(args, option))
        for option in SUFFIXES]
    if args.plot is not None:
        forces = args.plot.with_name(f"{args.plot.stem}_forces{args.plot.suffix}")
        paths.append((f"--plot (its forces' figure {forces.name})", forces))
    return paths


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


def _input_table(kernel: Any, args: argparse.Namespace) -> tuple[Any, str | None]:
    """The --inputs table of a mechanism with input drivers, or the whole message of what is
    wrong: a table for a mechanism without inputs, inputs without a table, a mistake in the
    table (located in the table by input_table)."""
    from symkin.cli import input_table

    names = tuple(getattr(kernel, "input_names", ()))
    if args.inputs is None:
        if names:
            return None, (f"{args.mechanism}: the drivers {', '.join(names)} are inputs "
                          "(written `input`): give their values with --inputs TABLE.csv, "
                          "whose columns are "
                          f"{input_table.expected(names)}")
        return None, None
    if not names:
        return None, (f"{args.mechanism}: --inputs {args.inputs}: this mechanism has no "
                      "input drivers (a "
                      "driver function written `input`); leave out --inputs")
    try:
        lengths = tuple(getattr(kernel, "input_lengths", ()))
        return input_table.read(args.inputs, names, lengths), None
    except input_table.TableError as error:
        return None, str(error)


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
    from symkin.build import index
    from symkin.runtime import driver

    options = index.Options(backend=backends.resolve(args.backend),
                            parameters=overrides.pairs(args.overrides))
    try:
        prepared = index.prepare(args.mechanism, options,
                                 outlines=args.animate is not None or args.html is not None)
    except BackendRefused as refused:  # a backend that cannot integrate it: name the file
        return _error(f"{args.mechanism}: {refused}", EXIT_BAD_INPUT)
    kernel = prepared.kernel
    moves = getattr(kernel, "moves_under_forces", False)
    if moves and args.at is not None:
        return _error(f"{args.mechanism}: --at solves one configuration, but this mechanism "
                      "moves under its forces: its state at a time comes from integrating "
                      "from t0. Use --t1 (the last row is the state at t1)", EXIT_BAD_INPUT)
    picture = run_outputs.Pictures.of(args, kernel)  # --select checked before any solving
    table, problem = _input_table(kernel, args)
    if problem:
        return _error(problem, EXIT_BAD_INPUT)
    if table is not None:
        times = table.t
    elif args.at is not None:
        times, problem = driver.grid(args.at, args.at, 1.0), None
    else:
        times, problem = _times(kernel, args)
    if problem:
        return _error(f"{args.mechanism}: {problem}", EXIT_BAD_INPUT)
    progress = ProgressBar(sys.stderr) if sys.stderr.isatty() and args.at is None else None
    given = {} if table is None else {"inputs": table.u, "input_rates": table.du,
                                      "input_accels": table.ddu}
    try:
        trajectory = driver.solve(kernel, t=times, progress=progress,
                                  stop_at_singular=args.stop_at_singular, **given)
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
    # From here every row is solved: a Ctrl-C is answered only once they are all written.
    with run_outputs.interrupts_deferred() as deferred:
        _warn_flagged(trajectory)
        trajectory = _with_pair_outputs(trajectory, args, prepared.system)
        written = _write(trajectory, args, prepared.outlines, picture)
    if deferred.interrupted:
        said = "".join(f"; wrote {path}" for path in written)
        return _error(f"{args.mechanism}: interrupted after the solve: all "
                      f"{trajectory.t.size} time points solved{said}", EXIT_INTERRUPTED)
    origin = ", cached kernel" if prepared.hit else ""
    # integrated under its forces (runtime.dynamics): said first, as the contract has it
    kind = " (dynamics)" if getattr(kernel, "moves_under_forces", False) else ""
    if args.at is not None:
        backend = f"{kernel.backend} backend{origin}"
        print(run_outputs.configuration(trajectory, kernel.name, backend), end="")
    else:
        print(f"solved {trajectory.t.size} time points, t = {trajectory.t[0]:g} to "
              f"{trajectory.t[-1]:g}{kind} ({kernel.backend} backend{origin})"
              + "".join(f"; wrote {path}" for path in written))
    if not getattr(kernel, "moves_under_forces", False):  # (its start: runtime.dynamics)
        _note_far_start(kernel, trajectory)
    if trajectory.lu_fallbacks:
        messages.note(run_outputs.fallback_note(trajectory.lu_fallbacks, trajectory.t.size,
                                                args.verbose))
    return EXIT_OK


def _stopped(args: argparse.Namespace, prepared: Any, stop: Any, total: int, why: str,
             status: int) -> int:
    """A run that ended early: say why first (even if writing then fails), then write the
    rows solved so far and say where they went."""
    solved = stop.trajectory.t.size
    message = f"{args.mechanism}: {why}"
    if status == EXIT_INTERRUPTED:
        during = getattr(stop, "during", "")
        message += f" while {during}, after the solve." if during else f" at t = {stop.t:g}."
    _error(f"{message} Solved {solved} of {total} time points.", status)
    _warn_flagged(stop.trajectory)  # after the error: a singular start flags its one row too
    try:
        trajectory = _with_pair_outputs(stop.trajectory, args, prepared.system)
        with run_outputs.interrupts_held():  # a second Ctrl-C must not cut the file short
            written = _write(trajectory, args, prepared.outlines,
                             run_outputs.Pictures.of(args, prepared.kernel))
    except CannotWrite as error:
        _error(str(error), EXIT_BAD_INPUT)
        return status
    if written:
        messages.note("the solved rows are written to " + ", ".join(map(str, written)))
    return status


def _note_far_start(kernel: Any, trajectory: Any) -> None:
    """A note when the start was assembled far from the file's q0 (runtime.solving.start)."""
    import numpy as np

    from symkin.runtime.solving.start import far_from_guess

    moved, scale = far_from_guess(kernel, np.asarray(kernel.q0, dtype=float), trajectory.q[0],
                                  float(trajectory.t[0]), trajectory.params)
    if moved:
        messages.note(run_outputs.far_start_note(moved, scale))


def _with_pair_outputs(trajectory: Any, args: argparse.Namespace, system: Any = None) -> Any:
    """The trajectory with what its pairs report (a cam's pressure angle and radius of
    curvature) when a results file is written and the mechanism has such pairs. The outputs
    come from the validated file and the pairs' own expressions: the System of a cold run
    (``system``), else the file read again — never a second derivation (a warm run of a cam
    stays seconds long, and one of other mechanisms free of it)."""
    if not (args.output or args.animate or args.html) or trajectory.t.size == 0:
        return trajectory  # written to the results file; contact points marked in pictures
    # Only a pair with its own coordinate NAME.s (a curve or a cam) reports outputs: any other
    # mechanism's warm run must not import the file's schema or SymPy.
    if not any(name.endswith(".s") for name in trajectory.coordinates):
        return trajectory
    from symkin import pairs
    from symkin.spec import validate

    mech = (system.mechanism if system is not None
            else validate.load(args.mechanism, overrides.parse(args.overrides)))
    if not any(pairs.of(c).outputs for section in pairs.SECTIONS
               for c in getattr(mech, section)):
        return trajectory
    from symkin.symbolic import outputs

    return outputs.with_mechanism_outputs(mech, trajectory)


def _warn_flagged(trajectory: Any) -> None:
    """One warning line per stretch of consecutive flagged points (the run still succeeds),
    after the note naming the rows removed as redundant, if any."""
    if getattr(trajectory, "removed", ()):
        messages.note(run_outputs.removed_note(trajectory))
        if run_outputs.indeterminate_note(trajectory):
            messages.note(run_outputs.indeterminate_note(trajectory))
    for line in run_outputs.flag_warnings(trajectory):
        messages.note(line)


def _write(trajectory: Any, args: argparse.Namespace, outlines: Any,
           picture: run_outputs.Pictures) -> list[Path]:
    """Save the results and pictures asked for (a partial trajectory too)."""
    try:
        return run_outputs.write(trajectory, args, outlines, picture)
    except OSError as error:
        raise CannotWrite(f"cannot write {error.filename or 'the output'}: "
                          f"{error.strerror or error}; check the path and its permissions"
                          ) from None


def _error(message: str, status: int) -> int:
    return messages.error(message, status)

"""``symkin scan``: the assembly branches at t0, then the singular configurations, limit
positions and flagged stretches over the driver range (symkin.runtime.scanning.scan), as a short
report; with ``--input NAME=VALUE`` (a mechanism with input drivers) every assembly at those inputs.

Exit status 0 when the scan ran, whatever it found (a limit position is a finding, not a
failure); 2 for bad input; 1 when the kernel cannot be built or cached; 130 on Ctrl-C.
"""

from __future__ import annotations

import argparse
import math
from typing import Any

from symkin import backends
from symkin.cli import messages, overrides
from symkin.cli.exits import EXIT_BAD_INPUT, EXIT_FAILED, EXIT_INTERRUPTED, EXIT_OK
from symkin.limits import listed, listed_groups


def handle(args: argparse.Namespace) -> int:
    """Run the subcommand; returns the exit status."""
    from symkin.build import index
    from symkin.errors import SolveError
    from symkin.runtime import driver
    from symkin.runtime.scanning.scan import scan

    for option in ("t0", "t1", "dt"):
        value = getattr(args, option)
        if value is not None and not math.isfinite(value):
            return messages.error(f"--{option} {value}: give a finite number", EXIT_BAD_INPUT)
    options = index.Options(backend=backends.resolve(args.backend),
                            parameters=overrides.pairs(args.overrides))
    try:
        kernel = index.prepare(args.mechanism, options).kernel
    except OSError as error:  # e.g. a cache folder that cannot be used at all
        return messages.error(f"{error.strerror or error}: {error.filename or ''}", EXIT_FAILED)
    t0, t1, dt = kernel.time_grid
    t0, t1, dt = (t0 if args.t0 is None else args.t0, t1 if args.t1 is None else args.t1,
                  dt if args.dt is None else args.dt)
    try:
        times = driver.grid(t0, t1, dt)
    except SolveError as error:
        return messages.error(f"{args.mechanism}: {error}; change --t0, --t1 or --dt",
                              EXIT_BAD_INPUT)
    inputs = _inputs(args.inputs)
    if isinstance(inputs, str):
        return messages.error(f"{args.mechanism}: {inputs}", EXIT_BAD_INPUT)
    names = tuple(getattr(kernel, "input_names", ()))
    if inputs is not None and not names:
        return messages.error(f"{args.mechanism}: this mechanism has no input drivers (a "
                              "driver function written `input`): leave out --input",
                              EXIT_BAD_INPUT)
    try:
        report = scan(kernel, t=times, all_branches=args.all_branches, inputs=inputs)
    except driver.SolveInterrupted:  # a SolveError too: first
        messages.note("interrupted")
        return EXIT_INTERRUPTED
    except SolveError as error:
        hint = " (give --input NAME=VALUE for each input driver)" if names else ""
        return messages.error(f"{args.mechanism}: {error}{hint}", EXIT_BAD_INPUT)
    print(text(report, kernel.name, f"t = {t0:g} to {t1:g} by {dt:g}, {kernel.backend} backend"),
          end="")
    return EXIT_OK


def _inputs(pairs: list[str]) -> dict[str, float] | str | None:
    """The --input NAME=VALUE pairs as a dict (None when none given), or what is wrong."""
    if not pairs:
        return None
    values: dict[str, float] = {}
    for pair in pairs:
        name, equals, value = pair.partition("=")
        try:
            number = float(value)
        except ValueError:
            number = math.nan
        if not equals or not name.strip() or not math.isfinite(number):
            return f"--input {pair}: write NAME=VALUE with a finite number"
        if name.strip() in values:
            return f"--input {pair}: {name.strip()} is given twice"
        values[name.strip()] = number
    return values


def text(report: Any, name: str, grid: str) -> str:
    """The report as a person reads it."""
    from symkin.runtime.scanning.scan import distinguishing, printed

    lines = [f"{name}: scan over {grid}"]
    shown = distinguishing(report)
    count = len(report.branches)
    near = sum(1 for branch in report.branches if branch.near_singular)
    at = "".join(f", {name} = {value:g}" for name, value in report.inputs.items())
    lines.append(f"assembly branches at t = {report.t0:g}{at}: {count}"
                 + ("" if count else " (none found: the mechanism cannot be assembled there)")
                 + (f" ({near} of them at or near a singular configuration, where branches "
                    "meet: those are approximate and their count is not exact)" if near else ""))
    for k, branch in enumerate(report.branches, start=1):
        values = ", ".join(f"{report.coordinates[c]} = {printed(branch.q[c])}" for c in shown)
        taken = " (reached from q0: a run takes it)" if branch.taken else ""
        taken += " (near a singular configuration)" if branch.near_singular else ""
        lines.append(f"  {k}{taken}: {values + '; ' if values else ''}"
                     f"condition of Phi_q {branch.cond:.3g}")
    for motion in report.motions:
        lines.append(f"motion from branch {motion.branch + 1}:")
        lines.extend(f"  {line}" for line in _motion_lines(motion, report.t1))
    return "\n".join(lines) + "\n"


def _motion_lines(motion: Any, t1: float) -> list[str]:
    lines = []
    for t, rank, groups in motion.singular:
        joints = listed_groups((_short(row) for row in group) for group in groups)
        lines.append(f"singular configuration passed at t = {t:.10g} (Phi_q loses rank {rank}; "
                     f"dependent joints: {joints})")
    for first, last in motion.flagged:
        where = f"t = {first:.10g}" if first == last else f"t = {first:.10g} .. {last:.10g}"
        lines.append(f"flagged (accuracy not guaranteed) at {where}")
    stop = motion.stop
    if stop is None:
        lines.append(f"reaches the end of the grid, t = {t1:g}")
    elif stop.reason == "limit position":
        lines.append(f"limit position at t = {stop.t:.10g}: joints "
                     f"{listed(_short(j) for j in stop.joints)} become aligned; "
                     f"{listed((_short(d) for d in stop.drivers), ' and ')} cannot go on beyond it")
    else:
        lines.append(f"stops at t = {stop.t:.10g} ({stop.reason}): {stop.message}")
    return lines


def _short(label: str) -> str:
    """A row label without its index: 'joints[2] B revolute coupler-rocker (x)' ->
    'B revolute coupler-rocker (x)'."""
    head, _, rest = label.partition("] ")
    return rest if head and rest else label

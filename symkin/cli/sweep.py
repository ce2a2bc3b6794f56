"""``symkin sweep``: many parameter sets of one mechanism — a grid, a table or Monte-Carlo
draws within tolerances — solved in this process, local processes or on a Dask cluster.

Prints how many sets were solved, the failed ones with their reason, and for every named point
the envelope of its position (min/max and mean ± 3 sigma over the solved sets, at the time of the
widest spread); with --monte-carlo also the first-order ±3 sigma from the sensitivities q_p
beside the Monte-Carlo one. Exit status 0 when at least one set was solved, 1 when none was,
2 for bad input (a one-paragraph message), 130 when interrupted.
"""

from __future__ import annotations

import argparse
import math
import re
import sys
from pathlib import Path
from typing import Any

from symkin import backends, outfiles
from symkin.cli import messages, overrides
from symkin.cli.exits import EXIT_BAD_INPUT, EXIT_FAILED, EXIT_OK
from symkin.errors import SolveError, SymkinError, UsageError

_VARY = re.compile(r"^\s*([A-Za-z_]\w*)\s*=\s*([^:]+):([^:]+):\s*(\d+)\s*$")
_TOLERANCE = re.compile(r"^\s*([A-Za-z_]\w*)\s*=\s*(?:±|\+-|\+/-)?\s*([^%\s]+)\s*(%?)\s*$")
SHOWN_FAILURES = 5


def handle(args: argparse.Namespace) -> int:
    """Run the subcommand; returns the exit status."""
    problem = _bad_usage(args)
    if problem:
        return messages.error(problem, EXIT_BAD_INPUT)
    from symkin.build import index

    options = index.Options(backend=backends.resolve(args.backend),
                            parameters=overrides.pairs(args.overrides))
    kernel = index.prepare(args.mechanism, options).kernel
    from symkin.runtime.input_driven.inputs import refuse_inputs

    try:
        refuse_inputs(kernel, "a sweep")  # the user's file, not a failed design: exit 2
    except SolveError as error:
        return messages.error(f"{args.mechanism}: {error}", EXIT_BAD_INPUT)
    try:
        design, spread = _design(kernel, args)
    except UsageError as error:
        return messages.error(f"{args.mechanism}: {error}", EXIT_BAD_INPUT)
    from symkin.runtime.driver import grid
    from symkin.sweeps.api import too_large

    problem = too_large(design.shape[0], grid(*kernel.time_grid).size, len(kernel.coordinates))
    if problem:
        return messages.error(f"{args.mechanism}: {problem}", EXIT_BAD_INPUT)
    return _run(kernel, args, design, spread)


def _bad_usage(args: argparse.Namespace) -> str | None:
    chosen = [bool(args.vary), args.params is not None, args.monte_carlo is not None]
    if sum(chosen) != 1:
        return ("give the parameter sets one way: --vary NAME=LO:HI:COUNT (repeatable), "
                "--params TABLE.csv, or --monte-carlo N with --tolerance NAME=±X")
    if args.monte_carlo is not None and not args.tolerance:
        return "--monte-carlo needs at least one --tolerance NAME=±X (e.g. --tolerance a=±0.01)"
    if args.tolerance and args.monte_carlo is None:
        return "--tolerance is for --monte-carlo N; add it, or use --vary for a grid"
    if args.output is not None and args.output.suffix.lower() != ".npz":
        return f"-o {args.output}: a sweep is written as .npz"
    if args.plot is not None and args.plot.suffix.lower() != ".png":
        return f"--plot {args.plot}: the file must end in .png"
    clash = outfiles.clash([("-o", args.output), ("--plot", args.plot)],
                           [("the mechanism file", args.mechanism),
                            ("the --params table", args.params)])
    if clash:
        return clash
    if args.workers is not None and args.workers < 1:
        return f"--workers {args.workers}: give at least 1"
    if args.scheduler is not None and args.workers is not None:
        return "--scheduler and --workers exclude each other: the cluster has its own workers"
    return None


def _design(kernel: Any, args: argparse.Namespace) -> tuple[Any, Any]:
    """The (M, NP) table of parameter sets, and the parameters' sigmas for Monte-Carlo."""
    from symkin.sweeps import tolerance

    if args.vary:
        return tolerance.grid_design(kernel, [_vary(text) for text in args.vary]), None
    if args.params is not None:
        return tolerance.table_design(kernel, args.params), None
    half_widths = dict(_tolerance(kernel, text) for text in args.tolerance)
    design = tolerance.monte_carlo_design(kernel, args.monte_carlo, half_widths,
                                          args.distribution, args.seed)
    return design, tolerance.sigmas(kernel, half_widths, args.distribution)


def _vary(text: str) -> Any:
    from symkin.sweeps.tolerance import Vary

    match = _VARY.match(text)
    if not match:
        raise UsageError(f"--vary {text!r}: write NAME=LO:HI:COUNT, e.g. b=4.5:5.5:11")
    name, low, high, count = match.groups()
    vary = Vary(name, _finite(low, f"--vary {text}"), _finite(high, f"--vary {text}"),
                int(count))
    if vary.count < 1:
        raise UsageError(f"--vary {text!r}: COUNT must be at least 1")
    return vary


def _tolerance(kernel: Any, text: str) -> tuple[str, float]:
    match = _TOLERANCE.match(text)
    if not match:
        raise UsageError(f"--tolerance {text!r}: write NAME=±X, NAME=+-X or NAME=±X% "
                         "(relative to the nominal value), e.g. a=±0.01")
    name, value, percent = match.groups()
    half_width = _finite(value, f"--tolerance {text}")
    if half_width < 0:
        raise UsageError(f"--tolerance {text!r}: the half-width must not be negative")
    if percent and name in kernel.parameter_names:
        nominal = kernel.p_values[list(kernel.parameter_names).index(name)]
        half_width = abs(nominal) * half_width / 100
    return name, half_width


def _finite(text: str, where: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise UsageError(f"{where}: {text.strip()!r} is not a number") from None
    if not math.isfinite(value):
        raise UsageError(f"{where}: {text.strip()!r} is not a finite number")
    return value


def _run(kernel: Any, args: argparse.Namespace, design: Any, spread: Any) -> int:
    from symkin.cli.run_outputs import ProgressBar
    from symkin.sweeps.api import sweep

    client = _client(args.scheduler) if args.scheduler else None
    progress = ProgressBar(sys.stderr) if sys.stderr.isatty() else None
    try:
        result = sweep(kernel, design, client=client, workers=args.workers, progress=progress)
    finally:
        if progress:
            progress.finish()
        if client is not None:
            client.close()
    _report(kernel, result, spread)
    _report_forces(result)
    written = _write(result, args)
    if written:
        print("wrote " + ", ".join(map(str, written)))
    return EXIT_OK if result.ok.any() else EXIT_FAILED


def _client(address: str) -> Any:
    try:
        from distributed import Client
    except ImportError:
        raise UsageError("--scheduler needs Dask: pip install 'symkin[distributed]'") from None
    try:
        return Client(address, timeout="10s")  # type: ignore[no-untyped-call,unused-ignore]
    except (OSError, TimeoutError, ValueError) as error:
        raise UsageError(f"--scheduler {address}: cannot connect ({error}); check the "
                         "address of the Dask scheduler and that it is running") from None


def _report(kernel: Any, result: Any, spread: Any) -> None:
    from symkin.sweeps import tolerance
    from symkin.sweeps.result import first_of_largest

    summary = result.summary()
    print(f"solved {summary['solved']} of {summary['sets']} parameter sets over "
          f"{result.t.size} time points, t = {result.t[0]:g} to {result.t[-1]:g}")
    if summary["failed"]:
        counts = ", ".join(f"{n} {reason}" for reason, n in sorted(summary["failed"].items()))
        print(f"failed: {counts}")
        for j in result.failed[:SHOWN_FAILURES]:
            values = ", ".join(f"{n}={v:.6g}" for n, v in zip(result.parameter_names,
                                                             result.params[j]))
            print(f"  set {j} ({values}): {result.reasons[j]} at t = {result.t_reached[j]:g}")
        if result.failed.size > SHOWN_FAILURES:
            print(f"  ... and {result.failed.size - SHOWN_FAILURES} more (see -o)")
    if not result.ok.any() or not result.points_named:
        return
    estimate = None
    if spread is not None and result.space == "3d":
        messages.note("no first-order estimate: it is computed for planar mechanisms only "
                      "(the Monte-Carlo spread below is)")
    elif spread is not None:
        try:
            estimate = tolerance.point_sensitivities(kernel, result.t)
        except SymkinError as error:  # the nominal design itself fails: no linearisation
            messages.note(f"no first-order estimate: the nominal design cannot be solved "
                          f"({error})")
    print("named points, position over the solved sets at the time of widest spread:")
    for body, name in result.points_named:
        band = tolerance.envelope(result, body, name)
        for axis, label in enumerate("xyz"[:result.point_size]):
            k = first_of_largest(band.high[:, axis] - band.low[:, axis])
            line = (f"  {body}.{name}.{label} at t = {result.t[k]:g}: min {band.low[k, axis]:.6g}"
                    f" max {band.high[k, axis]:.6g} mean {band.mean[k, axis]:.6g} "
                    f"±3σ {3 * band.std[k, axis]:.3g}")
            if estimate is not None:
                r_p = estimate[f"{body}.{name}"][1][k, axis]
                line += f" | first order ±3σ {3 * tolerance.first_order_std(r_p, spread):.3g}"
            print(line)


def _report_forces(result: Any) -> None:
    """The envelope of each effort and reaction: what a motor or a bearing must take."""
    envelope = result.force_envelope()
    if envelope:
        print("efforts and reactions over the solved sets (min, max; the largest magnitude "
              "at):")
    for name, low, high, t, j in envelope:
        print(f"  {name}: min {low:.6g} max {high:.6g} | largest at t = {t:g} (set {j})")


def _write(result: Any, args: argparse.Namespace) -> list[Path]:
    written = []
    try:
        if args.output:
            written.append(result.save(args.output, compress=args.compress))
        if args.plot and result.ok.any():
            from symkin.sweeps.plots import plot_envelopes

            written.append(plot_envelopes(result, args.plot))
    except OSError as error:
        raise UsageError(f"cannot write {error.filename or 'the output'}: "
                         f"{error.strerror or error}; check the path and its permissions"
                         ) from None
    return written

"""``symkin verify MECH --against HAND.py | HAND.m | FOLDER``."""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from symkin.cli.exits import EXIT_BAD_INPUT, EXIT_FAILED, EXIT_OK
from symkin.cli.messages import printable
from symkin.symbolic.derivation import derive
from symkin.verify.hand import HandModuleError
from symkin.verify.matlab_hand import is_matlab, verify_matlab
from symkin.verify.numeric import (
    DEFAULT_SAMPLES,
    DEFAULT_SPREAD,
    DEFAULT_TOLERANCE,
    derived_functions,
    verify,
)


def handle(args: argparse.Namespace) -> int:
    """Run the subcommand from its parsed arguments; returns the exit status."""
    return command(args.mechanism, args.against, samples=args.samples, seed=args.seed,
                   spread=args.spread, tolerance=args.tolerance)


def command(mechanism: str | Path, against: str | Path, *, samples: int = DEFAULT_SAMPLES,
            seed: int = 0, spread: float | None = None,
            tolerance: float = DEFAULT_TOLERANCE) -> int:
    """``symkin verify MECH --against HAND.py``: print the report, return the exit status.

    0 when every entry matches, 1 when some differ, 2 for bad input (the hand file is missing,
    fails to run, raises, or returns the wrong shape; bad options). Errors in the mechanism
    file are raised as MechanismError for the CLI to report. ``spread`` None is the default
    spread for Python hand files; .m hand files take none (see :func:`_matlab_spread`).
    """
    problem = (_option_problem(samples, DEFAULT_SPREAD if spread is None else spread, tolerance)
               or _matlab_spread(against, spread))
    if problem:
        print(f"symkin verify: error: {printable(problem)}", file=sys.stderr)
        return EXIT_BAD_INPUT
    system = derive(mechanism)
    try:
        if is_matlab(against):  # .m files, run in Octave at the nominal design
            report = verify_matlab(derived_functions(system), against, samples=samples,
                                   seed=seed, tolerance=tolerance)
        else:
            report = verify(system, against, samples=samples, seed=seed,
                            spread=DEFAULT_SPREAD if spread is None else spread,
                            tolerance=tolerance)
    except HandModuleError as error:
        print(f"symkin verify: error: {printable(str(error))}", file=sys.stderr)
        return EXIT_BAD_INPUT
    print(report.text(), end="")
    return EXIT_OK if report.ok else EXIT_FAILED


def _matlab_spread(against: str | Path, spread: float | None) -> str | None:
    """.m hand functions take no parameters (their data is fixed in the files, as the chapter's
    Dane.m does), so they are compared at the nominal design only: a spread asked for could not
    be applied, and is refused rather than ignored."""
    if not spread or not is_matlab(against):
        return None
    shown = str(against)[:200]
    return (f"--spread {spread:g}: the MATLAB/Octave hand functions of {shown} take no "
            f"parameters (their data is fixed in the files, as the chapter's Dane.m), so they "
            f"are compared at the nominal design only; leave out --spread, or give --spread 0")


def _option_problem(samples: int, spread: float, tolerance: float) -> str | None:
    if samples < 1:
        return f"--samples {samples}: give at least 1"
    if not (math.isfinite(spread) and spread >= 0):
        return f"--spread {spread}: give a number >= 0, e.g. 0.3"
    if not (math.isfinite(tolerance) and tolerance > 0):
        return f"--tolerance {tolerance}: give a positive number, e.g. 1e-8"
    return None

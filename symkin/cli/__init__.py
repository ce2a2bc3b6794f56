"""The ``symkin`` command: a thin layer over the Python API.

Exit status: 0 on success, 1 when a solve or a check fails, 2 for bad input (a one-paragraph
message naming the file and the place in it, never a traceback).
"""

from __future__ import annotations

import argparse
import os
import sys
import warnings

from symkin.cli import arguments, messages
from symkin.cli.exits import EXIT_BAD_INPUT, EXIT_FAILED, EXIT_INTERRUPTED
from symkin.errors import MechanismError, SymkinError, UsageError

# Not `typing.TYPE_CHECKING`: `symkin --help` imports neither typing nor a command's module
# (tests/cli/test_light_start.py); mypy takes any constant of this name as true.
TYPE_CHECKING = False
if TYPE_CHECKING:
    from collections.abc import Callable, Sequence
    from typing import Any, TextIO

# Every subcommand, in the order --help lists them: its name, its line in --help, the function
# of symkin.cli.arguments that adds its arguments, and "module:function", what runs it, imported
# only when it does (so --help and a mistyped command import no command's module).
SUBCOMMANDS: tuple[tuple[str, str, Callable[[argparse.ArgumentParser], None], str], ...] = (
    ("show", "print Phi, Phi_q, Phi_t, Gamma and the DOF count", arguments.show,
     "symkin.cli.show:show"),
    ("schema", "print the JSON Schema of mechanism files", arguments.schema,
     "symkin.cli.show:schema"),
    ("verify", "check hand-written phi, phi_q, phi_t, gamma against the derived ones",
     arguments.verify, "symkin.cli.verify:handle"),
    ("generate", "write the source of a mechanism in a backend's language (--backend)",
     arguments.generate, "symkin.cli.generate:handle"),
    ("run", "solve positions, velocities and accelerations over the time grid", arguments.run,
     "symkin.cli.run:handle"),
    ("scan", "list the assembly branches at t0, the singular configurations and the limit "
             "positions over the driver range", arguments.scan, "symkin.cli.scan:handle"),
    ("cache", "show or empty the kernel cache", arguments.cache,
     "symkin.cli.cache_command:handle"),
    ("sweep", "solve many parameter sets: grids, tables, Monte-Carlo tolerance analysis",
     arguments.sweep, "symkin.cli.sweep:handle"),
)


class _Handler:
    """A subcommand's implementation, named by "module:function" and imported when called."""

    def __init__(self, where: str) -> None:
        self.where = where

    def __call__(self, args: argparse.Namespace) -> int:
        import importlib

        module, function = self.where.split(":")
        status: int = getattr(importlib.import_module(module), function)(args)
        return status


def _columns() -> int:
    """``shutil.get_terminal_size().columns``, which argparse asks for, without importing
    shutil (and with it bz2, lzma and zlib: a tenth of ``symkin --help``)."""
    try:
        columns = int(os.environ["COLUMNS"])
    except (KeyError, ValueError):
        columns = 0
    if columns > 0:
        return columns
    stdout = sys.__stdout__
    try:
        return (os.get_terminal_size(stdout.fileno()).columns or 80) if stdout else 80
    except (AttributeError, ValueError, OSError):  # closed, detached, not a terminal
        return 80


class _Formatter(argparse.HelpFormatter):
    """argparse's own formatter, its width found as argparse finds it (see _columns)."""

    def __init__(self, prog: str, indent_increment: int = 2, max_help_position: int = 24,
                 width: int | None = None) -> None:
        super().__init__(prog, indent_increment, max_help_position,
                         _columns() - 2 if width is None else width)


class _Parser(argparse.ArgumentParser):
    """An ArgumentParser formatting with _Formatter; its subcommands' parsers are of this
    class too (argparse makes them of the parent's)."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        kwargs.setdefault("formatter_class", _Formatter)
        super().__init__(*args, **kwargs)


class _Version(argparse.Action):
    """``--version``, looked up only when asked for: reading the package metadata costs a
    tenth of a second that every other command would otherwise pay at start."""

    def __call__(self, parser: argparse.ArgumentParser, namespace: argparse.Namespace,
                 values: Any, option_string: str | None = None) -> None:
        import symkin

        print(f"symkin {symkin.__version__}")
        parser.exit()


def parser() -> argparse.ArgumentParser:
    main_parser = _Parser(
        prog="symkin", description="Symbolic kinematics code generator for planar mechanisms.")
    main_parser.add_argument("--version", action=_Version, nargs=0,
                             help="print symkin's version and exit")
    commands = main_parser.add_subparsers(dest="command", required=True)
    for name, summary, add_arguments, where in SUBCOMMANDS:
        command = commands.add_parser(name, help=summary)
        add_arguments(command)
        command.set_defaults(handler=_Handler(where))
    return main_parser


def _note_warning(message: Warning | str, category: type[Warning], filename: str, lineno: int,
                  file: TextIO | None = None, line: str | None = None) -> None:
    """Warnings reach a command-line user as one plain line, not as a source location."""
    messages.note(str(message))


def _located(error: MechanismError, args: argparse.Namespace) -> MechanismError:
    """A mistake found after loading (the rank of an over-constrained file at t0) placed in
    the file the command read."""
    from pathlib import Path

    mechanism = getattr(args, "mechanism", None)
    if error.source is not None or not isinstance(mechanism, Path):
        return error
    from symkin.spec import validate

    return validate.locate(error, mechanism)


def main(argv: Sequence[str] | None = None) -> int:
    args = parser().parse_args(argv)
    warnings.showwarning = _note_warning
    try:
        status: int = args.handler(args)
        sys.stdout.flush()  # a closed pipe shows here, not at interpreter exit
        return status
    except MechanismError as error:
        return messages.error(str(_located(error, args)), EXIT_BAD_INPUT)
    except UsageError as error:
        return messages.error(str(error), EXIT_BAD_INPUT)
    except SymkinError as error:
        return messages.error(str(error), EXIT_FAILED)
    except KeyboardInterrupt:
        messages.note("interrupted")
        return EXIT_INTERRUPTED
    except BrokenPipeError:
        # The reader went away (`symkin schema | head`): stop quietly, and keep Python from
        # failing again when it flushes stdout at exit.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return EXIT_FAILED


def leave(status: int) -> None:
    """End a ``symkin`` process with ``status`` without the interpreter's teardown.

    A command that derived a mechanism holds some hundred thousand SymPy objects; freeing them
    one by one and clearing every module at exit cost a tenth of a cold ``symkin generate``
    (0.3-0.4 s of the spherical four-bar's 3 s), and the process is ending anyway. What exit
    does that matters still happens: the streams are flushed and the exit functions run
    (temporary folders removed, worker pools joined). Where a thread other than the main one is
    still running, a profiler or tracer is attached (``python -m cProfile -m symkin`` writes its
    report after the command returns), or a stream cannot be flushed, Python's own exit decides
    as before."""
    import atexit
    import threading

    if threading.active_count() > 1 or sys.getprofile() or sys.gettrace():
        sys.exit(status)
    atexit._run_exitfuncs()
    try:  # after the exit functions, which may write too
        sys.stdout.flush()
        sys.stderr.flush()
    except (OSError, ValueError):
        sys.exit(status)
    os._exit(status)


def console() -> None:
    """The ``symkin`` script: :func:`main`, then :func:`leave`."""
    leave(main())


if __name__ == "__main__":
    console()

"""The ``symkin`` command: a thin layer over the Python API.

Exit status: 0 on success, 1 when a solve or a check fails, 2 for bad input (a one-paragraph
message naming the file and the place in it, never a traceback).
"""

from __future__ import annotations

import argparse
import os
import sys
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, TextIO

from symkin import backends
from symkin.cli import messages, overrides
from symkin.cli.exits import EXIT_BAD_INPUT, EXIT_FAILED, EXIT_INTERRUPTED, EXIT_OK
from symkin.codegen.target import chosen_options
from symkin.errors import BuildError, MechanismError, SymkinError, UsageError


def _load(args: argparse.Namespace) -> Any:
    """The validated mechanism of ``args.mechanism`` with the ``--set`` values."""
    from symkin.spec import validate

    return validate.load(args.mechanism, overrides.parse(args.overrides))


def _show(args: argparse.Namespace) -> int:
    from symkin.symbolic import derivation

    if args.local:
        from symkin.spec import drawn

        print(drawn.dump(_load(args)), end="")
        return EXIT_OK
    from symkin.symbolic import show

    system = derivation.derive(_load(args))
    print(show.latex(system) if args.latex else show.text(system), end="")
    return EXIT_OK


def _schema(args: argparse.Namespace) -> int:
    import json

    from symkin.spec import validate

    print(json.dumps(validate.json_schema(), indent=2))
    return EXIT_OK


def _add_show(commands: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    show = commands.add_parser("show", help="print Phi, Phi_q, Phi_t, Gamma and the DOF count")
    show.add_argument("mechanism", type=Path, help="mechanism file (.yaml or .toml)")
    show.add_argument("--latex", action="store_true", help="print LaTeX instead of text")
    show.add_argument("--local", action="store_true",
                      help="print the mechanism in the local layout (local vectors, v, phi0, "
                           "q0), as derived from a drawn file")
    overrides.add_argument(show)
    show.set_defaults(handler=_show)
    schema = commands.add_parser("schema", help="print the JSON Schema of mechanism files")
    schema.set_defaults(handler=_schema)


def _verify(args: argparse.Namespace) -> int:
    from symkin.cli import verify

    return verify.command(args.mechanism, args.against, samples=args.samples, seed=args.seed,
                          spread=args.spread, tolerance=args.tolerance)


def _add_verify(commands: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    check = commands.add_parser(
        "verify", help="check hand-written phi, phi_q, phi_t, gamma against the derived ones")
    check.add_argument("mechanism", type=Path, help="mechanism file (.yaml or .toml)")
    check.add_argument("--against", type=Path, required=True, metavar="HAND.py",
                       help="Python file defining phi(q, t, p), phi_q(q, t, p), phi_t(q, t, p) "
                            "and/or gamma(q, dq, t, p) in the order `symkin show` prints")
    check.add_argument("--samples", type=int, default=50, help="random states (default 50)")
    check.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    check.add_argument("--spread", type=float, default=None,
                       help="relative spread of parameters around the nominal design "
                            "(default 0.3; 0 keeps them nominal; .m hand files take no "
                            "parameters and are checked at the nominal design only)")
    check.add_argument("--tolerance", type=float, default=1e-8,
                       help="largest accepted relative error (default 1e-8)")
    check.set_defaults(handler=_verify)


# Each entry adds one subcommand; its handler returns the exit status.
_OPTION_DEST = "backend_option_"  # a backend's option never shadows one of the command's own


def _generate(args: argparse.Namespace) -> int:
    from symkin.codegen import render
    from symkin.symbolic import derivation

    # Writing source needs no compiler: only "auto" asks whether one can be built.
    backend = (backends.resolve(args.backend) if args.backend == backends.AUTO
               else backends.get(args.backend))
    given = {option.name: value for option in backends.declared_options()
             if (value := getattr(args, _OPTION_DEST + option.name)) is not None}
    try:  # before the derivation: a wrong flag is said at once
        chosen_options(backend, given, flags=True)
    except BuildError as error:
        return messages.error(str(error), EXIT_BAD_INPUT)
    system = derivation.derive(_load(args))
    paths = render.generate(system, backend, args.output, given, cse=not args.no_cse,
                            force=args.force)
    print("\n".join(str(path) for path in paths))
    return EXIT_OK


def _add_generate(commands: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    generate = commands.add_parser(
        "generate", help="write the source of a mechanism in a backend's language (--backend)")
    generate.add_argument("mechanism", type=Path, help="mechanism file (.yaml or .toml)")
    generate.add_argument("--backend", choices=backends.choices(), default="auto",
                          help="source to write (default auto, as for run: C when a C compiler "
                               "is found, else NumPy with a note)")
    generate.add_argument("-o", "--output", type=Path, required=True, help="output folder")
    for option in backends.declared_options():  # the backends' own options, as they declare
        generate.add_argument(f"--{option.name}", choices=option.choices, default=None,
                              dest=_OPTION_DEST + option.name, help=option.help)
    generate.add_argument("--force", action="store_true",
                          help="write into a folder that also holds files symkin did not "
                               "write (they are left alone)")
    generate.add_argument("--no-cse", action="store_true",
                          help="do not eliminate common subexpressions")
    overrides.add_argument(generate)
    generate.set_defaults(handler=_generate)


def _add_run(commands: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    from symkin.cli import run  # the `run` subcommand lives in its own module

    run.add_parser(commands)


def _add_sweep(commands: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    from symkin.cli import sweep

    sweep.add_parser(commands)


def _add_cache(commands: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    from symkin.cli import cache_command

    cache_command.add_parser(commands)


def _add_scan(commands: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    from symkin.cli import scan

    scan.add_parser(commands)


SUBCOMMANDS: list[Callable[[argparse._SubParsersAction[argparse.ArgumentParser]], None]] = [
    _add_show, _add_verify, _add_generate, _add_run, _add_scan, _add_cache, _add_sweep]


class _Version(argparse.Action):
    """``--version``, looked up only when asked for: reading the package metadata costs a
    tenth of a second that every other command would otherwise pay at start."""

    def __call__(self, parser: argparse.ArgumentParser, namespace: argparse.Namespace,
                 values: Any, option_string: str | None = None) -> None:
        import symkin

        print(f"symkin {symkin.__version__}")
        parser.exit()


def parser() -> argparse.ArgumentParser:
    main_parser = argparse.ArgumentParser(
        prog="symkin", description="Symbolic kinematics code generator for planar mechanisms.")
    main_parser.add_argument("--version", action=_Version, nargs=0,
                             help="print symkin's version and exit")
    commands = main_parser.add_subparsers(dest="command", required=True)
    for add in SUBCOMMANDS:
        add(commands)
    return main_parser


def _note_warning(message: Warning | str, category: type[Warning], filename: str, lineno: int,
                  file: TextIO | None = None, line: str | None = None) -> None:
    """Warnings reach a command-line user as one plain line, not as a source location."""
    messages.note(str(message))


def _located(error: MechanismError, args: argparse.Namespace) -> MechanismError:
    """A mistake found after loading (the rank of an over-constrained file at t0) placed in
    the file the command read."""
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


if __name__ == "__main__":
    sys.exit(main())

"""The ``symkin`` command: a thin layer over the Python API.

Exit status: 0 on success, 1 when a solve or a check fails, 2 for bad input (a one-paragraph
message naming the file and the place in it, never a traceback).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Callable, Sequence

from symkin.errors import MechanismError, SymkinError

EXIT_OK, EXIT_FAILED, EXIT_BAD_INPUT = 0, 1, 2


def _show(args: argparse.Namespace) -> int:
    from symkin import derivation, report

    system = derivation.derive(args.mechanism)
    print(report.latex(system) if args.latex else report.text(system), end="")
    return EXIT_OK


def _schema(args: argparse.Namespace) -> int:
    import json

    from symkin import model

    print(json.dumps(model.json_schema(), indent=2))
    return EXIT_OK


def _add_show(commands: argparse._SubParsersAction) -> None:
    show = commands.add_parser("show", help="print Phi, Phi_q, Phi_t, Gamma and the DOF count")
    show.add_argument("mechanism", type=Path, help="mechanism file (.yaml or .toml)")
    show.add_argument("--latex", action="store_true", help="print LaTeX instead of text")
    show.set_defaults(handler=_show)
    schema = commands.add_parser("schema", help="print the JSON Schema of mechanism files")
    schema.set_defaults(handler=_schema)


# Each entry adds one subcommand; its handler returns the exit status.
SUBCOMMANDS: list[Callable[[argparse._SubParsersAction], None]] = [_add_show]


def parser() -> argparse.ArgumentParser:
    main_parser = argparse.ArgumentParser(
        prog="symkin", description="Symbolic kinematics code generator for planar mechanisms.")
    commands = main_parser.add_subparsers(dest="command", required=True)
    for add in SUBCOMMANDS:
        add(commands)
    return main_parser


def main(argv: Sequence[str] | None = None) -> int:
    args = parser().parse_args(argv)
    try:
        return args.handler(args)
    except MechanismError as error:
        print(f"symkin: error: {error}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except SymkinError as error:
        print(f"symkin: error: {error}", file=sys.stderr)
        return EXIT_FAILED
    except KeyboardInterrupt:
        return 130


if __name__ == "__main__":
    sys.exit(main())

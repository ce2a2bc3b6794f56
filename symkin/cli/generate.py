"""``symkin generate``: write the source of a mechanism in a backend's language."""

from __future__ import annotations

import argparse

from symkin import backends
from symkin.cli import messages
from symkin.cli.arguments import OPTION_DEST
from symkin.cli.exits import EXIT_BAD_INPUT, EXIT_OK
from symkin.cli.show import load
from symkin.codegen.target import chosen_options
from symkin.errors import BuildError


def handle(args: argparse.Namespace) -> int:
    """Run the subcommand; returns the exit status."""
    from symkin.codegen import render
    from symkin.symbolic import derivation

    # Writing source needs no compiler: only "auto" asks whether one can be built.
    backend = (backends.resolve(args.backend) if args.backend == backends.AUTO
               else backends.get(args.backend))
    given = {name: value for name, *_ in backends.declared_flags()
             if (value := getattr(args, OPTION_DEST + name)) is not None}
    try:  # before the derivation: a wrong flag is said at once
        chosen_options(backend, given, flags=True)
    except BuildError as error:
        return messages.error(str(error), EXIT_BAD_INPUT)
    system = derivation.derive(load(args))
    paths = render.generate(system, backend, args.output, given, cse=not args.no_cse,
                            force=args.force)
    print("\n".join(str(path) for path in paths))
    return EXIT_OK

"""``symkin show`` (the derived equations, or a drawn file's local layout) and ``symkin
schema`` (the JSON Schema of mechanism files)."""

from __future__ import annotations

import argparse
import json

from symkin.cli import overrides
from symkin.cli.exits import EXIT_OK
from symkin.spec import validate


def load(args: argparse.Namespace) -> validate.Mechanism:
    """The validated mechanism of ``args.mechanism`` with the ``--set`` values."""
    return validate.load(args.mechanism, overrides.parse(args.overrides))


def show(args: argparse.Namespace) -> int:
    """Run ``symkin show``; returns the exit status."""
    from symkin.symbolic import derivation

    if args.local:
        from symkin.spec import drawn

        print(drawn.dump(load(args)), end="")
        return EXIT_OK
    from symkin.symbolic import show as shown

    system = derivation.derive(load(args))
    print(shown.latex(system) if args.latex else shown.text(system), end="")
    return EXIT_OK


def schema(args: argparse.Namespace) -> int:
    """Run ``symkin schema``; returns the exit status."""
    del args  # it takes none
    print(json.dumps(validate.json_schema(), indent=2))
    return EXIT_OK

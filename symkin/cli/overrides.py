"""``--set NAME=VALUE``: parameter values from the command line, for every command that reads a
mechanism (run, show, generate, and any command that varies parameters).

This module only reads the option's text; the values are checked where the file is read
(:func:`symkin.spec.validate.load` with ``overrides``): each must name a parameter of the file
and be a number or an expression of numbers (``2*pi/3``), read by the whitelist parser and
never evaluated as code.
"""

from __future__ import annotations

import argparse

from symkin.errors import UsageError


def add_argument(parser: argparse.ArgumentParser) -> None:
    """Add the repeatable ``--set NAME=VALUE`` option to a subcommand."""
    parser.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                        dest="overrides",
                        help="replace a parameter's value (repeatable); VALUE is a number or "
                             "an expression of numbers such as 2*pi/3")


def parse(items: list[str]) -> dict[str, str]:
    """``["b=5.5", "a = 2*pi"]`` -> {"b": "5.5", "a": "2*pi"}, in the order given.

    Raises:
        UsageError: an item without ``=``, without a name or value, or a name set twice.
    """
    found: dict[str, str] = {}
    for item in items:
        name, equals, value = item.partition("=")
        name, value = name.strip(), value.strip()
        if not equals or not name.isidentifier() or not value:
            raise UsageError(f"--set {item}: write NAME=VALUE with a parameter name and a "
                             "value, e.g. --set b=5.5")
        if name in found:
            raise UsageError(f"--set {name} is given twice ({found[name]} and {value}); "
                             "give each parameter once")
        found[name] = value
    return found


def pairs(items: list[str]) -> tuple[tuple[str, str], ...]:
    """The same as :func:`parse`, as a hashable tuple (for a cache key)."""
    return tuple(parse(items).items())

"""The command-line reference, written from symkin's own argument parser
(:func:`symkin.cli.parser`) when the docs are built: every command, its usage and options."""

from __future__ import annotations

import argparse
import os
from pathlib import Path

from symkin.cli import parser


def _commands(main: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    for action in main._actions:  # argparse keeps its sub-commands only here
        if isinstance(action, argparse._SubParsersAction):
            return dict(action.choices)
    return {}


def _help(command: argparse.ArgumentParser) -> str:
    # A fixed width, so the page is the same on every terminal.
    os.environ["COLUMNS"] = "96"
    return command.format_help().rstrip()


def page() -> str:
    main = parser()
    lines = ["# Command line", "",
             "Written from `symkin`'s argument parser when these pages are built, so it lists "
             "exactly the commands and options of this version. Run any command with `-h` to "
             "see the same text.", "", "```text", _help(main), "```", ""]
    for name, command in _commands(main).items():
        lines += [f"## `symkin {name}`", "", "```text", _help(command), "```", ""]
    return "\n".join(lines)


def write(out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    target = out / "cli.md"
    text = page()
    if not target.exists() or target.read_text(encoding="utf-8") != text:
        target.write_text(text, encoding="utf-8")

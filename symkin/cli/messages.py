"""What the command line prints: every message goes through :func:`printable`, so no control
character from a user's file or command line ever reaches the terminal (no title changes, no
screen clears), and :func:`error` is the one way to report a problem."""

from __future__ import annotations

import sys
import unicodedata

# Kept as they are: a message may span lines (a compiler's output) or be indented.
_KEPT = {"\n", "\t"}


def printable(text: str) -> str:
    """``text`` with every control or other non-printing character shown as an escape."""
    return "".join(ch if ch in _KEPT or unicodedata.category(ch)[0] != "C"
                   else ascii(ch)[1:-1] for ch in text)


def error(message: str, status: int) -> int:
    """Print ``symkin: error: message`` (escaped) to stderr and return ``status``."""
    print(f"symkin: error: {printable(message)}", file=sys.stderr)
    return status


def note(message: str) -> None:
    """Print ``symkin: message`` (escaped) to stderr: something the user should know."""
    print(f"symkin: {printable(message)}", file=sys.stderr)

"""``python -m symkin`` runs the command line."""

from symkin.cli import console

console()

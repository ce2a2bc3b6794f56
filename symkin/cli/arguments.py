"""Every subcommand's arguments, and nothing else.

Built for every ``symkin`` call, ``--help`` and a mistyped command included, so this module
imports only what argparse needs: the backends' names and flags come from the registry's light
table, never from a backend; what a command does is in its own module, imported only when it
runs (the table in :mod:`symkin.cli`).
"""

from __future__ import annotations

import argparse

from symkin import backends
from symkin.cli import overrides

# Not `typing.TYPE_CHECKING` (mypy takes any constant of this name as true): see _path.
TYPE_CHECKING = False
if TYPE_CHECKING:
    from pathlib import Path

OPTION_DEST = "backend_option_"
"""Prefix of a backend option's attribute: it never shadows one of the command's own."""

MECHANISM_HELP = "mechanism file (.yaml or .toml)"


def _path(text: str) -> Path:
    """A file or folder argument as a Path; pathlib is imported when a command is given one,
    not for ``--help`` (pathlib and what it imports are a tenth of that)."""
    from pathlib import Path

    return Path(text)


def show(command: argparse.ArgumentParser) -> None:
    command.add_argument("mechanism", type=_path, help=MECHANISM_HELP)
    command.add_argument("--latex", action="store_true", help="print LaTeX instead of text")
    command.add_argument("--local", action="store_true",
                         help="print the mechanism in the local layout (local vectors, v, phi0, "
                              "q0), as derived from a drawn file")
    overrides.add_argument(command)


def schema(command: argparse.ArgumentParser) -> None:
    del command  # it takes none


def verify(command: argparse.ArgumentParser) -> None:
    command.add_argument("mechanism", type=_path, help=MECHANISM_HELP)
    command.add_argument("--against", type=_path, required=True, metavar="HAND.py",
                         help="Python file defining phi(q, t, p), phi_q(q, t, p), phi_t(q, t, p) "
                              "and/or gamma(q, dq, t, p) in the order `symkin show` prints")
    command.add_argument("--samples", type=int, default=50, help="random states (default 50)")
    command.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    command.add_argument("--spread", type=float, default=None,
                         help="relative spread of parameters around the nominal design "
                              "(default 0.3; 0 keeps them nominal; .m hand files take no "
                              "parameters and are checked at the nominal design only)")
    command.add_argument("--tolerance", type=float, default=1e-8,
                         help="largest accepted relative error (default 1e-8)")


def generate(command: argparse.ArgumentParser) -> None:
    command.add_argument("mechanism", type=_path, help=MECHANISM_HELP)
    command.add_argument("--backend", choices=backends.choices(), default="auto",
                         help="source to write (default auto, as for run: C when a C compiler "
                              "is found, else NumPy with a note)")
    command.add_argument("-o", "--output", type=_path, required=True, help="output folder")
    for name, choices, _, text in backends.declared_flags():  # as the backends declare them
        command.add_argument(f"--{name}", choices=choices, default=None,
                             dest=OPTION_DEST + name, help=text)
    command.add_argument("--force", action="store_true",
                         help="write into a folder that also holds files symkin did not "
                              "write (they are left alone)")
    command.add_argument("--no-cse", action="store_true",
                         help="do not eliminate common subexpressions")
    overrides.add_argument(command)


def _grid(command: argparse.ArgumentParser) -> None:
    """--t0, --t1 and --dt: the file's time grid overridden (run and scan)."""
    command.add_argument("--t0", type=float, help="first time (default: the file's)")
    command.add_argument("--t1", type=float, help="last time, included (default: the file's)")
    command.add_argument("--dt", type=float, help="time step (default: the file's)")


def run(command: argparse.ArgumentParser) -> None:
    command.add_argument("mechanism", type=_path, help=MECHANISM_HELP)
    command.add_argument("--backend", choices=backends.choices(), default="auto",
                         help="kernel to run (default auto: the generated C when a C compiler "
                              "is found, else NumPy; c without a compiler is an error)")
    _grid(command)
    command.add_argument("--at", type=float, metavar="T",
                         help="solve the single configuration at time T and print q, dq, d2q "
                              "and the named points (no grid)")
    command.add_argument("--inputs", type=_path, metavar="TABLE.csv",
                         help="values of the input drivers (functions written `input`): CSV "
                              "columns t (the grid), then each input's name, optionally "
                              "followed by NAME_t (rate) and NAME_tt (acceleration)")
    command.add_argument("-o", "--output", type=_path, help="results file, .npz or .csv")
    command.add_argument("--plot", type=_path,
                         help="figure of position, velocity and acceleration against t: .png, "
                              ".svg or .pdf")
    command.add_argument("--select", metavar="NAMES",
                         help="what --plot and --html show: coordinates and named points, e.g. "
                              "crank.phi,coupler.P (default: the angles and the moving points)")
    command.add_argument("--html", type=_path,
                         help="interactive report: the mechanism moving under a time slider, "
                              "with paths, velocity and acceleration vectors, and the selected "
                              "plots (one self-contained file)")
    command.add_argument("--animate", type=_path, help="GIF of the mechanism moving")
    command.add_argument("--size", default="900x600", metavar="WxH",
                         help="--animate picture size in pixels (default 900x600)")
    command.add_argument("--fps", type=int, default=20,
                         help="--animate frames per second (default 20)")
    command.add_argument("-v", "--verbose", action="store_true",
                         help="say more in notes (why pivot fall-backs cost no accuracy)")
    overrides.add_argument(command)
    command.add_argument("--stop-at-singular", action="store_true",
                         help="stop at the first singular or ill-conditioned point instead of "
                              "passing through it (and do not subdivide a failed step)")


def scan(command: argparse.ArgumentParser) -> None:
    command.add_argument("mechanism", type=_path, help=MECHANISM_HELP)
    command.add_argument("--backend", choices=backends.choices(), default="auto",
                         help="kernel to run (default auto, as for run)")
    _grid(command)
    command.add_argument("--all-branches", action="store_true",
                         help="follow the motion from every branch found at t0, not only from "
                              "the one a run takes (reached from q0)")
    command.add_argument("--input", action="append", default=[], metavar="NAME=VALUE",
                         dest="inputs", help="the value of input driver NAME (repeat for each): "
                         "the branches are then the assemblies at these inputs")
    overrides.add_argument(command)


def cache(command: argparse.ArgumentParser) -> None:
    command.add_argument("action", choices=("info", "clear"),
                         help="info: where it is and what it holds; clear: remove symkin's "
                              "kernels, index and temporaries")


def sweep(command: argparse.ArgumentParser) -> None:
    command.add_argument("mechanism", type=_path, help=MECHANISM_HELP)
    design = command.add_argument_group("the parameter sets (one of)")
    design.add_argument("--vary", action="append", default=[], metavar="NAME=LO:HI:COUNT",
                        help="COUNT values from LO to HI; several names form every combination")
    design.add_argument("--params", type=_path, metavar="TABLE.csv",
                        help="a CSV table: a header of parameter names, one set per row")
    design.add_argument("--monte-carlo", type=int, metavar="N",
                        help="N sets drawn within the --tolerance of each parameter")
    command.add_argument("--tolerance", action="append", default=[], metavar="NAME=±X",
                         help="half-width of a parameter's tolerance, absolute or with %% "
                              "relative to the nominal value (a=±0.01, b=+-0.5%%)")
    command.add_argument("--distribution", choices=("normal", "uniform"), default="normal",
                         help="Monte-Carlo draws: normal with ±X as 3 sigma (default), or "
                              "uniform")
    command.add_argument("--seed", type=int, default=0,
                         help="Monte-Carlo random seed (default 0)")
    command.add_argument("--backend", choices=backends.choices(), default="auto")
    command.add_argument("--workers", type=int, help="local processes (default: the cores, "
                         "in this process for small sweeps)")
    command.add_argument("--scheduler", metavar="ADDRESS",
                         help="a Dask scheduler (tcp://host:8786): run the sweep on its cluster")
    command.add_argument("-o", "--output", type=_path, help="results file, .npz")
    command.add_argument("--compress", action="store_true",
                         help="write the .npz compressed (smaller, slower to write)")
    command.add_argument("--plot", type=_path, help="PNG of the named points' envelopes over t")
    overrides.add_argument(command)

"""The start of a `symkin` command: `--help`, a subcommand's help and a mistyped command,
timed against `python -c pass` of the same interpreter, for one or more installations.

    python3 bench/help_start.py [--rounds N] PYTHON [PYTHON ...]

Each PYTHON is an interpreter with symkin installed (a venv's bin/python; its console script
`symkin` is taken from the same folder). Every command runs N times (default 30), all of them
interleaved round by round, so that the machine's load falls on each alike; the table gives
the median and the least wall and CPU (user + system of the child) in milliseconds. Then, not
moved by load: the modules each command has imported (`-X importtime`), the sum of their own
import times (the least over 5 runs, per module) and, with `--instructions`, the instructions
each command executes (valgrind's callgrind; the same on a loaded machine as on an idle one).
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import time
from pathlib import Path

COMMANDS = (("python -c pass", ["-c", "pass"], False), ("symkin --help", ["--help"], True),
            ("python -m symkin --help", ["-m", "symkin", "--help"], False),
            ("symkin run --help", ["run", "--help"], True),
            ("symkin generate --help", ["generate", "--help"], True),
            ("symkin runn (usage error)", ["runn"], True))


def _argv(python: Path, arguments: list[str], script: bool) -> list[str]:
    return [str(python.parent / "symkin"), *arguments] if script else [str(python), *arguments]


def _once(argv: list[str], env: dict[str, str]) -> tuple[float, float]:
    """Wall and CPU seconds of one run, its output discarded."""
    start = time.perf_counter()
    null = os.open(os.devnull, os.O_WRONLY)
    try:
        pid = os.posix_spawn(argv[0], argv, env, file_actions=[
            (os.POSIX_SPAWN_DUP2, null, 1), (os.POSIX_SPAWN_DUP2, null, 2)])
    finally:
        os.close(null)
    _, _, usage = os.wait4(pid, 0)
    return time.perf_counter() - start, usage.ru_utime + usage.ru_stime


def _imports(python: Path, arguments: list[str], runs: int = 5) -> tuple[int, float]:
    """The modules ``python -X importtime -m symkin ARGS`` imports, and the sum of their own
    import times in ms (each module's least over ``runs``)."""
    least: dict[str, int] = {}
    for _ in range(runs):
        done = subprocess.run([str(python), "-X", "importtime", *arguments], env=_env(),
                              capture_output=True, text=True, check=False)
        for line in done.stderr.splitlines():
            head, _, name = line.rpartition("|")
            own = head.split("|")[0].removeprefix("import time:").strip()
            if own.isdigit():
                least[name.strip()] = min(int(own), least.get(name.strip(), int(own)))
    return len(least), sum(least.values()) / 1e3


def _instructions(argv: list[str]) -> int:
    """What callgrind counts for one run of ``argv`` (the whole process)."""
    done = subprocess.run(["valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null",
                           *argv], env=_env(), capture_output=True, text=True, check=False)
    return int(done.stderr.split("Collected :")[1].split()[0])


def _env() -> dict[str, str]:
    # the installation's own symkin, not a source tree on the path
    return {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("pythons", nargs="+", type=Path, metavar="PYTHON")
    parser.add_argument("--rounds", type=int, default=30)
    parser.add_argument("--instructions", action="store_true",
                        help="also count instructions with valgrind (a few seconds a command)")
    args = parser.parse_args()
    runs = [(python, label, _argv(python, arguments, script))
            for python in args.pythons for label, arguments, script in COMMANDS]
    times: dict[int, list[tuple[float, float]]] = {k: [] for k in range(len(runs))}
    for _ in range(args.rounds):
        for k, (_, _, argv) in enumerate(runs):
            times[k].append(_once(argv, _env()))
    print(f"{'installation':40} {'command':28} {'wall median/least':>18} {'CPU median/least':>17}")
    for k, (python, label, _) in enumerate(runs):
        wall, cpu = (sorted(x) for x in zip(*times[k]))
        print(f"{python!s:40} {label:28} {statistics.median(wall) * 1e3:8.1f} "
              f"{wall[0] * 1e3:7.1f}   {statistics.median(cpu) * 1e3:8.1f} {cpu[0] * 1e3:7.1f}")
    print(f"\n{'installation':40} {'imports of':28} {'modules':>8} {'own import ms':>14}")
    for python in args.pythons:
        for label, arguments in (("python -c pass", ["-c", "pass"]),
                                 ("python -m symkin --help", ["-m", "symkin", "--help"])):
            count, own = _imports(python, arguments)
            print(f"{python!s:40} {label:28} {count:8d} {own:14.1f}")
    if args.instructions:
        print(f"\n{'installation':40} {'command':28} {'instructions':>14}")
        for python, label, argv in runs:
            print(f"{python!s:40} {label:28} {_instructions(argv):14,d}")


if __name__ == "__main__":
    main()

"""A running GNU Octave that evaluates generated (or hand-written) .m functions for Python.

One ``octave-cli`` process per folder, started on first use and ended with the interpreter:
a call writes one line (the function's name, its arguments as exact decimal literals) and
reads the result back one value a line, printed with 17 significant digits, so every double
comes back bit for bit. Octave's own error message comes back as :class:`OctaveError`. Only
names symkin chose and numbers are ever written to Octave; no user text is evaluated by
Python.
"""

from __future__ import annotations

import atexit
import re
import shutil
import subprocess
import threading
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from symkin.errors import BuildError

PROGRAM = "octave-cli"
_BEGIN = "@@symkin-begin"  # what a function printed itself (a missing semicolon) comes before
_END = "@@symkin-end"
_ERROR = "@@symkin-error "
_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*\Z")


class OctaveError(BuildError):
    """A function evaluated in Octave raised an error (the message is Octave's)."""


def number(value: float) -> str:
    """A double as an exact MATLAB literal (the shortest round trip; Inf, NaN)."""
    if value != value:
        return "NaN"
    if value in (float("inf"), float("-inf")):
        return "Inf" if value > 0 else "-Inf"
    return repr(float(value))


def argument(value: float | Sequence[float] | NDArray[np.float64]) -> str:
    """A scalar, or a vector as a column."""
    array = np.asarray(value, dtype=float)
    if array.ndim == 0:
        return number(float(array))
    return "[" + ";".join(number(float(v)) for v in array.reshape(-1)) + "]"


class Session:
    """One Octave process with ``folder`` on its path (see the module docstring)."""

    def __init__(self, folder: Path) -> None:
        self.folder = folder
        self._process: subprocess.Popen[str] | None = None
        self._lock = threading.Lock()

    def _start(self) -> subprocess.Popen[str]:
        program = shutil.which(PROGRAM)
        if program is None:
            raise BuildError(f"GNU Octave ({PROGRAM}) is not on PATH; install it (Debian/Ubuntu: "
                             "apt-get install octave)")
        process = subprocess.Popen(
            [program, "--norc", "--quiet", "--no-history", "--no-gui"],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
            text=True, bufsize=1, cwd=self.folder)
        _STARTED.append(process)
        # The folder's own functions first; warnings (a singular matrix) are the caller's to
        # judge from the numbers, and would interleave with them.
        self._send(process, f"addpath({_string(str(self.folder))}); warning('off', 'all');"
                            f" fprintf('{_END}\\n');")
        self._read(process, "starting Octave")
        return process

    def exists(self, function: str) -> bool:
        """Whether ``function`` is a function Octave finds on its path."""
        found = self.evaluate(f"double(any(exist({_string(function)}) == [2 3 5]))", function)
        return bool(found.size and found.flat[0])

    def arguments_of(self, function: str) -> int:
        """How many arguments ``function`` declares (nargin; negative with varargin)."""
        return int(self.evaluate(f"nargin({_string(function)})", function).flat[0])

    def call(self, function: str, arguments: Sequence[object], output: int = 1
             ) -> NDArray[np.float64]:
        """``function(arguments...)``'s output number ``output`` (1-based), 2-D as in MATLAB."""
        if not _NAME.match(function):
            raise BuildError(f"internal error: {function!r} is not a MATLAB function name")
        text = ", ".join(argument(a) for a in arguments)  # type: ignore[arg-type]
        outputs = ", ".join(["~"] * (output - 1) + ["symkin_r"])
        return self.evaluate(f"{function}({text})", function, f"[{outputs}]")

    def evaluate(self, expression: str, origin: str, target: str = "symkin_r"
                 ) -> NDArray[np.float64]:
        """The value of an expression symkin wrote, as a 2-D array of MATLAB's shape."""
        line = (f"try, {target} = {expression}; symkin_r = full(double(symkin_r));"
                f" fprintf('{_BEGIN}\\n');"
                " fprintf('%d\\n', size(symkin_r, 1)); fprintf('%.17g\\n', symkin_r);"
                f" fprintf('{_END}\\n'); catch symkin_e, fprintf('{_ERROR}%s',"
                " strrep(symkin_e.message, char(10), ' ')); if ~isempty(symkin_e.stack),"
                " fprintf(' (%s, line %d)', symkin_e.stack(1).name, symkin_e.stack(1).line);"
                " end; fprintf('\\n'); end")
        with self._lock:
            if self._process is None or self._process.poll() is not None:
                self._process = self._start()
            self._send(self._process, line)
            values = self._read(self._process, origin)
        rows = int(values[0]) if values else 0
        flat = np.array([float(v) for v in values[1:]], dtype=float)
        return flat.reshape((rows, -1) if rows else (0, 0), order="F")

    def _send(self, process: subprocess.Popen[str], line: str) -> None:
        assert process.stdin is not None
        try:
            process.stdin.write(line + "\n")
            process.stdin.flush()
        except OSError as error:
            raise BuildError(f"Octave stopped ({error}); it ran the functions of "
                             f"{self.folder}") from None

    def _read(self, process: subprocess.Popen[str], origin: str) -> list[str]:
        assert process.stdout is not None
        values: list[str] = []
        while True:
            line = process.stdout.readline()
            if not line:
                raise BuildError(f"Octave stopped while evaluating {origin} (exit status "
                                 f"{process.poll()}); it ran the functions of {self.folder}")
            line = line.strip()
            if line == _END:
                return values
            if line.startswith(_ERROR):
                raise OctaveError(f"{origin}: Octave says: {line[len(_ERROR):][:400]}")
            if line == _BEGIN:
                values.clear()  # anything before it the function printed itself
            elif line:
                values.append(line)

    def close(self) -> None:
        if self._process is not None and self._process.poll() is None:
            _end(self._process)
        self._process = None


def _string(text: str) -> str:
    """A MATLAB single-quoted string (quotes doubled)."""
    return "'" + text.replace("'", "''") + "'"


_STARTED: list[subprocess.Popen[str]] = []


def _end(process: subprocess.Popen[str]) -> None:
    try:
        if process.stdin is not None:
            process.stdin.close()
        process.wait(timeout=5)
    except (OSError, subprocess.TimeoutExpired):
        process.kill()


@atexit.register
def _end_all() -> None:
    """End the Octave processes this interpreter started (and only those)."""
    for process in _STARTED:
        if process.poll() is None:
            _end(process)

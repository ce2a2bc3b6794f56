"""Error types: every mistake a user can make maps to one of these, with a fix in its message."""

from __future__ import annotations

from collections.abc import Sequence


class SymkinError(Exception):
    """Base class of every error symkin raises on purpose."""


class ExpressionError(SymkinError):
    """An expression in a mechanism file was refused by the whitelist parser."""

    def __init__(self, message: str, text: str = "", column: int | None = None) -> None:
        self.message = message
        self.text = text
        self.column = column
        super().__init__(self._render())

    def _render(self) -> str:
        if not self.text:
            return self.message
        where = f" at column {self.column + 1}" if self.column is not None else ""
        return f"in expression {self.text!r}{where}: {self.message}"


class MechanismError(SymkinError):
    """A mechanism description is invalid.

    Args:
        message: what is wrong.
        path: the field path inside the mechanism, e.g. ("joints", 2, "sA").
        hint: how to fix it.
        source: the file it came from, when there is one.
        line: the 1-based line in that file, when known.
    """

    def __init__(
        self,
        message: str,
        path: Sequence[str | int] = (),
        hint: str = "",
        source: str | None = None,
        line: int | None = None,
    ) -> None:
        self.message = message
        self.path = tuple(path)
        self.hint = hint
        self.source = source
        self.line = line
        super().__init__(self._render())

    def located(self, source: str | None, line: int | None) -> MechanismError:
        """Return a copy of this error that names the file and line."""
        return MechanismError(self.message, self.path, self.hint, source, line)

    def _render(self) -> str:
        place = ""
        if self.source:
            place = self.source + (f":{self.line}" if self.line else "") + ": "
        field = f"at {format_path(self.path)}: " if self.path else ""
        hint = f" {self.hint}" if self.hint else ""
        message = self.message if self.message.endswith((".", "?", "!")) else self.message + "."
        return f"{place}{field}{message}{hint}"


class SolveError(SymkinError):
    """The numerical solution failed (no convergence, singular Jacobian)."""


class BuildError(SymkinError):
    """Generating or compiling code failed; carries the command and its output."""


def format_path(path: Sequence[str | int]) -> str:
    """Render a field path the way a user reads it: ``joints[2].sA``."""
    text = ""
    for part in path:
        if isinstance(part, int):
            text += f"[{part}]"
        else:
            text += ("." if text else "") + str(part)
    return text


class SymkinWarning(UserWarning):
    """Something a user should know that does not stop the work (the CLI prints it as a note)."""


class UsageError(SymkinError):
    """A request that cannot be carried out as given (a bad path, an option that does not
    fit); the command line exits with status 2."""


class BackendRefused(UsageError):
    """A backend or option that cannot serve this mechanism (Octave or float for one its
    forces move: build.motion); the command line names the file before the message."""


class MissingToolError(UsageError, BuildError):
    """A backend asked for by name needs a program this machine lacks (GNU Octave for the
    octave backend; exit status 2)."""


class NoCompilerError(UsageError, BuildError):
    """The C backend was asked for by name and there is no C compiler (exit status 2)."""

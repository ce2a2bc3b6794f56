"""How symkin writes a file for the user: to a temporary file in the same folder, renamed over
the target only once it is whole, so that an interrupt, a full disk or a failing writer leaves
the file that was there before untouched; and which output paths are refused because they
name a file the same command reads.

A leaf module (the standard library only): the runtime's Trajectory.save, the pictures, the
report and the sweeps all write through it.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Iterator, Sequence
from pathlib import Path


@contextlib.contextmanager
def replacing(path: str | Path) -> Iterator[Path]:
    """Yield a temporary path next to ``path`` for a writer to fill; when the block ends
    normally it is renamed onto ``path`` (atomic on one file system), otherwise it is removed
    and ``path`` is as it was. The temporary name keeps the suffix, since writers such as
    numpy.savez, matplotlib and Pillow choose the format (or add a suffix) by it."""
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    # the suffix in lower case: numpy.savez adds ".npz" to a name ending ".NPZ"
    suffix = f".part{target.suffix.lower()}"
    handle, name = tempfile.mkstemp(prefix=f".{target.stem}.", suffix=suffix, dir=target.parent)
    os.close(handle)
    temporary = Path(name)
    try:
        yield temporary
        _keep_mode(target, temporary)
        os.replace(temporary, target)
    except BaseException as error:  # KeyboardInterrupt too: no half-written file may stay
        with contextlib.suppress(OSError):
            temporary.unlink()
        if isinstance(error, OSError):  # said of the user's file, not of the temporary one
            raise OSError(error.errno, error.strerror or str(error), str(target)) from None
        raise


def _keep_mode(target: Path, temporary: Path) -> None:
    """The replaced file's permissions, or the umask's default for a new file (mkstemp makes
    its file private, 0600, which a results file need not be)."""
    try:
        mode = target.stat().st_mode & 0o777
    except OSError:
        umask = os.umask(0)
        os.umask(umask)
        mode = 0o666 & ~umask
    with contextlib.suppress(OSError):
        os.chmod(temporary, mode)


def same_file(a: str | Path, b: str | Path) -> bool:
    """Whether two paths name one file: the same path once links are resolved, or the same
    file by device and inode (a hard link)."""
    a, b = Path(a), Path(b)
    try:
        if a.resolve() == b.resolve():
            return True
        return a.exists() and b.exists() and a.samefile(b)
    except (OSError, RuntimeError):  # a link loop: it names no file that is read
        return False


def clash(outputs: Sequence[tuple[str, str | Path | None]],
          inputs: Sequence[tuple[str, str | Path | None]]) -> str | None:
    """The first output that names one of the command's inputs, said as a sentence (None when
    none does). Each entry is (how the command line names it, its path or None)."""
    for flag, path in outputs:
        if path is None:
            continue
        for what, read in inputs:
            if read is not None and same_file(path, read):
                return (f"{flag} {path} is {what} {read} (the command reads it); writing "
                        "there would replace it: give another output file")
    return None

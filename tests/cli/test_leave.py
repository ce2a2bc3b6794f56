"""symkin.cli.leave: a command's process ends with its status, its output flushed and its exit
functions run, without the interpreter's teardown (freeing a derivation's SymPy objects one by
one cost a tenth of a cold `symkin generate`); with another thread still running, Python's
own exit waits for it as before."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

_SCRIPT = textwrap.dedent("""
    import atexit, sys, threading, time
    from symkin.cli import leave

    class Held:
        def __del__(self):
            print("torn down")

    held = Held()  # freed only by the interpreter's teardown
    atexit.register(lambda: print("exit function"))
    if sys.argv[1] == "profiled":
        sys.setprofile(lambda *_: None)  # as cProfile: its report is written after exit
    if sys.argv[1] == "thread":
        threading.Thread(target=lambda: (time.sleep(0.2), print("thread done"))).start()
    print("written", end="")  # no newline: still in the buffer at leave()
    try:
        leave(int(sys.argv[2]))
    finally:  # what cProfile's main does once the command returns: only if leave() raises
        if sys.argv[1] == "profiled":
            print("report")
""")


def _run(mode: str, status: int) -> subprocess.CompletedProcess[str]:
    buffered = {k: v for k, v in os.environ.items() if k != "PYTHONUNBUFFERED"}
    return subprocess.run([sys.executable, "-c", _SCRIPT, mode, str(status)],
                          capture_output=True, text=True, timeout=60, check=False, env=buffered)


def test_leave_keeps_the_status_output_and_exit_functions_but_skips_the_teardown() -> None:
    done = _run("plain", 3)
    assert done.returncode == 3
    assert done.stdout == "writtenexit function\n"  # flushed, then the exit function's line
    assert "torn down" not in done.stdout


def test_leave_with_a_running_thread_exits_as_python_does() -> None:
    done = _run("thread", 0)
    assert done.returncode == 0
    assert "thread done" in done.stdout and "exit function" in done.stdout


def test_leave_under_a_profiler_exits_as_python_does() -> None:
    done = _run("profiled", 2)
    assert done.returncode == 2
    assert done.stdout.startswith("writtenreport\nexit function\n")

"""After Ctrl-C the rows solved so far are written with Ctrl-C held off: a second Ctrl-C
while writing neither stops the writing nor leaves half a file."""

from __future__ import annotations

import os
import signal

import numpy as np
from codegen_support import compiled

import symkin
from symkin.cli.run_outputs import interrupts_held
from symkin.runtime.outputs.results import Trajectory


def test_a_second_interrupt_while_writing_is_held_off(tmp_path, crank_slider_path):
    kernel = compiled(crank_slider_path, "numpy")  # from its goldens: no derivation
    # the second Ctrl-C comes before the first row is written: any number of rows shows it
    trajectory: Trajectory = symkin.solve(kernel, t=np.linspace(0, 1.5, 201))
    before = signal.getsignal(signal.SIGINT)
    path = tmp_path / "rows.csv"
    with interrupts_held():
        assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN
        os.kill(os.getpid(), signal.SIGINT)  # the second Ctrl-C: ignored, no KeyboardInterrupt
        trajectory.save(path)
    assert signal.getsignal(signal.SIGINT) is before
    lines = path.read_text().splitlines()
    assert len(lines) == 202  # the header and every row
    np.testing.assert_array_equal(np.loadtxt(path, delimiter=",", skiprows=1)[:, 0],
                                  trajectory.t)

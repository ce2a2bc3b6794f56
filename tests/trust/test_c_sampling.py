"""The C backend's generation-time sampling of Phi_q (the sparse LU's pivot order) survives
expressions that are not real where it samples: the run then ends as the NumPy kernel's does,
with the row and time named, instead of a traceback while generating.

Reference: the NumPy backend's own exit code and message for the same file.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from symkin import cli

HERE = Path(__file__).resolve().parent
FILES = [("heaviside_not_real.yaml", "Phi in row 8 (drivers[0] angle crank-ground (angle)) is "
                                     "not finite at t = 0"),
         ("spatial_sqrt_driver.yaml", "(drivers[0] angle ground-crank (angle)) is not finite "
                                      "at t = 0")]


@pytest.mark.parametrize(("name", "said"), FILES)
def test_c_ends_as_numpy_does(name: str, said: str, tmp_path: Path,
                              capsys: pytest.CaptureFixture[str]) -> None:
    outcomes = []
    for backend in ("numpy", "c"):
        code = cli.main(["run", str(HERE / name), "--backend", backend, "-o",
                         str(tmp_path / f"{backend}.csv")])
        err = capsys.readouterr().err
        assert "Traceback" not in err
        outcomes.append((code, said in err))
    assert outcomes == [(1, True), (1, True)]

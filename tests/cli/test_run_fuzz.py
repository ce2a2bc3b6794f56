"""A seeded fuzz campaign through the command line: mutated spatial, forces, pairs and input
files (structural edits, extreme and subnormal numbers, long decimals, names that mean
something else, bad --inputs tables) through ``show`` and ``run`` on NumPy and, where a run
gets that far, on C. Each case must give no traceback (any exception outside symkin's own
error handling fails), end within a time bound (no hang), say every message in bounded
lines, and, where both backends succeed, agree on every unflagged row.

Bounded for CI; SYMKIN_FUZZ_EXAMPLES=N runs a longer campaign.
"""

from __future__ import annotations

import copy
import os
import shutil
import signal
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from hypothesis import HealthCheck, Phase, given, seed, settings
from hypothesis import strategies as st

from symkin import cli
from symkin.spec import loader

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
NAMES = ("rssr.yaml", "spatial_slider_crank.yaml", "cardan.yaml", "crank_slider_load.yaml",
         "four_bar_dynamics.yaml", "rack_linkage.yaml", "cam_cycloidal.yaml",
         "crank_slider_input.yaml", "parallelogram_extra_bar_loads.yaml")
SOURCES = {name: loader.read(EXAMPLES / name).data for name in NAMES}
EXTREME = [1e300, -1e300, 5e-324, -5e-324, 1e-200, 1e18, 1e-18, 0.0, -0.0,
           "0.86602540378443865475244008443621048", "1.00000000000000000000000000001",
           "2.5e-310", "123456789012345678901234567890"]
NAMES_OF_LINKS = ["input", "output", "crank", "sinf", "cosf", "main", "t", "ground", "ż",
                  "a" * 60]
CASES = int(os.environ.get("SYMKIN_FUZZ_EXAMPLES", "4"))
SEED = int(os.environ.get("SYMKIN_FUZZ_SEED", "4141"))  # another seed: another campaign
SHOW_SECONDS, RUN_SECONDS = 120, 240  # generous: a loaded CI machine is slow, a hang endless
MAX_LINE = 3000
"""A message line longer than this is unbounded (a list or a number printed in full)."""
CHC = shutil.which("cc") or shutil.which("gcc")


class Hang(BaseException):
    """A command ran past its time bound (BaseException: no handler of symkin's catches it)."""


def _bounded(seconds: int, argv: list[str]) -> int:
    """cli.main(argv) with an alarm after ``seconds``: a hang fails the case."""
    def alarm(signum: int, frame: Any) -> None:
        raise Hang(f"{' '.join(argv)} ran past {seconds} s")

    previous = signal.signal(signal.SIGALRM, alarm)
    signal.alarm(seconds)
    try:
        return cli.main(argv)
    except SystemExit as stop:  # argparse's own usage errors
        return int(stop.code or 0)
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)


def _places(node: Any, path: tuple = ()) -> list[tuple]:
    """Every path to a value inside the data (not the root)."""
    found = [path] if path else []
    items = node.items() if isinstance(node, dict) else enumerate(node) \
        if isinstance(node, list) else ()
    for key, value in items:
        found += _places(value, path + (key,))
    return found


def _structure_edit(draw: Any, data: Any) -> Any:
    """A key dropped, a list item duplicated, or a pair's bodies swapped."""
    place = draw(st.sampled_from(_places(data)))
    parent, key = _at(data, place[:-1]), place[-1]
    edit = draw(st.sampled_from(["drop", "duplicate", "swap"]))
    if edit == "swap" and isinstance(parent[key], dict) and {"i", "j"} <= set(parent[key]):
        parent[key]["i"], parent[key]["j"] = parent[key]["j"], parent[key]["i"]
    elif edit == "duplicate" and isinstance(parent, list):
        parent.insert(key, copy.deepcopy(parent[key]))
    else:
        del parent[key]
    return data


def _as_yaml(data: Any) -> str:
    return yaml.safe_dump(data, allow_unicode=True, sort_keys=False)


def _number_edit(draw: Any, data: Any) -> Any:
    """A number of the file replaced by an extreme, subnormal or long one."""
    numbers = [place for place in _places(data) if _is_number(_at(data, place))]
    if not numbers:
        return data
    place = draw(st.sampled_from(numbers))
    parent = _at(data, place[:-1])
    parent[place[-1]] = draw(st.sampled_from(EXTREME))
    return data


def _name_edit(draw: Any, data: Any) -> Any:
    """A body renamed everywhere (its references too) to a name people give links."""
    bodies = [name for name in data.get("bodies", {}) if name != "ground"]
    if not bodies:
        return data
    old, new = draw(st.sampled_from(bodies)), draw(st.sampled_from(NAMES_OF_LINKS))
    text = yaml.safe_dump(data, allow_unicode=True, sort_keys=False)
    return yaml.safe_load(text.replace(f"{old}", f"{new}")) if old != new else data


def _at(data: Any, place: tuple) -> Any:
    for part in place:
        data = data[part]
    return data


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _table(draw: Any) -> str:
    """An --inputs table for crank_slider_input (t, then the crank angle), good or bad."""
    t = np.linspace(0.0, 1.0, 11)
    u = 2 * np.pi * t
    kind = draw(st.sampled_from(["good", "negative", "huge", "nan", "word", "missing",
                                 "unsorted", "subnormal"]))
    rows = [[f"{a!r}", f"{b!r}"] for a, b in zip(t, u)]
    if kind == "negative":
        rows[3][1] = "-1"
    elif kind == "huge":
        rows[4][1] = "1e300"
    elif kind == "nan":
        rows[5][1] = "nan"
    elif kind == "word":
        rows[2][1] = "fast"
    elif kind == "missing":
        rows[6] = rows[6][:1]
    elif kind == "unsorted":
        rows[7][0], rows[8][0] = rows[8][0], rows[7][0]
    elif kind == "subnormal":
        rows[1][1] = "5e-324"
    return "t,crank_angle\n" + "\n".join(",".join(row) for row in rows) + "\n"


@st.composite
def cases(draw: Any) -> tuple[str, Any, str | None, bool]:
    name = draw(st.sampled_from(NAMES))
    data = copy.deepcopy(SOURCES[name])
    for _ in range(draw(st.integers(1, 2))):
        edit = draw(st.sampled_from(["number", "number", "name", "structure"]))
        data = (_number_edit if edit == "number" else _name_edit if edit == "name"
                else _structure_edit)(draw, data)
    table = _table(draw) if name == "crank_slider_input.yaml" else None
    return name, data, table, draw(st.booleans())


def _lines_bounded(text: str) -> None:
    assert "Traceback" not in text, text
    for line in text.splitlines():
        assert len(line) <= MAX_LINE, f"an unbounded message line: {line[:300]}..."


def _agree(numpy_csv: Path, c_csv: Path) -> None:
    """The unflagged rows of the two backends' results agree."""
    header = numpy_csv.read_text().splitlines()[0].split(",")
    assert c_csv.read_text().splitlines()[0].split(",") == header
    a = np.atleast_2d(np.loadtxt(numpy_csv, delimiter=",", skiprows=1))
    b = np.atleast_2d(np.loadtxt(c_csv, delimiter=",", skiprows=1))
    assert a.shape == b.shape, (a.shape, b.shape)
    flagged = header.index("flagged")
    rows = (a[:, flagged] == 0) & (b[:, flagged] == 0)
    coordinates = [k for k, name in enumerate(header)
                   if 0 < k < flagged and not name.endswith(("_t", "_tt"))]
    left, right = a[rows][:, coordinates], b[rows][:, coordinates]
    scale = 1.0 + np.nanmax(np.abs(left), initial=0.0)
    finite = np.isfinite(left) & np.isfinite(right)
    assert np.array_equal(finite, np.isfinite(left) | np.isfinite(right)), "inf/NaN differ"
    assert np.all(np.abs(left - right)[finite] <= 1e-6 * scale), "C and NumPy disagree"


@seed(SEED)
@settings(max_examples=CASES, deadline=None, database=None,
          phases=[Phase.explicit, Phase.generate],  # no shrinking: a hang costs minutes
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                 HealthCheck.function_scoped_fixture])
@given(cases())
def test_mutated_files_run_without_traceback_hang_or_disagreement(capsys, case) -> None:
    name, data, table, with_c = case
    with tempfile.TemporaryDirectory(prefix="symkin-run-fuzz-") as folder:
        path = Path(folder) / name
        path.write_text(_as_yaml(data), encoding="utf-8")
        extra = []
        if table is not None:
            (Path(folder) / "u.csv").write_text(table)
            extra = ["--inputs", str(Path(folder) / "u.csv")]
        try:
            _campaign(path, extra, with_c, capsys)
        except Hang as hang:  # said with the file, so that the case can be reproduced
            raise AssertionError(f"{hang}\n{path.read_text()[:4000]}") from None


def _campaign(path: Path, extra: list[str], with_c: bool, capsys: Any) -> None:
    """show, then run on NumPy (and C), each bounded in time; C and NumPy compared."""
    folder = path.parent
    status = _bounded(SHOW_SECONDS, ["show", str(path)])
    _lines_bounded(capsys.readouterr().err)
    assert status in (0, 1, 2)
    if status != 0:
        return
    runs = {}
    for backend in ("numpy", "c") if with_c and CHC else ("numpy",):
        out = Path(folder) / f"{backend}.csv"
        runs[backend] = (_bounded(RUN_SECONDS, ["run", str(path), "--backend", backend,
                                                "-o", str(out), *extra]), out)
        _lines_bounded(capsys.readouterr().err)
        assert runs[backend][0] in (0, 1, 2)
    if len(runs) == 2 and runs["numpy"][0] == runs["c"][0] == 0:
        _agree(runs["numpy"][1], runs["c"][1])


def test_the_campaign_fails_on_a_hang() -> None:
    """The time bound itself: a command that runs too long is a Hang, not a pass."""
    with pytest.raises(Hang):
        _bounded(1, ["run", str(EXAMPLES / "crank_slider.yaml"), "--backend", "numpy",
                     "--dt", "1e-5"])

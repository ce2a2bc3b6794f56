"""The generated C <prefix>_senses_rows: a whole run's senses in one call, each row equal to
the per-row <prefix>_senses (the reference), with one p[] for all rows, with one per row (an
input run's), without parameters (p NULL), and nothing at all for no rows."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from codegen_support import compiled

from symkin.runtime.kernel import Kernel

EXAMPLES = Path(__file__).resolve().parents[3] / "examples"
pytestmark = pytest.mark.filterwarnings("ignore::symkin.errors.SymkinWarning")


def _kernel(name: str) -> Kernel:
    kernel = compiled(EXAMPLES / f"{name}.yaml", "c")  # from the goldens
    assert kernel.backend == "c" and len(kernel.senses) >= 2
    return kernel


@pytest.fixture(scope="module")
def cardan() -> Kernel:  # senses that read p[] (the shafts' axes are parameters)
    return _kernel("cardan")


def _rows(kernel: Kernel, count: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(7)  # any q: a sense is a function of q, t, p, assembled or not
    return rng.normal(size=(count, kernel.nq)), np.linspace(0.0, 1.0, count)


def _one_by_one(kernel: Kernel, q: np.ndarray, t: np.ndarray, p=None) -> np.ndarray:
    return np.array([kernel.sense_values(q[k], t[k], None if p is None else p[k])
                     for k in range(t.size)])


def test_one_call_equals_the_rows_called_one_by_one(cardan):
    q, t = _rows(cardan, 9)
    assert np.array_equal(cardan.sense_rows(q, t), _one_by_one(cardan, q, t))


def test_a_p_per_row_is_read_at_its_own_row(cardan):
    q, t = _rows(cardan, 6)
    p = np.outer(1.0 + 0.3 * np.arange(t.size), cardan.p_values)  # every row its own p[]
    got = cardan.sense_rows(q, t, p)
    assert np.array_equal(got, _one_by_one(cardan, q, t, p))
    assert not np.array_equal(got, cardan.sense_rows(q, t))  # the rows' p[] mattered


def test_a_mechanism_without_parameters():
    delta = _kernel("delta")
    assert delta.p_values.size == 0  # p[] is NULL in the call
    q, t = _rows(delta, 5)
    assert np.array_equal(delta.sense_rows(q, t), _one_by_one(delta, q, t))


def test_no_rows_no_call(cardan):
    assert cardan.sense_rows(np.zeros((0, cardan.nq)), np.zeros(0)).shape == (0, 3)

"""Fixtures of the sweep tests that stop, start singular or re-run sets."""

from __future__ import annotations

import pytest

from symkin.sweeps import batch
from tests.driver_support import kernel_for


@pytest.fixture(scope="module", params=["c", "numpy"])
def crank_slider(request, crank_slider_system):
    return kernel_for(crank_slider_system, request.param)


@pytest.fixture
def reruns(monkeypatch):
    """The sets re-run through symkin.solve, by index within their chunk."""
    seen: list[int] = []
    original = batch._solve_one

    def spy(kernel, p, t, q0, options, chunk, j):
        seen.append(j)
        return original(kernel, p, t, q0, options, chunk, j)

    monkeypatch.setattr(batch, "_solve_one", spy)
    return seen

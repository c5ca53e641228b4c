"""The Kalman/RTS and recovery kernels' docstrings show an example that runs.

As the particle filter's kernels (``tests/particle_filter/test_docstrings.py``): a user who
calls ``rts_smooth``, ``recover_gap`` or ``goal_directed_path`` from their own tracker finds
shapes, errors and a call that works in ``help()``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import pytest

import pftrack
from pftrack import kalman
from tests.particle_filter.test_docstrings import check_sections, run_examples

KERNELS: dict[str, Callable[..., Any]] = {
    "cv_predict": kalman.cv_predict,
    "cv_update": kalman.cv_update,
    "rts_smooth": kalman.rts_smooth,
    "recover_gap": pftrack.recover_gap,
    "goal_directed_path": pftrack.goal_directed_path,
}


@pytest.mark.parametrize("name", KERNELS)
def test_the_docstring_has_every_section(name: str) -> None:
    check_sections(KERNELS[name], name)


@pytest.mark.parametrize("name", KERNELS)
def test_the_docstring_example_runs(name: str) -> None:
    run_examples(KERNELS[name], name)

"""The public kernels' docstrings say shapes, dtypes and errors, and hold an example that runs.

A user who writes their own filter reads ``help(pftrack.systematic_resample)``: each kernel
documents its parameters, its result, what it refuses, and shows a call (run here as a
doctest, so that an example cannot drift from what the code returns).
"""

from __future__ import annotations

import doctest
import re
from collections.abc import Callable
from typing import Any

import pytest

import pftrack
from pftrack.particle_filter import estimate, propagate

KERNELS: dict[str, Callable[..., Any]] = {
    "systematic_resample": pftrack.systematic_resample,
    "stratified_resample": pftrack.stratified_resample,
    "multinomial_resample": pftrack.multinomial_resample,
    "residual_resample": pftrack.residual_resample,
    "hsv_bins": pftrack.hsv_bins,
    "box_histograms": pftrack.box_histograms,
    "bhattacharyya_coefficient": pftrack.bhattacharyya_coefficient,
    "bhattacharyya_distance": pftrack.bhattacharyya_distance,
    "bhattacharyya_weights": pftrack.bhattacharyya_weights,
    "box_weights": pftrack.box_weights,
    "propagate": propagate,
    "estimate": estimate,
}


def check_sections(fn: Callable[..., Any], name: str, skip: tuple[str, ...] = ()) -> None:
    """Assert that `fn`'s docstring has the numpydoc sections a kernel's needs (but `skip`)."""
    doc = fn.__doc__ or ""
    for section in ("Parameters", "Returns", "Raises", "Examples"):
        if section in skip:
            continue
        assert re.search(rf"^\s*{section}\n\s*-{{{len(section)}}}\n", doc, re.M), (
            f"{name}'s docstring has no {section} section"
        )


def run_examples(fn: Callable[..., Any], name: str) -> None:
    """Run `fn`'s docstring examples as doctests; assert there are some and none fails."""
    tests = doctest.DocTestFinder(recurse=False).find(fn, name, globs={})
    examples = [e for t in tests for e in t.examples]
    assert examples, f"{name}'s docstring has no example"
    runner = doctest.DocTestRunner(optionflags=doctest.NORMALIZE_WHITESPACE)
    for t in tests:
        runner.run(t)
    result = runner.summarize(verbose=False)
    assert result.failed == 0, f"{name}'s example failed (see the output above)"


@pytest.mark.parametrize("name", KERNELS)
def test_the_docstring_has_every_section(name: str) -> None:
    # propagate updates its particles in place and returns None
    check_sections(KERNELS[name], name, ("Returns",) if name == "propagate" else ())


@pytest.mark.parametrize("name", KERNELS)
def test_the_docstring_example_runs(name: str) -> None:
    run_examples(KERNELS[name], name)

"""Every public path to a ``pftrack._core`` class method answers a wrong type in one line.

``_core``'s class methods (``BackgroundModel``, ``RJMCMCTracker``, ``BinnedImage``) given an
argument pybind11 cannot convert answer with its multi-line "incompatible function arguments"
list of signatures. The public wrappers check first; this probe feeds None, a list, a float32
(8, 8, 3) array and a 0-d array to each argument a public class or function forwards to one.
Three got through (left62): ``RJMCMCFilter.step``'s `candidate_hists` and ``RJMCMCFilter.warp``'s
`affine` as a 3-D array (pybind11's list), and ``BinnedImage``'s `n_bins` as a float array
(NumPy's "only integer scalar arrays can be converted to a scalar index", naming nothing).
``PaperDetector.model`` hands out the core's ``BackgroundModel`` itself, to read: its methods
are the private core's, left as they are (docs/kernels.md).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

import pftrack
from pftrack.detection import PaperConfig, PaperDetector
from pftrack.particle_filter import (
    BinnedImage,
    ColourParticleFilter,
    MHColourParticleFilter,
    RJMCMCConfig,
    RJMCMCFilter,
    hsv_bins,
)
from pftrack.particle_filter.filter import step_filters, step_filters_summary

BAD = {
    "None": None,
    "list": [[1, 2], [3, 4]],
    "float32": np.zeros((8, 8, 3), np.float32),
    "0-d": np.array(3.0),
}
FRAME = np.full((48, 64, 3), 90, np.uint8)
IMAGE = hsv_bins(FRAME)
MASK = np.zeros((48, 64), np.uint8)
BOX = np.array([[30.0, 20.0, 10.0, 20.0]])


def _filter(cls: type[ColourParticleFilter]) -> ColourParticleFilter:
    return cls(BOX[0], np.full(IMAGE.n_bins, 1 / IMAGE.n_bins), rng=0)


PATHS: dict[str, Callable[[Any], object]] = {
    "PaperDetector.detect": lambda x: PaperDetector(PaperConfig()).detect(x),
    "PaperDetector.foreground": lambda x: PaperDetector(PaperConfig()).foreground(x),
    "PaperDetector.prime": lambda x: PaperDetector(PaperConfig()).prime([x]),
    "BinnedImage bins": lambda x: BinnedImage(x, 10),
    "BinnedImage n_bins": lambda x: BinnedImage(np.zeros((4, 4), np.int16), x),
    "RJMCMCFilter.step binned": lambda x: RJMCMCFilter(RJMCMCConfig(), rng=0).step(x, MASK, []),
    "RJMCMCFilter.step mask": lambda x: RJMCMCFilter(RJMCMCConfig(), rng=0).step(IMAGE, x, []),
    "RJMCMCFilter.step candidates": lambda x: RJMCMCFilter(RJMCMCConfig(), rng=0).step(
        IMAGE, MASK, x
    ),
    "RJMCMCFilter.step candidate_hists": lambda x: RJMCMCFilter(RJMCMCConfig(), rng=0).step(
        IMAGE, MASK, BOX, x
    ),
    "RJMCMCFilter.warp": lambda x: RJMCMCFilter(RJMCMCConfig(), rng=0).warp(x),
    "ColourParticleFilter.step": lambda x: _filter(ColourParticleFilter).step(x),
    "MHColourParticleFilter.step": lambda x: _filter(MHColourParticleFilter).step(x),
    "step_filters": lambda x: step_filters([_filter(ColourParticleFilter)], x),
    "step_filters_summary": lambda x: step_filters_summary([_filter(ColourParticleFilter)], x),
    "Tracker.update frame": lambda x: pftrack.Tracker().update(np.zeros((0, 5)), x),
}


@pytest.mark.parametrize("bad", BAD, ids=list(BAD))
@pytest.mark.parametrize("path", PATHS, ids=list(PATHS))
def test_a_wrong_type_is_one_line(path: str, bad: str) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a grey frame's note: not what is tested
        try:
            PATHS[path](BAD[bad])
        except (TypeError, ValueError) as exc:
            message = str(exc)
        else:
            return  # taken (None candidate_hists: computed; a list of ints as bins)
    assert "\n" not in message and "incompatible function arguments" not in message, message
    assert "only integer scalar arrays" not in message, message  # names no argument


def test_the_three_that_got_through_name_the_argument() -> None:
    rj = RJMCMCFilter(RJMCMCConfig(), rng=0)
    hists = r"candidate_hists must have shape \(K, B\), one row of 110 bins per candidate"
    with pytest.raises(ValueError, match=rf"^RJMCMCFilter.step: {hists}, got \(8, 8, 3\)$"):
        rj.step(IMAGE, MASK, BOX, BAD["float32"])
    with pytest.raises(ValueError, match=r"^RJMCMCFilter.warp: affine must have shape \(2, 3\), "
                       r"got \(8, 8, 3\)$"):  # fmt: skip
        rj.warp(BAD["float32"])
    with pytest.raises(TypeError, match=r"^BinnedImage: n_bins must be an int, got ndarray of "
                       r"float64$"):  # fmt: skip
        BinnedImage(np.zeros((4, 4), np.int16), np.array(3.0))  # type: ignore[arg-type]
    assert BinnedImage(np.zeros((4, 4), np.int16), np.array(3)).n_bins == 3  # an int array: taken

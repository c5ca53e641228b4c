"""What a user sees when a filter's step refuses its values: the public function they called
(``ColourParticleFilter.step``, ``MHColourParticleFilter.step``, ``step_filters``) names the
error, not the C++ step inside it (were ``sis_step: ...``, ``mh_step: ...`` and
``sis_step_batch: ...``)."""

from __future__ import annotations

import re
from collections.abc import Callable

import numpy as np
import pytest

from pftrack import _core
from pftrack.particle_filter import (
    ColourParticleFilter,
    HsvBinning,
    MHColourParticleFilter,
    hsv_bins,
)
from pftrack.particle_filter.filter import step_filters

BOX = np.array([40.0, 30.0, 10.0, 20.0])


def _frame() -> np.ndarray:
    return np.random.default_rng(0).integers(0, 256, (60, 80, 3), dtype=np.uint8)


def _nan_particle(f: ColourParticleFilter) -> None:
    f.particles[2, 1] = np.nan


def _short_reference(f: ColourParticleFilter) -> None:
    f.reference = f.reference[:20].copy()  # set directly, past set_reference's check


def _inf_mean(f: ColourParticleFilter) -> None:
    f.means[0, 0] = np.inf


def _zero_weights(f: ColourParticleFilter) -> None:
    f.weights[:] = 0.0


def _few_weights(f: ColourParticleFilter) -> None:
    f.weights = np.full(3, 1 / 3)


def _five_columns(f: ColourParticleFilter) -> None:
    f.particles = np.ones((f.particles.shape[0], 5))


BAD: dict[str, tuple[Callable[[ColourParticleFilter], None], str]] = {
    "NaN particle": (_nan_particle, r"particles has a non-finite value nan at \[2, 1\]"),
    "reference of 20 bins": (_short_reference, r"reference has 20 bins, the image 110"),
    "inf mean": (_inf_mean, r"means has a non-finite value inf"),
    "zero weights": (_zero_weights, r"weights sum to 0"),
    "3 weights": (_few_weights, r"weights"),
    "5 columns": (_five_columns, r"particles"),
}


def _expected_name(call: str, cls: type) -> str:
    return f"{cls.__name__}.step: " if call == "step" else r"step_filters: filters\[1\]"


@pytest.mark.parametrize("cls", [ColourParticleFilter, MHColourParticleFilter])
@pytest.mark.parametrize("call", ["step", "step_filters"])
@pytest.mark.parametrize("bad", list(BAD))
def test_step_errors_name_the_public_call(cls, call, bad):
    image = hsv_bins(_frame())
    ref = _core.box_histograms(image, BOX[None])[0] + 1e-3
    good, f = cls(BOX, ref, rng=0), cls(BOX, ref, rng=1)
    spoil, words = BAD[bad]
    spoil(f)
    with pytest.raises(ValueError, match=_expected_name(call, cls)) as info:
        if call == "step":
            f.step(image)
        else:
            step_filters([good, f], image)
    text = str(info.value)
    assert "sis_step" not in text and "mh_step" not in text, text
    assert re.search(words, text), text


@pytest.mark.parametrize("cls", [ColourParticleFilter, MHColourParticleFilter])
@pytest.mark.parametrize("call", ["step", "step_filters"])
def test_image_of_another_binning_is_named(cls, call):
    binned = hsv_bins(_frame())
    ref = _core.box_histograms(binned, BOX[None])[0] + 1e-3
    f = cls(BOX, ref, rng=0)
    other = hsv_bins(_frame(), binning=HsvBinning(n_h=4, n_s=4, n_v=4))
    with pytest.raises(ValueError) as info:
        f.step(other) if call == "step" else step_filters([f], other)
    text = str(info.value)
    public = f"{cls.__name__}.step" if call == "step" else "step_filters: filters[0]"
    assert text.startswith(public), text
    assert "reference has 110 bins, the image 20" in text and "HsvBinning" in text, text

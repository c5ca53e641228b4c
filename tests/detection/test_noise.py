"""A video too noisy for background subtraction is said, once (`paper.NOISY_LEVEL`)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from pftrack.detection import PaperDetector
from pftrack.detection.paper import NOISY_FRAMES
from pftrack.io.mot import group_by_frame
from pftrack.synthetic import make_scene
from pftrack.tracking import track_frames


def _noisy(sigma: float, n: int = NOISY_FRAMES + 4) -> list[np.ndarray]:
    """`make_scene` frames with Gaussian sensor noise of `sigma` grey levels (seeded)."""
    rng = np.random.default_rng(5)
    frames = make_scene(n, rng=1, noise=0).frames
    return [np.clip(f + rng.normal(0, sigma, f.shape), 0, 255).astype(np.uint8) for f in frames]


def _said(caught: list[warnings.WarningMessage]) -> list[str]:
    return [str(w.message) for w in caught if "noisy or changing video" in str(w.message)]


@pytest.mark.parametrize("call", ["detect", "foreground"])
def test_a_noisy_video_is_said_once_a_video(call: str) -> None:
    """Was: sensor noise of 25 grey levels took a scene's MOTA from 95 to 29 (40: -34, nine
    ids for five people), the threshold at t_max all along, without a word."""
    frames = _noisy(25)
    det = PaperDetector()
    for again in (False, True):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            for k, frame in enumerate(frames, start=1):
                getattr(det, call)(frame)
                if k < NOISY_FRAMES:  # a passing burst of noise is not said
                    assert _said(caught) == []
        said = _said(caught)
        assert len(said) == 1, (again, said)
        assert "its bound t_max" in said[0] and "the noise itself passes it" in said[0]
        if call == "detect":
            assert "people come in fragments or are missed" in said[0]
        else:
            assert "--no-refine" in said[0]
        det.reset()  # a new video: said again


def test_noise_below_t_max_is_said_and_steady_video_is_not() -> None:
    """sigma 8: the threshold at 44 (MOTA 71); sigma 4 stays at t_min 25 (MOTA 94, as 3)."""
    for sigma, expected in ((8, 1), (4, 0)):
        det = PaperDetector()
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            for frame in _noisy(sigma):
                det.detect(frame)
        said = _said(caught)
        assert len(said) == expected, (sigma, said)
        if said:
            assert "the noise itself" not in said[0] and "t_max" not in said[0]


def test_a_tracking_run_gives_the_warning() -> None:
    frames = _noisy(25)
    truth = make_scene(len(frames), rng=1).truth
    dets = {f: r[:, 2:7] for f, r in group_by_frame(truth).items()}
    for given, words in ((None, "people come in fragments"), (dets, "--no-refine")):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            track_frames(frames, detections=given)
        said = _said(caught)
        assert len(said) == 1 and words in said[0], said

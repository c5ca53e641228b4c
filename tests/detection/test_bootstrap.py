"""Background bootstrapping: which frames start the background, and that it removes ghosts."""

from __future__ import annotations

import numpy as np
import pytest

from pftrack.detection import PaperDetector
from pftrack.detection.bootstrap import bootstrap_frames


def numbered(n: int) -> list[np.ndarray]:
    return [np.full((4, 5, 3), i, np.uint8) for i in range(n)]


def test_spread_takes_evenly_spaced_frames_first_and_last() -> None:
    got = [int(f[0, 0, 0]) for f in bootstrap_frames(numbered(100), 5, "spread")]
    assert got == [0, 25, 50, 74, 99]


def test_first_takes_the_start_and_a_stream_falls_back_to_first() -> None:
    assert [int(f[0, 0, 0]) for f in bootstrap_frames(numbered(100), 3, "first")] == [0, 1, 2]
    stream = iter(numbered(100))  # no len(): only the start can be taken
    assert [int(f[0, 0, 0]) for f in bootstrap_frames(stream, 3, "spread")] == [0, 1, 2]


def test_short_video_gives_every_frame_and_none_gives_nothing() -> None:
    assert len(bootstrap_frames(numbered(7), 30, "spread")) == 7
    assert bootstrap_frames(numbered(7), 30, "none") == []
    assert bootstrap_frames(numbered(7), 0, "spread") == []


@pytest.mark.parametrize(("n", "mode"), [(-1, "spread"), (3, "median"), (2.5, "first")])
def test_bad_arguments_raise(n: object, mode: str) -> None:
    with pytest.raises(ValueError, match="bootstrap"):
        bootstrap_frames(numbered(5), n, mode)  # type: ignore[arg-type]


def person_present_from_frame_one(n: int = 60) -> tuple[list[np.ndarray], np.ndarray]:
    """A textured scene; a 10x30 block stands at x 20..30 for the first third, then walks away
    right at 3 px a frame. Returns the frames and the empty background."""
    rng = np.random.default_rng(1)
    bg = rng.integers(60, 190, size=(60, 120, 3)).astype(np.uint8)
    frames = []
    for k in range(n):
        f = bg.copy()
        x = 20 if k < n // 3 else 20 + 3 * (k - n // 3)
        if x < 110:
            f[20:50, x : x + 10] = (30, 200, 30)
        frames.append(f)
    return frames, bg


def test_spread_bootstrap_leaves_no_ghost_where_first_frames_do() -> None:
    frames, _ = person_present_from_frame_one()
    ghost_area = {}
    for mode in ("spread", "first"):
        det = PaperDetector()
        det.prime(bootstrap_frames(frames, 30, mode))
        masks = [det.detect(f).mask for f in frames]
        # the last frame: the block has walked off; anything at x 20..30 is a ghost
        ghost_area[mode] = int((masks[-1][20:50, 20:30] > 0).sum())
    assert ghost_area["spread"] == 0
    assert ghost_area["first"] > 100

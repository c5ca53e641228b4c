"""A blind coast ends: LifecycleConfig.blind_coast.

With given detections on frames of one colour (a loop with only boxes passes black frames, as
experiments.public_detections does for the MOT15 sequences without video), a coasting track's
box is the centre filter's extrapolation alone. After more than `blind_coast` such frames with
detections in a row the track ends, and the offline linker decides whether the detection that
re-finds the object continues it (docs/tracking.md, "Blind coasts end after 3 frames").
The built-in detector's tracks too: its colour bins count foreground only, so a track coasting
over background, its object gone from the foreground, is blind as well.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable

import numpy as np
import pytest

import pftrack
from pftrack._typing import F64
from pftrack.particle_filter import box_histograms, hsv_bins
from pftrack.tracking.config import LifecycleConfig, TrackerConfig
from pftrack.tracking.track import LiveTrack

BLACK = np.zeros((120, 200, 3), np.uint8)
# black frames are the point here: the tracker's warning about them is expected
pytestmark = pytest.mark.filterwarnings("ignore:frame 1 is blank:UserWarning")


def _textured() -> np.ndarray:
    return np.random.default_rng(0).integers(40, 200, BLACK.shape, dtype=np.uint8)


def _tracker(blind: int | None) -> pftrack.Tracker:
    config = TrackerConfig()
    life = dataclasses.replace(config.lifecycle, blind_coast=blind)
    refine = dataclasses.replace(config.refine, enabled=False)
    config = dataclasses.replace(config, lifecycle=life, refine=refine)
    return pftrack.Tracker.from_config(config, 0, prime_frames=0)


def _stretches(outs: Iterable[F64], gap: range, left_of: float) -> list[set[int]]:
    """Ids of the rows left of x = `left_of` (the walker's), before `gap` and after it.

    `outs` are the outputs of frames 1, 2, ...
    """
    seen: list[set[int]] = [set(), set()]
    for k, out in enumerate(outs, start=1):
        if k not in gap:
            seen[k > gap.start] |= {int(r[4]) for r in out if r[0] < left_of}
    return seen


def _ids(tracker: pftrack.Tracker, frame: np.ndarray, others: bool) -> list[set[int]]:
    """Online ids of a walker missed on frames 11-16 (6 frames), per stretch seen.

    The walker moves 2 px a frame; with `others`, a second person far from it is detected on
    every frame, so frames 11-16 have detections (a miss counts).
    """

    def update(k: int) -> F64:
        x = 20.0 + 2.0 * k
        dets = [] if 11 <= k <= 16 else [[x, 30.0, x + 20.0, 80.0, 0.95]]
        if others:
            dets.append([160.0, 30.0, 180.0, 80.0, 0.95])
        return tracker.update(np.array(dets).reshape(-1, 5), frame)

    return _stretches(map(update, range(1, 31)), range(11, 17), 120)


def test_a_blind_coast_ends_after_blind_coast_frames() -> None:
    before, after = _ids(_tracker(3), BLACK, others=True)
    assert len(before) == len(after) == 1
    assert before != after  # ended after 4 blind frames: the walker's return is a new track


def test_without_the_rule_the_track_coasts_through() -> None:
    before, after = _ids(_tracker(None), BLACK, others=True)
    assert before == after  # max_coast (10) covers the 6 frames


def test_a_coast_the_colour_sees_is_not_blind() -> None:
    before, after = _ids(_tracker(3), _textured(), others=True)
    assert before == after


def test_frames_without_any_detection_are_not_counted() -> None:
    before, after = _ids(_tracker(3), BLACK, others=False)
    assert before == after  # a detector that saw nothing on frames 11-16 missed no one


def test_the_count_is_blind_frames_with_detections_in_a_row() -> None:
    cfg = TrackerConfig()
    box = np.array([30.0, 20.0, 20.0, 40.0])
    hist = box_histograms(hsv_bins(BLACK), [[40.0, 40.0, 20.0, 40.0]])[0] + 1e-3
    t = LiveTrack(1, box, hist, cfg, 0, 0.9)
    t.hits = cfg.lifecycle.min_hits
    rules = LifecycleConfig(blind_coast=2)
    for k in range(1, 4):
        t.predict(hsv_bins(BLACK), cfg.motion.colour_noise)
        assert t.flat
        t.coast(detected=True)
        assert t.blind == k
    assert not t.alive(rules)
    assert t.alive(LifecycleConfig(blind_coast=None))
    assert t.alive(LifecycleConfig(blind_coast=3))
    t.predict(hsv_bins(_textured()), cfg.motion.colour_noise)
    assert not t.flat
    t.coast(detected=True)
    assert t.blind == 0  # a frame the colour saw resets the count
    t.blind = 2
    t.matched(0.9, 0)
    assert t.blind == 0


def test_a_track_from_an_older_checkpoint_has_no_blind_count() -> None:
    cfg = TrackerConfig()
    hist = np.full(hsv_bins(BLACK).n_bins, 1.0)
    t = LiveTrack(1, np.array([30.0, 20.0, 20.0, 40.0]), hist / hist.sum(), cfg, 0, 0.9)
    del t.__dict__["blind"], t.__dict__["flat"]  # pickled before the count existed
    assert (t.blind, t.flat) == (0, False)
    assert t.alive(cfg.lifecycle)


BACKGROUND = np.random.default_rng(1).integers(90, 110, (160, 240, 3), dtype=np.uint8)


def _street(k: int, gone: bool) -> np.ndarray:
    """Frame k: a red walker (3 px a frame; absent when `gone`) and a blue person standing."""
    f = BACKGROUND.copy()
    if not gone:
        f[40:100, 20 + 3 * k : 40 + 3 * k] = (30, 30, 200)
    f[50:110, 190:210] = (200, 60, 30)  # detected on every frame: the frames have detections
    return f


def _builtin_ids(blind: int | None) -> list[set[int]]:
    """Online ids of the walker before and after it leaves the foreground on frames 21-26."""
    config = TrackerConfig()
    life = dataclasses.replace(config.lifecycle, blind_coast=blind)
    tracker = pftrack.Tracker.from_config(dataclasses.replace(config, lifecycle=life), 0)
    tracker.prime([BACKGROUND] * 30)
    outs = (tracker.update(None, _street(k, 21 <= k <= 26)) for k in range(1, 41))
    return _stretches(outs, range(21, 27), 170)


def test_the_builtin_detectors_blind_coast_ends() -> None:
    """Off the foreground no particle counts a pixel: the likelihood is flat, the coast blind.

    Was: the built-in detector's tracks kept `max_coast` (10), which covered the 6 frames.
    """
    before, after = _builtin_ids(3)
    assert len(before) == len(after) == 1
    assert before != after
    assert _builtin_ids(None) == [before, before]


@pytest.mark.parametrize(("bad", "error"), [(-1, ValueError), (2.5, TypeError), ("3", TypeError)])
def test_blind_coast_is_checked(bad: object, error: type[Exception]) -> None:
    with pytest.raises(error, match=r"^LifecycleConfig: blind_coast .*integer in \[0, "):
        LifecycleConfig(blind_coast=bad)  # type: ignore[arg-type]

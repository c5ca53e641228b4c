"""A tentative track may miss as often as the detector misses the people already tracked.

``LifecycleConfig.miss_window``: the confirmed tracks' miss rate ``p`` (in the frame,
overlapping no other track, over the last `miss_window` frames with detections) lets a
tentative track miss ``round((min_hits - 1) p / (1 - p))`` frames with detections in all
(docs/tracking.md, stop 69).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from pftrack._typing import F64
from pftrack.tracking.config import TrackerConfig
from pftrack.tracking.track import LiveTrack
from pftrack.tracking.tracker import MultiObjectTracker

SHAPE = (120, 200, 3)


def _config(window: int | None) -> TrackerConfig:
    config = TrackerConfig()
    life = dataclasses.replace(config.lifecycle, miss_window=window)
    refine = dataclasses.replace(config.refine, enabled=False)
    return dataclasses.replace(config, lifecycle=life, refine=refine)


def _live(box: list[float], hits: int, config: TrackerConfig) -> LiveTrack:
    hist = np.full(config.binning.n_bins, 1.0 / config.binning.n_bins)
    t = LiveTrack(1, np.array(box, np.float64), hist, config, 0, 1.0)
    t.hits = hits
    return t


# -- the allowance from the rate: a NumPy reference -------------------------------------------
def _reference(frames: list[tuple[F64, list[int], list[bool]]], window: int, min_hits: int,
               shape: tuple[int, ...], max_coast: int) -> int:  # fmt: skip
    """Loops over the frames' tracks: the misses a tentative track may have had."""
    kept = []
    for boxes, hits, matched in frames:
        misses = counted = 0
        for i, (x, y, w, h) in enumerate(boxes):
            before = hits[i] - matched[i]
            if before < min_hits or x < 0 or y < 0 or x + w > shape[1] or y + h > shape[0]:
                continue
            touches = False
            for j, (u, v, bw, bh) in enumerate(boxes):
                if j != i and min(x + w, u + bw) > max(x, u) and min(y + h, v + bh) > max(y, v):
                    touches = True
            if touches:
                continue
            counted += 1
            misses += not matched[i]
        kept = [*kept, (misses, counted)][-window:]
    total = sum(n for _, n in kept)
    if total == 0:
        return 0
    p = sum(m for m, _ in kept) / total
    return max_coast if p >= 1 else math.floor((min_hits - 1) * p / (1 - p) + 0.5)


@pytest.mark.parametrize("window", [1, 3, 50])
def test_the_allowance_follows_a_numpy_reference(window):
    rng = np.random.default_rng(4)
    config = _config(window)
    rules = config.lifecycle
    tracker = MultiObjectTracker(config, rng=0)
    frames = []
    for _ in range(12):
        n = int(rng.integers(1, 7))
        xy = rng.uniform([-20, -20], [190, 110], (n, 2))  # some boxes leave the frame
        boxes = np.column_stack([xy, rng.uniform(8, 30, (n, 2))])
        hits = rng.integers(1, 8, n).tolist()
        matched = (rng.random(n) < 0.6).tolist()
        # the tracker counts this frame's matches in hits before it measures (LiveTrack.matched)
        tracker.tracks = [
            _live(b.tolist(), h + m, config) for b, h, m in zip(boxes, hits, matched, strict=True)
        ]
        matches = [(i, i) for i in range(n) if matched[i]]
        got = tracker._count_misses(boxes, matches, True, SHAPE, config)
        frames.append((boxes, [h + m for h, m in zip(hits, matched, strict=True)], matched))
        want = _reference(frames, window, rules.min_hits, SHAPE, rules.max_coast)
        assert got == want


def test_frames_without_detections_are_not_counted():
    config = _config(50)
    tracker = MultiObjectTracker(config, rng=0)
    tracker.tracks = [_live([10, 10, 20, 40], 9, config)]
    # a confirmed track without its detection, but the frame had none: no miss counted
    assert tracker._count_misses(np.array([[10.0, 10, 20, 40]]), [], False, SHAPE, config) == 0
    assert len(tracker._misses) == 0
    # missed on 1 of 2 frames with detections: p = 1/2, (4 - 1) * 1 = 3 misses allowed
    assert tracker._count_misses(np.array([[10.0, 10, 20, 40]]), [], True, SHAPE, config) == 10
    tracker.tracks[0].hits += 1
    got = tracker._count_misses(np.array([[10.0, 10, 20, 40]]), [(0, 0)], True, SHAPE, config)
    assert got == 3


# -- a tentative track lives on its misses ----------------------------------------------------
def test_a_tentative_track_may_miss_the_allowance_in_all():
    config = _config(50)
    rules = config.lifecycle
    t = _live([10, 10, 20, 40], 1, config)
    t.coast(detected=False)  # no detection at all: not a miss
    assert t.missed_all == 0
    t.coast()
    assert t.missed_all == 1
    assert not t.alive(rules)  # tentative_coast 0, and no allowance
    assert t.alive(rules, 1)
    t.matched(1.0, 0)
    t.coast()
    assert (t.missed, t.missed_all) == (1, 2)  # a match clears `missed`, not the count in all
    assert not t.alive(rules, 1)
    assert t.alive(rules, 2)
    assert t.alive(dataclasses.replace(rules, tentative_coast=1))  # one in a row: as before


# -- whole runs -------------------------------------------------------------------------------
def _frame() -> np.ndarray:
    """Grey, with three coloured people: A (left, red), C (green) and B (right, blue)."""
    f = np.full(SHAPE, 90, np.uint8)
    f[20:80, 30:50] = (40, 40, 220)
    f[20:80, 85:105] = (40, 200, 40)
    f[20:80, 140:160] = (220, 60, 40)
    return f


def _run(window: int | None, a_missed: set[int]) -> dict[int, list[int]]:
    """Frames each id of person B is reported on (its history back-filled).

    A is detected from frame 1 except on `a_missed`, C on every frame (so every frame has
    detections: a miss counts), B from frame 20, missed on frame 21.
    """
    tracker = MultiObjectTracker(_config(window), rng=0)
    frame = _frame()
    b_ids: dict[int, list[int]] = {}
    for k in range(1, 41):
        dets = [[85.0, 20, 20, 60, 0.95]]
        if k not in a_missed:
            dets.append([30.0, 20, 20, 60, 0.95])
        if k >= 20 and k != 21:
            dets.append([140.0, 20, 20, 60, 0.95])
        for t in tracker.update(frame, np.array(dets).reshape(-1, 5)):
            if t.box_xywh[0] > 100:
                for f, _, _ in t.history:
                    b_ids.setdefault(t.id, []).append(f)
                b_ids.setdefault(t.id, []).append(k)
    return b_ids


def test_a_person_missed_after_birth_is_kept_where_the_detector_misses_the_tracked():
    # A missed on 7 of 14 frames: p = 7 / 30 with C's, (4 - 1) p / (1 - p) rounds to 1
    missed = {k for k in range(6, 20) if k % 2 == 0}
    with_rule = _run(50, missed)
    assert len(with_rule) == 1
    (frames,) = with_rule.values()
    assert frames[0] == 20  # B's track born on frame 20 lived through its miss on 21
    without = _run(None, missed)
    (frames,) = without.values()
    assert frames[0] == 22  # born again on 22: frames 20-21 lost


def test_a_detector_that_misses_nothing_allows_no_miss():
    assert _run(50, set()) == _run(None, set())
    (frames,) = _run(50, set()).values()
    assert frames[0] == 22

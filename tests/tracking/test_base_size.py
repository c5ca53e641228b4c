"""The particle filter's box and the shape of the detections its track follows."""

from __future__ import annotations

import numpy as np
import pytest

from pftrack.synthetic import make_scene
from pftrack.tracking import LifecycleConfig, MultiObjectTracker, TrackerConfig


@pytest.mark.xfail(
    reason="the filter's base size (w0, h0) is the birth detection's and a re-seed only "
    "rescales it; taking the matched detection's size (or the track's smoothed size) as base "
    "size was measured and not kept: PETS09 public 80.7 / 81.4 / 61.0 -> 77.3 / 75.1 / 57.3 "
    "(MOTA / IDF1 / HOTA, seed 0), present 84.9 -> 80.7 MOTA, TUD built-in 52.1 -> 49.0 MOTA "
    "(docs/tracking.md, 'Tried, none kept')",
    strict=True,
)
def test_track_born_from_a_sliver_takes_the_shape_of_its_detections():
    """A person entering through the border: walker 3 of the scene is born from a 2 x 63 px
    sliver (its box clipped by the frame), then its boxes widen to 26 x 63 px; its truth boxes
    are the only detections. After 25 frames of full-size detections the filter's box should
    have their shape; it is a 4 x 126 px strip (the birth box scaled by s_max = 2)."""
    scene = make_scene(n_frames=60, n_walkers=3, rng=0, occluder=False)
    rows = scene.truth[scene.truth[:, 1] == 3]
    assert rows[0, 4] <= 3 and rows[-1, 4] >= 20  # born a sliver, full size at the end
    tracker = MultiObjectTracker(
        TrackerConfig(lifecycle=LifecycleConfig(min_hits=1, min_score=0.5)), rng=0
    )
    for f, frame in enumerate(scene.frames, start=1):
        r = rows[rows[:, 0] == f]
        tracker.update(frame, np.column_stack([r[:, 2:6], np.full(len(r), 0.9)]))
    assert len(tracker.tracks) == 1
    w, h = tracker.tracks[0].filter.box_cxcywh[2:]
    det_w, det_h = rows[-1, 4:6]
    assert 0.75 <= (w / h) / (det_w / det_h) <= 1.25, (w, h, det_w, det_h)
    assert 0.5 * det_h <= h <= 1.5 * det_h, (w, h, det_w, det_h)

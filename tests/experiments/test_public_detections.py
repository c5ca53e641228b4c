"""``experiments.public_detections``: black frames, noisy detections, one scene end to end."""

from __future__ import annotations

import numpy as np
import pytest

from experiments import public_detections as ex
from pftrack.eval import evaluate_sequence
from pftrack.synthetic import make_busy_scene
from pftrack.tracking import TrackerConfig, track_frames


def test_black_frames_share_one_read_only_array() -> None:
    frames = ex.BlackFrames(3, 8, 6)
    assert len(frames) == 3 and frames[0].shape == (6, 8, 3) and not frames[0].any()
    assert frames[0] is frames[-1] and not frames[0].flags.writeable
    assert len(list(frames)) == 3
    with pytest.raises(IndexError):
        frames[3]


def test_noisy_detections_are_seeded_and_close_to_the_truth() -> None:
    scene = make_busy_scene("groups", n_frames=60, rng=0)
    a = ex.noisy_detections(scene.truth, 60, 360, 480, seed=1)
    b = ex.noisy_detections(scene.truth, 60, 360, 480, seed=1)
    assert a.keys() == b.keys() and all(np.array_equal(a[f], b[f]) for f in a)
    n_truth = len(scene.truth)
    n_det = sum(len(d) for d in a.values())
    assert 0.8 * n_truth < n_det < 1.2 * n_truth  # 10 % missed, a false box every other frame
    run = track_frames(scene.frames, detections=a, config=TrackerConfig(), rng=0)
    s = evaluate_sequence(scene.truth, run.rows)
    assert s.mot.mota > 0.3 and s.hota.hota > 0.3  # the tracker follows the jittered boxes
